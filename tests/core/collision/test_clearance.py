"""pkm.clearance against independent routes: MuJoCo's mj_geomDistance on the humanoid ankle's MJCF (capsules and a
box), a segment-to-segment distance on the Gough-Stewart's legs (capsules), differences of the minimum along the
closed loops for its gradient; and the refusals."""

from __future__ import annotations

import pickle
import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.bench.clearance import leg_distances
from pkm.core.collision import CollisionModel, clearance_map
from pkm.errors import InvalidInputError, NoCollisionGeometryError, PkmWarning, UnknownNameError
from tests.fd import richardson

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"
ANKLE = EXAMPLES / "humanoid_ankle"


@pytest.fixture(scope="module")
def ankle():
    return pkm.load(ANKLE / "ankle.closures.toml")


@pytest.fixture(scope="module")
def ankle_poses(ankle):
    """20 closed configurations of the ankle over its motors' range (seeded: the same every run)."""
    rng = np.random.default_rng(55)
    out, q = [], ankle.q_reference
    while len(out) < 20:
        res = pkm.close_loops(ankle, rng.uniform(-0.5, 0.5, 2), q)
        if res.converged:
            out.append(res.q)
    return out


def test_ankle_pairs_equal_mujocos_geom_distance(ankle, ankle_poses):
    mujoco = pytest.importorskip("mujoco")  # (the bench extra, installed by make test: the reference, not a dependency)
    m = mujoco.MjModel.from_xml_path(str(ANKLE / "ankle.xml"))
    d = mujoco.MjData(m)
    body_geoms: dict[str, list[int]] = {}
    for g in range(m.ngeom):
        body_geoms.setdefault(m.body(m.geom_bodyid[g]).name, []).append(g)
    worst, n = 0.0, 0
    for q in ankle_poses:
        for name, j in ankle.joints.items():
            adr = m.jnt_qposadr[m.joint(name).id]
            x = q[j.idx_q:j.idx_q + j.nq]
            d.qpos[adr:adr + j.nq] = x if j.nq == 1 else np.r_[x[3], x[:3]]  # (quaternion: MuJoCo's w first)
        mujoco.mj_kinematics(m, d)
        c = pkm.clearance(ankle, q)
        for (a, b), dist in c.pairs.items():
            ref = min(mujoco.mj_geomDistance(m, d, ga, gb, 1.0, None) for ga in body_geoms[a] for gb in body_geoms[b])
            worst, n = max(worst, abs(dist - ref)), n + 1
    assert n == 20 * len(CollisionModel.of(ankle).pairs) and n >= 20 * 6
    assert worst <= 1e-6, worst


@pytest.fixture(scope="module")
def gs():
    return pkm.load("gough_stewart")


def pose(gs, x, y, z, roll, pitch, yaw):
    quat = pin.Quaternion(pin.rpy.rpyToMatrix(roll, pitch, yaw)).coeffs()
    res = pkm.solve_ik(gs, [x, y, z, *quat])
    assert res.converged
    return res.q


@pytest.fixture(scope="module")
def gs_poses(gs):
    """Poses away from the reference: turned up to 1.3 rad about z (the legs lean towards one another), tilted,
    shifted."""
    return [pose(gs, *p) for p in [(0.05, 0.0, 0.7, 0.0, 0.0, 0.9), (0.0, 0.05, 0.65, 0.1, -0.05, 1.3),
                                   (-0.05, 0.02, 0.75, -0.1, 0.1, -1.1), (0.1, -0.1, 0.6, 0.05, 0.15, 0.4)]]


def leg_errors(mech, q) -> list[float]:
    """|pkm's distance - (segment distance - radii)| for every leg-leg pair at ``q`` (the closed form of the
    benchmark's baseline, :mod:`pkm.bench.clearance`)."""
    pairs = pkm.clearance(mech, q).pairs
    legs = [p for p in pairs if "platform_link" not in p]
    return [abs(pairs[p] - d) for p, d in zip(legs, leg_distances(mech, q, legs))]


def test_gough_stewart_leg_distances_equal_segment_distances_minus_radii(gs, gs_poses):
    errors = [e for q in gs_poses for e in leg_errors(gs, q)]
    assert len(errors) == 4 * 60  # (every leg pair: 12 capsules, the 6 cylinder-rod pairs of a leg its neighbours)
    assert max(errors) <= 1e-9, max(errors)


def test_map_pickle_and_result(gs, gs_poses):
    again = pickle.loads(pickle.dumps(gs))
    minima = clearance_map(again, np.array(gs_poses))
    expected = [pkm.clearance(gs, q) for q in gs_poses]
    assert np.allclose(minima, [c.minimum for c in expected], rtol=0, atol=1e-12)
    c = expected[0]
    pa, pb = c.witness[c.closest]
    assert abs(np.linalg.norm(pb - pa) - c.minimum) <= 1e-9 and not c.interferes
    assert abs(c.normals[c.closest] @ (pb - pa) - c.minimum) <= 1e-9
    assert c.excluded[("cylinder_1", "rod_1")].startswith("neighbours")
    assert c.excluded[("platform_link", "rod_1")].startswith("closure")


def fd_gradient(mech, q, h: float = 1e-4) -> np.ndarray:
    """d minimum / d q_a by Richardson-extrapolated central differences along the closed loops."""
    qa = mech.actuated_q(q)

    def minimum(x):
        return pkm.clearance(mech, pkm.close_loops(mech, x, q, tol=1e-13).q).minimum

    def diff(hh):
        return np.array([(minimum(qa + e) - minimum(qa - e)) / (2 * hh) for e in hh * np.eye(mech.na)])

    return richardson(diff, h)


def test_gradient_matches_differences_along_the_closed_loops(gs, gs_poses, ankle):
    """The Gough-Stewart (a free platform, universal joints) and the ankle (ball joints: quaternions), each at a
    configuration where one pair is the closest (where two tie, as at the ankle's symmetric poses, the minimum has a
    kink)."""
    for mech, q in ((gs, gs_poses[1]), (ankle, pkm.close_loops(ankle, [0.3, -0.2], ankle.q_reference).q)):
        fd = fd_gradient(mech, q)
        assert np.linalg.norm(fd) > 1e-2  # (the distance does change with the actuators)
        assert np.linalg.norm(pkm.clearance(mech, q).gradient - fd) <= 1e-6 * np.linalg.norm(fd), mech.name


def test_interference_is_the_penetration_depth():
    """Legs made thick enough to cross at a turned pose (off centre: no two pairs tie): the distance negative, the
    capsules' penetration depth (the segments' distance minus the radii), its gradient the differences'."""
    thick = pkm.build("gough_stewart", cylinder_radius=0.12, rod_radius=0.12)
    q = pose(thick, 0.03, 0.02, 0.65, 0.02, 0.0, 1.3)
    c = pkm.clearance(thick, q)
    assert c.interferes and c.minimum < -1e-2 and c.pairs[c.closest] == c.minimum
    assert sum(d < 0 for d in c.pairs.values()) >= 2
    assert max(leg_errors(thick, q)) <= 1e-9
    fd = fd_gradient(thick, q)
    assert np.linalg.norm(c.gradient - fd) <= 1e-6 * np.linalg.norm(fd)


def _without_collisions(urdf: str) -> str:
    import re
    return re.sub(r"<collision.*?</collision>", "", urdf, flags=re.DOTALL)


def test_refusals(gs):
    bare = pkm.from_strings(_without_collisions(gs.urdf), gs.spec)
    with pytest.raises(NoCollisionGeometryError, match=r"no collision geometry.*<collision>") as info:
        pkm.clearance(bare, bare.q_reference)
    assert info.value.kind == "no_geometry"
    with pytest.raises(InvalidInputError, match="not closed"):
        pkm.clearance(gs, gs.with_actuated(gs.q_reference, gs.actuated_q(gs.q_reference) + 0.01))
    with pytest.raises(InvalidInputError):
        pkm.clearance(gs, np.zeros(3))
    with pytest.raises(InvalidInputError):
        clearance_map(gs, np.full((2, gs.nq), np.nan))
    stretched = np.array([gs.q_reference, gs.q_reference])
    at = gs.joints["platform"].idx_q + 3
    stretched[1, at:at + 4] *= 2.0
    with pytest.raises(InvalidInputError, match="node 1: the quaternion of joint 'platform'"):
        clearance_map(gs, stretched)


def test_spec_pairs_round_trip_and_names(gs):
    import dataclasses

    from pkm.core.model.spec import ClosureSpec

    spec = dataclasses.replace(gs.spec, collision_exclude=(("rod_1", "rod_2"),),
                               collision_include=(("cylinder_1", "rod_1"),))
    assert ClosureSpec.from_toml(spec.to_toml()) == spec
    mech = pkm.from_strings(gs.urdf, spec)
    cm = CollisionModel.of(mech)
    assert ("rod_1", "rod_2") not in cm.pairs and cm.excluded[("rod_1", "rod_2")].startswith("spec")
    assert ("cylinder_1", "rod_1") in cm.pairs
    wrong = pkm.from_strings(gs.urdf, dataclasses.replace(gs.spec, collision_exclude=(("rod_1", "rod_9"),)))
    with pytest.raises(UnknownNameError, match="rod_9"):
        pkm.clearance(wrong, wrong.q_reference)


def test_missing_mesh_is_a_note_and_a_warning(gs):
    urdf = gs.urdf.replace('<link name="base"/>', '<link name="base"><collision><geometry><mesh filename='
                                                  '"package://nowhere/base.stl"/></geometry></collision></link>')
    mech = pkm.from_strings(urdf, gs.spec)
    with pytest.warns(PkmWarning, match="'base'.*nowhere/base.stl"):
        cm = CollisionModel.of(mech)
    assert any("base.stl" in n for n in cm.notes) and "base" not in cm.bodies
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert pkm.clearance(mech, mech.q_reference).minimum > 0.0


def test_scale_free(gs, gs_poses):
    """The same Gough-Stewart at a tenth of the size: the same pairs checked, every distance a tenth."""
    small = pkm.scaled_mechanism(gs, 0.1)
    q = pkm.scale_configuration(gs, gs_poses[0], 0.1)
    big, tenth = pkm.clearance(gs, gs_poses[0]), pkm.clearance(small, q)
    assert tenth.pairs.keys() == big.pairs.keys() and tenth.excluded.keys() == big.excluded.keys()
    assert max(abs(tenth.pairs[p] - 0.1 * d) for p, d in big.pairs.items()) <= 1e-9 * small.characteristic_length
