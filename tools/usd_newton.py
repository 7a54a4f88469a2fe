"""Does a USD file written by pkm load in Newton with pkm's mass matrix? (issue 56, item 4)

Two steps, in two environments (Newton is no pkm extra):

    python tools/usd_newton.py write OUT_DIR   # pkm's venv (the usd extra): the USD files and pkm's mass matrices
    python tools/usd_newton.py check OUT_DIR   # a venv with `pip install "newton[importers]"` (numpy, warp, usd-core)

``write`` saves the humanoid ankle's serial-equivalent model (:func:`pkm.core.formats.to_usd.serial_usd`), the ankle and
the Delta (:func:`pkm.save`), and for each ``<name>_pkm.json``: pkm's joint-space inertia of the tree (Pinocchio's
CRBA, the model's armature included: ΔM's diagonal for the serial model, the drives' reflected inertia for the others)
at a configuration (the closed reference + 0.05 on each motor; ``ankle_id``: the ankle's with its ball joints at the
identity), the coordinates by joint name. ``check`` loads each file with ``newton.ModelBuilder.add_usd``,
``finalize(device="cpu", skip_validation_inertia=True)`` (Newton would otherwise give pkm's massless bodies a mass),
sets the same coordinates by joint name, and compares ``newton.eval_mass_matrix`` (float32) with pkm's, writing
``tools/usd_newton.json`` (relative error: max |H - M| / max |M|).
"""

from __future__ import annotations

import json
import shutil
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
CASES = ("ankle_serial", "ankle", "ankle_id", "delta")


def _dump(out: Path, name: str, model, q: np.ndarray) -> None:  # type: ignore[no-untyped-def]
    import pinocchio as pin

    M = pin.crba(model, model.createData(), q)  # (Pinocchio adds model.armature to the diagonal)
    M = np.triu(M) + np.triu(M, 1).T
    names: list[str | None] = [None] * model.nv
    coords = {}
    for j in range(1, model.njoints):
        jm = model.joints[j]
        if jm.shortname() != "JointModelMimic":
            for k in range(jm.nv):
                names[jm.idx_v + k] = model.names[j]
            coords[model.names[j]] = [float(x) for x in q[jm.idx_q:jm.idx_q + jm.nq]]
    (out / f"{name}_pkm.json").write_text(json.dumps({"M": M.tolist(), "q": coords, "names": names}))


def write(out: Path) -> None:
    import warnings

    import pkm
    from pkm.core.formats.to_usd import serial_usd
    from pkm.errors import PkmWarning

    warnings.simplefilter("ignore", PkmWarning)
    out.mkdir(parents=True, exist_ok=True)
    ankle = pkm.load(ROOT / "examples" / "humanoid_ankle" / "ankle.closures.toml")
    se = pkm.serial_equivalent(ankle, limits=False)
    for joint, armature in se.armature.items():  # (ΔM's diagonal is the serial model's armature)
        assert se.model.armature[se.model.joints[se.model.getJointId(joint)].idx_v] == armature
    serial_usd(se, out / "ankle_serial.usda")
    _dump(out, "ankle_serial", se.model, se.q_reference)
    for name, mech in (("ankle", ankle), ("delta", pkm.load("delta"))):
        pkm.save(mech, out / f"{name}.usda")
        q = pkm.close_loops(mech, mech.actuated_q(mech.q_reference) + 0.05).q
        _dump(out, name, mech.model, q)
        if name == "ankle":
            for j in range(1, mech.model.njoints):
                if mech.model.joints[j].nq == 4:
                    iq = mech.model.joints[j].idx_q
                    q[iq:iq + 4] = [0.0, 0.0, 0.0, 1.0]
            shutil.copy(out / "ankle.usda", out / "ankle_id.usda")
            _dump(out, "ankle_id", mech.model, q)


def check(out: Path) -> dict:
    import newton
    import warp as wp

    wp.config.quiet = True
    results: dict = {"newton": newton.__version__, "warp": wp.config.version, "device": "cpu", "cases": {}}
    for name in CASES:
        ref = json.loads((out / f"{name}_pkm.json").read_text())
        builder = newton.ModelBuilder()
        t = time.process_time()
        builder.add_usd(str(out / f"{name}.usda"))
        model = builder.finalize(device="cpu", skip_validation_inertia=True)
        joints = [str(label).split("/")[-1] for label in model.joint_label]
        state = model.state()
        q = state.joint_q.numpy()
        qs, qd = model.joint_q_start.numpy(), model.joint_qd_start.numpy()
        rows: list[tuple[int, int]] = []  # (Newton's dof, pkm's dof)
        for j, n in enumerate(joints):
            if n in ref["q"]:
                value = ref["q"][n]
                q[qs[j]:qs[j] + len(value)] = value
                first = ref["names"].index(n)
                rows += [(int(qd[j]) + k, first + k) for k in range(int(qd[j + 1] - qd[j]))]
        state.joint_q.assign(q)
        newton.eval_fk(model, state.joint_q, state.joint_qd, state)
        H = newton.eval_mass_matrix(model, state).numpy()[0]
        a, b = [r[0] for r in rows], [r[1] for r in rows]
        Hn, M = H[np.ix_(a, a)], np.array(ref["M"])[np.ix_(b, b)]
        results["cases"][name] = {
            "coordinates": len(rows), "joints": joints, "dtype": str(state.joint_q.dtype).split(".")[-1].strip("'>"),
            "relative_error": float(np.abs(Hn - M).max() / np.abs(M).max()),
            "max_abs_error": float(np.abs(Hn - M).max()), "cpu_s": round(time.process_time() - t, 3)}
        print(name, results["cases"][name])
    (ROOT / "tools" / "usd_newton.json").write_text(json.dumps(results, indent=1) + "\n")
    return results


if __name__ == "__main__":
    if len(sys.argv) != 3 or sys.argv[1] not in ("write", "check"):
        sys.exit(__doc__)
    (write if sys.argv[1] == "write" else check)(Path(sys.argv[2]))
