"""Newton's Kamino as an anchor for pkm's forward kinematics (issue 56, item 5).

Kamino (``newton._src.solvers.kamino``, Newton's closed-loop solver, BETA) solves forward kinematics of a mechanism
with kinematic loops (:class:`ForwardKinematicsSolver`: Gauss-Newton on the bodies' poses, every joint a constraint,
float32, batched over worlds). Both solve the same problem from the same file: pkm's USD of a shipped closed-loop
mechanism (:func:`pkm.save`), read by Newton's importer, every loop a joint excluded from the articulation. Three
steps, in two environments (Newton is no pkm extra):

    PYTHONPATH=src python tools/kamino_fk.py write OUT_DIR    # pkm's venv (the usd extra)
    python tools/kamino_fk.py solve OUT_DIR                    # a venv with `pip install newton` (1.8.0: numpy, warp,
                                                               # usd-core; Warp's CPU device)
    PYTHONPATH=src python tools/kamino_fk.py compare OUT_DIR   # pkm's venv: tools/reports/kamino_fk.json

``write`` saves each mechanism's USD and ``S`` motor configurations about the closed reference (each motor uniform
within +-0.1 rad, seeded) with pkm's solution (:func:`pkm.close_loops`, float64, tolerance 1e-12 of the
characteristic length L) and its CPU time. ``solve`` loads each file with ``newton.ModelBuilder.add_usd`` into ``S``
worlds (``replicate``), ``ModelKamino.from_newton``, and solves all worlds at once with Kamino's
``ForwardKinematicsSolver`` (its defaults: tolerance 1e-6, reset to the file's reference pose, incremental steps,
axis joints on tie rods; ``use_graph=False``, CUDA graphs being GPU-only), after one untimed solve that compiles
the kernels; it writes each world's status, iterations, Kamino's own residual and the joints' coordinates
(``compute_joints_data``). ``compare`` puts Kamino's coordinates of pkm's tree joints into pkm's model (float64) and
evaluates pkm's closure residual there (:func:`pkm.core.kinematics.constraints.residual`: metres, radians for a 6-D
loop), and the motors' and the other joints' distance from pkm's solution (a ball joint: the angle of the relative
rotation); the joints an idle motion moves (:func:`pkm.idle_motions`: the ankle's rods spinning about their axis
between two balls, the five-bar's end body turning on its two coincident revolutes under its 6-D weld) are free in
both solvers, each picking its own, and are reported apart, not as an error.
"""

from __future__ import annotations

import json
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
#: name: what pkm.load reads
CASES = {"humanoid_ankle": "examples/humanoid_ankle/ankle.closures.toml",
         "delta": "delta", "gepetto_5bar": "gepetto:5bar_linkage", "gepetto_5bar_iso3d": "gepetto:5bar_linkage_iso3d"}
SAMPLES, SPREAD, SEED = 16, 0.1, 56
#: Kamino's FK solver configurations compared: its defaults (dense normal equations), and its sparse path (conjugate
#: gradients), which alone holds the five-bar's 6-D loop (redundant constraints: three of six in a planar loop)
CONFIGS = {"dense": {}, "sparse": {"use_sparsity": True}}
COMMAND = ("PYTHONPATH=src python tools/kamino_fk.py write OUT; python tools/kamino_fk.py solve OUT (newton 1.8.0's "
           "venv); PYTHONPATH=src python tools/kamino_fk.py compare OUT")


def _load(source: str):  # type: ignore[no-untyped-def]
    import pkm

    return pkm.load(ROOT / source if "/" in source else source)


def _coords(mech, q: np.ndarray) -> dict[str, list[float]]:  # type: ignore[no-untyped-def]
    model = mech.model
    return {model.names[j]: [float(x) for x in q[model.joints[j].idx_q:model.joints[j].idx_q + model.joints[j].nq]]
            for j in range(1, model.njoints)}


def write(out: Path) -> None:
    import warnings

    import pkm
    from pkm.core.kinematics.constraints import residual
    from pkm.errors import PkmWarning

    warnings.simplefilter("ignore", PkmWarning)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(SEED)
    for name, source in CASES.items():
        mech = _load(source)
        pkm.save(mech, out / f"{name}.usda")
        q_ref = pkm.close_loops(mech, mech.actuated_q(mech.q_reference)).q  # (what the USD writer poses)
        samples = []
        for _ in range(SAMPLES):
            qa = mech.actuated_q(q_ref) + rng.uniform(-SPREAD, SPREAD, len(mech.actuated_names))
            start = time.process_time()
            sol = pkm.close_loops(mech, qa, q_ref, raise_on_failure=False)
            cpu = time.process_time() - start
            if sol.converged:
                samples.append({"actuated": dict(zip(mech.actuated_names, map(float, qa), strict=True)),
                                "q": _coords(mech, sol.q), "cpu_s": cpu,
                                "residual": float(np.abs(residual(mech, sol.q)).max())})
        N = pkm.idle_motions(mech, q_ref)  # (a tie rod's spin: free in both solvers, no error)
        model = mech.model
        idle = [model.names[j] for j in range(1, model.njoints)
                if np.abs(N[model.joints[j].idx_v:model.joints[j].idx_v + model.joints[j].nv]).max(initial=0.0) > 1e-9]
        (out / f"{name}_pkm.json").write_text(json.dumps({"source": source, "samples": samples, "idle": idle,
                                                          "L": mech.characteristic_length}))
        print(name, len(samples), "samples")


def solve(out: Path) -> None:
    import newton
    import warp as wp
    from newton._src.solvers.kamino._src.core.joints import JointActuationType, JointCorrectionMode
    from newton._src.solvers.kamino._src.core.model import ModelKamino
    from newton._src.solvers.kamino._src.kinematics.joints import compute_joints_data
    from newton._src.solvers.kamino._src.solvers.fk import ForwardKinematicsSolver

    wp.config.quiet = True
    result: dict = {"newton": newton.__version__, "warp": wp.config.version, "device": "cpu", "cases": {}}
    for name in CASES:
        ref = json.loads((out / f"{name}_pkm.json").read_text())
        samples = ref["samples"]
        one = newton.ModelBuilder()
        one.begin_world()
        one.add_usd(str(out / f"{name}.usda"))
        one.end_world()
        builder = newton.ModelBuilder()
        builder.replicate(builder=one, copy_count=len(samples))
        case: dict = {"worlds": len(samples)}
        try:
            model = ModelKamino.from_newton(builder.finalize(device="cpu", skip_validation_inertia=True))
            labels = [str(x).split("/")[-1] for x in builder.joint_label]
            offsets = model.joints.coords_offset.numpy()
            sizes = model.joints.num_coords.numpy()
            worlds = model.joints.wid.numpy()
            actuated = model.joints.act_type.numpy() != JointActuationType.PASSIVE
            values = [samples[int(worlds[j])]["actuated"][labels[j]] for j in np.flatnonzero(actuated)]
            case["actuated_joints"] = sorted({labels[j] for j in np.flatnonzero(actuated)})
            actuator_q = wp.array(np.asarray(values, dtype=np.float32), dtype=wp.float32, device="cpu")
            data = model.data(device="cpu")
            for config, options in CONFIGS.items():
                solver = ForwardKinematicsSolver(model, ForwardKinematicsSolver.Config(**options))
                body_q = wp.zeros(model.size.sum_of_num_bodies, dtype=wp.transformf, device="cpu")
                solver.solve_fk(actuator_q, body_q, use_graph=False)  # (compiles the kernels)
                start, wall = time.process_time(), time.perf_counter()
                status = solver.solve_fk(actuator_q, body_q, use_graph=False, return_status=True)
                run: dict = {"cpu_s": time.process_time() - start, "wall_s": time.perf_counter() - wall}
                wp.copy(data.bodies.q_i, body_q)
                compute_joints_data(model=model, data=data, q_j_p=model.joints.q_j_0,
                                    correction=JointCorrectionMode.CONTINUOUS)
                q_j = data.joints.q_j.numpy().astype(float)
                run["success"] = [int(x) for x in status.success]
                run["iterations"] = [int(i) for i in status.iterations]
                run["kamino_residual"] = [float(r) for r in status.max_residual]
                run["q"] = [{} for _ in samples]
                for j, label in enumerate(labels):
                    run["q"][int(worlds[j])][label] = q_j[offsets[j]:offsets[j] + sizes[j]].tolist()
                case[config] = run
                print(name, config, {key: v for key, v in run.items() if key != "q"})
        except Exception as error:  # (recorded, as Kamino is a BETA: the report says what failed and where)
            case["error"] = f"{type(error).__name__}: {error}"
        result["cases"][name] = case
    (out / "kamino_solve.json").write_text(json.dumps(result))


def _angle(a: list[float], b: list[float]) -> float:
    """The angle [rad] between two unit quaternions (x, y, z, w)."""
    return float(2.0 * np.arccos(min(1.0, abs(float(np.dot(a, b))))))


def _errors(mech, ref: dict, run: dict) -> dict:  # type: ignore[no-untyped-def]
    """Kamino's run against pkm's solutions, over the worlds Kamino says converged."""
    from pkm.core.kinematics.constraints import residual

    model = mech.model
    residuals, motors, joints, idle = [], [], [], []
    for s, qk, ok in zip(ref["samples"], run["q"], run["success"], strict=True):
        if not ok:
            continue
        q = np.array(mech.q_reference, dtype=float)
        for j in range(1, model.njoints):
            jm, label = model.joints[j], model.names[j]
            value = np.asarray(qk[label], dtype=float)
            if jm.nq == 4:
                value = value / np.linalg.norm(value)
            q[jm.idx_q:jm.idx_q + jm.nq] = value
            err = _angle(value, s["q"][label]) if jm.nq == 4 else float(abs(value[0] - s["q"][label][0]))
            (motors if label in mech.actuated_names else idle if label in ref["idle"] else joints).append(err)
        residuals.append(float(np.abs(residual(mech, q)).max()))
    failed = [r if np.isfinite(r) else str(r) for r, ok in zip(run["kamino_residual"], run["success"], strict=True)
              if not ok]  # (Kamino's residual of the worlds it gave up: NaN, written "nan")
    n = len(ref["samples"])
    return {"converged": int(sum(run["success"])), "of": n, "iterations_max": max(run["iterations"]),
            "failed_residuals": failed,
            "own_residual_max": max((r for r, ok in zip(run["kamino_residual"], run["success"], strict=True) if ok),
                                    default=None),
            "pkm_residual_at_kamino_max": max(residuals, default=None),
            "pkm_residual_at_kamino_over_L": max(residuals) / ref["L"] if residuals else None,
            "motor_error_max_rad": max(motors, default=None), "joint_error_max": max(joints, default=None),
            "idle_joints": ref["idle"], "idle_joint_difference_max": max(idle, default=None),
            "cpu_s_all_worlds": run["cpu_s"], "cpu_s_per_world": run["cpu_s"] / n}


def compare(out: Path) -> dict:
    import warnings

    from pkm.errors import PkmWarning

    warnings.simplefilter("ignore", PkmWarning)
    kamino = json.loads((out / "kamino_solve.json").read_text())
    report: dict = {"command": COMMAND, "device": f"Warp 'cpu' ({platform.machine()}), one core of a shared "
                    "two-core host; GPU: missing, no GPU was lent to this session",
                    "newton": kamino["newton"], "warp": kamino["warp"], "samples": SAMPLES, "spread_rad": SPREAD,
                    "cases": {}}
    for name, source in CASES.items():
        ref = json.loads((out / f"{name}_pkm.json").read_text())
        k = kamino["cases"][name]
        mech = _load(source)
        row: dict = {"source": source, "L_m": ref["L"], "worlds": len(ref["samples"]),
                     "pkm": {"residual_max": max(s["residual"] for s in ref["samples"]),
                             "cpu_s_per_solve": float(np.mean([s["cpu_s"] for s in ref["samples"]]))}}
        if "error" in k:
            row["kamino"] = {"error": k["error"]}
            report["cases"][name] = row
            continue
        row["kamino"] = {config: _errors(mech, ref, k[config]) for config in CONFIGS}
        report["cases"][name] = row
        print(name, row)
    reports = ROOT / "tools" / "reports"
    (reports / "kamino_fk.json").write_text(json.dumps(report, indent=1) + "\n")
    md = ["| mechanism | solver | converged | closure residual (pkm's, at the solution) [m] | relative to L | "
          "joints vs pkm's FK [rad, m] | CPU per world [ms] |", "|---|---|---|---|---|---|---|"]
    for name, row in report["cases"].items():
        md.append(f"| {name} | pkm `close_loops` (float64) | {row['worlds']}/{row['worlds']} | "
                  f"{row['pkm']['residual_max']:.1e} | {row['pkm']['residual_max'] / row['L_m']:.1e} | — | "
                  f"{1e3 * row['pkm']['cpu_s_per_solve']:.2f} |")
        for config, r in row["kamino"].items():
            if r["converged"] == 0:
                md.append(f"| {name} | Kamino FK, {config} (float32) | 0/{r['of']} | — | — | — | "
                          f"{1e3 * r['cpu_s_per_world']:.2f} |")
                continue
            md.append(f"| {name} | Kamino FK, {config} (float32) | {r['converged']}/{r['of']} | "
                      f"{r['pkm_residual_at_kamino_max']:.1e} | {r['pkm_residual_at_kamino_over_L']:.1e} | "
                      f"{max(r['motor_error_max_rad'], r['joint_error_max'] or 0.0):.1e} | "
                      f"{1e3 * r['cpu_s_per_world']:.2f} |")
    (reports / "kamino_fk.md").write_text("\n".join(md) + "\n")
    print("\n".join(md))
    return report


if __name__ == "__main__":
    steps = {"write": write, "solve": solve, "compare": compare}
    if len(sys.argv) != 3 or sys.argv[1] not in steps:
        sys.exit(__doc__)
    steps[sys.argv[1]](Path(sys.argv[2]))
