"""Every assembly mode by homotopy continuation against a multistart Newton given the same time (issue 17).

For each mechanism, at its reference actuators:

* ``pkm.assembly_modes``: wall time to every real mode, the count, paths tracked, completeness;
* a multistart of the generic core with the same wall-time budget: Levenberg-Marquardt on the loop closures
  (:func:`pkm.assemble`, the actuators held) from the reference with every passive joint drawn at random, as
  many starts as fit; the distinct modes it finds, and how many of the homotopy's;
* for the 6-UPS also the homotopy from scratch (a 128-path total-degree start, no generic start): what the
  shipped start saves.

Mechanisms: the shipped ones, and ``gough_stewart_generic``: a Gough-Stewart with random base and platform points
(seed 3), whose 40 complex modes are the known count. Usage: ``python tools/bench_assembly.py [--json]
[--quick] [--budget-factor 1.0] [MECH ...]``.
"""

from __future__ import annotations

import importlib.util
import time

import numpy as np
import pinocchio as pin

import pkm
from pkm.bench import main
from pkm.errors import PkmError

QUICK = {"mechanisms": ["delta", "rrr3"], "from_scratch": False, "budget_factor": 0.5}
GENERIC = "gough_stewart_generic"


def _mechanism(name: str) -> pkm.Mechanism:
    if name != GENERIC:
        return pkm.load(name)
    rng = np.random.default_rng(3)
    base = rng.uniform(-0.6, 0.6, (6, 3)) * [1.0, 1.0, 0.2]
    platform = rng.uniform(-0.4, 0.4, (6, 3)) * [1.0, 1.0, 0.2]
    return pkm.build("gough_stewart", base=base.tolist(), platform=platform.tolist(), leg_min=0.3, leg_max=1.6)


def _same(mech, q1, q2) -> bool:
    d = mech.model.createData()
    jp = mech.model.frames[mech.ee_frame].parentJoint
    poses = []
    for q in (q1, q2):
        pin.forwardKinematics(mech.model, d, q)
        poses.append(d.oMi[jp].copy())
    return bool(np.abs(pin.log6(poses[0].actInv(poses[1])).vector).max() < 1e-7)


def multistart(mech: pkm.Mechanism, qa: np.ndarray, budget: float, seed: int = 0) -> tuple[list[np.ndarray], int]:
    """Distinct assemblies found by the generic core from random starts within ``budget`` seconds."""
    rng = np.random.default_rng(seed)
    hold = [j.name for j in mech.actuated]
    q_ref = mech.with_actuated(mech.q_reference, qa)
    passive = np.zeros(mech.nv, dtype=bool)
    passive[mech.passive_v] = True
    found: list[np.ndarray] = []
    starts, t0 = 0, time.perf_counter()
    while time.perf_counter() - t0 < budget:
        starts += 1
        q0 = pin.integrate(mech.model, q_ref, np.where(passive, rng.normal(scale=1.5, size=mech.nv), 0.0))
        try:
            q = pkm.assemble(mech, q0, hold=hold, restarts=0, seed=starts, tol=1e-10).q
        except PkmError:
            continue
        if not any(_same(mech, q, f) for f in found):
            found.append(q)
    return found, starts


def bench(name: str, budget_factor: float, from_scratch: bool) -> dict:
    mech = _mechanism(name)
    qa = mech.actuated_q(mech.q_reference)
    t0 = time.perf_counter()
    modes = pkm.assembly_modes(mech, qa)
    seconds = time.perf_counter() - t0
    found, starts = multistart(mech, qa, budget_factor * seconds)
    out = {"mechanism": name, "homotopy_s": seconds, "modes": len(modes), "complex": modes.n_complex,
           "paths": modes.n_paths, "complete": modes.complete, "method": modes.method,
           "multistart_budget_s": budget_factor * seconds, "multistart_starts": starts,
           "multistart_modes": len(found),
           "multistart_found_of_homotopy": sum(any(_same(mech, m.q, f) for f in found) for m in modes)}
    if from_scratch and name.startswith("gough_stewart"):
        t0 = time.perf_counter()
        full = pkm.assembly_modes(mech, qa, method="total-degree")
        out["total_degree_s"] = time.perf_counter() - t0
        out["total_degree_modes"] = len(full)
        out["total_degree_paths"] = full.n_paths
    return out


def add_arguments(ap) -> None:
    ap.add_argument("--budget-factor", type=float, default=1.0, help="multistart time / homotopy time")
    ap.add_argument("--no-from-scratch", dest="from_scratch", action="store_false",
                    help="skip the 6-UPS's 128-path total-degree solve")
    ap.add_argument("mechanisms", nargs="*", default=[*pkm.MECHANISMS, GENERIC])


def run(args) -> list[dict]:
    if importlib.util.find_spec("bertini") is None:  # the homotopy's solver: the optional extra pkm-robotics[homotopy]
        return [{"mechanism": name, "skipped": "bertini2 is not installed (pip install \"pkm-robotics[homotopy]\")"}
                for name in args.mechanisms]
    return [bench(name, args.budget_factor, args.from_scratch) for name in args.mechanisms]


def table(results: list[dict]) -> str:
    lines = [f"{'mechanism':22} {'homotopy s':>10} {'modes':>5} {'paths':>5} {'complete':>8} "
             f"{'multistart':>10} {'found':>5} {'of ours':>7} {'128-path s':>10}"]
    for r in results:
        if "skipped" in r:
            lines.append(f"{r['mechanism']:22} skipped: {r['skipped']}")
            continue
        scratch = f"{r['total_degree_s']:10.1f}" if "total_degree_s" in r else f"{'-':>10}"
        lines.append(f"{r['mechanism']:22} {r['homotopy_s']:10.2f} {r['modes']:5d} {r['paths']:5d} "
                     f"{r['complete']!s:>8} {r['multistart_starts']:10d} {r['multistart_modes']:5d} "
                     f"{r['multistart_found_of_homotopy']:7d} {scratch}")
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main("assembly"))
