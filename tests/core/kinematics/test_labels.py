"""Mode labels on every solve result, the warning when a solve ends in another mode than its seed, and the
nearest assembly to the zero pose."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import minimize

import pkm
from pkm.core.kinematics import constraints
from pkm.errors import ModeChangeWarning

ROOT = Path(__file__).resolve().parents[3]


def test_an_ik_across_a_direct_singularity_warns_and_fk_confirms_the_other_assembly_mode(built):
    """The toy five-bar's tip moved down past the aligned distal links: the inverse kinematics follows the path
    (well posed there) into the other assembly mode and says so; the loop closure from the reference at the same
    actuators (an independent route) lands elsewhere, in the reference's assembly mode. A short move stays silent."""
    mech = built("fivebar")
    y0 = pkm.TaskMap.of(mech).value(mech.q_reference)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ModeChangeWarning)
        near = pkm.solve_ik(mech, y0 + [0.0, -0.1])
    assert near.mode == pkm.solve_ik(mech, y0).mode == pkm.ModeLabel((1,), (1, 1))
    with pytest.warns(ModeChangeWarning) as record:
        far = pkm.solve_ik(mech, y0 + [0.0, -0.3])
    w = record[0].message
    assert w.changed == ("assembly",) and w.seed.assembly == (1,) and w.result == far.mode
    assert far.mode.assembly == (-1,) and far.mode.assembly_id == 1 and far.mode.working == (1, 1)
    fk = pkm.close_loops(mech, mech.actuated_q(far.q))  # from the reference, which it keeps
    assert fk.mode.assembly == (1,) and np.abs(mech.difference(fk.q, far.q)).max() > 0.1
    assert np.abs(mech.actuated_q(fk.q) - mech.actuated_q(far.q)).max() < 1e-12


def test_nearest_assembly_is_the_closed_configuration_nearest_the_zero_pose(tmp_path):
    """The five-bar of examples/your_own_fivebar.py states no [reference]: pkm.nearest_assembly gives the closed
    configuration nearest q = 0 (SLSQP from 12 starts, an independent route, finds no nearer one; the default
    assembly is 2.7 times as far), of the mirrored pair q, -q the one with the larger first coordinate."""
    spec = (ROOT / "examples" / "your_own_fivebar.py").read_text().split('SPEC = """\\\n')[1].split('"""')[0]
    (tmp_path / "fivebar.urdf").write_text((ROOT / "examples" / "gepetto_fivebar" / "robot.urdf").read_text())
    (tmp_path / "fivebar.closures.toml").write_text(spec)
    mech = pkm.load(tmp_path / "fivebar.closures.toml")
    res = pkm.nearest_assembly(mech)
    q = res.q
    assert res.converged and np.abs(constraints.residual(mech, q)).max() < 1e-12
    rng = np.random.default_rng(1)
    best = np.inf
    for _ in range(12):
        r = minimize(lambda x: x @ x, rng.uniform(-np.pi, np.pi, 4), jac=lambda x: 2 * x, method="SLSQP",
                     constraints=[{"type": "eq", "fun": lambda x: constraints.residual(mech, x)[:2]}],
                     options={"ftol": 1e-14, "maxiter": 500})
        if np.abs(constraints.residual(mech, r.x)).max() < 1e-9:
            best = min(best, float(np.linalg.norm(r.x)))
    assert np.linalg.norm(q) <= best + 1e-7 and np.linalg.norm(q) < 0.5 * np.linalg.norm(mech.q_reference)
    assert np.abs(constraints.residual(mech, -q)).max() < 1e-12 and q[0] > 0  # the mirrored one: not chosen


def test_mode_label_takes_any_array_like_and_refuses_a_bad_configuration():
    """``q`` as a list labels as the array does (it raised Pinocchio's TypeError); a wrong length is pkm's error."""
    delta = pkm.load("delta")
    q = pkm.branch_seed(delta, "knee_in")
    assert pkm.mode_label(delta, list(q)) == pkm.mode_label(delta, q)
    with pytest.raises(pkm.errors.InvalidInputError):
        pkm.mode_label(delta, q[:-1])


def _from_scratch(mech, q) -> pkm.ModeLabel:
    """The label by the first route: a kinematics pass at ``q``, then each block's sign alone."""
    from pkm.core.kinematics import labels

    fk, ik = labels._structures(mech)
    Jc, J = labels._scaled(mech, pkm.Configuration.at(mech, q).closure_and_task_jacobian)
    return pkm.ModeLabel(*(() if b is None else tuple(labels._sign(A[np.ix_(b.rows, b.cols)][np.ix_(r, c)]) * s
                                                      for r, c, s in b.blocks) for b, A in ((fk, Jc), (ik, J))))


@pytest.mark.parametrize("name", ["delta", "hexapod", "gough_stewart", "prs3", "rrr3"])
def test_the_solvers_label_from_their_own_newton_matrices_as_from_scratch(built, name, monkeypatch):
    """The labels of close_loops and solve_ik come from the solver's Newton matrices (the last solve's result as the
    next seed: its label kept), with no kinematics pass of their own, and equal the labels computed from scratch,
    block by block (on the delta's knee-in branch too: signs -1)."""
    from pkm.core.kinematics import labels

    mech = built(name)
    task = pkm.TaskMap.of(mech)
    rng = np.random.default_rng(3)
    labels._structures(mech)  # (the blocks, found once per mechanism from three passes)
    passes = []
    mats = labels._mats
    monkeypatch.setattr(labels, "_mats", lambda m, q: passes.append(q) or mats(m, q))
    for branch in [None] + (["knee_in"] if name == "delta" else []):
        seed = mech.q_reference if branch is None else pkm.branch_seed(mech, branch)
        fk = pkm.close_loops(mech, mech.actuated_q(seed) + 0.05 * rng.uniform(-1, 1, mech.na), seed)
        fk2 = pkm.close_loops(mech, mech.actuated_q(fk.q) + 0.05 * rng.uniform(-1, 1, mech.na), fk.q)
        ik = pkm.solve_ik(mech, task.retract(task.value(fk2.q), 0.005 * rng.uniform(-1, 1, task.size)), fk2.q)
        assert passes == []
        for res in (fk, fk2, ik):
            assert res.mode == _from_scratch(mech, res.q) and res.mode.assembly
    assert name != "delta" or ik.mode.working == (1, -1, -1, -1)


def test_the_stacked_signs_equal_each_blocks_sign_near_and_far_from_singular():
    """:func:`labels._signs` (one LAPACK call a stack, the SVD skipped where the determinant proves the block
    regular) gives each block's :func:`labels._sign`: blocks whose smallest singular value is 1e-3 to 1e-12 of the
    largest, either sign, around the threshold (1e-8) included."""
    from pkm.core.kinematics import labels

    rng = np.random.default_rng(7)
    for n in (1, 3, 8):
        stack = []
        for smin in (1.0, 1e-3, 2e-7, 5e-8, 1.1e-8, 0.9e-8, 1e-9, 1e-12, 0.0):
            U, _ = np.linalg.qr(rng.standard_normal((n, n)))
            V, _ = np.linalg.qr(rng.standard_normal((n, n)))
            s = np.linspace(1.0, smin, n) if n > 1 else np.array([smin])
            stack.append(rng.choice([-1.0, 1.0]) * (U * s) @ V.T)
        B = np.array(stack)
        assert labels._signs(B) == [labels._sign(b) for b in B]
        assert set(labels._signs(B)) >= {0} and set(labels._signs(B)) - {0}


def test_every_joint_actuated_the_closure_checks_the_actuators_and_labels_the_working_mode(built, all_actuated):
    """The five-bar with its elbows actuated too (no passive coordinate: the labels' reduction over the empty
    passive columns raised numpy's ValueError): the loop closure at the actuated values of a five-bar's closed
    configuration, one away from the reference's and one in its other working mode, is that configuration (no path,
    no iteration, no mode-change warning), with no assembly label and the five-bar's own working label (the same
    closure-and-task matrix); values that open the loop are refused naming the closure; the inverse kinematics
    agrees with the five-bar's."""
    five, mech = built("fivebar"), all_actuated
    assert len(mech.passive_v) == 0
    y0 = pkm.TaskMap.of(five).value(five.q_reference)
    away, inner = pkm.solve_ik(five, y0 + [0.02, -0.03]).q, pkm.solve_ik(five, y0, branch="elbows_in").q
    with warnings.catch_warnings():
        warnings.simplefilter("error", ModeChangeWarning)
        for q in (away, inner):
            res = pkm.close_loops(mech, mech.actuated_q(q))
            assert res.converged and res.iterations == 0 and np.abs(mech.difference(q, res.q)).max() < 1e-12
            assert res.mode == pkm.mode_label(mech, q) == pkm.ModeLabel((), pkm.mode_label(five, q).working)
    assert pkm.mode_label(mech, inner).differs(pkm.mode_label(mech, away)) == ("working",)
    with pytest.raises(pkm.errors.ConvergenceError) as info:
        pkm.close_loops(mech, mech.actuated_q(away) + [0.0, 0.0, 0.01, 0.0])
    assert info.value.worst_closure == "tip" and info.value.worst_gap > 1e-4
    ik = pkm.solve_ik(mech, y0 + [0.02, -0.03])
    assert ik.converged and np.abs(mech.difference(away, ik.q)).max() < 1e-9
