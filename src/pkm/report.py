"""The papers' published numbers next to ours, as files and as a terminal table (``pkm report``).

:func:`run` calls every study module of :mod:`pkm.papers` (``reproduce``, ``figures``, ``series``)
and writes, under its output directory::

    summary.json             every row (Row.to_dict), per paper with its title, counts, files
    report.md                a table per paper, mismatches named in its summary line, figures linked
    figures/<paper>/*.png    the papers' figures redrawn
    series/<paper>/*.csv     time series and maps behind them

:func:`format_table` renders the same rows as plain text for a terminal.
"""

from __future__ import annotations

import json
import math
import sys
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import pkm
from pkm import papers as _papers
from pkm._optional import require
from pkm.errors import InvalidInputError
from pkm.papers import Row

STEPS = ("reproduce", "figures", "series")


@dataclass(frozen=True)
class Counts:
    """How many rows of a paper (or of all) reproduce the published value.

    Attributes:
        rows: Rows in all.
        matches: Rows whose value matches the published one (``Row.matches is True``).
        mismatches: Rows that do not (``Row.matches is False``).
        unchecked: Rows with nothing to compare (``Row.matches is None``).
        no_published: Rows whose paper gives no value (``published is None``; a subset of ``unchecked``).
        unexplained: Mismatches without a :attr:`Row.why`.
    """

    rows: int
    matches: int
    mismatches: int
    unchecked: int
    no_published: int
    unexplained: int = 0

    @classmethod
    def of(cls, rows: Iterable[Row]) -> Counts:
        rows = list(rows)
        m = [r.matches for r in rows]
        return cls(len(rows), m.count(True), m.count(False), m.count(None), sum(r.published is None for r in rows),
                   sum(r.matches is False and not r.why for r in rows))

    def __add__(self, other: Counts) -> Counts:
        return Counts(*(a + b for a, b in zip(self.as_tuple(), other.as_tuple())))

    def as_tuple(self) -> tuple[int, ...]:
        return self.rows, self.matches, self.mismatches, self.unchecked, self.no_published, self.unexplained

    def to_dict(self) -> dict[str, int]:
        return dict(zip(("rows", "matches", "mismatches", "unchecked", "no_published", "unexplained"),
                        self.as_tuple()))

    def line(self) -> str:
        """``"5 rows: 3 match the paper, 1 does not (explained), 1 has no published value (ours recorded)"``."""
        said = "each explained" if not self.unexplained else f"{self.unexplained} without a reason"
        s = (f"{self.rows} rows: {self.matches} match{'es' * (self.matches == 1)} the paper, {self.mismatches} "
             f"do{'es' * (self.mismatches == 1)} not ({said})")
        if self.no_published:
            s += (f", {self.no_published} ha{'s' if self.no_published == 1 else 've'} no published value "
                  "(ours recorded)")
        if self.unchecked - self.no_published:
            s += f", {self.unchecked - self.no_published} cannot be compared"
        return s


@dataclass(frozen=True)
class PaperResult:
    """What the report gathered for one paper.

    Attributes:
        name: The paper's study module name (one of :func:`pkm.papers.names`).
        title: Its ``TITLE``.
        rows: Its rows, in the order ``reproduce()`` gives them.
        figures: PNG files written (absolute paths).
        series: CSV files written (absolute paths).
        seconds: Wall time of each step run [s].
    """

    name: str
    title: str
    rows: tuple[Row, ...]
    figures: tuple[Path, ...] = ()
    series: tuple[Path, ...] = ()
    seconds: dict[str, float] = field(default_factory=dict)

    @property
    def counts(self) -> Counts:
        return Counts.of(self.rows)

    @property
    def mismatches(self) -> tuple[Row, ...]:
        return tuple(r for r in self.rows if r.matches is False)


@dataclass(frozen=True)
class Report:
    """The outcome of :func:`run`.

    Attributes:
        out_dir: The output directory.
        papers: One result per paper, in the order asked.
        summary: Path of ``summary.json``.
        markdown: Path of ``report.md``.
        seconds: Wall time of the whole run [s].
    """

    out_dir: Path
    papers: tuple[PaperResult, ...]
    summary: Path
    markdown: Path
    seconds: float

    @property
    def counts(self) -> Counts:
        total = Counts(0, 0, 0, 0, 0)
        for p in self.papers:
            total = total + p.counts
        return total


def run(out_dir, papers: Sequence[str] | None = None, *, figures: bool = True, series: bool = True,
        progress: bool = True) -> Report:
    """Reproduce the papers and write the report under ``out_dir`` (see the module doc for the layout).

    Args:
        out_dir: Output directory (created if needed; files of a previous run are overwritten).
        papers: Study names among :func:`pkm.papers.names`, in the order to report them.
        figures: Redraw the figures (PNG) too.
        series: Write the CSV series too (for papers whose study has ``series``).
        progress: Show a tqdm bar on stderr (only when stderr is a terminal).

    Returns:
        A :class:`Report`; the rows are those of ``pkm.papers.<name>.reproduce()``.

    Raises:
        UnknownNameError: A name is not a paper (listing the valid ones), before anything runs.
        InvalidInputError: No paper, or one named twice.
        MissingDependencyError: ``figures`` without matplotlib (``pip install "pkm-robotics[figures]"``), before
            anything runs; a step that needs another extra (a series through :func:`pkm.sweep`) raises it when it runs.
    """
    names = _papers.names() if papers is None else tuple(papers)
    if not names:
        raise InvalidInputError("papers", f"name at least one paper among {list(_papers.names())}", papers)
    if len(set(names)) != len(names):
        raise InvalidInputError("papers", f"each paper once, got {list(names)}", papers)
    modules = {n: _papers.module(n) for n in names}
    if figures:
        require("figures", "pkm report's figures (--no-figures leaves them out)")
    out = Path(out_dir).resolve()
    out.mkdir(parents=True, exist_ok=True)

    plan = [(n, "reproduce") for n in names]
    plan += [(n, "figures") for n in names if figures]
    plan += [(n, "series") for n in names if series and modules[n].series is not None]
    plan.sort(key=lambda step: names.index(step[0]))  # paper by paper, steps in STEPS order (stable sort)

    from tqdm import tqdm

    t_start = time.perf_counter()
    got: dict[str, dict[str, Any]] = {n: {"rows": (), "figures": (), "series": (), "seconds": {}} for n in names}
    with tqdm(total=len(plan), desc="pkm report", unit="step", file=sys.stderr,
              disable=not (progress and sys.stderr.isatty())) as bar:
        for name, step in plan:
            bar.set_postfix_str(f"{name} {step}")
            mod = modules[name]
            t0 = time.perf_counter()
            if step == "reproduce":
                got[name]["rows"] = tuple(mod.reproduce())
            elif step == "figures":
                got[name]["figures"] = tuple(Path(p).resolve() for p in mod.figures(out / "figures" / name))
            else:
                got[name]["series"] = tuple(Path(p).resolve() for p in mod.series(out / "series" / name))
            got[name]["seconds"][step] = time.perf_counter() - t0
            bar.update()

    results = tuple(PaperResult(n, modules[n].TITLE, **got[n]) for n in names)
    summary, markdown = out / "summary.json", out / "report.md"
    report = Report(out, results, summary, markdown, 0.0)
    summary.write_text(json.dumps(summary_dict(report), indent=2, allow_nan=False) + "\n", encoding="utf-8")
    markdown.write_text(format_markdown(report), encoding="utf-8")
    return Report(out, results, summary, markdown, time.perf_counter() - t_start)


# ---------------------------------------------------------------------- summary.json
def summary_dict(report: Report) -> dict[str, Any]:
    """The content of ``summary.json``: version, total counts, and per paper its title, counts, rows, files.

    Non-finite numbers become the strings ``"nan"``, ``"inf"``, ``"-inf"`` (JSON has none); paths are
    relative to the output directory.
    """
    return {
        "pkm_version": pkm.__version__,
        "counts": report.counts.to_dict(),
        "papers": {
            p.name: {
                "title": p.title,
                "counts": p.counts.to_dict(),
                "mismatches": [r.id for r in p.mismatches],
                "rows": [jsonable(r.to_dict()) for r in p.rows],
                "figures": [_rel(f, report.out_dir) for f in p.figures],
                "series": [_rel(f, report.out_dir) for f in p.series],
                "seconds": {k: round(v, 3) for k, v in p.seconds.items()},
            }
            for p in report.papers
        },
    }


def jsonable(x: Any) -> Any:
    """``x`` with numpy arrays and scalars made plain Python, non-finite floats spelled as strings (valid JSON)."""
    if isinstance(x, dict):
        return {k: jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple, np.ndarray)):
        return [jsonable(v) for v in x]
    if isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return str(x)
    return x


def _rel(path: Path, root: Path) -> str:
    try:
        return path.relative_to(root).as_posix()
    except ValueError:
        return path.as_posix()


# ---------------------------------------------------------------------- formatting
def fmt_value(v: Any, empty: str = "—") -> str:
    """A row value for a table: 6 significant digits, booleans as true/false, ``empty`` for None."""
    if v is None:
        return empty
    if isinstance(v, (bool, np.bool_)):
        return "true" if v else "false"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        return f"{float(v):.6g}"
    return str(v)


def fmt_tolerance(row: Row, empty: str = "—") -> str:
    """How ours is checked: ``± tol`` (equal within), ``<= published (+tol)``, ``>= ...``, ``exact``."""
    tol = row.tolerance
    if row.relation == "==":
        if tol is not None:
            return f"± {tol:g}"
        return "exact" if isinstance(row.published, (bool, str)) else empty
    bound = f"{row.relation} published"
    return bound + (f" (+{tol:g})" if row.relation == "<=" and tol else f" (-{tol:g})" if tol else "")


def fmt_match(row: Row, empty: str = "—") -> str:
    return {True: "yes", False: "no", None: empty}[row.matches]


def format_markdown(report: Report) -> str:
    """``report.md``: totals, then per paper a summary line (mismatches named), the table, figures and series."""
    c = report.counts
    lines = [
        "# pkm: the papers' published numbers next to ours",
        "",
        (f"pkm {pkm.__version__}; {len(report.papers)} paper(s), {c.line()}. "
         "A row matches when ours is within its tolerance of the published value (or on the stated side of it); "
         "the note says how ours was computed and, where it differs, why. Machine-readable: "
         "[summary.json](summary.json)."),
        "",
    ]
    lines += summary_lines(report, markdown=True) + [""]
    for p in report.papers:
        pc = p.counts
        lines += [f"## {p.name}: {p.title}", ""]
        flag = f" **Mismatches: {', '.join(f'`{r.id}`' for r in p.mismatches)}** (see their notes)." \
            if p.mismatches else " All compared rows match."
        lines += [f"{pc.line()}.{flag}", ""]
        lines += ["| id | published | ours | unit | tolerance | match | source | note |",
                  "|---|---|---|---|---|---|---|---|"]
        for r in p.rows:
            match = "**no**" if r.matches is False else fmt_match(r)
            cells = [f"`{r.id}`", fmt_value(r.published), fmt_value(r.computed), r.unit or "—", fmt_tolerance(r),
                     match, r.source, r.note]
            lines.append("| " + " | ".join(_md_cell(x) for x in cells) + " |")
        lines.append("")
        if p.figures:
            lines += ["Figures:", ""]
            behind = getattr(_papers.module(p.name), "SERIES", {})
            written = {f.stem: f for f in p.series}
            for f in p.figures:
                lines += [f"![{f.stem}]({_rel(f, report.out_dir)})", ""]
                numbers = [written[n] for n in behind.get(f.stem, ()) if n in written]
                if numbers:
                    lines += ["Its numbers: " + ", ".join(f"[{c.name}]({_rel(c, report.out_dir)})" for c in numbers),
                              ""]
        if p.series:
            lines += ["Series (CSV): " + ", ".join(f"[{f.name}]({_rel(f, report.out_dir)})" for f in p.series), ""]
    return "\n".join(lines)


def summary_lines(report: Report, *, markdown: bool = False) -> list[str]:
    """What matched, what did not and why (a line each), and what has no published value: the report's opening."""
    rows = [r for p in report.papers for r in p.rows]
    code = (lambda t: f"`{t}`") if markdown else (lambda t: t)
    bullet = "- " if markdown else "  "
    matched = [r.id for r in rows if r.matches is True]
    missed = [r for r in rows if r.matches is False]
    blank = [r.id for r in rows if r.published is None]
    out = [f"{bullet}matched ({len(matched)}): ours within the stated tolerance of the printed value"
           + (f": {', '.join(code(i) for i in matched)}" if markdown else "")]
    out += [f"{bullet}did not match: {code(r.id)} (published {fmt_value(r.published)}, ours {fmt_value(r.computed)}"
            f"{' ' + r.unit if r.unit else ''}): {r.why or 'see its note'}" for r in missed]
    by_paper = ", ".join(f"{p.name} {sum(r.published is None for r in p.rows)}" for p in report.papers
                         if any(r.published is None for r in p.rows))
    if blank:
        out.append(f"{bullet}no published value ({len(blank)}; {by_paper}): numbers the papers do not print (curves "
                   "whose image is lost, forces shown only as plots, our kernels' operation counts), recorded so that "
                   "a change shows")
    return out


def _md_cell(text: str) -> str:
    return " ".join(str(text).split()).replace("|", "\\|")


def format_table(report: Report | Sequence[PaperResult], *, width: int = 100) -> str:
    """The rows as a plain-text table for a terminal, each mismatch followed by its note.

    Args:
        report: A :class:`Report` or its papers.
        width: Notes of mismatches are wrapped to this many characters.
    """
    import textwrap

    results = report.papers if isinstance(report, Report) else tuple(report)
    out: list[str] = []
    head = ("match", "id", "published", "ours", "unit", "tolerance")
    for p in results:
        out += [f"== {p.name}: {p.title}", f"   {p.counts.line()}"]
        table = [head] + [(fmt_match(r, "-"), r.id, fmt_value(r.published, "-"), fmt_value(r.computed, "-"),
                           r.unit or "-", fmt_tolerance(r, "-")) for r in p.rows]
        w = [max(len(row[i]) for row in table) for i in range(len(head))]
        for k, row in enumerate(table):
            out.append("   " + "  ".join(cell.ljust(w[i]) for i, cell in enumerate(row)).rstrip())
            if k and p.rows[k - 1].matches is False and p.rows[k - 1].note:
                out += textwrap.wrap(p.rows[k - 1].note, width, initial_indent="      why: ",
                                     subsequent_indent="           ")
        files = len(p.figures) + len(p.series)
        if files:
            out.append(f"   {len(p.figures)} figure(s), {len(p.series)} series file(s)")
        out.append("")
    if isinstance(report, Report):
        out += summary_lines(report)
        out.append(f"total: {report.counts.line()}; {report.markdown} ({report.seconds:.1f} s)")
    return "\n".join(out)


__all__ = ["STEPS", "Counts", "PaperResult", "Report", "format_markdown", "format_table", "run", "summary_dict",
           "summary_lines"]
