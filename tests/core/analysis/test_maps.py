"""pkm.core.analysis.maps: generic maps through the twin equal the papers' closed-form maps (the 3-RRR's eight GCIs and
their CI maps, the Delta's K(R) and workspace volumes) and work on a user's mechanism."""

from __future__ import annotations

import math

import numpy as np
import pytest

import pkm
from pkm.core.analysis.maps import workspace_map
from pkm.core.differential import indices
from pkm.errors import InvalidInputError
from pkm.mechanisms.delta import DeltaParams
from pkm.mechanisms.delta.workspace import workspace
from pkm.mechanisms.rrr3 import workspace as W
from pkm.papers import delta as delta_study
from pkm.papers import rrr3 as rrr3_study


def _rrr3_map(figure: str):
    d = rrr3_study.figure_design(figure)
    mech = pkm.build("rrr3", a=d.a, b=d.b, h=d.h, H=d.H)
    g = rrr3_study.paper_grid(d)
    return d, g, workspace_map(mech, {"x": g.xs, "y": g.ys}, {"yaw": 0.0}, length=d.h / math.sqrt(3))


@pytest.mark.parametrize("figure", sorted(rrr3_study.PUBLISHED))
def test_the_3rrr_gcis_through_the_generic_route_equal_the_closed_form(figure):
    """On the paper's 801 x 801 grid: the same reachable nodes; each node's CI within 1e-10 of LAPACK's SVD of the
    closed form's matrix (1e-8 at the few nodes exactly on an inverse singularity, CI < 1e-8, where Newton locates
    the double root to 1e-7) and within 1e-9 of the closed form's CI wherever that is itself within 1e-10 of LAPACK
    (it is not where two singular values coincide: 8e-9 off); the overall and area GCI (the paper's two numbers per
    figure) within 1e-9."""
    d, g, m = _rrr3_map(figure)
    hand = rrr3_study.figure_map(figure)
    assert np.array_equal(m.reachable, hand.reachable)
    ci = m.condition_index("2")
    r = hand.reachable
    K, _ = W.inverse_jacobian_stack(d, *np.meshgrid(g.xs, g.ys), W.CiSettings())
    s = np.linalg.svd(K[r], compute_uv=False)
    lapack = s[:, -1] / s[:, 0]
    closed_ok = (np.abs(hand.ci[r] - lapack) <= 1e-10) & (lapack >= 1e-8)
    on_singularity = lapack < 1e-8
    assert np.abs(ci[r] - lapack)[~on_singularity].max() <= 1e-10
    assert np.abs(ci[r] - lapack)[on_singularity].max(initial=0.0) <= 1e-8
    assert np.abs(ci[r][closed_ok] - hand.ci[r][closed_ok]).max() <= 1e-9
    assert abs(m.gci() - hand.gci().value) <= 1e-9
    area = g.square_mask(W.AREA_SIDE, d.base_centroid)
    assert abs(m.gci(region=area) - hand.area_gci().value) <= 1e-9


def test_the_delta_condition_numbers_through_the_generic_route_equal_the_closed_form():
    """K(R) of Fig. 5 in the three conventions at the study pose: the generic IK, then the twin's inverse Jacobian
    (compiled) and pkm.core.differential.indices, equal the closed form to 1e-9 relative."""
    for R in (0.100, 0.120, 0.150, 0.200):
        p = delta_study.PAPER
        mech = pkm.build("delta", La=p.La, Lb=p.Lb, r=p.r, R=R, home=tuple(p.home))
        q = pkm.solve_ik(mech, delta_study.POSE).q
        K = pkm.Kernels(mech).inverse_jacobian(q)
        closed = delta_study._at(R)
        for kind in delta_study.KINDS:
            assert math.isclose(indices.condition_number(K, kind), closed[kind], rel_tol=1e-9), (R, kind)


def test_the_delta_workspace_volumes_through_the_generic_route_equal_the_closed_form():
    """The 8 mm grid of the radius study (110 x 110 x 55 = 665,500 nodes) at R = 120 mm: the same reachable nodes,
    volume and volume where K_2 <= 3 as the closed form's."""
    p = delta_study.PAPER
    mech = pkm.build("delta", La=p.La, Lb=p.Lb, r=p.r, R=0.120, home=tuple(p.home))
    hand = workspace(DeltaParams(La=p.La, Lb=p.Lb, r=p.r, R=0.120, home=tuple(p.home)), delta_study.SPACING,
                     kinds=("2",))
    xy, _, z = hand.axes
    m = workspace_map(mech, {"x": xy, "y": xy, "z": z})
    reach = np.transpose(m.reachable, (2, 1, 0))  # (z, y, x) -> (x, y, z), the closed form's layout
    assert np.array_equal(reach, hand.reachable)
    assert math.isclose(m.size, hand.volume, rel_tol=1e-12)
    K2 = np.transpose(1.0 / m.condition_index("2"), (2, 1, 0))
    assert np.count_nonzero(K2 <= delta_study.K_MAX) == np.count_nonzero(hand.K["2"] <= delta_study.K_MAX)
    both = hand.reachable & np.isfinite(hand.K["2"])
    assert np.abs(K2[both] / hand.K["2"][both] - 1.0).max() <= 1e-9


def test_a_users_mechanism_gets_its_map():
    """The Gough-Stewart of examples/ (a user's files, a pose task): a 121 x 121 map of the platform's x, y at the
    reference height and orientation, L = 0.1 m. At random reachable nodes pkm.solve_ik and the kernels' inverse
    Jacobian give the same CI (1e-8); the manipulability and the smallest singular value are positive inside."""
    from tests.core.twin.test_tree import FILES

    mech = pkm.load(FILES["gough_stewart"])
    y0 = pkm.TaskMap(mech).named(mech.q_reference)
    xs, ys = y0["x"] + np.linspace(-0.06, 0.06, 121), y0["y"] + np.linspace(-0.06, 0.06, 121)
    m = workspace_map(mech, {"x": xs, "y": ys}, length=0.1)
    assert m.nodes > 1000 and m.reachable[60, 60]
    ci = m.condition_index("2")
    K = pkm.Kernels(mech)
    rng = np.random.default_rng(0)
    for k in rng.choice(np.flatnonzero(m.reachable.ravel()), 5, replace=False):
        iy, ix = np.unravel_index(k, m.reachable.shape)
        q = pkm.solve_ik(mech, {"x": xs[ix], "y": ys[iy]}).q
        J = K.inverse_jacobian(q) @ np.diag(m.scale)
        assert math.isclose(1.0 / indices.condition_number(J, "2"), ci[iy, ix], rel_tol=1e-8)
    inside = m.reachable
    assert np.all(m.manipulability()[inside] > 0) and np.all(m.sigma_min()[inside] > 0)
    assert math.isclose(m.size, m.nodes * 0.001 ** 2, rel_tol=1e-9)


def test_the_workspace_over_orientations():
    """A 3-D map (x, y, yaw) of the 3-RRR: its maximal and total-orientation workspaces equal the closed form's
    reachability over the same orientations, any and all."""
    mech = pkm.load("rrr3")
    d = W.Design.of(mech.params)
    xs, phis = np.linspace(0.0, d.H, 41), np.radians(np.arange(-30.0, 31.0, 10.0))
    m = workspace_map(mech, {"x": xs, "y": xs, "yaw": phis}, length=d.h / math.sqrt(3))
    X, Y, P = np.meshgrid(xs, xs, phis)  # (y, x, phi)
    _, reach = W.condition_index_phi(d, X, Y, P, W.CiSettings())
    assert np.array_equal(m.reachable_over("yaw", "any"), reach.any(axis=-1))
    assert np.array_equal(m.reachable_over("yaw", "all"), reach.all(axis=-1))
    with pytest.raises(InvalidInputError, match="mode"):
        m.reachable_over("yaw", "some")


def test_bad_maps_are_refused():
    mech = pkm.load("rrr3")
    with pytest.raises(InvalidInputError, match="not a task coordinate"):
        workspace_map(mech, {"q": [0.0]})
    with pytest.raises(InvalidInputError, match="characteristic length"):
        workspace_map(mech, {"x": [0.5], "y": [0.3]})
    with pytest.raises(InvalidInputError, match="1 to 3"):
        workspace_map(mech, {})
    with pytest.raises(InvalidInputError, match="finite"):
        workspace_map(mech, {"x": [np.nan]}, length=0.05)


def test_coordinates_beyond_the_float_spacing_of_tol_are_refused():
    """Issue 47's repro: the 3-PRS's map over ``pitch`` = [1e308, 1e-2] rad (``length=1e7``) called 1e308 rad
    reachable and returned a size of inf. A coordinate beyond ``tol / eps`` (4.5e5 at tol = 1e-10) cannot be solved
    to ``tol`` (its float spacing is larger): refused, naming the axis; the bound is met just inside."""
    from pkm.core.analysis.maps import EPS

    mech = pkm.load("prs3")
    with pytest.raises(InvalidInputError, match=r"'pitch': 1e\+308 is beyond 450360 .*tol = 1e-10"):
        workspace_map(mech, {"z": [0.99], "pitch": [1e308, 1e-2]}, length=1e7)
    with pytest.raises(InvalidInputError, match="beyond") as info:
        workspace_map(mech, {"z": [0.99]}, {"pitch": 1e6}, length=1e7)
    assert info.value.name == "fixed"
    m = workspace_map(mech, {"pitch": [1e-10 / EPS * (1 - 1e-12)]}, length=0.1)
    assert np.isfinite(m.size)


def test_the_old_name_warns_and_without_a_compiler_the_error_is_pkms(monkeypatch):
    """``pkm.task_map`` (0.1) is ``pkm.workspace_map`` with a DeprecationWarning; without a C compiler the map
    raises pkm's CompilerError (still a RuntimeError, as before) saying why."""
    import pkm
    from pkm.core.analysis import maps
    from pkm.core.twin import codegen
    from pkm.errors import CompilerError, PkmError

    assert maps.TaskGridMap is maps.WorkspaceMap
    mech = pkm.load("delta")
    with pytest.warns(DeprecationWarning, match="workspace_map"):
        m = pkm.task_map(mech, {"x": [0.0, 0.01]}, kernels=None)
    assert isinstance(m, maps.WorkspaceMap) and m.reachable.all()
    monkeypatch.setattr(codegen, "compile_library", lambda *a, **k: (None, "no cc on PATH"))
    with pytest.raises(CompilerError, match="maps need a C compiler: no cc on PATH") as info:
        pkm.workspace_map(mech, {"x": [0.0]})
    assert isinstance(info.value, PkmError) and isinstance(info.value, RuntimeError)


def test_an_unevenly_spaced_axis_measures_each_node_s_own_cell():
    """The cell was the first two nodes' gap on every node: x = [0.45, 0.46, 0.50, 0.60] measured 0.04 m where the
    span is 0.15 m. Each node now counts half the way to each neighbour (an end node its gap), an evenly spaced
    grid as before (count x cell, bit for bit), and the size says its unit (an axis of one node has no extent)."""
    mech = pkm.load("rrr3")
    uneven = workspace_map(mech, {"x": [0.45, 0.46, 0.50, 0.60]}, length=0.1)
    assert uneven.reachable.all() and not uneven.uniform
    assert np.allclose(uneven.cells, [0.01, 0.025, 0.07, 0.1], rtol=1e-12)
    assert uneven.size == pytest.approx(0.205, rel=1e-12) and uneven.size_unit == "m"
    with pytest.raises(InvalidInputError, match="unevenly spaced"):
        uneven.cell  # noqa: B018
    even = workspace_map(mech, {"x": np.linspace(0.45, 0.5, 6), "yaw": [0.0, 0.05], "y": [0.29]}, length=0.1)
    assert even.uniform and even.size == even.nodes * even.cell and even.size_unit == "m rad"
    assert np.allclose(even.cells, even.cell, rtol=1e-12)


def test_a_mechanism_with_idle_motions_gets_its_map():
    """The humanoid ankle (its rods spin between two balls: idle motions, held in the Newton steps): a 3 x 2 map of
    pitch and roll, every node reachable, each node's singular values those of pkm.inverse_jacobian at its
    configuration (the core's, whose rods' spin is of least norm) to 1e-10 relative."""
    from pathlib import Path

    mech = pkm.load(Path(__file__).resolve().parents[3] / "examples" / "humanoid_ankle" / "ankle.closures.toml")
    pitch, roll = np.array([-0.3, 0.0, 0.3]), np.array([-0.2, 0.1])
    m = workspace_map(mech, {"ankle_pitch": pitch, "ankle_roll": roll}, configurations=True)
    assert m.reachable.all()
    for iy, ix in np.ndindex(m.reachable.shape):
        s = np.linalg.svd(pkm.inverse_jacobian(mech, m.q[iy, ix]) @ np.diag(m.scale), compute_uv=False)
        np.testing.assert_allclose(m.singular_values[iy, ix], s, rtol=1e-10)
        assert np.allclose(pkm.TaskMap(mech).value(m.q[iy, ix]), [pitch[ix], roll[iy]], rtol=0, atol=1e-10)
