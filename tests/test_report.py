"""The papers' report (pkm.report): summary.json, report.md, figures, series, terminal table."""

from __future__ import annotations

import csv
import json
import math

import pytest

import pkm
from pkm import report
from pkm.errors import InvalidInputError, UnknownNameError
from pkm.papers import Row
from pkm.papers import hexapod as hexapod_study

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def hexapod_report(tmp_path_factory):
    """The report of the fastest paper (hexapod: rows and figures, ~1 s), written once for the module."""
    return report.run(tmp_path_factory.mktemp("report"), ["hexapod"], progress=False)


def _table_lines(md: str) -> list[str]:
    return [ln for ln in md.splitlines() if ln.startswith("| `")]


def test_summary_json_holds_the_rows_of_reproduce_and_consistent_counts(hexapod_report):
    """summary.json lists exactly the ids of hexapod.reproduce() with their values, and its counts add up."""
    data = json.loads(hexapod_report.summary.read_text())
    assert data["pkm_version"] == pkm.__version__
    paper = data["papers"]["hexapod"]
    assert paper["title"] == hexapod_study.TITLE
    rows = hexapod_study.reproduce()
    assert [r["id"] for r in paper["rows"]] == [r.id for r in rows]
    for got, row in zip(paper["rows"], rows):
        assert got["published"] == row.published and got["unit"] == row.unit and got["matches"] == row.matches
        assert math.isclose(got["computed"], row.computed, rel_tol=1e-9)
    c = paper["counts"]
    flags = [r["matches"] for r in paper["rows"]]
    assert c["rows"] == len(rows) == c["matches"] + c["mismatches"] + c["unchecked"]
    assert (c["matches"], c["mismatches"], c["unchecked"]) == (flags.count(True), flags.count(False), flags.count(None))
    assert c["no_published"] == sum(r["published"] is None for r in paper["rows"]) <= c["unchecked"]
    assert data["counts"] == c  # one paper: the totals are its counts
    assert paper["mismatches"] == [r["id"] for r in paper["rows"] if r["matches"] is False]


def test_report_md_has_one_table_row_per_row_and_flags_mismatches(hexapod_report):
    """report.md has one table line per Row, in order; each mismatch reads **no** and is named in the summary line."""
    md = hexapod_report.markdown.read_text()
    lines = _table_lines(md)
    rows = hexapod_report.papers[0].rows
    assert [ln.split("|")[1].strip().strip("`") for ln in lines] == [r.id for r in rows]
    for ln, r in zip(lines, rows):
        match_cell = ln.split(" | ")[5]
        assert match_cell == {True: "yes", False: "**no**", None: "—"}[r.matches]
    summary_line = next(ln for ln in md.splitlines() if ln.startswith(f"{len(rows)} rows:"))
    for r in hexapod_report.papers[0].mismatches:
        assert f"`{r.id}`" in summary_line


def test_figures_are_real_pngs_linked_from_the_report(hexapod_report):
    """Every figure lands under figures/hexapod/, is a PNG of more than 10 kB, and report.md links it, with the CSV
    series of its numbers linked just below it."""
    out, figs = hexapod_report.out_dir, hexapod_report.papers[0].figures
    assert len(figs) >= 3
    md = hexapod_report.markdown.read_text()
    listed = json.loads(hexapod_report.summary.read_text())["papers"]["hexapod"]["figures"]
    for f in figs:
        assert f.parent == out / "figures" / "hexapod"
        assert f.read_bytes()[:8] == PNG and f.stat().st_size > 10_000
        rel = f.relative_to(out).as_posix()
        assert f"]({rel})" in md and rel in listed
        below = md[md.index(f"]({rel})"):].split("\n\n", 2)[1]
        assert below.startswith("Its numbers: ") and all(f"series/hexapod/{n}.csv" in below
                                                          for n in hexapod_study.SERIES[f.stem])


def test_series_are_csv_files_that_parse(tmp_path):
    """The 3-PRS series (no figures) land under series/prs3/ as CSV with a header and equal-length numeric rows."""
    rep = report.run(tmp_path, ["prs3"], figures=False, progress=False)
    files = rep.papers[0].series
    assert files and not (tmp_path / "figures").exists()
    md = rep.markdown.read_text()
    for f in files:
        assert f.parent == tmp_path / "series" / "prs3" and f.suffix == ".csv"
        with f.open(newline="") as fh:
            header, *body = list(csv.reader(fh))
        assert len(header) >= 2 and len(body) > 10
        assert all(len(r) == len(header) for r in body)
        assert all(math.isfinite(float(x)) for r in body for x in r)
        assert f"]({f.relative_to(tmp_path).as_posix()})" in md


def _synthetic() -> report.Report:
    rows = (Row("x.a", 1.0, 1.05, "mm", 0.1, "Table 1", "close"),
            Row("x.b", 2.0, 3.0, "deg", 0.5, "Fig. 2", "off because | the paper rounds"),
            Row("x.c", None, float("nan"), "N", None, "sec. 3", "no published value"),
            Row("x.d", 10.0, 12.0, "ms", None, "sec. 4", "a bound", relation="<="))
    paper = report.PaperResult("x", "A synthetic paper", rows)
    from pathlib import Path

    return report.Report(Path("/nonexistent"), (paper,), Path("/nonexistent/summary.json"),
                         Path("/nonexistent/report.md"), 0.0)


def test_counts_and_formatting_of_a_synthetic_paper():
    """Counts split rows into 1 match, 2 mismatches, 1 unchecked; report.md escapes '|' and flags both
    mismatches; the terminal table explains each mismatch by its note; JSON turns NaN into "nan"."""
    rep = _synthetic()
    assert rep.counts == report.Counts(rows=4, matches=1, mismatches=2, unchecked=1, no_published=1, unexplained=2)
    assert "2 do not (2 without a reason)" in rep.counts.line()
    md = report.format_markdown(rep)
    lines = _table_lines(md)
    assert len(lines) == 4 and "off because \\| the paper rounds" in lines[1]
    assert [ln.split(" | ")[5] for ln in lines] == ["yes", "**no**", "—", "**no**"]
    assert "**Mismatches: `x.b`, `x.d`**" in md
    assert "<= published" in lines[3]
    text = report.format_table(rep)
    assert text.count("why: ") == 2 and "why: off because | the paper rounds" in text
    data = json.loads(json.dumps(report.summary_dict(rep), allow_nan=False))
    assert data["papers"]["x"]["rows"][2]["computed"] == "nan"
    assert data["papers"]["x"]["mismatches"] == ["x.b", "x.d"]


def test_terminal_table_lists_every_row(hexapod_report):
    """format_table prints the paper title, every row id with our value, and the totals."""
    text = report.format_table(hexapod_report)
    assert hexapod_study.TITLE in text and text.splitlines()[-1].startswith("total: ")
    assert "do not (each explained)" in text.splitlines()[-1] or "does not (each explained)" in text.splitlines()[-1]
    for r in hexapod_report.papers[0].mismatches:  # one line each, with its reason, above the total
        assert f"did not match: {r.id} " in text and r.why in text
    for r in hexapod_report.papers[0].rows:
        assert r.id in text and report.fmt_value(r.computed) in text


def test_bad_paper_names_are_refused_before_anything_is_written(tmp_path):
    """An unknown paper raises UnknownNameError listing the papers; no paper or a repeated one: InvalidInputError."""
    with pytest.raises(UnknownNameError, match="valid papers: 'hexapod'"):
        report.run(tmp_path / "a", ["hexapod", "nope"], progress=False)
    assert not (tmp_path / "a").exists()
    with pytest.raises(InvalidInputError):
        report.run(tmp_path / "b", [], progress=False)
    with pytest.raises(InvalidInputError):
        report.run(tmp_path / "c", ["hexapod", "hexapod"], progress=False)


def test_progress_bar_stays_off_when_stderr_is_not_a_terminal(tmp_path, capfd):
    """With progress=True but stderr captured (not a TTY), the report writes nothing to stderr."""
    report.run(tmp_path, ["hexapod"], figures=False, progress=True)
    assert capfd.readouterr().err == ""
