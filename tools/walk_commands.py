"""Every documented ``pkm`` command on every shipped mechanism with its defaults (run by ``.ci/run``).

Two walks, each cell run in-process (:func:`tests.cli.helpers.run`, as ``python -m pkm ARGS`` would run it) in a
temporary folder of its own:

* **defaults**: each command of :data:`RECIPES` (one per subcommand of ``pkm --help``) on each mechanism of
  :data:`MECHANISMS` (the shipped ones and the humanoid ankle example the docs use), its required options filled from
  the mechanism itself (its reference pose, its reference actuated joints), its input files made first by the
  ``pkm`` command the docs use to make them (``pkm calibrate plan`` before ``pkm calibrate``, ``pkm excite`` before
  ``pkm identify``, ``pkm sweep`` before ``pkm sweep plot``);
* **docs**: each fenced ``pkm ...`` line of README.md and docs/**/*.md (:func:`documented_lines`) as written (the
  files it names taken from the checkout, :data:`DOC_FILES`).

A cell is ``ok`` (exit 0), ``n/a`` (a refusal that says the command does not apply, :data:`NOT_APPLICABLE`),
``refused`` (exit 1 or 2 with one ``pkm: error:`` line: a :class:`~pkm.errors.PkmError`;
``refused*`` where that message names no fix, :func:`names_fix`) or ``FAILED`` (a traceback, another exit status, or
a success that prints a configuration outside the position limits the model states); ``known``: a cell of
:data:`KNOWN` that is not ok. Exit status 1 on any ``FAILED`` or ``refused*`` cell.

Usage: ``python tools/walk_commands.py [--jobs N] [--only COMMAND ...] [--mechanism NAME ...] [--no-docs]
[--no-defaults] [--full]``.
"""

from __future__ import annotations

import argparse
import os
import re
import shlex
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:  # (tests.cli.helpers: the in-process runner the CLI's tests use)
    sys.path.insert(0, str(ROOT))

#: The mechanisms of the defaults walk: the shipped ones, and the example the docs' ``pkm`` lines use.
MECHANISMS = ("delta", "hexapod", "rrr3", "prs3", "gough_stewart", "examples/humanoid_ankle/ankle.closures.toml")

#: Files a documented line names as if they were in the current folder: where the checkout has them.
DOC_FILES = {"prs3_motions.toml": "dynamics/prs3_motions.toml"}

#: Refusals that say the command does not apply to a mechanism: (command, mechanism) -> what the message says.
NOT_APPLICABLE = {("transmission", m): r"outputs are one-coordinate serial joints|a parallel mechanism whose output "
                  r"is a frame" for m in ("delta", "hexapod", "rrr3", "prs3", "gough_stewart")}

#: Cells known to fail, each with what is known (shown as ``known`` with their message; the exit status ignores them):
#: remove an entry once fixed (the walk then checks it like any other).
KNOWN: dict[tuple[str, str], str] = {}

#: Documented lines not run, with the reason (a server or a live viewer runs until Ctrl-C).
DOC_SKIPS = {"pkm serve": "a server that runs until Ctrl-C (tests/cli/test_serve.py starts and stops it)",
             "pkm preview": "the live viewer waits for Ctrl-C (walked with --html)"}


@dataclass(frozen=True)
class Recipe:
    """How the defaults walk runs one command: ``steps`` (argv templates; the last is the command walked, those
    before make its inputs; a callable writes a file instead), on every mechanism of :data:`MECHANISMS` or, where
    ``per_mechanism`` is false, once; ``skip``: why the command is not run; ``quick``: see below."""

    steps: tuple[str | Callable[[dict, Path], None], ...] = ()
    per_mechanism: bool = True
    skip: str = ""
    quick: str = ""
    """Documented options that make the last step smaller, added unless ``--full`` (CI's walk)."""
    quick_mechanisms: tuple[str, ...] = ()
    """Unless ``--full``, these mechanisms only (where the others cost minutes each)."""


def _path_csv(info: dict, folder: Path) -> None:
    """A two-waypoint path for ``pkm plan``: the reference pose and the pose 5 % of the characteristic length (or
    0.05 rad) away along the first task coordinate."""
    names = list(info["pose"])
    start = info["pose"]
    end = dict(start, **{names[0]: start[names[0]] + 0.05 * info["scale"][names[0]]})
    (folder / "path.csv").write_text(",".join(names) + "\n" + "\n".join(
        ",".join(repr(p[n]) for n in names) for p in (start, end)) + "\n")


#: The mechanisms whose excitation takes seconds (with 3 SLSQP iterations, on 2 busy cores: the Delta 2 s, the 3-RRR
#: 2 s, the 3-PRS 1 s; the Gough-Stewart 85 s, the hexapod 125 s, the humanoid ankle 73 s): CI's walk excites these.
CHEAP_EXCITATION = ("delta", "rrr3", "prs3")

RECIPES: dict[str, Recipe] = {
    "list": Recipe(("list {mech}",)),
    "preview": Recipe(("preview {mech} --html page.html",)),
    "ik": Recipe(("ik {mech} --pose {pose}",)),
    "fk": Recipe(("fk {mech} --joints {joints}",)),
    "map": Recipe(("map {mech} --axis {axis0} --axis {axis1} --png map.png",)),
    "dynamics": Recipe(("dynamics {mech}",)),
    "simulate": Recipe(("simulate {mech} --duration 0.1s --out sim.csv",)),
    "plan": Recipe((_path_csv, "plan {mech} --path path.csv --points 50 --out plan.csv")),
    "excite": Recipe(("excite {mech} --out exc.csv",), quick="--iterations 3", quick_mechanisms=CHEAP_EXCITATION),
    "identify": Recipe(("excite {mech} --iterations 3 --out exc.csv", "identify {mech} exc.csv --out id.closures.toml"),
                       quick_mechanisms=CHEAP_EXCITATION),
    "calibrate plan": Recipe(("calibrate plan {mech} --poses 30 --out data.csv --simulate 1",)),
    "calibrate": Recipe(("calibrate plan {mech} --poses 30 --out data.csv --simulate 1",
                         "calibrate {mech} data.csv --out calibrated")),
    "capability": Recipe(("capability {mech}",)),
    "stiffness": Recipe(("stiffness {mech}",)),
    "clearance": Recipe(("clearance {mech}",)),
    "export": Recipe(("export c {mech} --out c",)),
    "convert": Recipe(("convert {mech} out/model.closures.toml",)),
    "spec": Recipe(("convert {mech} out/model.xml", "spec init out/model.xml --force")),
    "report": Recipe(per_mechanism=False, skip="the papers' rows: its documented line is walked (80 s for all four)"),
    "serve": Recipe(per_mechanism=False, skip=DOC_SKIPS["pkm serve"]),
    "transmission": Recipe(("transmission {mech} --out tx",)),
    "bench": Recipe(per_mechanism=False, skip="benchmarks: their documented lines (--quick) are walked"),
    "sweep": Recipe(("sweep {mech} {sweep_param} --objective condition --scheduler serial --no-progress "
                     "--out d.parquet",)),
    "sweep plot": Recipe(("sweep {mech} {sweep_param} --objective condition --scheduler serial --no-progress "
                          "--out d.parquet", "sweep plot d.parquet --out figures")),
    "sweep best": Recipe(("sweep {mech} {sweep_param} --objective condition --scheduler serial --no-progress "
                          "--out d.parquet", "sweep best d.parquet --by condition --n 1")),
}
"""The defaults walk: one recipe per command of :data:`pkm.cli.commands.COMMANDS` (``tests/test_walk_commands.py``
checks that every command and every documented ``pkm X`` has one)."""


def documented_lines(root: Path = ROOT) -> Iterator[tuple[str, str, str]]:
    """``(where, line, block)`` for each ``pkm ...`` command of the fenced blocks of README.md and docs/**/*.md (a
    ``$ `` prompt taken off; a line ``A && B`` gives one entry; ``block``: where its fenced block starts, the lines
    of one block run in order in one folder, a line reading what one above it wrote)."""
    for path in [root / "README.md", *sorted((root / "docs").rglob("*.md"))]:
        block = ""
        for k, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            text = line.strip()
            if text.startswith("```"):
                block = "" if block else f"{path.relative_to(root)}:{k}"
                continue
            text = text.removeprefix("$ ")
            if block and text.startswith("pkm "):
                yield f"{path.relative_to(root)}:{k}", text, block


def command_of(argv: list[str]) -> str:
    """The command of ``pkm ARGV`` as :data:`pkm.cli.commands.COMMANDS` names it (``sweep plot``: two words)."""
    from pkm.cli.commands import COMMANDS

    for name in (" ".join(argv[:2]), argv[0].replace("-", " ")):
        if name in COMMANDS:
            return name
    return argv[0]


def split_line(line: str) -> list[list[str]]:
    """A documented line's commands: its ``&&``-separated parts, each an argv without ``pkm`` and the comment."""
    words = shlex.split(line, comments=True)
    parts: list[list[str]] = [[]]
    for w in words:
        if w == "&&":
            parts.append([])
        else:
            parts[-1].append(w)
    return [p[1:] for p in parts if p and p[0] == "pkm"]


# --- what a mechanism fills in -------------------------------------------------------------------------------------

def mechanism_info(name: str) -> dict:
    """What a recipe's templates take of a mechanism: ``{mech}``, ``{pose}`` (its reference pose, every task
    coordinate), ``{joints}`` (its reference actuated joints), ``{axis0}``, ``{axis1}`` (5 points over +/- 5 % of
    the characteristic length, or 0.05 rad, about the reference, on its first two task coordinates), and
    ``{sweep_param}`` (its first length parameter over 90 % .. 110 % of its value, 2 points)."""
    import pkm
    from pkm.cli.parsing import param_info

    mech = pkm.load(str(ROOT / name) if name.endswith(".toml") else name)
    task = pkm.TaskMap.of(mech)
    pose = task.named(mech.q_reference)
    scale = {k: (mech.characteristic_length if kind not in ("roll", "pitch", "yaw", "angle") else 1.0)
             for k, kind in task.kinds.items()}
    axes = [f"{k}={pose[k] - 0.05 * scale[k]!r}:{pose[k] + 0.05 * scale[k]!r}:5" for k in list(pose)[:2]]
    joints = dict(zip(mech.actuated_names, map(float, mech.actuated_q(mech.q_reference))))
    sweep = ""
    if name in pkm.MECHANISMS:
        p = next(p for p in param_info(name).values() if p.unit == "m" and isinstance(p.default, float))
        sweep = f"{p.name}={0.9 * p.default!r}:{1.1 * p.default!r}:2"
    return {"mech": str(ROOT / name) if name.endswith(".toml") else name, "pose": pose, "scale": scale,
            "joints": joints, "axes": axes + axes[:1] * (2 - len(axes)), "sweep_param": sweep}


def fill(template: str, info: dict) -> list[str]:
    """``template``'s argv with ``info`` (:func:`mechanism_info`) filled in."""
    words = []
    for w in shlex.split(template):
        if w == "{pose}":
            words += [f"{k}={v!r}" for k, v in info["pose"].items()]
        elif w == "{joints}":
            words += [f"{k}={v!r}" for k, v in info["joints"].items()]
        elif w == "{sweep_param}":
            if not info["sweep_param"]:
                raise LookupError("no design parameter to sweep (not a shipped mechanism)")
            words.append(info["sweep_param"])
        else:
            words.append(w.format(mech=info["mech"], axis0=info["axes"][0], axis1=info["axes"][1]))
    return words


# --- one cell ------------------------------------------------------------------------------------------------------

FIX = re.compile(r"--[a-z][\w-]*|\b\w+=|\bone of\b|\bknown\b|\bexpected\b|\bpick\b|\buse\b|\bgive\b|\bpass\b|"
                 r"\bset\b|\btry\b|\binstall\b|\braise\b|\blower\b|\bincrease\b|\breduce\b|\bnearer\b", re.I)


def names_fix(message: str) -> bool:
    """Whether a refusal's message names a fix: an option (``--x``), a value to give (``NAME=``), the values
    accepted (one of, known, expected), or what to do (use, give, set, try, install, raise, lower...)."""
    return bool(FIX.search(message))


@dataclass
class Cell:
    """One walked command: its row (the command), column (mechanism, or the documented line's place), argv, the
    verdict (``ok``, ``refused``, ``refused*``, ``FAILED``, ``skipped``), what it printed last, seconds."""

    command: str
    column: str
    argv: list[str] = field(default_factory=list)
    verdict: str = ""
    detail: str = ""
    seconds: float = 0.0
    group: str = ""
    """Cells of one group run in order in one folder (a documented block's lines); "": a folder of its own."""


OUTSIDE = re.compile(r'"status": "outside_limits"|outside the position limits the model states')


def judge(proc) -> tuple[str, str]:
    """The verdict on one finished command (``proc``: :func:`tests.cli.helpers.run`'s) and the line that says why."""
    err = proc.stderr.strip().splitlines()
    last = err[-1] if err else ""
    if "Traceback (most recent call last)" in proc.stderr:
        return "FAILED", last
    if proc.returncode == 0:
        if OUTSIDE.search(proc.stdout) or OUTSIDE.search(proc.stderr):
            line = next((ln for ln in (proc.stdout + proc.stderr).splitlines() if OUTSIDE.search(ln)), "")
            return "FAILED", "a success outside the position limits: " + line.strip()[:300]
        return "ok", ""
    errors = [ln for ln in err if ln.startswith("pkm: error: ")]
    if proc.returncode in (1, 2) and errors:
        message = errors[-1].removeprefix("pkm: error: ")
        return ("refused" if names_fix(message) else "refused*"), message
    return "FAILED", f"exit {proc.returncode}: {last}"


def run_cell(cell: Cell, steps: list, folder: Path | None = None) -> Cell:
    """Run ``steps`` (argv lists, or callables ``fn(folder)``) in ``folder`` (default: a fresh temporary one); the
    last is judged, a step before it that does not succeed is the cell's verdict."""
    from tests.cli.helpers import run

    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="pkm-walk-") as tmp:
        folder = Path(tmp) if folder is None else folder
        for step in steps:
            if callable(step):
                step(folder)
                continue
            cell.argv = step
            proc = run(*step, cwd=folder)
            cell.verdict, cell.detail = judge(proc)
            na = NOT_APPLICABLE.get((cell.command, cell.column))
            if cell.verdict.startswith("refused") and na and re.search(na, cell.detail):
                cell.verdict = "n/a"
            elif cell.verdict != "ok" and (cell.command, cell.column) in KNOWN:
                cell.verdict, cell.detail = "known", f"{cell.detail} [{KNOWN[cell.command, cell.column]}]"
            if cell.verdict != "ok":
                break
    cell.seconds = time.perf_counter() - t0
    return cell


def _work(group: list[tuple[Cell, list]]) -> list[Cell]:
    """Run a group's cells in order in one temporary folder."""
    with tempfile.TemporaryDirectory(prefix="pkm-walk-") as tmp:
        for cell, steps in group:
            try:
                run_cell(cell, steps, Path(tmp))
            except Exception as exc:  # (the walk's own failure to set a cell up: reported as the cell's)
                cell.verdict, cell.detail = "FAILED", f"{type(exc).__name__}: {exc}"
    return [cell for cell, _ in group]


def cells(only: set[str] | None, mechanisms: tuple[str, ...], docs: bool, defaults: bool,
          full: bool = False) -> Iterator[tuple[Cell, list]]:
    """The walk's cells with their steps (skipped ones with no steps and their reason); ``full``: the recipes
    without their ``quick`` options."""
    if defaults:
        infos: dict[str, dict | Exception] = {}
        for name in mechanisms:
            try:
                infos[name] = mechanism_info(name)
            except Exception as exc:  # (a mechanism that does not load fails its cells)
                infos[name] = exc
        for command, recipe in RECIPES.items():
            if only and command not in only:
                continue
            if recipe.skip:
                yield Cell(command, "-", verdict="skipped", detail=recipe.skip), []
                continue
            for name in mechanisms if recipe.per_mechanism else ("-",):
                cell = Cell(command, Path(name).parent.name if "/" in name else name)
                if not full and recipe.quick_mechanisms and name not in recipe.quick_mechanisms:
                    cell.verdict, cell.detail = "skipped", "minutes on this mechanism: walked with --full"
                    yield cell, []
                    continue
                info = infos[name]
                if isinstance(info, Exception):
                    cell.verdict, cell.detail = "FAILED", f"loading it: {info}"
                    yield cell, []
                    continue
                templates = list(recipe.steps)
                if recipe.quick and not full:
                    templates[-1] = f"{templates[-1]} {recipe.quick}"
                try:
                    steps = [s if callable(s) else fill(s, info) for s in templates]
                except LookupError as exc:
                    cell.verdict, cell.detail = "skipped", str(exc)
                    yield cell, []
                    continue
                yield cell, [_bind(s, info) if callable(s) else s for s in steps]
    if docs:
        for where, line, block in documented_lines():
            parts = split_line(line)
            command = command_of(parts[-1])
            if only and not {command_of(p) for p in parts} & only:
                continue
            cell = Cell(command, where, group=block)
            skip = next((why for start, why in DOC_SKIPS.items() if line.startswith(start)), "")
            if skip and not (line.startswith("pkm preview") and "--html" in line):
                cell.argv, cell.verdict, cell.detail = parts[-1], "skipped", skip
                yield cell, []
                continue
            yield cell, [[str(ROOT / DOC_FILES[w.split(":")[0]]) + w[len(w.split(":")[0]):]
                          if w.split(":")[0] in DOC_FILES else str(ROOT / w) if (ROOT / w).is_file() else w
                          for w in p] for p in parts]


class _Bound:
    """A file-writing step with its mechanism bound (picklable, for the process pool)."""

    def __init__(self, fn: Callable[[dict, Path], None], info: dict) -> None:
        self.fn, self.info = fn, info

    def __call__(self, folder: Path) -> None:
        self.fn(self.info, folder)


def _bind(fn: Callable[[dict, Path], None], info: dict) -> _Bound:
    return _Bound(fn, info)


# --- the table -----------------------------------------------------------------------------------------------------

def table(done: list[Cell]) -> str:
    """The defaults walk as a command x mechanism table, then the documented lines, then every cell not ``ok``."""
    grid = [c for c in done if ":" not in c.column]
    cols = list(dict.fromkeys(c.column for c in grid if c.column != "-"))
    rows = list(dict.fromkeys(c.command for c in grid))
    at = {(c.command, c.column): c for c in grid}
    width = max([len(r) for r in rows] + [12])
    lines = ["defaults walk:", " ".join([" " * width] + [f"{c:>14}" for c in cols])]
    for r in rows:
        if (r, "-") in at:
            c = at[r, "-"]
            lines.append(f"{r:<{width}} {c.verdict}: {c.detail}")
            continue
        lines.append(" ".join([f"{r:<{width}}"] + [f"{at[r, c].verdict + f' {at[r, c].seconds:.0f}s':>14}"
                                                   if (r, c) in at else f"{'':>14}" for c in cols]))
    lines.append("documented lines:")
    for c in (c for c in done if ":" in c.column):
        lines.append(f"  {c.verdict:<9} {c.seconds:5.1f}s  {c.column}: pkm {' '.join(c.argv)[:100]}")
    bad = [c for c in done if c.verdict not in ("ok", "skipped", "n/a")]
    if bad:
        lines.append("not ok:")
        for c in bad:
            lines.append(f"  {c.verdict:<9} {c.command} [{c.column}] pkm {shlex.join(c.argv)[:160]}\n"
                         f"            {c.detail[:600]}")
    counts: dict[str, int] = {}
    for c in done:
        counts[c.verdict] = counts.get(c.verdict, 0) + 1
    lines.append("counts: " + ", ".join(f"{v} {n}" for v, n in sorted(counts.items())))
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=max(1, os.cpu_count() or 1), help="processes (default: the CPUs)")
    ap.add_argument("--only", nargs="+", metavar="COMMAND", help="these commands only ('calibrate plan')")
    ap.add_argument("--mechanism", nargs="+", default=list(MECHANISMS), help="the defaults walk's mechanisms")
    ap.add_argument("--no-docs", action="store_true", help="leave the documented lines out")
    ap.add_argument("--no-defaults", action="store_true", help="leave the defaults walk out")
    ap.add_argument("--full", action="store_true", help="the defaults as they are (not the recipes' quick options: "
                                                        "an excitation's 60 SLSQP iterations on six motors)")
    args = ap.parse_args(argv)
    os.environ.setdefault("MPLBACKEND", "Agg")
    t0 = time.perf_counter()
    todo = list(cells(set(args.only) if args.only else None, tuple(args.mechanism), not args.no_docs,
                      not args.no_defaults, args.full))
    groups: dict[str, list[tuple[Cell, list]]] = {}
    for k, (cell, steps) in enumerate(todo):
        if steps:
            groups.setdefault(cell.group or str(k), []).append((cell, steps))

    def progress(group: list[Cell]) -> list[Cell]:
        for cell in group:
            print(f"  {cell.verdict:<9} {cell.seconds:5.1f}s  {cell.command} [{cell.column}]", file=sys.stderr,
                  flush=True)
        return group

    ran: dict[int, Cell] = {}
    if args.jobs > 1:
        with ProcessPoolExecutor(args.jobs) as pool:
            futures = {pool.submit(_work, g): g for g in groups.values()}
            for f in as_completed(futures):
                ran.update(zip((id(c) for c, _ in futures[f]), progress(f.result())))
    else:
        for g in groups.values():
            ran.update(zip((id(c) for c, _ in g), progress(_work(g))))
    done = [ran.get(id(cell), cell) for cell, _ in todo]  # (in the walk's order)
    print(table(done))
    wall = time.perf_counter() - t0
    print(f"walk: {len(done)} cells in {wall:.1f} s ({args.jobs} processes)")
    return 1 if any(c.verdict in ("FAILED", "refused*") for c in done) else 0


if __name__ == "__main__":
    sys.exit(main())
