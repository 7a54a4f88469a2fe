"""The round-trip matrix (issue 43): every writer (pkm.save: pkm's spec + URDF, MJCF, Gepetto's URDF + YAML, URDF+,
SDF + spec, USD: issue 56, through pkm's double-precision attributes) followed by pkm.load gives the same mechanism, for every shipped mechanism (pkm.MECHANISMS), tests/fivebar,
the acceptance set (tests/test_acceptance.py) and the other examples under examples/.

"The same": the joint names (MJCF and SDF write a universal joint ``u`` as two hinges ``u__1``, ``u__2``: read
back as two revolute joints, the stated mapping), the limits (a universal's on both hinges; MJCF folds a mimic
joint's range into its leader's; to 1e-12: SDF writes them from the reference), the actuated joints (as a set:
Gepetto's YAML reads them back in the URDF's order, permuted here) and their drives (reflected inertia, viscous and
Coulomb friction), the closure types and names (Gepetto's format has no names), and at three random closed states
(the original's values computed once for every writer, :func:`states`) the residual of the copy (<= 1e-12), every
joint's placement, the passive map G (joint rates from actuated rates; with the placements it gives any task's forward
Jacobian), the forward Jacobian itself where the task survives (pkm's spec), the inverse dynamics and M_a (Gepetto's
YAML and URDF+ hold no spec drives: the copy is given the original's), all to 1e-12 (relative to the largest entry, or
absolute below 1). Two stated exceptions: MJCF raises a body's mass to MuJoCo's ``boundmass`` (1e-9 kg), so where the
original has lighter (massless) bodies (the Delta, the hexapod) the efforts and M_a agree to MASSLESS (measured: 1e-9,
3e-10); SDF's G to ROUNDED (:data:`REWRITTEN`). URDF+ has no spherical or universal joint: a mechanism with
``[joint_types]`` is refused by name (:data:`REFUSED`).
"""

from __future__ import annotations

import atexit
import functools
import shutil
import tempfile
import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.formats.to_gepetto import gepetto_from_mechanism
from pkm.core.formats.to_mjcf import MIN_MASS
from pkm.core.formats.writers import WRITERS
from pkm.core.kinematics import constraints
from pkm.errors import PkmWarning
from tests import test_acceptance

EXAMPLES = test_acceptance.EXAMPLES
#: name -> loader: the shipped mechanisms, tests/fivebar, the acceptance set, the other examples.
CASES = {
    **{name: functools.partial(pkm.load, name) for name in (*pkm.MECHANISMS, "fivebar")},
    **{f"acceptance:{name}": functools.partial(test_acceptance.load, name) for name in test_acceptance.ACCEPTANCE},
    "humanoid_ankle": functools.partial(pkm.load, EXAMPLES / "humanoid_ankle" / "ankle.closures.toml"),
    "humanoid_knee": functools.partial(pkm.load, EXAMPLES / "humanoid_knee" / "knee.closures.toml"),
    "mjcf_gripper": functools.partial(pkm.load, EXAMPLES / "mjcf_gripper" / "gripper.xml"),
}
TOL = 1e-12
#: MJCF's massless bodies weigh 1e-9 kg (MuJoCo's boundmass): the efforts and M_a differ by about that mass times
#: accelerations and squared lengths of a metre or so; bounded here by 1e-8 (relative).
MASSLESS = 1e-8
#: Writers whose files hold other numbers than the original's (SDFormat: world poses at the reference, rounded to an
#: ulp, re-derived by the reader): there G is compared to ROUNDED. G's idle part is the least-kinetic-energy one
#: (pkm.core.differential.idle), which a rounding of 1e-16 in the poses moves by up to 1.6e-12 on the acceptance
#: set's RSSR (its ball joint spins idle); at most 2e-13 on every other case.
REWRITTEN, ROUNDED = ("sdf",), 1e-11
#: writer -> what makes it refuse a mechanism by name (a SpecError saying what), asserted for those cases.
REFUSED = {"urdfplus": (lambda mech: bool(mech.spec.joint_types), "cannot state the joint types")}
_TMP = Path(tempfile.mkdtemp(prefix="pkm-roundtrip-"))
atexit.register(shutil.rmtree, _TMP, True)


@functools.cache
def original(case: str) -> pkm.Mechanism:
    return CASES[case]()


@functools.cache
def copy(case: str, writer: str) -> pkm.Mechanism:
    """``case`` written by ``writer`` and loaded back (once per test process)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PkmWarning)  # what a format cannot hold: test_writers checks the warning
        path = pkm.save(original(case), _TMP / writer / case.replace(":", "_") / f"robot{WRITERS[writer].suffixes[0]}")
        return pkm.load(path)


def _names(src: pkm.Mechanism, dst: pkm.Mechanism) -> dict[str, list[str]]:
    """Each joint of ``src`` (with coordinates) -> its joint(s) in ``dst``: itself, or a universal's two hinges."""
    out = {}
    for name, j in src.joints.items():
        if name in dst.joints:
            out[name] = [name]
        elif src.model.joints[j.id].shortname() == "JointModelUniversal":
            out[name] = [f"{name}__1", f"{name}__2"]
    assert set(dst.joints) == {n for parts in out.values() for n in parts}
    return out


def _moved(src: pkm.Mechanism, dst: pkm.Mechanism, x: np.ndarray, kind: str) -> np.ndarray:
    """A configuration (``kind`` "q") or a rate (``"v"``) of ``src`` in ``dst``'s coordinates, joint by name."""
    out = pin.neutral(dst.model) if kind == "q" else np.zeros(dst.model.nv)
    for name, parts in _names(src, dst).items():
        js = src.model.joints[src.joints[name].id]
        k, n = (js.idx_q, js.nq) if kind == "q" else (js.idx_v, js.nv)
        for i, part in enumerate(parts):  # one joint: its coordinates; a universal's hinges: one each
            jd = dst.model.joints[dst.joints[part].id]
            start = jd.idx_q if kind == "q" else jd.idx_v
            out[start:start + (n if len(parts) == 1 else 1)] = x[k:k + n] if len(parts) == 1 else x[k + i]
    return out


def _rows(mech: pkm.Mechanism, joint: str) -> np.ndarray:
    jm = mech.model.joints[mech.joints[joint].id]
    return np.arange(jm.idx_v, jm.idx_v + jm.nv)


def _placements(mech: pkm.Mechanism, q: np.ndarray) -> dict[str, np.ndarray]:
    data = mech.model.createData()
    pin.forwardKinematics(mech.model, data, q)
    return {mech.model.names[j]: data.oMi[j].homogeneous for j in range(1, mech.model.njoints)}


def _err(a: np.ndarray, b: np.ndarray) -> float:
    """max |a - b| relative to max(1, max |a|)."""
    return float(np.abs(a - b).max(initial=0.0) / max(1.0, np.abs(a).max(initial=0.0)))


def compare(case: str, writer: str) -> dict[str, float]:
    """The largest errors of the copy against the original at three random closed states (see the module doc)."""
    src, dst = original(case), copy(case, writer)
    names = _names(src, dst)
    expected = {p for n in src.joints for p in names.get(n, [n])}
    assert set(dst.joints) == expected, case
    mimic = {n for n, j in src.joints.items() if src.model.joints[j.id].shortname() == "JointModelMimic"}
    limits = {p: v for n, v in src.limits.items() for p in names.get(n, [n]) if writer != "mjcf" or n not in mimic}
    assert dst.limits.keys() == limits.keys(), case  # (SDF writes them from the reference: to 1 ulp)
    assert all(np.abs(np.subtract(dst.limits[n], v)).max() <= TOL * max(1.0, np.abs(v).max())
               for n, v in limits.items()), case
    assert sorted(dst.actuated_names) == sorted(src.actuated_names), case
    order = [dst.actuated_names.index(n) for n in src.actuated_names]  # dst's index of each of src's actuators
    if writer == "gepetto" and dst.actuated_names != src.actuated_names:  # (the writer says the order it reads back)
        assert f"read back in the URDF's order: {list(dst.actuated_names)}" in str(gepetto_from_mechanism(src)[1])
    drives = [(d.reflected_inertia, d.viscous, d.coulomb) for d in src.actuators]
    if writer in ("gepetto", "urdfplus"):  # neither holds the spec's drives (the writers say so): given back here
        dst = pkm.with_actuators(dst, {d.joint: d for d in src.actuators})
    assert [(d.reflected_inertia, d.viscous, d.coulomb) for d in (dst.actuators[k] for k in order)] == drives, case
    assert [c.type for c in dst.spec.closures] == [c.type for c in src.spec.closures], case
    if writer != "gepetto":
        assert [c.name for c in dst.spec.closures] == [c.name for c in src.spec.closures], case
    rows = np.concatenate([_rows(dst, p) for n in names for p in names[n]])  # the same joints' rates, in order
    src_rows = np.concatenate([_rows(src, n) for n in names])
    err = dict.fromkeys(("residual", "placements", "G", "J", "tau", "M_a"), 0.0)
    for q, v, a, pa, Ga, Ja, ta, Ma in states(case):
        qb, vb, ab = _moved(src, dst, q, "q"), _moved(src, dst, v, "v"), _moved(src, dst, a, "v")
        err["residual"] = max(err["residual"], float(np.abs(constraints.residual(dst, qb)).max(initial=0.0)))
        pb = _placements(dst, qb)
        ends = {n: names[n][-1] for n in names}  # a universal's frame: its second hinge's
        err["placements"] = max(err["placements"], max(_err(pa[n], pb[ends[n]]) for n in ends))
        err["G"] = max(err["G"], _err(Ga[src_rows], pkm.passive_map(dst, qb)[rows][:, order]))
        if writer == "pkm":
            err["J"] = max(err["J"], _err(Ja, pkm.forward_jacobian(dst, qb)))
        err["tau"] = max(err["tau"], _err(ta, pkm.inverse_dynamics(dst, qb, vb, ab)[order]))
        err["M_a"] = max(err["M_a"], _err(Ma, pkm.mass_matrix(dst, qb)[np.ix_(order, order)]))
    return err


@functools.cache
def states(case: str) -> list[tuple]:
    """The original's three random closed states and its values there, computed once for every writer's row:
    ``(q, v, a, joint placements, G, forward Jacobian, inverse dynamics, M_a)``."""
    src, rng, out = original(case), np.random.default_rng(43), []
    for _ in range(3):
        qa = src.actuated_q(src.q_reference) + 0.01 * rng.standard_normal(src.na)
        q = pkm.close_loops(src, qa).q
        v = pkm.velocities(src, q, rng.standard_normal(src.na))
        a = pkm.accelerations(src, q, v, rng.standard_normal(src.na))
        out.append((q, v, a, _placements(src, q), pkm.passive_map(src, q), pkm.forward_jacobian(src, q),
                    pkm.inverse_dynamics(src, q, v, a), pkm.mass_matrix(src, q)))
    return out


@pytest.mark.parametrize("writer", list(WRITERS))
def test_every_writer_then_load_gives_the_same_mechanism(writer):
    """The matrix row of ``writer``: every case reads back as the same mechanism (module doc), but those the format
    refuses by name (:data:`REFUSED`; more refusals: tests/core/formats/test_bad_input.py)."""
    from pkm.errors import SpecError

    worst: dict[str, float] = {}
    refuses, reason = REFUSED.get(writer, (lambda mech: False, ""))
    held = [case for case in CASES if not refuses(original(case))]
    assert len(held) >= 5, held  # (a row that refuses nearly everything proves little)
    for case in CASES:
        if case not in held:
            with pytest.raises(SpecError, match=reason):
                copy(case, writer)
            continue
        err = compare(case, writer)
        worst = {k: max(worst.get(k, 0.0), v) for k, v in err.items()}
        light = any(original(case).model.inertias[j].mass < MIN_MASS for j in range(1, original(case).model.njoints))
        dynamic = MASSLESS if writer == "mjcf" and light else TOL
        rates = ROUNDED if writer in REWRITTEN else TOL
        assert err["residual"] <= TOL and err["placements"] <= TOL and err["G"] <= rates and err["J"] <= TOL, \
            (case, err)
        assert err["tau"] <= dynamic and err["M_a"] <= dynamic, (case, err)
    print(writer, {k: f"{v:.1e}" for k, v in worst.items()})
