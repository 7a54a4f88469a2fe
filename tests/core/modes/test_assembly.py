"""Every assembly mode by homotopy continuation, checked against the closed forms the papers give and against the
generic core (every mode's configuration closes its loops; the count is complete or says why not)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.modes import assembly_modes
from pkm.core.modes.assembly import VERIFY_TOL
from pkm.core.modes.continuation import solve
from pkm.core.modes.equations import FKSystem
from pkm.core.modes.reduce import reduce_mechanism
from pkm.mechanisms.rrr3 import kinematics as rrr3_kinematics

pytest.importorskip("bertini")


def test_delta_has_its_two_sphere_intersection_roots():
    """The Delta's forward kinematics is the intersection of three spheres: two roots, mirror images in the plane
    of their centres; the homotopy finds both and the 6 other paths of the 8-path total-degree start go to
    infinity."""
    delta = pkm.load("delta")
    qa = delta.actuated_q(delta.q_reference) + np.array([0.1, -0.2, 0.15])
    modes = assembly_modes(delta, qa)
    assert modes.complete and len(modes) == 2 and modes.n_paths == 8 and modes.n_infinite == 6
    z = sorted(pkm.TaskMap.of(delta).value(m.q)[2] for m in modes)
    assert z[0] < 0.0 < z[1]  # below and above the base
    for m in modes:
        assert m.residual <= VERIFY_TOL and m.certificate.certified
        assert np.allclose(delta.actuated_q(m.q), qa, atol=1e-12)
    # the core's Newton from the reference lands on one of them
    below = pkm.close_loops(delta, qa).q
    task = pkm.TaskMap.of(delta)
    assert min(np.abs(task.value(below) - task.value(m.q)).max() for m in modes) < 1e-9


def test_rrr3_modes_are_the_exact_polynomials_on_random_designs():
    """On random designs and motor angles, the set equals the roots of the 3-RRR's exact FK polynomial
    (:func:`pkm.mechanisms.rrr3.kinematics.forward_kinematics`), pose by pose to 1e-8 (m, rad), for every count of
    real modes the 3-RRR has here: none, two, four and six. (Each design checked is one Bertini solve of 16 paths, a
    quarter of a second; the designs are drawn until each count has been met, at most two checked per count: six
    solves, where the first twenty designs drawn were fifteen of two modes or none, 5 s of CPU.)"""
    rng = np.random.default_rng(0)
    checked: dict[int, int] = {}
    for _ in range(200):  # (the 16th draw meets the last count, four)
        if set(checked) == {0, 2, 4, 6}:
            break
        H = rng.uniform(0.5, 1.5)
        h, a, b = H * rng.uniform(0.1, 0.5), H * rng.uniform(0.3, 0.7), H * rng.uniform(0.3, 0.7)
        try:
            mech = pkm.build("rrr3", a=a, b=b, h=h, H=H)
        except pkm.PkmError:
            continue  # a design without a well-conditioned reference pose
        qa = mech.actuated_q(mech.q_reference) + rng.uniform(-0.3, 0.3, 3)
        try:
            exact = rrr3_kinematics.forward_kinematics(mech.params, qa)
        except pkm.errors.AssemblyError:
            exact = ()
        if checked.get(len(exact), 0) >= 2:
            continue
        modes = assembly_modes(mech, qa)
        assert modes.complete, modes.summary()
        got = sorted((pkm.TaskMap.of(mech).value(m.q) for m in modes), key=lambda y: y[2] % (2 * np.pi))
        want = sorted((s.y for s in exact), key=lambda y: y[2] % (2 * np.pi))
        assert len(got) == len(want), (mech.params, qa, modes.summary())
        for g, w in zip(got, want):
            assert np.abs(g[:2] - w[:2]).max() < 1e-8
            assert abs((g[2] - w[2] + np.pi) % (2 * np.pi) - np.pi) < 1e-8
        checked[len(got)] = checked.get(len(got), 0) + 1
    assert set(checked) == {0, 2, 4, 6}, checked  # (not a test of empty sets, nor of pairs alone)


def test_a_dropped_path_is_reported_and_the_set_not_complete():
    """A planted loss: the path that reached one mode is marked failed; the set says it is not complete, lists the
    path, and lacks that mode."""
    delta = pkm.load("delta")
    qa = delta.actuated_q(delta.q_reference)
    full = assembly_modes(delta, qa)
    d = delta.model.createData()
    pin.forwardKinematics(delta.model, d, delta.with_actuated(delta.q_reference, qa))
    system = FKSystem(reduce_mechanism(delta), d)
    cont = solve(system.polys, system.groups)
    lost = [p.index for p in cont.paths if p.status == "finite"][:1]
    planted = assembly_modes(delta, qa, continuation=cont.without(lost))
    assert full.complete and not planted.complete
    assert [p.index for p in planted.failed] == lost and planted.failed[0].code == "dropped"
    assert len(planted) == len(full) - 1
    assert "NOT complete: 1 path(s) failed" in planted.summary()


def test_prs3_has_eight_real_modes_at_its_reference():
    """The 3-PRS's family has 16 generic solutions (its generic start); at the paper's reference 8 are real, each
    certified and closed by the core; the default precision (double, then adaptive where in doubt) finds the modes
    adaptive precision finds, in the same order, to 1e-12 (six of them in two threes at one distance from the
    reference: the order is the distance's to 10 digits, then the configuration's)."""
    prs3 = pkm.load("prs3")
    modes = assembly_modes(prs3, prs3.actuated_q(prs3.q_reference))
    adaptive = assembly_modes(prs3, prs3.actuated_q(prs3.q_reference), precision="adaptive")
    assert np.abs(np.array([m.q for m in modes]) - np.array([m.q for m in adaptive])).max() < 1e-12
    assert (modes.n_complex, modes.n_exceptional) == (adaptive.n_complex, adaptive.n_exceptional)
    assert modes.complete and modes.n_paths == 16 and len(modes) == 8
    assert all(m.certificate.certified and m.residual <= VERIFY_TOL for m in modes)
    assert np.abs(prs3.difference(modes[0].q, prs3.q_reference)).max() < 1e-8  # mode 0: the reference itself
