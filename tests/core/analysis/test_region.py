"""pkm.core.analysis.region: the feasible pitch-roll polygon of the parallel ankle: every vertex is stopped by what it
says (a motor at its limit to 1e-6 rad, or the singularity distance at its bound to 1e-6), inside it every pose is
feasible, and it is not the box a hand-written limit claims."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import pkm
from pkm.core.analysis.region import Region, feasible_region, largest_box
from pkm.errors import InvalidInputError, PkmWarning

ANKLE = Path(__file__).resolve().parents[3] / "examples" / "ankle" / "ankle.closures.toml"
AXES = ("ankle_pitch", "ankle_roll")
MOTORS = {"motor_left": (-0.7, 0.7), "motor_right": (-0.7, 0.7)}


@pytest.fixture(scope="module")
def ankle():
    return pkm.load(ANKLE)


def _q(mech, point, q0=None):
    return pkm.solve_ik(mech, {AXES[0]: float(point[0]), AXES[1]: float(point[1])}, q0).q


def test_each_vertex_is_stopped_by_what_it_names(ankle):
    region = feasible_region(ankle, AXES, limits=MOTORS, directions=12)
    limits = {**ankle.limits, **MOTORS}  # (the file's pitch and roll limits, the motors' travel given here)
    assert {b.split(" at ")[0] for b in region.binding} <= {f"joint {j}" for j in limits} | {"reach"}
    assert {"joint motor_left", "joint motor_right"} <= {b.split(" at ")[0] for b in region.binding}
    for vertex, why in zip(region.vertices, region.binding):
        if why == "reach":
            continue
        joint, side = why.split()[1], why.split()[4]
        value = float(np.atleast_1d(ankle.q_to_dict(_q(ankle, vertex))[joint])[0])
        assert abs(value - limits[joint][0 if side == "low" else 1]) <= 1e-6
    # a box limit: the joints' own box (pitch ±0.6, roll ±0.4) is not feasible, and the largest box the polygon holds
    # leaves a third of it out (0.43 of 0.78 rad² when written)
    half = region.box()
    own = np.array([ankle.limits["ankle_pitch"][1], ankle.limits["ankle_roll"][1]])
    assert not all(region.contains(region.center + 0.99 * own * np.array(s)) for s in ((1, 1), (1, -1), (-1, 1),
                                                                                         (-1, -1)))
    assert region.area > 1.5 * 4 * half[0] * half[1]
    corners = [region.center + half * np.array(s) for s in ((1, 1), (1, -1), (-1, 1), (-1, -1))]
    assert all(region.contains(c) for c in corners) and not region.contains(region.center + 1.01 * half * 3)
    # inside (shrunk toward the centre), every pose solves within the motors' travel
    for vertex in region.vertices[::3]:
        q = ankle.q_to_dict(_q(ankle, 0.9 * vertex))
        assert all(MOTORS[m][0] <= float(np.atleast_1d(q[m])[0]) <= MOTORS[m][1] for m in MOTORS)


def test_a_singularity_bound_stops_the_vertices_at_it(ankle):
    bound = 0.02  # (the reference's own distances: 0.20 direct, 0.035 inverse)
    free = {j: (-3.0, 3.0) for j in ankle.limits}  # (no joint limit: the bound alone stops the rays)
    region = feasible_region(ankle, AXES, limits=free, singularity=bound, directions=8, reach=1.5)
    stopped = [(v, b) for v, b in zip(region.vertices, region.binding) if "singularity" in b]
    assert stopped
    for vertex, why in stopped:
        d = pkm.diagnose(ankle, _q(ankle, vertex))
        assert abs(min(d.direct_distance, d.inverse_distance) - bound) <= 1e-6, why


def test_bad_arguments_are_refused(ankle):
    with pytest.raises(InvalidInputError, match="two distinct"):
        feasible_region(ankle, ("ankle_pitch", "ankle_pitch"))
    with pytest.raises(InvalidInputError, match="not a joint"):
        feasible_region(ankle, AXES, limits={"elbow": (-1.0, 1.0)})
    with pytest.raises(InvalidInputError, match="not feasible"):
        feasible_region(ankle, AXES, limits={"motor_left": (0.5, 0.7)})


def test_rays_cut_by_the_reach_are_said_so(ankle):
    """A ray that meets no limit within ``reach`` stops there: the region's edge is then the search's, not the
    mechanism's (a robot five times larger than the default reach of 1 m or rad was cut silently)."""
    with pytest.warns(PkmWarning, match="8 of 8 rays found no limit within reach = 0.01"):
        region = feasible_region(ankle, AXES, directions=8, steps=1, reach=0.01)
    assert set(region.binding) == {"reach"}


def test_a_limit_the_file_does_not_state_is_no_limit():
    """Gepetto's five-bar states no joint limit (Pinocchio's placeholder 0/0 on every joint): its region is bounded
    by its singularities and the reach, not by an empty interval (before: 'the reference pose is not feasible: joint
    mot1 at its low limit'); the shared reading (pkm.core.model.joints.stated_limits) gives (-inf, inf) there."""
    import warnings

    from pkm.core.model.joints import stated_limits

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PkmWarning)
        five = pkm.load("gepetto:5bar_linkage")
        region = feasible_region(five, ("mot1", "mot2"), reach=1.0, directions=8)
    assert np.all(five.model.lowerPositionLimit >= five.model.upperPositionLimit)  # (the file's placeholders)
    assert np.all(np.isinf(stated_limits(five.model)[0])) and not any("limit" in b for b in region.binding)
    assert np.ptp(region.vertices, axis=0).min() > 0.1  # (a region, not the reference point alone) [rad]


def test_the_largest_box_about_a_point_is_found_where_it_is_known():
    """The largest axis-aligned box inside a polygon that holds a point, not centred on it: in an L of a 5 x 1 arm
    and a 1 x 4 arm, the arm the point is in (both at their corner: the longer); in the right triangle of legs 2, the
    unit square (area 1, the inscribed rectangle's largest); a point outside the polygon is refused."""
    ell = np.array([(0, 0), (5, 0), (5, 1), (1, 1), (1, 4), (0, 4)], dtype=float)
    for point, (lo, hi) in (((0.5, 0.5), ((0, 0), (5, 1))), ((0.5, 2.0), ((0, 0), (1, 4))),
                            ((3.0, 0.2), ((0, 0), (5, 1)))):
        lower, upper = largest_box(ell, np.array(point))
        np.testing.assert_allclose(np.concatenate([lower, upper]), np.concatenate([lo, hi]), rtol=0, atol=1e-6)
    triangle = np.array([(0, 0), (2, 0), (0, 2)], dtype=float)
    lower, upper = largest_box(triangle, np.array([0.2, 0.2]))
    assert abs(float(np.prod(upper - lower)) - 1.0) <= 1e-6 and np.all(lower >= -1e-12)
    region = Region(("x", "y"), {}, np.array([0.2, 0.2]), triangle, ("closure",) * 3, np.zeros(3), 1e-2)
    assert np.allclose(region.largest_box()[1] - region.largest_box()[0], upper - lower)
    with pytest.raises(InvalidInputError, match="around"):
        region.largest_box([1.5, 1.5])
