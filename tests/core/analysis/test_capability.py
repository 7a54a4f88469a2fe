"""pkm.core.analysis.capability: the polytopes are what their definitions say (each vertex a box corner mapped: the
statics ``τ = Jᵀ w + g``, the forward dynamics from rest, ``J q̇``), their extents equal linear programs
(``scipy.optimize.linprog``, 1e-9), the ellipsoid lies inside the polytope, and a mechanism without limits is
refused naming the actuator."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import scipy.optimize

import pkm
from pkm.core.analysis.capability import capability
from pkm.errors import InvalidInputError
from tests.core.dynamics.test_model import mechanism

NAMES = ["delta", "prs3", "rrr3"]


def _state(name):
    mech = mechanism(name)
    qa = mech.actuated_q(mech.q_reference) + 0.03 * np.array([1.0, -0.5, 0.7])[:mech.na]
    return mech, pkm.close_loops(mech, qa, mech.q_reference).q


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("kind", ["wrench", "twist", "acceleration"])
def test_the_extents_are_linear_programs(name, kind):
    mech, q = _state(name)
    c = capability(mech, q, kind)
    P = c.polytope
    n = len(P.axes)
    assert c.origin_inside
    for i, axis in enumerate(P.axes):
        for sign, value in zip((1.0, -1.0), c.along[axis]):
            cost = np.zeros(n)
            cost[i] = -sign
            others = np.delete(np.eye(n), i, axis=0)
            lp = scipy.optimize.linprog(cost, A_ub=P.A, b_ub=P.b, A_eq=others, b_eq=np.zeros(n - 1),
                                        bounds=[(None, None)] * n, method="highs")
            assert lp.status == 0 and abs(-lp.fun - value) <= 1e-9 * abs(value)
    for unit, r in c.isotropic.items():  # (the ball of that radius touches the boundary: a LP along its normal)
        cols = [k for k, u in enumerate(P.units) if u == unit]
        assert r > 0 and min(P.reach(np.eye(n)[k]) for k in cols) >= r * (1 - 1e-12)
    # every vertex is inside and on the boundary; the ellipsoid's semi-axes end inside
    assert all(P.contains(v) for v in P.vertices)
    ends = [c.ellipsoid_center + sign * 0.999 * s * u for s, u in zip(c.ellipsoid_axes, c.ellipsoid_directions.T)
            for sign in (1.0, -1.0)]
    assert all(P.contains(x) for x in ends)
    assert not P.contains(c.ellipsoid_center + 1.5 * np.sqrt(n) * c.ellipsoid_axes[0] * c.ellipsoid_directions[:, 0])


@pytest.mark.parametrize("name", NAMES)
def test_the_vertices_are_what_the_limits_give(name):
    """Each box corner of efforts: the wrench vertex satisfies ``τ = Jᵀ w + g_a``; the acceleration vertex is
    ``J q̈_a`` of the forward dynamics from rest (:meth:`ActuatorSpaceModel.accelerations`, no friction)."""
    mech, q = _state(name)
    J = pkm.forward_jacobian(mech, q)
    g = pkm.gravity_efforts(mech, q)
    model = pkm.actuator_model(mech, q, np.zeros(mech.na))
    limit = np.array([a.effort_limit for a in mech.actuators])
    corners = [np.array(c) * limit for c in itertools.product((-1.0, 1.0), repeat=mech.na)]
    W = capability(mech, q, "wrench").polytope.vertices
    Acc = capability(mech, q, "acceleration").polytope.vertices
    for k, tau in enumerate(corners):
        assert np.allclose(J.T @ W[k] + g, tau, rtol=1e-10, atol=1e-9 * limit.max())
        assert np.allclose(Acc[k], J @ model.accelerations(tau, friction=False), rtol=1e-9, atol=1e-9)


def test_refusals_name_what_is_missing():
    gs = pkm.with_actuators(pkm.load("gough_stewart"), {"leg1": {"effort_limit": np.inf}})  # (no limit on leg 1)
    with pytest.raises(InvalidInputError, match=r"leg1\.effort_limit"):
        capability(gs, gs.q_reference, "wrench")
    delta = mechanism("delta")
    with pytest.raises(InvalidInputError, match="kind"):
        capability(delta, delta.q_reference, "power")


def test_the_map_is_the_pointwise_capability(tmp_path):
    """A 5 x 4 map of the Delta's wrench capability: each reachable node's isotropic value is that of
    :func:`pkm.capability` at the node's own inverse kinematics (1e-9), the figure is drawn; unknown axes refused."""
    from pkm.core.analysis.capability import capability_map

    mech = mechanism("delta")
    xs, ys = np.linspace(-0.1, 0.1, 5), np.linspace(-0.05, 0.05, 4)
    cm = capability_map(mech, {"x": xs, "y": ys}, {"z": -0.35})
    assert cm.reachable.shape == (4, 5) and cm.reachable.all()
    q = pkm.solve_ik(mech, {"x": xs[3], "y": ys[1], "z": -0.35}).q
    assert cm.isotropic["N"][1, 3] == pytest.approx(capability(mech, q).isotropic["N"], rel=1e-9)
    assert cm.along["z"][0][1, 3] == pytest.approx(capability(mech, q).along["z"][0], rel=1e-9)
    pytest.importorskip("matplotlib")
    from pathlib import Path

    assert Path(cm.figure(str(tmp_path / "map.png"))).stat().st_size > 1000
    assert Path(cm.figure(str(tmp_path / "z.png"), along="z", negative=True)).stat().st_size > 1000
    with pytest.raises(InvalidInputError, match="along"):
        cm.figure(str(tmp_path / "w.png"), along="w")
    with pytest.raises(InvalidInputError, match="not a task coordinate"):
        capability_map(mech, {"w": xs})


@pytest.mark.parametrize("name", ["delta", "prs3"])
def test_the_compiled_map_gives_the_pointwise_capability(name):
    """:func:`map_capability` on a compiled workspace map (every node in one batch) equals :func:`capability` at the
    node's own configuration, each kind, to 1e-12 relative; same nodes as the Python :func:`capability_map`."""
    from pkm.core.analysis.capability import capability_map, map_capability
    from pkm.core.analysis.maps import workspace_map

    mech = mechanism(name)
    axes, fixed = ({"x": np.linspace(-0.1, 0.1, 7), "y": np.linspace(-0.05, 0.05, 5)}, {"z": -0.35}) \
        if name == "delta" else ({"pitch": np.radians(np.linspace(-5, 5, 7)), "z": np.linspace(0.95, 1.05, 5)}, None)
    length = None if name == "delta" else 0.1  # (the 3-PRS's task mixes lengths and angles)
    wmap = workspace_map(mech, axes, fixed, configurations=True, length=length)
    assert wmap.q.shape == wmap.reachable.shape + (mech.nq,) and np.isnan(wmap.q[~wmap.reachable]).all()
    for kind in ("wrench", "twist", "acceleration"):
        cm = map_capability(mech, wmap, kind)
        assert cm.reachable.sum() >= 30
        for j, i in np.argwhere(cm.reachable)[::4]:
            c = capability(mech, wmap.q[j, i], kind)
            for axis, (plus, minus) in c.along.items():
                assert cm.along[axis][0][j, i] == pytest.approx(plus, rel=1e-12)
                assert cm.along[axis][1][j, i] == pytest.approx(minus, rel=1e-12)
            for unit, r in c.isotropic.items():
                assert cm.isotropic[unit][j, i] == pytest.approx(r, rel=1e-12)
    python = capability_map(mech, axes, fixed, "twist")
    assert np.array_equal(python.reachable, cm.reachable)
    with pytest.raises(InvalidInputError, match="configurations=True"):
        map_capability(mech, workspace_map(mech, axes, fixed, length=length), "wrench")


def test_both_map_routes_count_the_nodes_where_the_weight_cannot_be_held():
    """A Delta whose motors give 0.1834 N m holds its weight only at the centre of x in [-15, 15] cm: the compiled
    route kept the other nodes (indices 0) and the Python route dropped them, so ``pkm map --index`` and ``pkm
    capability --axis`` disagreed on the same map. Both now keep them, with their indices 0, and say how many
    (``below_weight``, ``inside``); the pointwise capability says so too (``origin_inside``)."""
    import dataclasses

    from pkm.core.analysis.capability import capability_map, map_capability
    from pkm.core.analysis.maps import workspace_map

    weak = pkm.load("delta")
    weak.actuators = tuple(dataclasses.replace(a, effort_limit=0.1834) for a in weak.actuators)
    xs = np.linspace(-0.15, 0.15, 7)
    python = capability_map(weak, {"x": xs})
    compiled = map_capability(weak, workspace_map(weak, {"x": xs}, configurations=True))
    for cm in (python, compiled):
        assert cm.reachable.all() and cm.inside.tolist() == [False] * 3 + [True] + [False] * 3
        assert cm.below_weight == 6 and cm.summary()["below_weight"] == 6
        assert (cm.isotropic["N"][~cm.inside] == 0.0).all() and cm.isotropic["N"][3] > 0.0
    assert np.allclose(python.isotropic["N"], compiled.isotropic["N"], rtol=1e-9, atol=0)
    assert not capability(weak, pkm.solve_ik(weak, {"x": xs[0], "y": 0.0, "z": pkm.TaskMap.of(weak).named(
        weak.q_reference)["z"]}).q).origin_inside


def test_a_configuration_whose_loops_are_open_is_refused():
    """The 3-RRR's reference with one motor turned 0.3 rad (the loops open by 0.15 m) was given a capability of
    3769 N with no word: a polytope of no assembly. Refused, naming the closure and the gap relative to the size;
    a configuration closed to 1e-10 passes."""
    mech = mechanism("rrr3")
    q = mech.q_reference.copy()
    q[mech.act_q[0]] += 0.3
    with pytest.raises(InvalidInputError, match=r"the loops are not closed: closure .* open by 0\.1"):
        capability(mech, q)
    capability(mech, mech.q_reference)
