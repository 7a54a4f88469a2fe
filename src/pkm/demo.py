"""``python -m pkm.demo`` (``make demo``): the four reference designs through the generic core.

For each mechanism: its size, then at random reachable poses around its reference the agreement
between the paper's closed forms and the generic Pinocchio core, and the conditioning of its
Jacobian. It grows into the full report of the papers' results in later work.
"""

from __future__ import annotations

import time

import numpy as np

import pkm
from pkm.core import TaskMap, close_loops, constraints, diagnose, solve_ik
from pkm.errors import PkmError
from pkm.mechanisms import NAMES, TITLES, module


def _summary(name: str, n: int = 20, seed: int = 0) -> dict[str, float]:
    mech, mod = pkm.load(name), module(name)
    task = TaskMap(mech)
    rng = np.random.default_rng(seed)
    y_ref = task.value(mech.q_reference)
    worst = {"closure": 0.0, "fk": 0.0, "ik": 0.0, "paper_fk": 0.0}
    conds, t_generic, t_closed = [], 0.0, 0.0
    done = 0
    while done < n:
        y = task.retract(y_ref, 0.02 * rng.uniform(-1, 1, task.size))
        try:
            t0 = time.perf_counter()
            qa = mod.closed_form_ik(mech.params, y)
            t_closed += time.perf_counter() - t0
            t0 = time.perf_counter()
            ik = solve_ik(mech, y)
            t_generic += time.perf_counter() - t0
        except PkmError:
            continue
        fk = close_loops(mech, qa)
        worst["closure"] = max(worst["closure"], fk.residual)
        worst["fk"] = max(worst["fk"], float(np.abs(task.error(y, task.value(fk.q))).max()))
        worst["ik"] = max(worst["ik"], float(np.abs(mech.actuated_q(ik.q) - qa).max()))
        if hasattr(mod, "closed_form_fk"):
            worst["paper_fk"] = max(worst["paper_fk"],
                                    float(np.abs(task.error(y, mod.closed_form_fk(mech.params, qa))).max()))
        conds.append(np.linalg.cond(pkm.forward_jacobian(mech, fk.q)))
        done += 1
    d = diagnose(mech, mech.q_reference)
    return {"mech": mech, "diag": d, "worst": worst, "cond": float(np.median(conds)),
            "t_generic": t_generic / n, "t_closed": t_closed / n, "has_fk": hasattr(mod, "closed_form_fk"),
            "ref_res": float(np.abs(constraints.residual(mech, mech.q_reference)).max())}


def main() -> None:
    print(f"pkm {pkm.__version__}: the papers' reference designs through the generic closed-loop core\n")
    for name in NAMES:
        s = _summary(name)
        mech, d, w = s["mech"], s["diag"], s["worst"]
        outputs = list(mech.spec.task.components) + list(mech.spec.task.joints)
        print(f"== {name}: {TITLES[name]}")
        print(f"   tree: nq={mech.nq} nv={mech.nv}; {len(mech.spec.closures)} closures ({mech.n_constraints} eq., "
              f"rank {d.constraint_rank}); mobility {d.mobility}; actuated {list(mech.actuated_names)}")
        print(f"   outputs {outputs}; working modes {list(mech.spec.branches)} (default {mech.spec.default_branch})")
        print(f"   reference: closure residual {s['ref_res']:.1e}, {d.classification} "
              f"(sigma direct {d.sigma_direct:.3g}, inverse {d.sigma_inverse:.3g})")
        fk_paper = f", paper FK vs pose {w['paper_fk']:.1e}" if s["has_fk"] else ""
        print(f"   20 random poses: closure {w['closure']:.1e}, IK->FK round trip {w['fk']:.1e}, "
              f"generic IK vs paper closed form {w['ik']:.1e}{fk_paper}")
        print(f"   median cond(J_fwd) {s['cond']:.3g}; generic IK {1e3 * s['t_generic']:.2f} ms vs closed form "
              f"{1e6 * s['t_closed']:.0f} us\n")


if __name__ == "__main__":
    main()
