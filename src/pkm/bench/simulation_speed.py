"""The actuator-space model and the simulation in C: against Pinocchio, the Python route and MuJoCo, in one run.

(a) ``M_a`` and ``h_a`` of the 3-PRS (Table 2 design) and the Delta along a smooth path of every actuator
(:func:`pkm.bench.twin._path`, closed by :meth:`pkm.Kernels.close_loops_path`), µs per sample:

* ``c_batch``: :meth:`pkm.Kernels.mass_and_bias` on the whole path (one fused generated kernel, its C loop);
* ``pinocchio``: the baseline, Pinocchio's ``crba`` and ``rnea`` (``a = 0``) of the open tree at the same joint
  rates, one call each per sample from Python (the tree's ``nv x nv`` mass matrix and bias, before any reduction to
  the actuated coordinates);
* ``python``: :func:`pkm.actuator_model` per sample (the Python route, which reduces Pinocchio's to ``M_a``, ``h_a``).

(b) 10 s (``--duration``) of the Delta at 1 kHz, RK4. The start is the pose ``(0, 0, -0.35)`` m (the inverse
kinematics' default branch), held by constant efforts ``g_a`` (gravity's there, a stable equilibrium: the gravity
stiffness ``dg_a/dq_a`` is positive definite) plus a chirp of 0.02 N m (0.5 Hz rising by 1 Hz per second; motor
weights 1, -0.5, 0.3): a sampled torque table, interpolated linearly; the motion stays regular, its amplitude
about 0.4 rad (released from rest without efforts the Delta reaches a direct singularity at 0.23 s instead):

* ``c``: :func:`pkm.simulate` with ``backend="c"``, wall time of a run once the mechanism's simulation is
  compiled (the first run's build and compile given apart);
* ``python``: the same with ``backend="python"``, over ``--python-duration`` (default the whole run), scaled to the
  run's length (it is linear in the steps); both routes' samples are compared over that span;
* ``mujoco`` (the ``bench`` extra; skipped without it): MuJoCo stepping the Delta's MJCF
  (:func:`pkm.core.formats.to_mjcf.mjcf_from_mechanism`, motors on the actuated joints, the closures as soft
  ``connect`` equalities) from the same state with the same efforts held per step, at the same step, with its RK4
  and with its default Euler integrator (``mujoco.rollout``, MuJoCo's own C loop, when it is there); how far its
  motors go from pkm's over the run is reported (another model of the closures: not a check).

Usage: ``python -m pkm.bench.simulation_speed [--json] [--quick] [-n 20000] [--duration 10]``.
"""

from __future__ import annotations

import time

import numpy as np

from pkm.bench import best_time, main, median_us

QUICK = {"n": 400, "repeat": 2, "calls": 50, "duration": 0.2, "python_duration": 0.05}
MECHANISMS = ("prs3", "delta")
POSE = (0.0, 0.0, -0.35)
CHIRP = (0.02, (1.0, -0.5, 0.3))  # N m, motor weights


def add_arguments(ap) -> None:
    ap.add_argument("-n", type=int, default=20_000, help="samples along each path for M_a + h_a (default 20,000)")
    ap.add_argument("--repeat", type=int, default=5, help="timed repeats of each batch and of the C run (best kept)")
    ap.add_argument("--calls", type=int, default=500, help="timed single calls of the Python and Pinocchio routes")
    ap.add_argument("--duration", type=float, default=10.0, help="simulated time of the Delta [s] (default 10)")
    ap.add_argument("--python-duration", type=float, default=None,
                    help="simulated time of the Python route [s] (default: --duration)")


def _model(name: str, args) -> dict:
    import pinocchio as pin

    import pkm
    from pkm.bench.twin import _path

    if name == "prs3":
        from pkm.mechanisms.prs3 import Prs3Params
        from pkm.mechanisms.prs3.dynamics import Prs3Dynamics

        mech = Prs3Dynamics(Prs3Params()).mechanism
    else:
        mech = pkm.load(name)
    K = pkm.Kernels(mech)
    QA, QD, _ = _path(mech, args.n)
    Q = K.close_loops_path(QA).q
    K.mass_and_bias(Q[:10], QD[:10])
    c_t, (M, h) = best_time(lambda: K.mass_and_bias(Q, QD), args.repeat)
    V = K.velocities(Q, QD)
    m = min(args.n, args.calls)
    idx = np.linspace(0, args.n - 1, m).astype(int)
    model, data = mech.model, mech.data
    zero = np.zeros(mech.nv)

    def tree(k: int) -> None:
        pin.crba(model, data, Q[k])
        pin.rnea(model, data, Q[k], V[k], zero)

    pin_us = median_us(tree, [(int(k),) for k in idx], m)
    py_us = median_us(lambda k: pkm.actuator_model(mech, Q[k], QD[k]), [(int(k),) for k in idx[:50]],
                      max(10, m // 5))
    worst = 0.0
    for k in idx[:20]:
        ref = pkm.actuator_model(mech, Q[k], QD[k])
        worst = max(worst, float(np.abs(M[k] - ref.M).max() / np.abs(ref.M).max()),
                    float(np.abs(h[k] - ref.h).max() / max(np.abs(ref.h).max(), 1e-300)))
    c_us = c_t / args.n * 1e6
    return {"c_batch_us": c_us, "pinocchio_crba_rnea_us": pin_us, "python_actuator_model_us": py_us,
            "ratio_pinocchio_to_c": pin_us / c_us, "ratio_python_to_c": py_us / c_us,
            "max_relative_difference_to_python": worst, "samples": args.n, "how": K.how["mass_and_bias"]}


def _start():
    import pkm

    mech = pkm.load("delta")
    q0 = pkm.solve_ik(mech, list(POSE)).q
    return mech, q0, pkm.gravity_efforts(mech, q0)


def _table(g: np.ndarray, duration: float, dt: float) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(round(duration / dt) + 1) * dt
    amp, weights = CHIRP
    return t, g + amp * np.sin(2 * np.pi * (0.5 + 0.5 * t) * t)[:, None] * np.array(weights)


def _mujoco(mech, q0: np.ndarray, table: tuple[np.ndarray, np.ndarray], dt: float, repeat: int,
            actuated: np.ndarray | None = None) -> dict:
    from pkm.bench.mujoco_baseline import MujocoRigid, unavailable

    reason = unavailable()
    if reason is not None:
        return {"mujoco": reason}
    import mujoco

    rigid = MujocoRigid(mech)
    m, d = rigid.model, rigid.data
    m.opt.timestep = dt
    rigid._state(q0, np.zeros(mech.nv), np.zeros(mech.nv))
    mujoco.mj_forward(m, d)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.empty(mujoco.mj_stateSize(m, spec))
    mujoco.mj_getState(m, d, state, spec)
    ctrl = np.ascontiguousarray(table[1][:-1])
    try:
        from mujoco import rollout
    except ImportError:
        rollout = None
    out: dict = {"mujoco_loop": "mujoco.rollout" if rollout is not None else "mj_step from Python"}
    for label, integrator in (("rk4", mujoco.mjtIntegrator.mjINT_RK4), ("euler", mujoco.mjtIntegrator.mjINT_EULER)):
        m.opt.integrator = integrator

        def run() -> None:
            if rollout is not None:
                rollout.rollout(m, d, state[None], ctrl[None])
                return
            mujoco.mj_setState(m, d, state, spec)
            for u in ctrl:
                d.ctrl[:] = u
                mujoco.mj_step(m, d)

        wall, _ = best_time(run, max(1, min(repeat, 3)))
        out[f"mujoco_{label}_s"] = wall
        if rollout is not None and actuated is not None:  # (how far MuJoCo's motors go from pkm's: not a check)
            states = rollout.rollout(m, d, state[None], ctrl[None])[0][0]
            adr = [int(m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n)]) for n in mech.actuated_names]
            out[f"mujoco_{label}_deviation_rad"] = float(np.abs(states[:, 1:][:, adr] - actuated[1:]).max())
    return out


def _simulation(args) -> dict:
    import pkm

    dt = 1e-3
    mech, q0, g = _start()
    table = _table(g, args.duration, dt)
    t0 = time.perf_counter()
    pkm.simulate(mech, q0, duration=min(args.duration, 0.01), dt=dt, torques=table, backend="c")
    build = time.perf_counter() - t0
    c_wall, run_c = best_time(lambda: pkm.simulate(mech, q0, duration=args.duration, dt=dt, torques=table,
                                                   backend="c"), max(1, min(args.repeat, 3)))
    span = args.duration if args.python_duration is None else min(args.python_duration, args.duration)
    t0 = time.perf_counter()
    run_py = pkm.simulate(mech, q0, duration=span, dt=dt, torques=table, backend="python")
    py_wall = (time.perf_counter() - t0) * args.duration / span
    n = len(run_py)
    out = {
        "duration_s": args.duration, "dt_s": dt, "steps": len(run_c) - 1,
        "start": f"pose {POSE} m, efforts g_a there + a {CHIRP[0]} N m chirp (weights {CHIRP[1]})",
        "event": None if run_c.event is None else run_c.event.kind,
        "amplitude_rad": float(np.abs(run_c.actuated - run_c.actuated[0]).max()),
        "c_s": c_wall, "c_build_first_run_s": build, "python_s": py_wall, "python_simulated_s": span,
        "ratio_python_to_c": py_wall / c_wall,
        "difference_to_python": {
            "q": float(np.abs(run_c.q[:n] - run_py.q).max()),
            "rates": float(np.abs(run_c.actuated_velocity[:n] - run_py.actuated_velocity).max()),
            "energy_J": float(np.abs(run_c.energy[:n] - run_py.energy).max())},
        "energy_range_J": float(np.ptp(run_c.energy)),
    }
    mj = _mujoco(mech, q0, table, dt, args.repeat, run_c.actuated if run_c.event is None else None)
    out.update(mj)
    if "mujoco_rk4_s" in mj:
        out["ratio_mujoco_to_c"] = {k: mj[f"mujoco_{k}_s"] / c_wall for k in ("rk4", "euler")}
    return out


def run(args) -> dict:
    return {
        "model": {name: _model(name, args) for name in MECHANISMS},
        "simulation": _simulation(args),
        "goals": {"c_batch_us": 1.0, "c_simulation_s (10 s at 1 kHz)": 0.2},
    }


def table(result: dict) -> str:
    names = list(result["model"])
    lines = [f"{'M_a + h_a, us per sample':34s}" + "".join(f"{n:>12s}" for n in names)]
    for label, key in (("C batch (fused kernel)", "c_batch_us"), ("Pinocchio crba + rnea (tree)", "pinocchio_crba_rnea_us"),
                       ("Python actuator_model", "python_actuator_model_us")):
        lines.append(f"{label:34s}" + "".join(f"{result['model'][n][key]:12.3f}" for n in names))
    lines.append(f"{'max rel. difference to Python':34s}" + "".join(
        f"{result['model'][n]['max_relative_difference_to_python']:12.1e}" for n in names))
    s = result["simulation"]
    lines.append(f"Delta, {s['duration_s']:g} s at {1 / s['dt_s']:g} Hz (RK4; {s['start']}):")
    lines.append(f"  C backend        {s['c_s']:9.3f} s   (first run, with the build: {s['c_build_first_run_s']:.2f} s)")
    lines.append(f"  Python backend   {s['python_s']:9.3f} s   ({s['ratio_python_to_c']:.0f} x; timed over "
                 f"{s['python_simulated_s']:g} s, scaled)")
    if "mujoco_rk4_s" in s:
        for label, key in (("RK4", "rk4"), ("Euler", "euler")):
            off = s.get(f"mujoco_{key}_deviation_rad")
            lines.append(f"  MuJoCo, {label:8s} {s[f'mujoco_{key}_s']:9.3f} s   ({s['ratio_mujoco_to_c'][key]:.2f} x C"
                         + ("" if off is None else f"; its motors within {off:.1e} rad of pkm's") + ")")
    else:
        lines.append(f"  MuJoCo not run ({s['mujoco']})")
    d = s["difference_to_python"]
    lines.append(f"  C vs Python: max |q| {d['q']:.1e}, rates {d['rates']:.1e}, energy {d['energy_J']:.1e} J; "
                 f"event {s['event']}, amplitude {s['amplitude_rad']:.3f} rad")
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main("simulation_speed"))
