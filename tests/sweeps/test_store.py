"""pkm.sweeps.store, without running a sweep: chunks written atomically and read back, resumed from the parts of an
unfinished sweep (overlapping parts, designs in order), a finished output found again, another sweep's output or
parts refused, and the manifest read from a results file or a parts folder. (Resuming after a real kill is
``tests/sweeps/test_engine.py``.)"""

from __future__ import annotations

import json

import numpy as np
import pyarrow.parquet as pq
import pytest

from pkm import sweeps
from pkm.errors import InvalidInputError, SweepError
from pkm.sweeps import store
from pkm.sweeps.family import RegisteredFamily

FAMILY = RegisteredFamily("rrr3")
DESIGNS = sweeps.grid(a="30cm:60cm:3", h="5cm:10cm:2").designs(FAMILY.units)  # 6 designs
OBJECTIVES = [sweeps.objective("gci:step=4cm"), sweeps.objective("cov=coverage:step=4cm")]


def _chunk(ids, failed=()):
    """The table of designs ``ids`` as the engine builds it: made-up values 10 * id, failures recorded."""
    cols = {"design": list(ids), "gci:step=4cm": [None if i in failed else 10.0 * i for i in ids],
            "cov": [0.5] * len(ids), "status": ["failed" if i in failed else "ok" for i in ids],
            "error": ["InvalidParameterError" if i in failed else None for i in ids],
            "message": ["h: must be > 0" if i in failed else None for i in ids]}
    return store.chunk_table(DESIGNS, OBJECTIVES, cols)


def _manifest(objectives=OBJECTIVES, designs=DESIGNS):
    return store.manifest_of(FAMILY, designs, objectives)


def test_a_chunk_holds_the_designs_values_and_survives_parquet(tmp_path):
    """Columns: design, the parameters (from the designs' values), the objectives, status, error, message; written
    atomically (no temporary file left) and read back equal, nulls kept."""
    table = _chunk([1, 4], failed=(4,))
    assert table.schema.names == ["design", "a", "h", "gci:step=4cm", "cov", "status", "error", "message"]
    np.testing.assert_array_equal(np.column_stack([table.column("a"), table.column("h")]), DESIGNS.values[[1, 4]])
    path = tmp_path / "part.parquet"
    store.write_atomic(table, path, {"k": "v"})
    assert [p.name for p in tmp_path.iterdir()] == ["part.parquet"]
    back = pq.read_table(path)
    assert back.equals(table.replace_schema_metadata(back.schema.metadata))
    assert back.schema.metadata[b"k"] == b"v" and back.column("gci:step=4cm").to_pylist() == [10.0, None]
    assert store.count_failed(back) == 1


def test_resume_starts_a_parts_folder_then_returns_its_parts_and_combine_orders_them(tmp_path):
    """A new output: an empty parts folder with the manifest; parts written there (overlapping, out of order) come
    back, and combine keeps each design once, in design order."""
    out = tmp_path / "r.parquet"
    manifest = _manifest()
    assert store.resume(out, manifest, overwrite=False) == ([], None)
    parts = store.parts_folder(out)
    assert parts.name == "r.parquet.parts" and json.loads((parts / "manifest.json").read_text()) == manifest
    for ids in ([3, 4, 5], [0, 1], [1, 2]):
        store.write_atomic(_chunk(ids), parts / f"part-{ids[0]:09d}-{ids[-1]:09d}.parquet")
    tables, complete = store.resume(out, manifest, overwrite=False)
    assert complete is None and sum(t.num_rows for t in tables) == 7
    table = store.combine(tables, DESIGNS, OBJECTIVES)
    assert table.column("design").to_pylist() == list(range(6))
    assert table.column("gci:step=4cm").to_pylist() == [10.0 * i for i in range(6)]
    with pytest.raises(SweepError, match="5 of the 6 designs"):
        store.combine(tables[:1] + tables[2:], DESIGNS, OBJECTIVES)  # (design 2 lost)


def test_a_finished_output_is_returned_whole_and_another_sweep_is_refused(tmp_path):
    """The joined file with its manifest: resume returns it (and removes stale parts); the same output asked for
    other objectives or designs is a SweepError, unless overwrite, which removes it."""
    out = tmp_path / "r.parquet"
    table = store.combine([_chunk(range(6))], DESIGNS, OBJECTIVES)
    store.write_atomic(table, out, {"pkm.sweep": json.dumps(_manifest())})
    store.parts_folder(out).mkdir()
    done, complete = store.resume(out, _manifest(), overwrite=False)
    assert done is None and complete.equals(pq.read_table(out)) and not store.parts_folder(out).exists()
    other = _manifest(objectives=OBJECTIVES[:1])
    with pytest.raises(SweepError, match="holds another sweep") as info:
        store.resume(out, other, overwrite=False)
    assert info.value.path == out
    fewer = sweeps.grid(a="30cm:60cm:3", h="5cm").designs(FAMILY.units)
    with pytest.raises(SweepError):
        store.resume(out, _manifest(designs=fewer), overwrite=False)
    assert store.resume(out, other, overwrite=True) == ([], None) and not out.exists()


def test_parts_of_another_sweep_are_refused(tmp_path):
    """An unfinished folder whose manifest differs (or is unreadable) is not mixed in: SweepError naming the folder."""
    out = tmp_path / "r.parquet"
    store.resume(out, _manifest(), overwrite=False)
    with pytest.raises(SweepError, match="parts of another sweep"):
        store.resume(out, _manifest(objectives=OBJECTIVES[1:]), overwrite=False)
    (store.parts_folder(out) / "manifest.json").write_text("{not json")
    with pytest.raises(SweepError) as info:
        store.resume(out, _manifest(), overwrite=False)
    assert info.value.path == store.parts_folder(out)


def test_manifest_records_what_makes_two_sweeps_the_same():
    """Format, family, parameters and their units, design count, objectives with their units, and a hash of the
    values that changes with any value."""
    m = _manifest()
    assert set(store.SAME) <= set(m) and m["format"] == store.FORMAT == "pkm.sweep/1"
    assert m["parameters"] == ["a", "h"] and m["units"] == {"a": "m", "h": "m"} and m["designs"] == 6
    assert m["family"] == {"registered": "rrr3", "fixed": {}}
    assert [o["column"] for o in m["objectives"]] == ["gci:step=4cm", "cov"]
    shifted = sweeps.grid(a="30cm:60cm:3", h="5cm:10.001cm:2").designs(FAMILY.units)
    assert _manifest(designs=shifted)["values_sha256"] != m["values_sha256"]


def test_read_manifest_refuses_what_is_not_a_sweep_s_results(tmp_path):
    """A missing path, a file that is not Parquet, and a Parquet file without the manifest: InvalidInputError."""
    with pytest.raises(InvalidInputError, match="no such file"):
        store.read_manifest(tmp_path / "none.parquet")
    (tmp_path / "text.parquet").write_text("hello")
    with pytest.raises(InvalidInputError, match="is not a Parquet file"):
        store.read_manifest(tmp_path / "text.parquet")
    store.write_atomic(_chunk([0]), tmp_path / "bare.parquet")
    with pytest.raises(InvalidInputError, match="no manifest"):
        store.read_manifest(tmp_path / "bare.parquet")


def test_recorded_seed_is_read_from_the_output_or_its_parts(tmp_path):
    """A sampled sweep's seed is found in its parts folder (unfinished) or its file (finished); a grid has none."""
    sampled = sweeps.sobol(4, seed=7, a="30cm:60cm", h="5cm:10cm").designs(FAMILY.units)
    out = tmp_path / "s.parquet"
    assert store.recorded_seed(out) is None
    store.resume(out, _manifest(designs=sampled), overwrite=False)
    assert store.recorded_seed(out) == 7
    grid_out = tmp_path / "g.parquet"
    store.write_atomic(_chunk([0]), grid_out, {"pkm.sweep": json.dumps(_manifest())})
    assert store.recorded_seed(grid_out) is None
