"""pkm.core.model.scale: the characteristic length, the Jacobians' homogenisation by it, a mechanism scaled in size.
(The property that every classification survives scaling: tests/properties/test_scale.py.)"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.kinematics import constraints
from pkm.core.model.builder import scaled_mechanism
from pkm.core.model.scale import JacobianScales, scale_configuration
from pkm.errors import InvalidInputError
from tests.test_gepetto_robots import gepetto

PRISMATIC = ("JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned")


def test_the_characteristic_length_is_the_rms_distance_of_the_joints_from_their_centroid():
    """Recomputed from Pinocchio's joint placements at the reference (1e-12)."""
    mech = pkm.load("gough_stewart")
    data = mech.model.createData()
    pin.forwardKinematics(mech.model, data, mech.q_reference)
    p = np.array([data.oMi[j].translation for j in range(1, mech.model.njoints)])
    want = np.sqrt(np.mean(np.sum((p - p.mean(axis=0)) ** 2, axis=1)))
    assert abs(mech.characteristic_length - want) <= 1e-12 * want


def test_the_homogenisation_scales_rotation_rows_angular_tasks_and_translation_columns():
    """Gough-Stewart: prismatic legs and a free-flying platform (translation columns times L), a pose task (its three
    angles times L); robot_delta: 6-D loops (their rotation rows times L), regular and no longer "near" (it was, at
0.00022, before the homogenisation). diagnose's direct distance is the ratio of
    the singular values of J_p so scaled, rebuilt here by hand from the closure types and the joint kinds (1e-12)."""
    gs = pkm.load("gough_stewart")
    sc = JacobianScales.of(gs)
    L = gs.characteristic_length
    legs = [gs.joints[f"leg{i}"].idx_v for i in range(1, 7)]
    base = gs.joints["platform"].idx_v
    assert np.all(sc.columns[legs] == L) and np.all(sc.columns[base:base + 3] == L)
    assert np.all(sc.columns[base + 3:base + 6] == 1.0) and np.all(sc.constraint_rows == 1.0)
    assert list(sc.task_rows) == [1.0, 1.0, 1.0, L, L, L]

    mech = gepetto("robot_delta")
    q = mech.q_reference
    L = mech.characteristic_length
    rows = np.concatenate([[1.0, 1.0, 1.0] + ([L] * 3 if c.type == "frame" else []) for c in mech.spec.closures])
    s = np.linalg.svd(rows[:, None] * constraints.jacobian(mech, q)[:, mech.passive_v], compute_uv=False)
    s = s[s > 1e-9 * s[0]]  # (off its three idle motions: coaxial revolutes of the planar loops)
    d = pkm.diagnose(mech, q)
    assert d.idle_motions == mech.nv - mech.na - len(s) == 3
    assert abs(d.direct_distance - s[-1] / s[0]) <= 1e-12 and d.classification == "regular" and d.near == ()


def test_a_scaled_mechanism_has_its_lengths_and_inertias_scaled():
    """Gough-Stewart by 3: joint placements and centres of mass times 3, rotational inertias times 9, masses, angles
    and revolute limits unchanged, prismatic limits times 3; scaled back by 1/3 it is the original (1e-12)."""
    mech = pkm.load("gough_stewart")
    big = scaled_mechanism(mech, 3.0)
    back = scaled_mechanism(big, 1.0 / 3.0)
    for other, s in ((big, 3.0), (back, 1.0)):
        for j in range(1, mech.model.njoints):
            a, b = mech.model.jointPlacements[j], other.model.jointPlacements[j]
            assert np.allclose(b.translation, s * a.translation, rtol=1e-12, atol=1e-15)
            assert np.allclose(b.rotation, a.rotation, rtol=0, atol=1e-15)
            ia, ib = mech.model.inertias[j], other.model.inertias[j]
            assert abs(ib.mass - ia.mass) <= 1e-12 * ia.mass
            assert np.allclose(ib.lever, s * ia.lever, rtol=1e-12, atol=1e-15)
            assert np.allclose(ib.inertia, s * s * ia.inertia, rtol=1e-12, atol=1e-15)
        for name, (lo, hi) in mech.limits.items():
            k = s if mech.joints[name].kind in PRISMATIC else 1.0
            assert np.allclose(other.limits[name], (k * lo, k * hi), rtol=1e-12), name
    assert any(mech.joints[n].kind in PRISMATIC for n in mech.limits)  # (a prismatic limit was checked)
    qs = scale_configuration(mech, mech.q_reference, 3.0)
    assert np.abs(big.difference(big.q_reference, qs)).max() <= 1e-9


def test_scaling_refuses_a_bad_factor_and_a_mechanism_without_urdf():
    mech = pkm.load("rrr3")
    for bad in (0.0, -1.0, float("nan"), "2"):
        with pytest.raises(InvalidInputError):
            scaled_mechanism(mech, bad)
    with pytest.raises(InvalidInputError, match="no URDF"):
        scaled_mechanism(pkm.Mechanism(pin.Model(mech.model), mech.spec), 2.0)


@pytest.mark.parametrize(("name", "files"), [("gepetto:robot_delta", "robot_delta"), ("prs3", "prs3")])
def test_the_same_files_scaled_assemble_to_the_same_reference_and_the_same_verdicts(name, files):
    """The reference assembled from the files' zero pose (robot_delta's 6-D loops: translation and rotation rows;
    the 3-PRS without its [reference]: prismatic columns) is the same on the files scaled by 10 and by 0.1: angles to
    1e-9 rad, lengths to 1e-9 relative, the direct and inverse singularity distances to 1e-9 relative. (Before the
    assembly's metric was made scale-free, robot_delta's copies assembled 0.24 and 0.20 rad away, mot1_rod1 at
    -0.0969 rad against -0.0920.)"""
    import dataclasses

    from pkm.core.model.scale import scale_urdf

    mech = gepetto(files) if name.startswith("gepetto:") else pkm.load(name)
    spec = dataclasses.replace(mech.spec, reference={})  # (the 3-PRS's stated reference left out: assembled)
    one = pkm.from_strings(mech.urdf, spec, source=files)
    d1 = pkm.diagnose(one, one.q_reference)
    for s in (10.0, 0.1):
        copy = pkm.from_strings(scale_urdf(mech.urdf, s), spec, source=f"{files} x {s}")
        q = scale_configuration(copy, copy.q_reference, 1.0 / s)
        lengths = np.zeros(one.nv, dtype=bool)
        lengths[JacobianScales.of(one).columns != 1.0] = True
        gap = one.difference(one.q_reference, q)
        assert np.abs(gap[~lengths]).max() <= 1e-9, (s, np.abs(gap).max())
        assert np.all(np.abs(gap[lengths]) <= 1e-9 * max(1.0, np.abs(one.q_reference).max())), s
        assert abs(copy.characteristic_length - s * one.characteristic_length) <= 1e-9 * s * one.characteristic_length
        d = pkm.diagnose(copy, copy.q_reference)
        for a, b in ((d.direct_distance, d1.direct_distance), (d.inverse_distance, d1.inverse_distance)):
            assert abs(a - b) <= 1e-9 * b, (s, a, b)
    if name == "prs3":
        assert (JacobianScales.of(one).columns != 1.0).any()  # (the prismatic columns were measured in L)
