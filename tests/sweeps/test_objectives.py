"""Objectives (pkm.sweeps.objectives): the papers' studies through pkm.sweep equal the serial ones; the generic
routes agree with the closed forms; loaded mechanisms vary their joint origins; user callables; bad specs; the closed
forms are the mechanisms' own, found through the registry."""

from __future__ import annotations

import ast
import dataclasses
import math
import re
from pathlib import Path

import numpy as np
import pytest

import pkm
from pkm import sweeps
from pkm.errors import InvalidInputError, UnknownNameError
from pkm.mechanisms import REGISTRY, register
from pkm.mechanisms.delta import design
from pkm.mechanisms.rrr3 import workspace as maps
from pkm.papers import delta as delta_paper
from pkm.papers import rrr3 as rrr3_paper
from pkm.sweeps.objectives import OBJECTIVES, ClosedForm, closed_forms


def test_the_delta_radius_study_through_the_sweep_equals_the_serial_study():
    """Volumes (8 mm grid) and K(R) at the study pose, at two radii (6 and 19 cm): bit for bit the serial study's and
    Fig. 5's curves."""
    R = delta_paper.R_STUDY[[2, 24]]
    res = delta_paper.radius_sweep(R, scheduler="serial")
    study = design.workspace_vs_radius(delta_paper.PAPER, R, kind="2", spacing=delta_paper.SPACING)
    np.testing.assert_array_equal(res.column("volume"), study.volume)
    np.testing.assert_array_equal(res.column("volume_K3"), study.conditioned_volume(delta_paper.K_MAX))
    np.testing.assert_array_equal(res.column("weighted"), study.weighted_volume())
    K = design.condition_vs_radius(delta_paper.PAPER, delta_paper.POSE, R, "knee_out", ("2", "fro"))
    np.testing.assert_array_equal(res.column("K_2"), K["2"])
    np.testing.assert_array_equal(res.column("K_fro"), K["fro"])


def test_the_rrr3_paper_route_is_the_serial_loop():
    """The paper's route on 4^3 of its designs (the grid's corners and inner points; the 1,000: the report's rows)
    equals the serial loop's columns bit for bit, the designs where a column has no value included."""
    res = rrr3_paper.design_sweep(step=0.04, scheduler="serial", n=4)
    loop = maps.sweep(rrr3_paper.paper_sweep_designs(n=4), step=0.04, progress=False)
    assert len(res.designs) == 64 and all(np.ma.count_masked(a) for a in (res.gci, loop.gci))
    for a, b in zip((res.gci, res.area_gci, res.coverage, res.min_area_ci),
                    (loop.gci, loop.area_gci, loop.coverage, loop.min_area_ci)):
        np.testing.assert_array_equal(np.ma.filled(a, np.nan), np.ma.filled(b, np.nan))


def test_the_generic_condition_number_agrees_with_the_delta_closed_form():
    """kappa_2 and kappa_F of the inverse Jacobian at a pose off the axis, generic (solve_ik, inverse_jacobian)
    against the closed form (the paper's eq. 12 Jacobians), over three base radii."""
    pose = "pose=x=2cm/y=-1cm/z=-36cm"
    res = pkm.sweep("delta", sweeps.grid(R="12cm:18cm:3"), [f"c2=condition:{pose}", f"g2=condition:{pose},route=generic",
                                                             f"cf=condition:{pose},kind=fro",
                                                             f"gf=condition:{pose},kind=fro,route=generic"],
                    scheduler="serial")
    assert res.ok.all()
    np.testing.assert_allclose(res.column("g2"), res.column("c2"), rtol=1e-9)
    np.testing.assert_allclose(res.column("gf"), res.column("cf"), rtol=1e-9)
    assert len(set(np.round(res.column("c2"), 6))) == 3


def test_the_generic_reachable_interval_agrees_with_the_hexapod_closed_form():
    """beta's reachable length at the reference pose: a 1-degree scan of the compiled map against the exact
    intervals (within half a scan step: each gap between two reachable nodes counts; nodes times the step overstated
    each reachable run by a step, 2.3737 against 2.3575 rad at the paper's design)."""
    res = pkm.sweep("hexapod", sweeps.table({"h": [0.034]}),
                    ["reachable_interval", "scan=reachable_interval:route=generic,parameter=beta_1,"
                                           "range=-90deg:90deg:181", "beta_gain"], scheduler="serial")
    assert res.ok.all(), res.failures()
    exact, scan = res.column("reachable_interval")[0], res.column("scan")[0]
    assert 1.0 < exact <= math.pi and abs(scan - exact) <= 0.5 * math.radians(1.0)
    assert res.column("beta_gain")[0] > 0.0  # beta* beats the reference beta (0)


def test_a_loaded_mechanism_sweeps_its_joint_origins():
    """pkm's delta files as a user's own mechanism: motor_1's origin y [m] varied (one motor moved: a design no
    generator makes); at the file's own value the objective is that of the mechanism as loaded."""
    mech = pkm.load("delta")
    res = pkm.sweep(mech, sweeps.grid(**{"motor_1.y": "13cm:15cm:3"}), ["condition"], scheduler="serial")
    assert res.manifest["family"]["source"] == mech.source and res.manifest["units"] == {"motor_1.y": "m"}
    K = res.column("condition")
    unchanged = pkm.sweep(mech, sweeps.table({"motor_1.y": [0.15]}), ["condition"], scheduler="serial")
    assert np.all(np.isfinite(K)) and res.stats.failed == 0  # (every design builds: its loops re-assembled)
    assert K[2] == unchanged.column("condition")[0] and len(set(K)) == 3
    closed = pkm.sweep("delta", sweeps.table({"R": [0.15]}), ["condition"], scheduler="serial")
    np.testing.assert_allclose(K[2], closed.column("condition")[0], rtol=1e-9)
    with pytest.raises(UnknownNameError, match=r"motor_1\.w"):
        pkm.sweep(mech, sweeps.grid(**{"motor_1.w": [0.1]}), ["condition"], scheduler="serial")


def test_the_capability_of_a_loaded_mechanism_s_designs_through_the_shared_twin():
    """The acceptance-set Gough-Stewart with its six base joints moved (tests/core/twin/test_design.py's design: its
    shared and own twins compiled once for both tests): the capability objective (the smallest isotropic force and
    the mean isotropic moment its 1000 N legs give over a 6 x 6 map) through the family's shared twin equals
    :func:`map_capability` on the design's own mechanism and kernels to 1e-12, the stiffness objective (1e6 N/m
    legs) :func:`stiffness_map`'s smallest to 1e-9; a unit group the task has not is refused, naming those it has."""
    from pkm.core.analysis.capability import map_capability
    from tests.core.twin.test_design import moved_design
    from tests.core.twin.test_tree import FILES

    mech = pkm.load(FILES["gough_stewart"])
    region = "region=x=-0.1:0.1:6/y=-0.1:0.1:6,length=0.5"
    values = moved_design(mech)
    res = pkm.sweep(mech, sweeps.table([values]), [f"f=capability:{region}",
                                                   f"m=capability:{region},unit=N m,stat=mean",
                                                   f"k=stiffness:{region},drives=1e6"], scheduler="serial")
    design = sweeps.family_of(mech).mechanism(values)
    wmap = pkm.workspace_map(design, {"x": np.linspace(-0.1, 0.1, 6), "y": np.linspace(-0.1, 0.1, 6)},
                             length=0.5, configurations=True)
    cap = map_capability(design, wmap)
    assert cap.reachable.sum() == 36
    np.testing.assert_allclose(res.column("f")[0], cap.isotropic["N"][cap.reachable].min(), rtol=1e-12)
    np.testing.assert_allclose(res.column("m")[0], cap.isotropic["N m"][cap.reachable].mean(), rtol=1e-12)
    from pkm.core.compliance.maps import stiffness_map  # (the stiffness objective: its map's smallest, 1e6 N/m legs)

    legs = stiffness_map(design, wmap, joints=dict.fromkeys(design.actuated_names, 1e6))
    np.testing.assert_allclose(res.column("k")[0], legs.force_min[legs.reachable].min(), rtol=1e-9)
    bad = pkm.sweep(mech, sweeps.table([values]), [f"capability:{region},unit=kg"], scheduler="serial")
    assert bad.stats.failed == 1 and "N m" in bad.table.column("message")[0].as_py()


def test_user_callables_their_nulls_and_their_failures():
    def triangle(design):
        h = design.values["h"]
        return None if h > 0.15 else 3**0.5 / 4 * h**2

    def text(design):
        return "large"

    res = pkm.sweep("rrr3", sweeps.grid(h="10cm:20cm:3"), [sweeps.objective(triangle, sense="min"), text],
                    scheduler="serial")
    area = res.column("triangle")
    assert area[0] == pytest.approx(3**0.5 / 4 * 0.01, rel=1e-15) and np.isnan(area[2])
    assert not res.ok.any() and {f["error"] for f in res.failures()} == {"InvalidInputError"}
    assert res.objectives["triangle"]["sense"] == "min" and res.best("triangle", 1)[0]["design"] == 0


@pytest.mark.parametrize("objectives,error,match", [
    (["gcii"], UnknownNameError, "gcii"),
    (["gci:stp=1cm"], UnknownNameError, "stp"),
    (["gci:step=3deg"], InvalidInputError, "deg"),
    (["beta_gain"], InvalidInputError, "beta_gain has no route for rrr3"),
    (["workspace_volume:route=closed_form", "x=gci"], InvalidInputError, "no closed form"),
    (["gci", "gci"], InvalidInputError, "named twice"),
    (["gci:kind=fro"], InvalidInputError, "fro_normalized"),
    (["operation_count:count=bogus"], InvalidInputError, "total"),
    (["peak_effort:samples=-1"], InvalidInputError, "samples"),
    (["gci:region=x=0:1:\u00b2"], InvalidInputError, "COUNT"),
])
def test_bad_objectives_are_refused_before_any_design_is_evaluated(objectives, error, match):
    space = sweeps.grid(h="10cm:20cm:3")
    mech = "prs3" if "closed_form" in objectives[0] else "rrr3"
    with pytest.raises(error, match=match):
        pkm.sweep(mech, space if mech == "rrr3" else sweeps.grid(h=[0.1]), objectives, scheduler="serial")


def test_the_3rrr_closed_form_maps_the_designs_working_mode():
    """branch is a design field: each design's map is of its own working mode (or of the option's)."""
    res = pkm.sweep("rrr3", sweeps.grid(branch=[1, 2]), ["gci:step=4cm", "m3=gci:step=4cm,branch=mode3"],
                    scheduler="serial")
    d = maps.Design.of(pkm.design_params("rrr3"))
    direct = [maps.ci_map(d, maps.workspace_grid(d, 0.04), maps.CiSettings(branch=m)).gci().value for m in (1, 2, 3)]
    np.testing.assert_array_equal(res.column("gci:step=4cm"), direct[:2])
    np.testing.assert_array_equal(res.column("m3"), [direct[2]] * 2)
    assert direct[0] != direct[1]


@pytest.mark.parametrize("call,match", [
    (lambda: pkm.sweep("rrr3", sweeps.sobol(4, branch="1:8"), ["gci"], scheduler="serial"), "integers"),
    (lambda: pkm.sweep("rrr3", sweeps.grid(a=[0.4]), ["gci"], fixed={"a": 0.5}, scheduler="serial"), "swept and"),
    (lambda: pkm.sweep("rrr3", sweeps.grid(a=[0.4]), ["gci"], workers=2, scheduler="serial"), "workers"),
    (lambda: pkm.sweep("rrr3", sweeps.grid(a=[0.4]), ["gci"], chunk_size=0, scheduler="serial"), "chunk_size"),
])
def test_conflicting_arguments_are_refused(call, match):
    with pytest.raises(InvalidInputError, match=match):
        call()


# ---------------------------------------------------------------------- the fast paths belong to the mechanisms
def _code_names(path: Path) -> set[str]:
    """Identifiers, imported modules and string constants of a module's code (docstrings and comments left out:
    a usage example may name a mechanism)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docs = {id(n.body[0].value) for n in ast.walk(tree)
            if isinstance(n, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and n.body
            and isinstance(n.body[0], ast.Expr) and isinstance(n.body[0].value, ast.Constant)}
    out: set[str] = set()
    for n in ast.walk(tree):
        if isinstance(n, ast.Name):
            out.add(n.id)
        elif isinstance(n, ast.Attribute):
            out.add(n.attr)
        elif isinstance(n, (ast.FunctionDef, ast.ClassDef, ast.AsyncFunctionDef)):
            out.add(n.name)
        elif isinstance(n, ast.alias):
            out.update((n.name, n.asname or ""))
        elif isinstance(n, ast.ImportFrom) and n.module:
            out.add(n.module)
        elif isinstance(n, ast.Constant) and isinstance(n.value, str) and id(n) not in docs:
            out.add(n.value)
    return out


def test_the_sweeps_package_names_no_mechanism():
    """The closed forms are found through the registry (each entry's ``sweeps``): no code of ``pkm/sweeps`` names a
    registered mechanism (in a name, an import or a string), so that adding one touches no other package."""
    folder = Path(sweeps.__file__).parent
    hits = {}
    for path in sorted(folder.glob("*.py")):
        words = {w for text in _code_names(path) for w in re.findall(r"[A-Za-z0-9]+", text.lower())}
        named = sorted(n for n in REGISTRY if set(n.lower().split("_")) <= words and (n.lower() in words or "_" in n))
        if named:
            hits[path.name] = named
    assert len(list(folder.glob("*.py"))) >= 7 and not hits, hits


def test_the_scan_sees_a_mechanism_named_in_code(tmp_path):
    (tmp_path / "m.py").write_text('"""rrr3 in a docstring"""\nfrom pkm.mechanisms.delta import design\n'
                                   'def f():\n    """hexapod"""\n    return OBJ.get("prs3")\n')
    words = {w for text in _code_names(tmp_path / "m.py") for w in re.findall(r"[A-Za-z0-9]+", text.lower())}
    assert {"delta", "prs3"} <= words and not {"rrr3", "hexapod"} & words


def _toy_gci(c, o):
    """The toy's closed form of gci: its link length d times an option of its own."""
    return o["toy_scale"] * c.params.d


#: A closed form of the tests' five-bar (this module is its ``sweeps`` module while the test runs).
CLOSED_FORMS = {"gci": ClosedForm(_toy_gci, {"toy_scale": ("float", 2.0, "toy: the factor")}, "m")}


def test_a_registered_mechanism_brings_its_own_fast_path():
    """The five-bar registered again with this module as its ``sweeps``: gci takes its closed form (and its option,
    and its unit), the other objectives and mechanisms do not see it; unregistered, the generic route is back."""
    plain = REGISTRY["fivebar"]
    register(dataclasses.replace(plain, sweeps=__name__), replace=True)
    try:
        assert set(closed_forms("gci")) == {"rrr3", "fivebar"} and "toy_scale" in OBJECTIVES["gci"].options
        assert "toy_scale" not in OBJECTIVES["gci_area"].options
        res = pkm.sweep("fivebar", sweeps.table({"d": [0.2, 0.25]}), ["gci", "g3=gci:toy_scale=3"], scheduler="serial")
        np.testing.assert_allclose(res.column("gci"), [0.4, 0.5], rtol=1e-15)
        np.testing.assert_allclose(res.column("g3"), [0.6, 0.75], rtol=1e-15)
        assert res.objectives["gci"]["unit"] == "m"
        with pytest.raises(InvalidInputError, match="no closed form for fivebar"):
            pkm.sweep("fivebar", sweeps.table({"d": [0.2]}), ["gci_area:route=closed_form"], scheduler="serial")
    finally:
        register(plain, replace=True)
    assert set(closed_forms("gci")) == {"rrr3"} and "toy_scale" not in OBJECTIVES["gci"].options
    with pytest.raises(UnknownNameError, match="toy_scale"):
        sweeps.objective("gci:toy_scale=3")


def test_a_design_that_does_not_follow_the_motion_fails_saying_where(tmp_path):
    """The 3-PRS tilting at 3 rad/s for 1 s leaves its workspace at sample 9 of 21: its peak effort and power were
    blank (NaN efforts read as None) with the status "ok"; the design now fails, naming the first jump."""
    motion = tmp_path / "tilt.toml"
    motion.write_text('format = "pkm.motion/1"\nmechanism = "prs3"\ncoordinates = ["z", "pitch", "roll"]\n'
                      '[case.up]\nduration = 1.0\ndt = 0.05\nz = { law = "constant", value = 0.81 }\n'
                      'pitch = { law = "linear", start = 0.0, rate = 3.0 }\nroll = { law = "constant", value = 0.0 }\n')
    res = pkm.sweep("prs3", sweeps.grid(l=[1.0]), [f"peak_effort:file={motion},motion=up"], scheduler="serial")
    (failure,) = res.failures()
    assert not res.ok.any() and "does not follow motion 'up': at sample 9 of 21, did not converge" in failure["message"]


def test_the_condition_of_a_mixed_task_defaults_to_each_designs_characteristic_length():
    """The 3-RRR (task x, y, yaw) swept over its proximal length ``a`` without ``length``: each design's condition
    number is the one with that design's own characteristic length given (so a design's scale changes it as its
    geometry does, not by an absolute length)."""
    res = pkm.sweep("rrr3", sweeps.table({"a": [0.36, 0.44]}), ["condition"], scheduler="serial")
    assert res.stats.failed == 0
    for a, kappa in zip((0.36, 0.44), res.column("condition")):
        L = pkm.build("rrr3", a=a).characteristic_length
        given = pkm.sweep("rrr3", sweeps.table({"a": [a]}), [f"condition=condition:length={L!r}"], scheduler="serial")
        assert kappa == given.column("condition")[0] and math.isfinite(kappa)
