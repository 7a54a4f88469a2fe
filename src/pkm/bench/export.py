"""The exported C library (``pkm export c``) per call, next to pkm's Python routes timed in the same run.

For each mechanism (default: the humanoid ankle and knee of ``examples/humanoid_ankle`` and ``humanoid_knee``, and
the Delta) the library is
exported, built ``-O2`` (:func:`pkm.core.export.harness.build`: the strict C99 build) and timed in C over ``-n``
calls (default 10⁵), in blocks of 100, the median block's time per call:

* ``fk``: the forward kinematics along a 1 kHz motion of the actuators (0.2 rad sines at 0.5 and 0.7 Hz, or 0.2 of
  the mechanism's size for prismatic ones), each call warm-started from the previous call's solution;
* ``ik``: the inverse kinematics of the same path's task values, each from the previous sample's configuration;
* ``ik_actuators``: the closed-form inverse kinematics of the actuators, where the mechanism has one (crank legs:
  the ankle, the knee), of the same task values;
* ``jacobians`` (both), ``inverse_dynamics`` (unit rates and accelerations), ``mass_matrix`` at its configurations.

The Python routes, per call (median of ``--calls``): :func:`pkm.close_loops` from the previous sample,
:func:`pkm.solve_ik` from the previous sample, :func:`pkm.forward_jacobian` with :func:`pkm.inverse_jacobian`,
:func:`pkm.actuator_model` (``M_a qdd + h_a``), :func:`pkm.mass_matrix`. The targets of issue 31 on this machine are
for the ankle: FK ≤ 1 µs, IK ≤ 0.3 µs (the closed form's), inverse dynamics ≤ 1 µs.

Usage: ``python -m pkm.bench.export [--json] [--quick] [-n 100000] [--calls 300] [--mechanism NAME ...]``.
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from pkm.bench import median_us

QUICK = {"n": 1000, "calls": 10, "mechanism": ["delta"]}
EXAMPLES = Path(__file__).resolve().parents[3] / "examples"
MECHANISMS = ("humanoid_ankle", "humanoid_knee", "delta")
#: What each C function is timed against.
PYTHON = {"fk": "close_loops", "ik": "solve_ik", "ik_actuators": "solve_ik", "jacobians": "forward_jacobian + inverse_jacobian",
          "inverse_dynamics": "actuator_model", "mass_matrix": "mass_matrix"}


def add_arguments(ap) -> None:
    ap.add_argument("-n", type=int, default=100_000, help="calls timed in C per function (default 10^5)")
    ap.add_argument("--calls", type=int, default=300, help="calls timed in Python per function (default 300)")
    ap.add_argument("--mechanism", nargs="*", default=list(MECHANISMS),
                    help="shipped names or folders of examples/ (default: the humanoid ankle and knee, the Delta)")


def _load(name: str):
    """A shipped mechanism, or one of the checkout's ``examples/<name>`` (None when pkm runs from a wheel, which
    does not ship them)."""
    import pkm
    from pkm.mechanisms import REGISTRY

    local = sorted((EXAMPLES / name).glob("*.closures.toml")) if (EXAMPLES / name).is_dir() else []
    if local:
        return pkm.load(local[0])
    return pkm.load(name) if name in REGISTRY or Path(name).exists() else None


def _one(name: str, args, folder: Path) -> dict[str, Any]:
    import pkm
    from pkm.core.export import export_c
    from pkm.core.export.harness import build

    mech = _load(name)
    if mech is None:
        return {"mechanism": name, "skipped": "examples/ is not shipped in the wheel: run from a checkout"}
    lib = export_c(mech, folder / name)
    h = build(lib, optimise="-O2")
    ref, n, na, nq = mech.q_reference, max(args.n, 200), mech.na, mech.nq
    t = np.arange(n) * 1e-3
    amp = np.array([0.2 if mech.joints[j].revolute else 0.2 * 0.05 for j in mech.actuated_names])
    QA = mech.actuated_q(ref) + amp * np.sin(2 * np.pi * (0.5 + 0.2 * np.arange(na)) * t[:, None] + np.arange(na))
    zeros = np.zeros((n, 1))
    rows = np.hstack([QA, np.tile(ref, (n, 1)), zeros])
    solved = h.run("fk", rows)  # (the path's configurations, each from the reference)
    ok = solved[:, 0] == 0
    Q, Y = solved[:, 4:4 + nq], solved[:, 4 + nq:]
    previous = np.vstack([ref, Q[:-1]])
    ones = np.ones((n, na))
    c = {"fk": h.bench("fk", rows),
         "ik": h.bench("ik", np.hstack([Y, previous, zeros])),
         "jacobians": h.bench("jacobians", Q),
         "inverse_dynamics": h.bench("inverse_dynamics", np.hstack([Q, ones, ones])),
         "mass_matrix": h.bench("mass_matrix", Q)}
    if not lib.closed_form:
        c["ik_actuators"] = h.bench("ik_actuators", np.hstack([Y, zeros]))
    idx = np.linspace(1, n - 1, min(args.calls, n - 1)).astype(int)
    calls = [(int(k),) for k in idx]
    m = len(calls)

    def model(k: int) -> np.ndarray:
        a = pkm.actuator_model(mech, Q[k], ones[k])
        return a.M @ ones[k] + a.h

    py = {"fk": median_us(lambda k: pkm.close_loops(mech, QA[k], Q[k - 1]), calls, m),
          "ik": median_us(lambda k: pkm.solve_ik(mech, Y[k], Q[k - 1]), calls, m),
          "jacobians": median_us(lambda k: (pkm.forward_jacobian(mech, Q[k]), pkm.inverse_jacobian(mech, Q[k])),
                                 calls, m),
          "inverse_dynamics": median_us(model, calls, m),
          "mass_matrix": median_us(lambda k: pkm.mass_matrix(mech, Q[k]), calls, m)}
    if "ik_actuators" in c:
        py["ik_actuators"] = py["ik"]
    fk_path = h.run("fk", np.hstack([QA[:2000], previous[:2000], zeros[:2000]]))
    return {"mechanism": mech.name, "calls": n, "path_solved": int(ok.sum()),
            "fk_iterations_warm": float(fk_path[1:, 1].mean()),
            "c_us": {k: v * 1e6 for k, v in c.items()}, "python_us": py,
            "ratio_python_to_c": {k: py[k] / (c[k] * 1e6) for k in c}, "operations": lib.operations}


def run(args) -> dict[str, Any]:
    from pkm.core.export.harness import compiler

    if compiler("cc") is None:
        return {"mechanisms": [], "skipped": "no C compiler"}
    with tempfile.TemporaryDirectory() as tmp:
        return {"mechanisms": [_one(name, args, Path(tmp)) for name in args.mechanism]}


def table(r: dict[str, Any]) -> str:
    if r.get("skipped"):
        return f"export: skipped ({r['skipped']})"
    lines = ["exported C per call (median over blocks of 100 calls, -O2) against pkm's Python route:"]
    for m in r["mechanisms"]:
        if "skipped" in m:
            lines.append(f"  {m['mechanism']}: skipped ({m['skipped']})")
            continue
        lines.append(f"  {m['mechanism']} ({m['calls']} calls; forward kinematics warm-started: "
                     f"{m['fk_iterations_warm']:.2f} Newton evaluations a call)")
        for k, us in m["c_us"].items():
            lines.append(f"    {k:17s} C {us:8.3f} us   Python {m['python_us'][k]:9.1f} us ({PYTHON[k]})   "
                         f"ratio {m['ratio_python_to_c'][k]:8.0f}")
    return "\n".join(lines)


if __name__ == "__main__":
    from pkm.bench import main

    raise SystemExit(main("export"))
