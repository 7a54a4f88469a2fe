"""pkm.core.analysis.reconfiguration: redundant parameters of any mechanism chosen through the twin, checked against the
hexapod's closed forms and against the generic core driven by scipy (one and two parameters)."""

from __future__ import annotations

import math
import shutil

import numpy as np
import pinocchio as pin
import pytest
from scipy.optimize import minimize, minimize_scalar

import pkm
from pkm.core.analysis.reconfiguration import reconfigure
from pkm.errors import InvalidInputError, UnreachableError
from pkm.mechanisms import hexapod as hx
from pkm.mechanisms.hexapod import reconfiguration as hr
from pkm.papers import hexapod as study
from tests.core.twin.test_tree import EXAMPLES


def _core_index(mech, target: dict, params, length: float, kind: str = "ci_2") -> float:
    """1/kappa_2 (or the normalised Frobenius index) of the inverse Jacobian with the parameters held, by the
    generic core (no twin)."""
    task = pkm.TaskMap(mech)
    q = pkm.solve_ik(mech, target).q
    K = pkm.inverse_jacobian(mech, q)
    rows = [i for i, n in enumerate(mech.actuated_names) if n not in params]
    cols = [i for i, k in enumerate(task.keys) if k not in params]
    scale = np.array([1.0 if task.kinds[task.keys[i]] == "length" else 1.0 / length for i in cols])
    s = np.linalg.svd(K[np.ix_(rows, cols)] * scale, compute_uv=False)
    return s[-1] / s[0] if kind == "ci_2" else len(s) / math.sqrt(np.sum(s * s) * np.sum(1.0 / (s * s)))


@pytest.fixture(scope="module")
def hexapod_pose_t():
    mech = pkm.load("hexapod")
    R, P = study.pose_T_placement()
    return mech, R, P, {"pose": pin.SE3(R, P), "beta_1": 0.0}


def test_one_parameter_the_hexapods_beta_at_pose_t(hexapod_pose_t):
    """The reachable interval of beta at pose T equals the closed form's (1e-6 rad); beta* of 1/kappa_2 equals the
    generic core's maximiser (scipy's bounded Brent on pkm.solve_ik + pkm.inverse_jacobian) to 1e-5 rad."""
    mech, R, P, target = hexapod_pose_t
    r = reconfigure(mech, [target], ["beta_1"], [(-math.pi / 2, math.pi / 2)], length=0.1)
    ((lo, hi),) = hr.reachable_intervals(hx.Params(), R, P)
    assert abs(r.lower[0] - lo) <= 1e-6 and abs(r.upper[0] - hi) <= 1e-12
    f = lambda b: -_core_index(mech, {**target, "beta_1": b}, ["beta_1"], 0.1)
    ref = minimize_scalar(f, bounds=(math.radians(60), math.radians(85)), method="bounded",
                          options={"xatol": 1e-9})
    assert abs(r.x[0] - ref.x) <= 1e-5 and math.isclose(r.value[0], -ref.fun, rel_tol=1e-8)
    assert np.abs(pkm.TaskMap(mech).value(r.q[0])[-1] - r.x[0]) <= 1e-10  # the configuration at the choice
    again = reconfigure(mech, [target], ["beta_1"], [(-math.pi / 2, math.pi / 2)], length=0.1,
                        kernels=pkm.Kernels(mech))  # (kernels given: the same choice, to 1e-12)
    assert np.allclose(again.x, r.x, rtol=0, atol=1e-12) and np.allclose(again.value, r.value, rtol=1e-12)


def test_one_parameter_along_a_path_keeps_the_rate_limit(hexapod_pose_t):
    """Six poses of the paper's spiral, 2 deg per pose at most: the profile respects it, ends no worse than the
    pointwise optima clipped to it, and reports its gain over beta = 0."""
    mech = hexapod_pose_t[0]
    poses = [{"pose": pin.SE3(R, P), "beta_1": 0.0} for R, P in study.spiral_poses(6)]
    r = reconfigure(mech, poses, ["beta_1"], [(-math.pi / 2, math.pi / 2)], length=0.1,
                    rate_limit=math.radians(2.0), baseline=0.0)
    opt = r.optimum
    assert opt.converged and opt.max_rate <= math.radians(2.0) + 1e-9
    assert opt.objective >= opt.start_objective - 1e-12 and np.all(opt.baseline_ok)


def test_two_parameters_of_a_users_mechanism(tmp_path):
    """The Gough-Stewart of examples/ with a task of x, y, z, roll and two leg lengths: the two lengths chosen for a
    pose (the normalised Frobenius index, smooth: 1/kappa_2 has a kink where singular values cross, as at this
    symmetric design) equal scipy's L-BFGS-B on the generic core (1e-6 m), inside the limits."""
    src = EXAMPLES / "gough_stewart"
    for f in src.iterdir():
        shutil.copy(f, tmp_path / f.name)
    spec = tmp_path / "gough_stewart.closures.toml"
    spec.write_text(spec.read_text().replace('components = ["pose"]',
                                             'components = ["x", "y", "z", "roll"]\njoints = ["leg1", "leg2"]'))
    mech = pkm.load(spec)
    named = pkm.TaskMap(mech).named(mech.q_reference)
    l1, l2 = named["leg1"], named["leg2"]
    limits = [(l1 - 0.02, l1 + 0.02), (l2 - 0.02, l2 + 0.02)]
    r = reconfigure(mech, [named], ["leg1", "leg2"], limits, length=0.1, grid=7, index="ci_fro")
    assert r.x.shape == (1, 2) and np.all(r.x[0] >= [lo for lo, _ in limits]) and np.all(r.x[0] <= [h for _, h in limits])
    f = lambda x: -_core_index(mech, {**named, "leg1": x[0], "leg2": x[1]}, ["leg1", "leg2"], 0.1, "ci_fro")
    ref = minimize(f, r.x[0] + 0.002, bounds=limits, method="L-BFGS-B", options={"ftol": 1e-15, "gtol": 1e-11})
    assert np.abs(r.x[0] - ref.x).max() <= 1e-6 and r.value[0] >= -ref.fun - 1e-12


def test_bad_requests_are_refused(hexapod_pose_t):
    mech, _, _, target = hexapod_pose_t
    with pytest.raises(InvalidInputError, match="task joints"):
        reconfigure(mech, [target], ["alpha_1"], [(-1.0, 1.0)], length=0.1)
    with pytest.raises(InvalidInputError, match="low < high"):
        reconfigure(mech, [target], ["beta_1"], [(1.0, -1.0)], length=0.1)
    with pytest.raises(InvalidInputError, match="characteristic length"):
        reconfigure(mech, [target], ["beta_1"], [(-1.0, 1.0)])
    with pytest.raises(InvalidInputError, match="index"):
        reconfigure(mech, [target], ["beta_1"], [(-1.0, 1.0)], length=0.1, index="dexterity")
    for other in (pkm.Kernels(pkm.load("rrr3")), "kernels"):
        with pytest.raises(InvalidInputError, match="Kernels of this mechanism"):
            reconfigure(mech, [target], ["beta_1"], [(-1.0, 1.0)], length=0.1, kernels=other)
    far = {"pose": pin.SE3(np.eye(3), np.array([0.0, -2.0, 0.0])), "beta_1": 0.0}
    with pytest.raises((UnreachableError, pkm.errors.ConvergenceError)):
        reconfigure(mech, [far], ["beta_1"], [(-1.0, 1.0)], length=0.1)


def test_an_index_that_is_no_name_is_refused_by_pkm():
    """The fuzz's repro (issue 47): ``index=`` an array raised numpy's "truth value of an array is ambiguous"."""
    mech = pkm.load("hexapod")
    with pytest.raises(InvalidInputError, match="index"):
        reconfigure(mech, [pkm.TaskMap.of(mech).value(mech.q_reference)], ["beta_1"], [(-0.5, 0.5)], length=0.1,
                    index=np.array(["a", "b"]))
