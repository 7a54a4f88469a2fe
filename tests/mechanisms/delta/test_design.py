"""Delta base radius: reach of a pose vs R (closed form), condition numbers vs R, the minimising R,
and the radius-choice procedures."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from pkm.core.differential.indices import KINDS
from pkm.errors import InvalidInputError, UnreachableError
from pkm.mechanisms import delta as D
from pkm.mechanisms.delta import design as G

P = D.DeltaParams()
POSE = np.array([0.0, 0.0, -0.375])


def _reaches(R: float, p) -> bool:
    try:
        D.arm_angles(P.La, P.Lb, R - P.r, np.asarray(p, dtype=float), (1, 1, 1))
        return True
    except UnreachableError:
        return False


def test_reach_limit_of_the_study_pose_is_the_stretched_arm():
    """On the axis the pose is reachable for 0 < R <= r + sqrt((La + Lb)^2 - z^2) = 280.163 mm; the inverse
    kinematics succeeds 1e-9 m inside and fails 1e-9 m outside, naming arm 1 and the 1e-9 m shortfall."""
    (lo, hi), = G.reachable_radii(P, POSE)
    expected = P.r + math.sqrt((P.La + P.Lb) ** 2 - POSE[2] ** 2)
    assert lo == 0.0 and hi == pytest.approx(expected, abs=1e-15)
    assert hi * 1e3 == pytest.approx(280.163, abs=1e-3)
    assert _reaches(hi - 1e-9, POSE)
    with pytest.raises(UnreachableError) as info:
        G.condition_vs_radius(P, POSE, [hi + 1e-9])
    assert info.value.leg == 1 and info.value.excess == pytest.approx(1e-9 * (hi - P.r) / (P.La + P.Lb), rel=1e-3)


@pytest.mark.parametrize("branch", ["knee_out", "knee_in"])
def test_condition_vs_radius_is_each_design_on_its_own(branch):
    """Every radius at once (off the axis, both working modes): the condition numbers of each design built with that
    R, one at a time, bit for bit; the first radius out of reach in a list raises, naming it."""
    p = np.array([0.03, -0.05, -0.36])
    R = np.linspace(0.06, 0.24, 37)
    K = G.condition_vs_radius(P, p, R, branch)
    for j, R_j in enumerate(R):
        one = G.condition_numbers(dataclasses.replace(P, R=float(R_j)), p, branch)[0]
        assert all(K[kind][j] == one[kind] for kind in KINDS)
    (_, hi), = G.reachable_radii(P, p)
    with pytest.raises(UnreachableError, match=f"at R = {hi + 0.01:.6g} m"):
        G.condition_vs_radius(P, p, [0.1, hi + 0.01, 0.2, hi + 0.02], branch)


def test_reachable_radii_agree_with_the_inverse_kinematics_off_the_axis():
    """For 40 random poses, R is inside the closed-form intervals exactly when every arm reaches
    (checked on 200 radii from 1 to 400 mm, skipping radii within 1e-9 m of an interval end)."""
    rng = np.random.default_rng(2)
    radii = np.linspace(0.001, 0.4, 200)
    for _ in range(40):
        p = rng.uniform([-0.25, -0.25, -0.45], [0.25, 0.25, 0.0])
        intervals = G.reachable_radii(P, p)
        for R in radii:
            if any(abs(R - e) < 1e-9 for iv in intervals for e in iv):
                continue
            assert any(lo <= R <= hi for lo, hi in intervals) == _reaches(R, p)


def test_condition_on_the_axis_is_the_symmetric_closed_form():
    """On the axis, by the three-fold symmetry, K_2 = sqrt(2) |b| / |a| with (a, b) the forearm vector in
    the arm plane (a = r - R - La cos th, b = z - La sin th); the general route agrees to 1e-10 relative."""
    R = np.linspace(0.05, 0.28, 24)
    K = G.condition_vs_radius(P, POSE, R, kinds=("2",))["2"]
    for Rj, Kj in zip(R, K):
        th = D.inverse_kinematics(dataclasses.replace(P, R=Rj), POSE)[0]
        a, b = P.r - Rj - P.La * math.cos(th), POSE[2] - P.La * math.sin(th)
        ratio = math.sqrt(2.0) * abs(b) / abs(a)
        assert Kj == pytest.approx(max(ratio, 1.0 / ratio), rel=1e-10)


def test_condition_is_smallest_with_the_arms_vertical():
    """Every convention is smallest at the same R, where the arms hang vertically:
    R = r + sqrt(Lb^2 - (|z| - La)^2) = 246.660 mm (1e-7 m); it is a minimum (K larger 0.1 mm either side),
    and K_2 there is 1.906, not 1."""
    R_star = P.r + math.sqrt(P.Lb**2 - (abs(POSE[2]) - P.La) ** 2)
    for kind in KINDS:
        R_min, K_min = G.radius_minimising_condition(P, POSE, "knee_out", kind)
        assert R_min == pytest.approx(R_star, abs=1e-7)
        around = G.condition_vs_radius(P, POSE, [R_min - 1e-4, R_min + 1e-4], kinds=(kind,))[kind]
        assert np.all(around > K_min)
    th = D.inverse_kinematics(dataclasses.replace(P, R=R_star), POSE)
    np.testing.assert_allclose(th, -math.pi / 2, atol=1e-12)
    assert G.radius_minimising_condition(P, POSE)[1] == pytest.approx(1.906, abs=1e-3)


def test_knee_in_condition_blows_up_at_its_direct_singularity():
    """Knee in: K_2 has a simple pole at R = r + sqrt(La^2 - (z + Lb)^2) = 150.374 mm (K_2 > 1e6 at 1e-7 m,
    ten times its value at 1e-6 m, to 1 %), and is below 100 20 mm away on either side."""
    R_s = P.r + math.sqrt(P.La**2 - (POSE[2] + P.Lb) ** 2)
    assert R_s * 1e3 == pytest.approx(150.374, abs=1e-3)
    K = G.condition_vs_radius(P, POSE, [R_s - 0.02, R_s + 1e-7, R_s + 1e-6, R_s + 0.02], "knee_in", ("2",))["2"]
    assert K[1] > 1e6 and K[1] / K[2] == pytest.approx(10.0, rel=0.01)
    assert K[0] < 100 and K[3] < 100


def test_radius_study_scores_and_choices():
    """The study's volumes equal the workspace grids'; best_conditioned maximises the volume with K_2 <= k_max
    and a tighter bound never chooses a smaller R here (K_2 improves with R on most of the workspace)."""
    R = np.array([0.10, 0.14, 0.18, 0.22])
    study = G.workspace_vs_radius(P, R, spacing=0.015)
    assert np.all(np.diff(study.volume) < 0.0)
    cv = study.conditioned_volume(3.0)
    assert np.all(cv <= study.volume) and study.best_conditioned(3.0) == R[int(np.argmax(cv))]
    assert study.best_conditioned(2.5) >= study.best_conditioned(5.0)
    assert np.all(study.weighted_volume() < study.volume)
    with pytest.raises(InvalidInputError):
        study.conditioned_volume(math.inf)


def test_region_mean_condition_rules_out_radii_that_miss_part_of_the_region():
    """Mean K_2 over a small region round the study pose: finite where the whole region is reachable, inf
    for radii beyond the reach of its lowest points; the mean equals that of the one-pose values."""
    region = POSE + np.array([[0.0, 0.0, 0.0], [0.02, 0.0, -0.02], [0.0, -0.02, 0.02]])
    R = [0.12, 0.20, 0.279]
    mean = G.region_mean_condition(P, R, region)
    assert np.isfinite(mean[0]) and np.isfinite(mean[1]) and np.isinf(mean[2])
    one = [G.condition_vs_radius(P, x, [0.12], kinds=("2",))["2"][0] for x in region]
    assert mean[0] == pytest.approx(np.mean(one), rel=1e-12)
    with pytest.raises(InvalidInputError):
        G.region_mean_condition(P, R, np.zeros((0, 3)))
