"""Interference in the workspace answers (pkm.core.collision.interference): the Gough-Stewart's map at a fixed
orientation with legs thick enough to cross, its interference-free workspace beside the limits-only one (the sweep
objectives), both against an independent count: each node's joints against their limits one by one, and the legs'
segment-to-segment distances minus their radii (written here: the interior critical point or an end point against
the other segment)."""

from __future__ import annotations

import itertools
import warnings

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm import sweeps
from pkm.core.collision.interference import checks_collisions, first_interference, minimum_distances
from pkm.errors import NoCollisionGeometryError
from pkm.sweeps.family import RegisteredFamily
from pkm.sweeps.objectives import OBJECTIVES, _map_key

RADIUS = 0.095  # [m] cylinders and rods: at a yaw of 1 rad some nodes' legs cross, others' do not
REGION = "region=x=-0.15:0.15:5/y=-0.15:0.15:5,pose=yaw=1.0,length=0.5"


def point_segment(p, a, b) -> float:
    t = np.clip((p - a) @ (b - a) / ((b - a) @ (b - a)), 0.0, 1.0)
    return float(np.linalg.norm(p - (a + t * (b - a))))


def segment_segment(p1, q1, p2, q2) -> float:
    """The distance between two segments: at the interior critical point of |p1 + s d1 - p2 - t d2| where it lies in
    the unit square, else the least of the four end points' distances to the other segment."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    A = np.array([[d1 @ d1, -d1 @ d2], [-d1 @ d2, d2 @ d2]])
    ends = min(point_segment(p1, p2, q2), point_segment(q1, p2, q2), point_segment(p2, p1, q1),
               point_segment(q2, p1, q1))
    if abs(np.linalg.det(A)) <= 1e-12 * A[0, 0] * A[1, 1]:
        return ends
    s, t = np.linalg.solve(A, [-d1 @ r, d2 @ r])
    inside = np.linalg.norm(r + s * d1 - t * d2) if 0.0 <= s <= 1.0 and 0.0 <= t <= 1.0 else np.inf
    return float(min(inside, ends))


def legs_minimum(mech, q) -> float:
    """The smallest distance between two legs' capsules (cylinder from the universal joint, rod to the ball, each
    ``leg_min / 2`` long, as the design writes them) not of one leg, minus the radii."""
    m, d, p = mech.model, mech.data, mech.params
    pin.forwardKinematics(m, d, q)
    pin.updateFramePlacements(m, d)
    caps = []
    for k in range(1, 7):
        a = d.oMi[m.getJointId(f"u{k}")].translation
        b = d.oMf[mech.frame_id(f"ball_{k}")].translation
        u = (b - a) / np.linalg.norm(b - a)
        caps += [(k, a, a + p.leg_min / 2 * u, p.cylinder_radius), (k, b - p.leg_min / 2 * u, b, p.rod_radius)]
    return min(segment_segment(a1, b1, a2, b2) - r1 - r2
               for (k1, a1, b1, r1), (k2, a2, b2, r2) in itertools.combinations(caps, 2) if k1 != k2)


@pytest.fixture(scope="module")
def thick():
    """A Gough-Stewart design with thick legs, its limits-only and interference-free areas by the sweep objectives,
    and the one map they share (configurations kept: 25 nodes)."""
    c = RegisteredFamily("gough_stewart").candidate({"cylinder_radius": RADIUS, "rod_radius": RADIUS})
    o = {k: sweeps.objective(f"{k}:{REGION}") for k in ("limits_volume", "interference_free_volume")}
    values = {k: OBJECTIVES[k].generic(c, v.options) for k, v in o.items()}
    return c, values, c.peek(_map_key(o["limits_volume"].options))


def test_the_interference_free_area_beside_the_limits_only_area_equals_an_independent_count(thick):
    c, values, m = thick
    mech = c.mechanism
    Q = m.q.reshape(-1, mech.nq)
    reach = m.reachable.ravel()
    inside = np.array([r and not mech.outside_limits(q) for r, q in zip(reach, Q)])
    legs = np.array([legs_minimum(mech, q) if r else np.nan for r, q in zip(reach, Q)])
    free = inside & (legs > 0.0)
    assert reach.sum() == 25 and 0 < free.sum() < inside.sum() < 25  # (both bounds bite on this grid)
    assert values["limits_volume"] == pytest.approx(inside.sum() * 0.075 ** 2, rel=1e-12)
    assert values["interference_free_volume"] == pytest.approx(free.sum() * 0.075 ** 2, rel=1e-12)
    # the map's clearance per node: the legs' where they are the closest pair (a cylinder may be closer to the
    # platform's disc: never negative here)
    clear = m.clearance.ravel()
    assert np.all(clear <= legs + 1e-9) and np.all(clear[legs < 0.0] == pytest.approx(legs[legs < 0.0], abs=1e-9))
    np.testing.assert_array_equal(m.interferes.ravel(), legs < 0.0)
    np.testing.assert_array_equal(m.within_limits.ravel(), inside)
    np.testing.assert_array_equal(m.feasible.ravel(), free)


def test_a_map_marks_interference_only_where_asked_and_where_there_is_geometry(thick, tmp_path, monkeypatch):
    """collisions=False leaves the interference out (the same reach), as a grid larger than COLLISION_NODES does
    unless collisions=True; unreached nodes' clearance is NaN; the CSV carries the three columns; the first
    interfering configuration of a sequence names its pair."""
    from pkm.core.analysis import maps

    c, _, m = thick
    mech = c.mechanism
    again = pkm.workspace_map(mech, dict(m.axes), {"yaw": 1.0}, length=0.5, kernels=c.kernels, collisions=False)
    assert again.clearance is None and again.interferes is None and again.within_limits is None
    np.testing.assert_array_equal(again.reachable, m.reachable)
    monkeypatch.setattr(maps, "COLLISION_NODES", 24)  # (the grid has 25)
    assert pkm.workspace_map(mech, dict(m.axes), {"yaw": 1.0}, length=0.5, kernels=c.kernels).clearance is None
    forced = pkm.workspace_map(mech, dict(m.axes), {"yaw": 1.0}, length=0.5, kernels=c.kernels, collisions=True)
    np.testing.assert_array_equal(forced.clearance, m.clearance)
    assert np.isnan(np.where(m.reachable, np.nan, m.clearance)).all()
    header = m.write_csv(tmp_path / "m.csv").read_text().splitlines()[0].split(",")
    assert header[-3:] == ["clearance", "within_limits", "interferes"]
    Q = m.q.reshape(-1, mech.nq)
    k = int(np.flatnonzero(m.interferes.ravel())[0])
    hit = first_interference(mech, Q[k - 1:k + 1] if k else Q[k:k + 1])
    assert hit is not None and hit.at == (1 if k else 0) and hit.distance == pytest.approx(m.clearance.ravel()[k])
    assert pkm.clearance(mech, Q[k]).closest == hit.pair
    assert np.isnan(minimum_distances(mech, np.full((1, mech.nq), np.nan))).all()


def test_without_geometry_nothing_changes_and_nothing_is_said():
    """The Delta with its collision elements taken out of its URDF: not checked, no warning, its map that of the
    Delta with collisions=False; the objective refuses."""
    import types

    from tests.core.collision.test_clearance import _without_collisions

    delta = pkm.load("delta")
    bare = pkm.from_strings(_without_collisions(delta.urdf), delta.spec)
    axes = {"x": np.linspace(-0.05, 0.05, 3)}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert not checks_collisions(bare) and checks_collisions(delta)
        m = pkm.workspace_map(bare, axes, {"z": -0.35})
    assert m.clearance is None and m.within_limits is None and m.interferes is None
    np.testing.assert_array_equal(m.feasible, m.reachable)
    np.testing.assert_array_equal(m.singular_values, pkm.workspace_map(delta, axes, {"z": -0.35},
                                                                       collisions=False).singular_values)
    with pytest.raises(NoCollisionGeometryError):
        OBJECTIVES["interference_free_volume"].generic(types.SimpleNamespace(mechanism=bare), sweeps.objective(
            "interference_free_volume:region=x=-0.05:0.05:3,pose=z=-0.35").options)


def test_a_configuration_s_distances_do_not_depend_on_those_computed_before():
    """The Delta's forearms (thin parallel cylinders) along its arc in 40 samples: the smallest distances computed
    forwards, backwards and one configuration a call are equal (Pinocchio's requests warm-started each GJK from the
    pair's last result: backwards, a forearm pair came out -1.8e308 m)."""
    from pkm.core.collision import clearance_map
    from pkm.core.timing import waypoint_path
    from tests.core.timing.conftest import ARC

    delta = pkm.load("delta")
    Q = pkm.follow_task(delta, waypoint_path(delta, ARC).evaluate(np.linspace(0.0, 1.0, 40))[0], efforts=False).q
    forwards, backwards = clearance_map(delta, Q), clearance_map(delta, Q[::-1])[::-1]
    alone = np.array([clearance_map(delta, q[None])[0] for q in Q])
    assert np.all((forwards > 0.05) & (forwards < 0.1))  # (the forearms about 8 cm apart)
    np.testing.assert_array_equal(forwards, backwards)
    np.testing.assert_array_equal(forwards, alone)


#: A configuration of the Delta on its arc where coal's GJK fails on its base disc and a forearm at 1e-12 of the size.
GJK_FAILS = [-0.4664982539902116, -1.6700480254981542, 0.11045207434554571, -0.4782990241148424, -1.6641276802412222,
             -0.11422052849577913, -0.8061882192855698, -1.4897321395782104, 0.0037447077819097174,
             -0.036375118446675465, 0.02242810640238015, -0.3263578403964298]


def test_a_pair_coal_s_gjk_fails_on_is_computed_again():
    """coal answers -DBL_MAX for the Delta's base disc and forearm_2 at GJK_FAILS (its GJK at 1e-12 of the size);
    pkm.clearance and clearance_map answer that pair again with Nesterov's acceleration: the distance of the plain GJK
    at 1e-9 of the size, to 1e-9 m."""
    import pinocchio as pin

    from pkm.core.collision import CollisionModel, clearance_map
    from pkm.core.collision.geometry import GJK_RTOL

    delta = pkm.load("delta")
    q = np.array(GJK_FAILS)
    cm = CollisionModel.of(delta)

    def plain(rtol: float) -> np.ndarray:
        gd = cm.geometry.createData()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            for r in gd.distanceRequests:
                r.enable_signed_distance, r.enable_cached_gjk_guess = True, False
                r.gjk_tolerance = r.epa_tolerance = rtol * delta.characteristic_length
        pin.computeDistances(delta.model, delta.data, cm.geometry, gd, q)
        return np.array([r.min_distance for r in gd.distanceResults])

    assert plain(GJK_RTOL).min() < -1e300  # (the failure this guards against)
    loose = plain(1e-9)
    c = pkm.clearance(delta, q)
    k = cm.pairs.index(("base", "forearm_2"))
    assert abs(c.pairs[("base", "forearm_2")] - loose[cm.pair_of == k].min()) <= 1e-9
    assert clearance_map(delta, q[None])[0] == c.minimum > 0.05
