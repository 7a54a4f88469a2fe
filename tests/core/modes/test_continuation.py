"""Homotopy continuation (:mod:`pkm.core.modes.continuation`) on systems of two unknowns whose solutions are known in
closed form: finite, infinite and singular ends classified, the Bezout bound equal to the paths Bertini starts, a
projective system and a parameter homotopy; and the bookkeeping of paths (crossings, dropped paths) without Bertini."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pkm.core.modes.continuation import Continuation, Path, _crossings, _retrack, bezout, solve, track
from pkm.core.modes.polynomial import variables

pytest.importorskip("bertini")


def _finite(cont: Continuation) -> list[np.ndarray]:
    return [p.point for p in cont.paths if p.status == "finite"]


def test_a_quadratic_has_its_two_roots_and_nothing_else():
    """x^2 - 2: two paths (the total degree), both finite, nonsingular, at +-sqrt 2 (1e-10); the set is complete."""
    (x,) = variables(1)
    cont = solve([x * x - 2.0])
    assert cont.bound == len(cont.paths) == 2 and cont.complete and cont.start == "total-degree homotopy"
    roots = sorted(p.point[0].real for p in cont.paths if not p.singular)
    assert np.allclose(roots, [-math.sqrt(2.0), math.sqrt(2.0)], rtol=0, atol=1e-10)


def test_paths_to_infinity_are_told_from_solutions():
    """xy = 1 and xy + x = 2 have the one solution (1, 1) (x = 2 - 1 from the difference); the other three of the
    four total-degree paths go to infinity and the set is still complete."""
    x, y = variables(2)
    cont = solve([x * y - 1.0, x * y + x - 2.0])
    assert cont.bound == 4 and cont.count("finite") == 1 and cont.count("infinite") == 3 and cont.complete
    assert np.abs(_finite(cont)[0] - 1.0).max() <= 1e-10


def test_a_double_root_ends_two_singular_paths_not_a_crossing():
    """x^2 = 0, y = 1: both paths end at (0, 1), singular with winding number 2, and are not marked as a crossing
    (several paths may end at one singular point)."""
    x, y = variables(2)
    cont = solve([x * x, y - 1.0])
    assert [p.status for p in cont.paths] == ["finite", "finite"] and cont.complete
    assert all(p.singular and p.cycle == 2 and np.abs(p.point - [0.0, 1.0]).max() <= 1e-6 for p in cont.paths)


@pytest.mark.parametrize("system, groups, count", [
    ("x^2 y = 1, x = y", [[0], [1]], 3),  # the coefficient of z1 z2 in (2 z1 + z2)(z1 + z2)
    ("xy = 1, xy + x = 2", [[0], [1]], 2),  # two bilinear equations: (z1 + z2)^2
    ("x^2 y = 1, x = y", [[0, 1]], 3),  # one group: the total degree 3 x 1
])
def test_the_bezout_bound_is_the_number_of_paths_bertini_starts(system, groups, count):
    """The (multi)homogeneous Bezout number, counted by hand (the coefficient of prod z_g^dim_g), equals bezout() and
    the paths Bertini's start system tracks; every finite end solves the system (1e-10)."""
    x, y = variables(2)
    polys = {"x^2 y = 1, x = y": [x * x * y - 1.0, x - y], "xy = 1, xy + x = 2": [x * y - 1.0, x * y + x - 2.0]}[system]
    assert bezout(polys, groups) == count
    cont = solve(polys, groups)
    assert len(cont.paths) == count == cont.bound and cont.complete
    for pt in _finite(cont):
        assert max(abs(p(pt)) for p in polys) <= 1e-10


def test_a_projective_system_is_solved_on_a_patch_and_normalised():
    """a^2 - 2b^2 - c^2 = 0 and a - 3b + c = 0 in P^2: b (6a - 11b) = 0, so [1 : 0 : -1] and [11 : 6 : 7]; each end
    is proportional to one of them (1e-10) with largest coordinate 1. Non-homogeneous polynomials or several groups
    are refused (ValueError)."""
    a, b, c = variables(3)
    polys = [a * a - 2.0 * b * b - c * c, a - 3.0 * b + c]
    cont = solve(polys, projective=True)
    expected = [np.array([1.0, 0.0, -1.0]), np.array([11.0, 6.0, 7.0])]
    found = []
    for pt in _finite(cont):
        assert abs(np.abs(pt).max() - 1.0) <= 1e-12
        found.append(next(k for k, e in enumerate(expected) if np.linalg.norm(np.cross(pt, e)) <= 1e-10 * 11))
    assert sorted(found) == [0, 1]
    with pytest.raises(ValueError, match="homogeneous"):
        solve([a * a - 1.0, b - c], projective=True)
    with pytest.raises(ValueError, match="one variable group"):
        solve(polys, [[0], [1, 2]], projective=True)


def test_a_parameter_homotopy_carries_each_start_to_its_target():
    """x^2 = (1 - t) 2 + t: from the roots +-1 at t = 1 to +-sqrt 2 at t = 0, each path keeping its sign (1e-10)."""
    x, t = variables(2)
    (X,) = variables(1)
    cont = track([x * x - (1.0 - t) * 2.0 - t * 1.0], [X * X - 2.0], [np.array([1.0]), np.array([-1.0])])
    assert cont.start == "parameter homotopy" and cont.bound == 2 and cont.complete
    assert np.allclose([p.point[0] for p in cont.paths], [math.sqrt(2.0), -math.sqrt(2.0)], rtol=0, atol=1e-10)


def test_auto_precision_tracks_again_adaptively_only_the_paths_double_precision_leaves_in_doubt():
    """precision="auto" (the default): x^2 = (1 - t) 2 + t tracked in double precision, no path again (both ends
    nonsingular and distinct), the ends those of adaptive precision to 1e-12; x^2 = t (a double root at t = 0):
    both singular ends tracked again in adaptive precision."""
    x, t = variables(2)
    (X,) = variables(1)
    starts = [np.array([1.0]), np.array([-1.0])]
    auto = track([x * x - (1.0 - t) * 2.0 - t * 1.0], [X * X - 2.0], starts)
    adaptive = track([x * x - (1.0 - t) * 2.0 - t * 1.0], [X * X - 2.0], starts, precision="adaptive")
    assert auto.settings["mptype"] == "auto" and auto.settings["retracked"] == [] and auto.complete
    assert np.allclose([p.point for p in auto.paths], [p.point for p in adaptive.paths], rtol=0, atol=1e-12)
    double = track([x * x - t], [X * X], starts)
    assert double.settings["retracked"] == [0, 1] and all(p.singular for p in double.paths)


def test_a_double_precision_end_in_doubt_is_tracked_again_until_none_is_shared():
    """(Bookkeeping, a planted adaptive tracker.) Paths 1 and 2 share an end, 3 is singular, 4 went to infinity,
    5 failed: those are tracked again; path 2's adaptive end is path 0's double one, so 0 is tracked again in a
    second round; path 6 stays as double precision left it."""
    double = [_path(0, [1.0]), _path(1, [2.0]), _path(2, [2.0]), _path(3, [0.0], True),
              Path(4, "infinite", "GoingToInfinity", None, False, math.nan, math.nan, 1),
              Path(5, "failed", "MinStepSizeReached", None, False, math.nan, math.nan, 1), _path(6, [5.0])]
    truth = {0: [7.0], 1: [2.0], 2: [1.0], 3: [0.0], 4: [3.0], 5: [4.0]}
    rounds = []

    def adaptive(indices):
        rounds.append(indices)
        return [_path(i, truth[i], singular=i == 3) for i in indices]

    paths, again = _retrack(double, adaptive)
    assert rounds == [[1, 2, 3, 4, 5], [0]] and again == [0, 1, 2, 3, 4, 5]
    assert [p.index for p in paths] == list(range(7))
    assert [p.point[0].real for p in paths] == [7.0, 2.0, 1.0, 0.0, 3.0, 4.0, 5.0]


def _path(k, point, singular=False):
    return Path(k, "finite", "Success", None if point is None else np.array(point, dtype=complex), singular, 1.0, 0.0,
                1)


def test_a_path_ending_at_anothers_nonsingular_end_is_a_failed_crossing():
    """(Pure bookkeeping.) Two nonsingular ends within 1e-8 (relative): the later is failed with code PathCrossing;
    two singular ends at one point both stay; distinct points stay."""
    paths = [_path(0, [1.0, 2.0]), _path(1, [1.0 + 1e-10, 2.0]), _path(2, [0.0, 0.0], True),
             _path(3, [0.0, 0.0], True), _path(4, [1.0, 2.1])]
    out = _crossings(paths)
    assert [(p.status, p.code) for p in out] == [("finite", "Success"), ("failed", "PathCrossing"),
                                                 ("finite", "Success"), ("finite", "Success"), ("finite", "Success")]


def test_dropping_paths_makes_the_set_incomplete():
    """without(indices) marks exactly those paths failed (code "dropped", no point), keeps the others and the bound,
    and the set is no longer complete; count() and failed agree."""
    cont = Continuation(tuple(_path(k, [float(k)]) for k in range(4)), 4, "total-degree homotopy", 0.0)
    assert cont.complete and cont.count("finite") == 4
    lost = cont.without([1, 3])
    assert [p.status for p in lost.paths] == ["finite", "failed", "finite", "failed"] and lost.bound == 4
    assert not lost.complete and [p.index for p in lost.failed] == [1, 3] and lost.count("failed") == 2
    assert all(p.code == "dropped" and p.point is None for p in lost.failed)
    assert not Continuation(cont.paths[:3], 4, "total-degree homotopy", 0.0).complete  # (a path missing)
