"""The results on disk: one Parquet file a sweep, written chunk by chunk while it runs.

While a sweep runs, every finished chunk is a file of its own in ``<out>.parts/`` (``part-<first>-<last>.parquet``,
written to a temporary name and renamed: whole or absent), beside ``manifest.json``, what the sweep is (family,
space and seed, objectives, a hash of the designs' values). Run again with the same output, the sweep reads the
parts whose manifest matches and evaluates only the designs they lack; when none is left the parts are joined, in
design order, into ``<out>`` (the manifest in the file's metadata, key ``pkm.sweep``) and the folder is removed.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import uuid
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from pkm.errors import InvalidInputError, SweepError
from pkm.sweeps.family import Family
from pkm.sweeps.objectives import Objective
from pkm.sweeps.space import Designs

FORMAT = "pkm.sweep/1"
#: What must agree for an output to hold the same sweep.
SAME = ("format", "family", "parameters", "designs", "objectives", "values_sha256")


def schema(names: Sequence[str], objectives: Sequence[Objective]):
    import pyarrow as pa

    return pa.schema([("design", pa.int64())] + [(n, pa.float64()) for n in names]
                     + [(o.column, pa.float64()) for o in objectives]
                     + [("status", pa.string()), ("error", pa.string()), ("message", pa.string())])


def chunk_table(designs: Designs, objectives: Sequence[Objective], cols: Mapping[str, list]):
    import pyarrow as pa

    ids = np.asarray(cols["design"], dtype=np.int64)
    data: dict[str, Any] = {"design": ids}
    for k, n in enumerate(designs.names):
        data[n] = designs.values[ids, k]
    for o in objectives:
        data[o.column] = cols[o.column]
    for key in ("status", "error", "message"):
        data[key] = cols[key]
    return pa.Table.from_pydict(data, schema=schema(designs.names, objectives))


def write_atomic(table, path: Path, metadata: Mapping[str, str] | None = None) -> None:
    import pyarrow.parquet as pq

    if metadata:
        table = table.replace_schema_metadata({**(table.schema.metadata or {}), **metadata})
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    pq.write_table(table, tmp)
    os.replace(tmp, path)


def parts_folder(out: Path) -> Path:
    return out.with_name(out.name + ".parts")


def manifest_of(family: Family, designs: Designs, objectives: Sequence[Objective]) -> dict[str, Any]:
    import pkm

    return {"format": FORMAT, "pkm": pkm.__version__, "family": family.describe(), "space": designs.description,
            "parameters": list(designs.names), "units": {n: family.units(n)[1] for n in designs.names},
            "designs": len(designs),
            "objectives": [o.describe(family) for o in objectives],
            "values_sha256": _sha(designs.values)}


def _sha(values: np.ndarray) -> str:
    return hashlib.sha256(np.ascontiguousarray(values, dtype="<f8").tobytes()).hexdigest()


def _same(a: Mapping[str, Any], b: Mapping[str, Any]) -> bool:
    return all(json.dumps(a.get(k), sort_keys=True) == json.dumps(b.get(k), sort_keys=True) for k in SAME)


def read_manifest(path) -> dict[str, Any]:
    """The manifest of a results file (or of an unfinished sweep's parts folder)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    path = Path(path)
    if path.is_dir():
        return json.loads((path / "manifest.json").read_text(encoding="utf-8"))
    if not path.is_file():
        raise InvalidInputError("path", f"no such file: {path}", str(path))
    try:
        meta = pq.read_schema(path).metadata or {}
    except (OSError, pa.ArrowException) as exc:  # not Parquet, or damaged
        raise InvalidInputError("path", f"{path} is not a Parquet file ({exc})", str(path)) from None
    if b"pkm.sweep" not in meta:
        raise InvalidInputError("path", f"{path} is not a pkm sweep's results (no manifest in its metadata)", str(path))
    return json.loads(meta[b"pkm.sweep"])


def recorded_seed(out: Path) -> int | None:
    """The seed of the samples of the sweep ``out`` holds (finished or not), or None: a sampled sweep started
    again without a seed resumes with the samples it drew (:meth:`pkm.sweeps.Space.with_seed`)."""
    for where in (out, parts_folder(out)):
        if where.exists():
            try:
                seed = read_manifest(where).get("space", {}).get("seed")
            except (OSError, ValueError):
                return None
            return seed if isinstance(seed, int) else None
    return None


def resume(out: Path, manifest: dict[str, Any], overwrite: bool):
    """Designs already done (their tables), or None when the output is complete already (then its table)."""
    import pyarrow.parquet as pq

    parts = parts_folder(out)
    if overwrite:
        shutil.rmtree(parts, ignore_errors=True)
        out.unlink(missing_ok=True)
    if out.exists():
        try:
            old = read_manifest(out)
        except ValueError as exc:  # (InvalidInputError, or a manifest that is not JSON)
            raise SweepError(f"{out} exists and is not a pkm sweep's results ({exc}); pass overwrite=True "
                             "(--overwrite) to replace it", out) from None
        if not _same(old, manifest):
            raise SweepError(f"{out} holds another sweep (other designs, objectives or mechanism); pass "
                             "overwrite=True (--overwrite) to replace it, or choose another output", out)
        shutil.rmtree(parts, ignore_errors=True)  # (left by a run stopped between the final write and its cleanup)
        return None, pq.read_table(out)
    tables = []
    if parts.exists():
        try:
            old = read_manifest(parts)
        except (OSError, ValueError):
            old = {}
        if not _same(old, manifest):
            raise SweepError(f"{parts} holds the parts of another sweep; pass overwrite=True (--overwrite) to "
                             "start again, or choose another output", parts)
        for p in sorted(parts.glob("part-*.parquet")):
            tables.append(pq.read_table(p))
    else:
        parts.mkdir(parents=True)
        (parts / "manifest.json").write_text(json.dumps(manifest, indent=1), encoding="utf-8")
    return tables, None


def combine(tables, designs: Designs, objectives):
    """One table of every design, in design order: the parts' rows, each design once (parts of runs with other
    chunk sizes may overlap; a design's row is the same in each).

    Raises:
        SweepError: a design has no row (a bug: the caller evaluates every design the parts lack).
    """
    import pyarrow as pa

    target = schema(designs.names, objectives)
    table = pa.concat_tables([t.cast(target) for t in tables]) if tables else target.empty_table()
    ids = np.asarray(table.column("design"), dtype=np.int64)
    first = np.unique(ids, return_index=True)[1]
    if len(first) != len(designs) or (len(first) and (ids[first[0]] != 0 or ids[first[-1]] != len(designs) - 1)):
        raise SweepError(f"the results hold {len(first)} of the {len(designs)} designs", None)
    return table.take(first)  # (np.unique's indices: sorted by design, the first row of each)


def count_failed(table) -> int:
    return int(sum(1 for s in table.column("status").to_pylist() if s == "failed"))



__all__ = ["FORMAT", "SAME", "chunk_table", "combine", "count_failed", "manifest_of", "parts_folder", "read_manifest",
           "recorded_seed", "resume", "schema", "write_atomic"]
