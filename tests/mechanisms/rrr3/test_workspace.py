"""Planar 3-RRR maps: vectorised CI against the per-pose route, workspaces, GCI choices, similarity law, sweeps."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pkm.core.differential.indices import inverse_condition
from pkm.errors import InvalidInputError, InvalidParameterError, UnreachableError
from pkm.mechanisms import rrr3
from pkm.mechanisms.rrr3 import workspace as maps
from pkm.mechanisms.rrr3.workspace import CiSettings, Design, Grid

FIG6 = Design(0.60, 0.60, 0.10, 1.00)
FIG5 = Design(0.40, 0.30, 0.40, 0.70)


def _nodes(design, n, seed, spread=0.35):
    rng = np.random.default_rng(seed)
    return design.base_centroid + rng.uniform(-spread, spread, (n, 2))


@pytest.mark.parametrize("design", [FIG6, FIG5], ids=["fig6", "fig5"])
@pytest.mark.parametrize("settings", [CiSettings(), CiSettings(phi=0.4, branch=3),
                                      CiSettings(branch=8, kind="fro_normalized"),
                                      CiSettings(phi=-0.2, reference="A", length=0.07),
                                      CiSettings(branch=6, reference="origin", kind="fro_normalized")],
                         ids=["default", "phi-mode3", "mode8-fro", "A-L", "origin-fro"])
def test_vectorised_ci_equals_the_svd_of_the_per_pose_jacobians(design, settings):
    """On 150 random nodes the closed-form eigenvalue CI equals pkm.core.differential.indices on rrr3.homogenized_jacobians (1e-9 rel),
    and the reachable mask equals the closed-form IK's success."""
    pts = _nodes(design, 150, seed=1)
    ci, ok = maps.condition_index(design, pts[:, 0], pts[:, 1], settings)
    naive = np.array([maps.naive_condition_index(design, [*p, settings.phi], settings) for p in pts])
    np.testing.assert_array_equal(ok, np.isfinite(naive))
    assert ok.sum() > 50 and np.all(np.isnan(ci[~ok]))
    np.testing.assert_allclose(ci[ok], naive[ok], rtol=1e-9, atol=1e-13)


def test_inverse_jacobian_stack_equals_the_per_pose_matrices():
    """K = J_q^-1 J_x of the stack equals rrr3.homogenized_jacobians node by node (1e-12), elbows on the mode's side."""
    pts = _nodes(FIG6, 40, seed=2, spread=0.2)
    params = rrr3.Rrr3Params(a=0.6, b=0.6, h=0.1, H=1.0)
    for mode in (1, 5):
        st = CiSettings(phi=0.25, branch=mode)
        K, ok = maps.inverse_jacobian_stack(FIG6, pts[:, 0], pts[:, 1], st)
        for k in np.flatnonzero(ok):
            Jx, Jq = rrr3.homogenized_jacobians(params, [*pts[k], 0.25], mode)
            np.testing.assert_allclose(K[k], Jx / np.diag(Jq)[:, None], rtol=1e-12, atol=1e-12)


def test_ci_is_zero_on_singularities_and_one_when_isotropic():
    """CI = 0 at a stretched leg (no NaN), and the spectral CI of a hand-built isotropic K is 1."""
    P = rrr3.Rrr3Params()
    u = np.array([math.cos(0.3), math.sin(0.3)])
    G = rrr3.centroid_from_a(P, (P.a + P.b) * u, 0.0)
    ci, ok = maps.condition_index(P, G[0], G[1])
    assert ok and ci == pytest.approx(0.0, abs=1e-6)
    rows = [(math.cos(t), math.sin(t), 1.0) for t in (0.0, 2 * math.pi / 3, 4 * math.pi / 3)]
    iso = maps._condition_index([tuple(np.array([v]) for v in r) for r in rows], [np.array([2.0])] * 3, "2")
    assert iso[0] == pytest.approx(inverse_condition(np.array(rows), "2"), abs=1e-12)


def test_modes_1_and_8_are_mirror_images():
    """At Phi = 0 the map of mode 8 is the map of mode 1 mirrored about the vertical through the base centroid (1e-12)."""
    grid = Grid.square(FIG6.base_centroid, 0.7, 0.02)
    m1 = maps.ci_map(FIG6, grid, CiSettings(branch=1))
    m8 = maps.ci_map(FIG6, grid, CiSettings(branch=8))
    np.testing.assert_array_equal(m1.reachable, m8.reachable[:, ::-1])
    np.testing.assert_allclose(m1.ci[m1.reachable], m8.ci[:, ::-1][m1.reachable], atol=1e-12)


def test_similarity_law_makes_the_overall_gci_scale_invariant_but_not_the_fixed_area():
    """Designs h = H/10, a = b = 0.4 H on grids scaled with H have identical CI maps (1e-12); the 30 cm area GCI grows with H."""
    maps_ = []
    for H in (1.0, 2.0):
        d = Design.similarity_law(H)
        maps_.append(maps.ci_map(d, Grid.square(d.base_centroid, 0.8 * H / 2, 0.01 * H / 2)))
    np.testing.assert_array_equal(maps_[0].reachable, maps_[1].reachable)
    np.testing.assert_allclose(maps_[0].ci[maps_[0].reachable], maps_[1].ci[maps_[1].reachable], atol=1e-12)
    assert maps_[0].gci().value == pytest.approx(maps_[1].gci().value, abs=1e-12)
    fixed = [maps.ci_map(Design.similarity_law(H), Grid.square(Design.similarity_law(H).base_centroid, 0.5, 0.01))
             for H in (1.0, 2.0)]
    assert fixed[1].area_gci().value - fixed[0].area_gci().value > 0.1


def test_gci_counts_reachable_nodes_and_says_so():
    """GCI excludes unreachable nodes by default; counting them as CI = 0 scales it by reachable/nodes; both report counts."""
    m = maps.ci_map(FIG5, Grid.square(FIG5.base_centroid, 0.7, 0.01))
    ex, zero = m.gci(), m.gci(unreachable="zero")
    assert ex.nodes == zero.nodes == m.grid.size and ex.counted == ex.reachable == int(m.reachable.sum())
    assert zero.value == pytest.approx(ex.value * ex.reachable / ex.nodes, rel=1e-12)
    assert ex.value == pytest.approx(float(np.nanmean(m.ci)), rel=1e-12)
    area = m.area_gci()
    assert area.nodes == 31 * 31 and 0 < area.reachable < area.nodes  # Fig. 5's area has holes


def test_empty_workspaces_give_explicit_empty_results_never_nan():
    """A design that cannot reach anywhere gives an empty workspace (area 0) and GCI value None; an orientation with an
    empty workspace is masked in an orientation sweep, not NaN."""
    tiny = Design(0.05, 0.05, 0.1, 1.0)
    ws = maps.workspace(tiny)
    assert ws.empty and ws.area == 0.0
    g = maps.ci_map(tiny, Grid.square(tiny.base_centroid, 0.3, 0.01)).gci()
    assert g.empty and g.value is None and g.reachable == 0
    wide = Design(0.3, 0.3, 0.5, 1.0)  # platform vertices point at the base vertices only near Phi = 0
    xs = np.linspace(-0.2, 1.2, 71)
    sw = maps.orientation_sweep(wide, xs, xs, np.radians([0.0, 60.0, 180.0]))
    assert sw.reachable_nodes[0] > 0 and sw.reachable_nodes[2] == 0
    assert sw.gci.mask[2] and not np.any(np.isnan(sw.gci.compressed()))


def test_workspace_matches_the_closed_form_reach_and_orientation_sweep():
    """Reachable nodes are exactly where rrr3.closed_form_ik succeeds (checked on a sub-sample); the 3-D sweep counts agree."""
    P = rrr3.Rrr3Params()
    ws = maps.workspace(P, 0.2)
    assert not ws.touches_edge and 0.2 < ws.area < 0.4  # m^2 (Fig. 3: about 3,000 cm^2)
    rng = np.random.default_rng(3)
    for _ in range(300):
        i, j = rng.integers(0, ws.reachable.shape[0], 2)
        try:
            rrr3.closed_form_ik(P, [ws.grid.xs[j], ws.grid.ys[i], 0.2])
            reach = True
        except UnreachableError:
            reach = False
        assert reach == ws.reachable[i, j]
    g = ws.grid
    sw = maps.orientation_sweep(P, g.xs, g.ys, [0.0, 0.2])
    assert sw.nodes == 2 * g.size and sw.reachable_nodes[1] == ws.nodes
    assert sw.areas[0] > sw.areas[1]  # largest at Phi = 0 (sec. III)


def test_reach_margin_is_positive_exactly_on_the_workspace_and_zero_where_a_leg_stretches():
    """The continuous margin drawn as Fig. 3's boundary: > 0 on reachable nodes, < 0 elsewhere (nodes within 1e-9 m of
    the boundary aside), and 0 where a leg is stretched (the platform vertex at a + b from its base vertex)."""
    P = rrr3.Rrr3Params()
    ws = maps.workspace(P, 0.3)
    margin = maps.reach_margin(P, ws.grid.xs[None, :], ws.grid.ys[:, None], 0.3)
    clear = np.abs(margin) > 1e-9
    assert np.array_equal((margin > 0)[clear], ws.reachable[clear])
    # G such that vertex 1 (at angle phi + _VERTEX_ANGLES[0] from G) lies a + b from the base vertex A1 = (0, 0)
    rc, ang = P.h / math.sqrt(3.0), 0.3 + maps._VERTEX_ANGLES[0]
    v = (P.a + P.b) * np.array([math.cos(math.pi / 6), math.sin(math.pi / 6)])  # (towards the base centroid)
    G = v - rc * np.array([math.cos(ang), math.sin(ang)])
    assert maps.reach_margin(P, G[0], G[1], 0.3) == pytest.approx(0.0, abs=1e-12)


def test_direct_singularity_crossings_separate_the_working_modes():
    """On Fig. 9's design no det J_x sign change lies inside the workspace in mode 1; mode 2 has a singularity curve."""
    d = Design.similarity_law(2.0)
    grid = Grid.square(d.base_centroid, 0.8, 0.02)
    assert maps.direct_singularity_crossings(d, grid, CiSettings(branch=1)) == 0
    assert maps.direct_singularity_crossings(d, grid, CiSettings(branch=2)) > 10


@pytest.mark.parametrize("design", [FIG5, Design(0.30, 0.30, 0.10, 1.00), Design.similarity_law(3.0)],
                         ids=["fig5", "small", "large"])
def test_ci_map_evaluates_inside_its_reach_box_alone_with_the_same_map(design):
    """ci_map evaluates the nodes of its reach box only (_reach_box, a map's cost): the map equals condition_index on
    every node of the grid, to the bit, on a design whose box cuts the grid, a small one (a box of 5 % of the grid) and
    one that fills it; the crossings alike (counted on a whole-grid mask region); a region of another shape is
    refused."""
    grid, st = Grid.square(design.base_centroid, 0.8, 0.02), CiSettings(phi=0.3, branch=2)
    m = maps.ci_map(design, grid, st)
    ci, ok = maps.condition_index(design, grid.xs[None, :], grid.ys[:, None], st)
    np.testing.assert_array_equal(m.reachable, ok)
    np.testing.assert_array_equal(m.ci, ci)
    rows, cols = maps._reach_box(design, grid, st.phi)
    assert ok.any() and ok[rows, cols].sum() == ok.sum()
    full = np.ones(ok.shape, dtype=bool)
    assert maps.direct_singularity_crossings(design, grid, st) == maps.direct_singularity_crossings(design, grid, st,
                                                                                                    full)
    with pytest.raises(InvalidInputError, match="region"):
        maps.direct_singularity_crossings(design, grid, st, full[1:])


def test_sweep_is_the_per_design_maps_with_masked_empties():
    """A small sweep (with its progress bar) equals ci_map per design; the design that cannot reach is masked."""
    designs = tuple(Design(a, b, h, 1.0) for a in (0.2, 0.65) for b in (0.2, 0.65) for h in (0.05, 0.5))
    designs += (Design(0.05, 0.05, 0.1, 1.0),)
    res = maps.sweep(designs, step=0.02, progress=True)
    for k, d in enumerate(designs):
        g = maps.ci_map(d, maps.workspace_grid(d, 0.02)).gci()
        assert (res.gci.mask[k] and g.empty) or res.gci[k] == pytest.approx(g.value, rel=1e-12)
    assert res.gci.count() >= 4
    assert res.gci.mask[-1] and res.area_gci.mask[-1] and res.coverage[-1] == 0.0
    best = res.best(min_coverage=0.0)
    assert best is not None and res.area_gci[best] == res.area_gci.max()


@pytest.mark.parametrize("kwargs", [{"kind": "inf"}, {"kind": "fro"}, {"branch": 9}, {"length": -1.0}, {"reference": "B"},
                                    {"phi": float("nan")}])
def test_bad_settings_are_refused(kwargs):
    """Unknown kinds (the core's unnormalised "fro" has no closed form here), branches, references and non-positive
    L or non-finite Phi raise InvalidInputError."""
    with pytest.raises(InvalidInputError):
        CiSettings(**kwargs)


def test_bad_designs_grids_and_nodes_are_refused():
    """Non-positive lengths, malformed grids and non-finite nodes raise pkm errors."""
    with pytest.raises(InvalidParameterError):
        Design(0.4, -0.4, 0.1, 1.0)
    for args in (((0.0, 0.0), -1, 0.01), ((0.0, 0.0), 3, 0.0), ((0.0,), 3, 0.01), ((0.0, 0.0), 20000, 0.01)):
        with pytest.raises(InvalidInputError):
            Grid(*args)
    with pytest.raises(InvalidInputError):
        maps.condition_index(FIG6, [0.5, float("nan")], [0.3, 0.3])
    with pytest.raises(InvalidInputError):
        maps.ci_map(FIG6, Grid.square(FIG6.base_centroid, 0.1, 0.01)).gci(np.ones((3, 3), bool))
    with pytest.raises(InvalidInputError):
        Design.of("fig6")


# ---------------------------------------------------------------------- the former names (deprecated in 0.2.0)
def test_the_kinds_are_the_cores():
    """The maps' kinds are condition-index kinds of pkm.core.differential.indices (those with a closed form here)."""
    from pkm.core.differential import indices

    assert maps.KINDS == ("2", "fro_normalized") and set(maps.KINDS) <= set(indices.KINDS)


def test_ci_settings_former_mode_and_norm_warn_and_give_the_same_settings():
    """CiSettings(mode=, norm=) are CiSettings(branch=, kind=) with a DeprecationWarning each; .mode, .norm and the
    module's NORMS (now KINDS) warn too; the same map comes out."""
    new = CiSettings(phi=0.1, branch=3, kind="fro_normalized")
    with pytest.warns(DeprecationWarning) as record:
        old = CiSettings(phi=0.1, mode=3, norm="fro_normalized")
    assert old == new
    assert [str(w.message).split(" (")[0] for w in record] == ["CiSettings: 'mode' is now 'branch'",
                                                               "CiSettings: 'norm' is now 'kind'"]
    with pytest.warns(DeprecationWarning, match="'mode' is now 'branch'"):
        assert new.mode == 3
    with pytest.warns(DeprecationWarning, match="'norm' is now 'kind'"):
        assert new.norm == "fro_normalized"
    with pytest.warns(DeprecationWarning, match="'NORMS' is now 'KINDS'"):
        from pkm.mechanisms.rrr3.workspace import NORMS
    assert NORMS == maps.KINDS and "NORMS" not in maps.__all__
    grid = maps.workspace_grid(FIG6, 0.05)
    np.testing.assert_array_equal(maps.ci_map(FIG6, grid, old).ci, maps.ci_map(FIG6, grid, new).ci)


@pytest.mark.parametrize("old, new", [({"norm": "inf"}, {"kind": "inf"}), ({"mode": 9}, {"branch": 9})])
def test_bad_settings_under_the_former_names_are_refused_as_before(old, new):
    with pytest.raises(InvalidInputError) as exc_new:
        CiSettings(**new)
    with pytest.warns(DeprecationWarning), pytest.raises(InvalidInputError) as exc_old:
        CiSettings(**old)
    assert (exc_old.value.name, str(exc_old.value)) == (exc_new.value.name, str(exc_new.value))
    assert exc_old.value.name in ("kind", "branch")
