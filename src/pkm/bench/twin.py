"""The generic route at closed-form speed: the twin's generated kernels against the hand-written 3-PRS and MuJoCo.

For the 3-PRS along sec. 5 case 3 (Table 2 design), the Delta and the hexapod along a smooth path of every
actuator, all timed in this run:

* ``hand_written_batch`` (3-PRS only, the baseline of the issue): :meth:`Prs3Dynamics.batch`, vectorised numpy;
* ``kernel_batch_c``: :meth:`pkm.Kernels.inverse_dynamics` on the whole path at once, generated C (the C loop of
  the batch driver; the per-sample time is the C time plus one ctypes call over the path);
* ``kernel_batch_numpy``: the same kernel as numpy vectorised over the samples (what runs without a compiler);
* ``kernel_call``: one sample from Python (compiled);
* ``core``: :func:`pkm.inverse_dynamics` at a precomputed state (the generic route before the twin);
* ``closure_path``: :meth:`pkm.Kernels.close_loops_path`, per solve, warm-started along the path (compiled), next to
  ``closure_core``: :func:`pkm.close_loops` from the previous sample;
* ``mujoco``: MuJoCo's rigid solve at the same states, when MuJoCo is installed (a benchmark-only dependency):
  ``mj_fwdPosition`` and ``mj_rne``, then the actuated efforts and the loops' multipliers from the
  ``nv x (na + nc)`` balance ``B^T tau + J_c^T lambda = rne`` by least squares (:mod:`pkm.bench.mujoco_baseline`).

Every route's efforts are compared with the generic core's (max difference, N or N m).

Usage: ``python -m pkm.bench.twin [--json] [--quick] [-n 20000]``.
"""

from __future__ import annotations

import numpy as np

from pkm.bench import best_time, main, median_us

QUICK = {"n": 100, "repeat": 1, "calls": 50}
MECHANISMS = ("prs3", "delta", "hexapod")


def add_arguments(ap) -> None:
    ap.add_argument("-n", type=int, default=20_000, help="samples along each path (default 20,000)")
    ap.add_argument("--repeat", type=int, default=5, help="timed repeats of each batch route (best kept)")
    ap.add_argument("--calls", type=int, default=2000, help="timed single calls (median kept)")


def _path(mech, n: int):
    """A smooth path of every actuator around the reference: ``qa, qd, qdd`` (n x na), a period over 2 s."""
    t = np.linspace(0.0, 2.0, n)
    amp = 0.01 * (1 + np.arange(mech.na) % 3) / 3
    phase = np.arange(mech.na) * 2 * np.pi / mech.na
    w = np.pi
    s = np.sin(w * t[:, None] + phase)
    c = np.cos(w * t[:, None] + phase)
    return mech.actuated_q(mech.q_reference) + amp * s, amp * w * c, -amp * w * w * s


def _one(name: str, args) -> dict:
    import pkm
    from pkm.bench.mujoco_baseline import MujocoRigid, unavailable

    n = args.n
    out: dict = {}
    if name == "prs3":
        from pkm.mechanisms.prs3 import Prs3Params
        from pkm.mechanisms.prs3.dynamics import Prs3Dynamics
        from pkm.papers.prs3 import motions

        dyn = Prs3Dynamics(Prs3Params())
        mech = dyn.mechanism
        _, Y, Yd, Ydd = motions()["3"].sample(np.linspace(0.0, 5.0, n))
        hand_t, hand = best_time(lambda: dyn.batch(Y, Yd, Ydd), args.repeat)
        QA, QD, QDD = hand.q_actuated, hand.qd_actuated, hand.qdd_actuated
        out["path"] = f"sec. 5 case 3 over 5 s, {n} samples (Table 2, P-actuated)"
        out["hand_written_batch_us"] = hand_t / n * 1e6
    else:
        mech = pkm.load(name)
        QA, QD, QDD = _path(mech, n)
        out["path"] = f"every actuator 0.0033..0.01 (rad or m) sinusoids around the reference, {n} samples"
    K = pkm.Kernels(mech)
    closure_t, path = best_time(lambda: K.close_loops_path(QA, tol=1e-12), args.repeat)
    Q = path.q
    K.inverse_dynamics(Q[:10], QD[:10], QDD[:10])
    c_t, tau = best_time(lambda: K.inverse_dynamics(Q, QD, QDD), args.repeat)
    numpy_route = pkm.Kernels(mech, compiled=False)
    m = min(n, 2000)
    numpy_t, tau_numpy = best_time(lambda: numpy_route.inverse_dynamics(Q[:m], QD[:m], QDD[:m]), max(1, args.repeat // 2))
    k = n // 3
    call_us = median_us(lambda: K.inverse_dynamics(Q[k], QD[k], QDD[k]), [()], args.calls)
    idx = np.linspace(0, n - 1, min(n, 50)).astype(int)
    states = []
    for i in idx:
        v = pkm.velocities(mech, Q[i], QD[i])
        states.append((Q[i], v, pkm.accelerations(mech, Q[i], v, QDD[i])))
    core_tau = np.array([pkm.inverse_dynamics(mech, *s) for s in states])
    core_us = median_us(lambda: pkm.inverse_dynamics(mech, *states[len(states) // 2]), [()], max(20, args.calls // 20))
    closure_core_us = median_us(lambda: pkm.close_loops(mech, QA[k + 1], Q[k]), [()], max(20, args.calls // 20))
    count = K.operation_count()
    diff = {"kernel_batch_c": float(np.abs(tau[idx] - core_tau).max()),
            "kernel_batch_numpy": float(np.abs(tau_numpy - tau[:m]).max())}
    if name == "prs3":
        diff["hand_written_batch"] = float(np.abs(hand.tau[idx] - core_tau).max())
    out.update({
        "kernel_batch_c_us": c_t / n * 1e6,
        "kernel_batch_numpy_us": numpy_t / m * 1e6,
        "kernel_call_us": call_us,
        "core_us": core_us,
        "closure_path_us_per_solve": closure_t / n * 1e6,
        "closure_path_iterations_mean": float(path.iterations.mean()),
        "closure_path_fallbacks": len(path.fallback),
        "closure_core_us_per_solve": closure_core_us,
        "operation_count": {"mul": count.mul, "add": count.add},
        "how": K.how["inverse_dynamics"],
    })
    reason = unavailable()
    if reason is None:
        rigid = MujocoRigid(mech)
        mj_us = median_us(lambda: rigid.efforts(*states[len(states) // 2]), [()], max(20, args.calls // 10))
        diff["mujoco"] = float(np.abs(np.array([rigid.efforts(*s) for s in states]) - core_tau).max())
        out["mujoco_rigid_us"] = mj_us
        out["ratio_to_mujoco"] = {"kernel_batch_c": mj_us / out["kernel_batch_c_us"],
                                  "kernel_call": mj_us / call_us}
    else:
        out["mujoco_rigid_us"] = None
        out["mujoco"] = reason
    if name == "prs3":
        out["ratio_to_hand_written_batch"] = {"kernel_batch_c": out["kernel_batch_c_us"] / out["hand_written_batch_us"],
                                              "kernel_batch_numpy": out["kernel_batch_numpy_us"] / out["hand_written_batch_us"]}
    out["max_effort_difference_to_core"] = diff
    return out


def run(args) -> dict:
    return {
        "mechanisms": {name: _one(name, args) for name in MECHANISMS},
        "goals": {"prs3_batch_vs_hand_written": 3.0, "c_us_per_sample": 1.0, "call_us": 30.0,
                  "closure_us_per_solve (delta, prs3)": 20.0},
    }


def table(result: dict) -> str:
    rows = [("hand-written batch (3-PRS)", "hand_written_batch_us"), ("kernel batch, C", "kernel_batch_c_us"),
            ("kernel batch, numpy", "kernel_batch_numpy_us"), ("kernel, one call", "kernel_call_us"),
            ("generic core, one call", "core_us"), ("MuJoCo rigid solve", "mujoco_rigid_us"),
            ("closure path, per solve", "closure_path_us_per_solve"),
            ("close_loops, per solve", "closure_core_us_per_solve")]
    names = list(result["mechanisms"])
    lines = [f"{'us per sample':30s}" + "".join(f"{n:>12s}" for n in names)]
    for label, key in rows:
        vals = [result["mechanisms"][n].get(key) for n in names]
        lines.append(f"{label:30s}" + "".join(f"{v:12.3f}" if isinstance(v, float) else f"{'-':>12s}" for v in vals))
    lines.append(f"{'operations (mul/add)':30s}" + "".join(
        f"{result['mechanisms'][n]['operation_count']['mul']:>7d}/{result['mechanisms'][n]['operation_count']['add']:<4d}"
        for n in names))
    for n in names:
        lines.append(f"{n}: max |tau - core| " + ", ".join(
            f"{k} {v:.1e}" for k, v in result["mechanisms"][n]["max_effort_difference_to_core"].items()))
        if result["mechanisms"][n]["mujoco_rigid_us"] is None:
            lines.append(f"{n}: MuJoCo not run ({result['mechanisms'][n]['mujoco']})")
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main("twin"))
