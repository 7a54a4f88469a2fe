"""pkm.sweeps.family: what a sweep varies. A registered family's parameters are its design's scalar fields with
their units, fixed values are read with units and kept, designs are built from the values (integers checked), the
family describes, pickles and rebuilds itself; a loaded mechanism's family varies its URDF joint origins.
(Sweeping a loaded mechanism end to end is ``tests/sweeps/test_objectives.py``.)"""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import pkm
from pkm import sweeps
from pkm.core.kinematics import constraints
from pkm.core.model.urdf import parse_xml
from pkm.errors import InvalidInputError, InvalidParameterError, UnknownNameError
from pkm.mechanisms.rrr3 import Rrr3Params
from pkm.sweeps.family import Candidate, ModelFamily, RegisteredFamily, family_of, from_description, origins_set


def test_a_registered_family_s_parameters_are_the_scalar_fields_with_their_units():
    """The 3-RRR's: its lengths [m], masses [kg], branch (an integer, no unit) and collision sizes [m]; not home (a
    tuple); an unknown name or a tuple field is refused listing the parameters."""
    fam = RegisteredFamily("rrr3")
    assert fam.parameters() == ("a", "b", "h", "H", "branch", "m_proximal", "m_distal", "m_platform", "link_radius",
                                "platform_thickness")
    assert fam.units("a") == ({"length"}, "m") and fam.units("m_distal") == ({"mass"}, "kg")
    assert fam.units("link_radius") == ({"length"}, "m")
    assert fam.units("branch") == ({None}, "-") and fam.integer("branch") and not fam.integer("a")
    for bad in ("home", "c"):
        with pytest.raises(UnknownNameError, match="'a', 'b', 'h', 'H', 'branch'") as info:
            fam.units(bad)
        assert info.value.kind == "parameter"


def test_designs_are_the_fixed_design_with_the_values_and_integers_are_checked():
    """Fixed values (with units) are kept in every design; a swept value replaces its field; branch 3.0 is the
    integer 3, branch 2.5 refused; a value the design refuses fails where the design is made."""
    fam = RegisteredFamily("rrr3", {"H": "90cm", "home": (0.0, 0.0, 0.0)})
    assert fam.fixed == {"H": 0.9, "home": (0.0, 0.0, 0.0)} and fam.registered == "rrr3"
    p = fam.params({"a": 0.5, "branch": 3.0})
    assert p == Rrr3Params(a=0.5, H=0.9, branch=3, home=(0.0, 0.0, 0.0)) and type(p.branch) is int
    with pytest.raises(InvalidInputError, match="branch takes integers"):
        fam.params({"branch": 2.5})
    with pytest.raises(InvalidParameterError, match=r"^a: "):
        fam.params({"a": -0.1})


def test_a_candidate_makes_each_thing_once():
    """cached(key, make) calls make once per key; params is cached; mechanism builds the candidate's design."""
    c = RegisteredFamily("rrr3").candidate({"a": 0.45})
    calls = []
    assert c.cached("k", lambda: calls.append(1) or 7) == 7 and c.cached("k", lambda: calls.append(1) or 8) == 7
    assert calls == [1] and c.params is c.params and c.params.a == 0.45 and isinstance(c, Candidate)
    assert c.mechanism.params == c.params and c.mechanism is c.mechanism


def test_a_registered_family_describes_pickles_and_rebuilds_itself():
    """describe() is JSON-able (tuples as lists) and from_description gives the same designs; pickling goes through
    the name and the fixed values (the module itself does not pickle)."""
    fam = RegisteredFamily("delta", {"R": "12cm", "home": (0.0, 0.0, -0.36)})
    desc = fam.describe()
    assert desc == {"registered": "delta", "fixed": {"R": 0.12, "home": [0.0, 0.0, -0.36]}}
    for again in (from_description(desc), pickle.loads(pickle.dumps(fam))):
        assert again.params({"La": 0.1}) == fam.params({"La": 0.1}) and again.describe() == desc


def test_family_of_takes_names_mechanisms_families_and_refuses_misplaced_fixed_values(built):
    """A registered name gives its RegisteredFamily, a family itself, a Mechanism its ModelFamily; fixed values must
    be a mapping and are for registered mechanisms only."""
    fam = family_of("delta")
    assert isinstance(fam, RegisteredFamily) and family_of(fam) is fam
    assert isinstance(family_of(built("delta")), ModelFamily)
    with pytest.raises(InvalidInputError, match=r"expected \{parameter: value\}"):
        family_of("delta", [("R", 0.1)])
    with pytest.raises(InvalidInputError, match="for registered mechanisms"):
        family_of(built("delta"), {"R": 0.1})
    with pytest.raises(UnknownNameError):
        RegisteredFamily("dleta")


def test_origins_set_writes_the_named_components_and_refuses_unknown_joints():
    """JOINT.y sets the second number of the joint's xyz, JOINT.yaw the third of its rpy (created when the joint has
    none), the others kept; an unknown joint or component lists the valid parameters."""
    urdf = pkm.load("delta").urdf
    text = origins_set(urdf, {"motor_1.y": 0.2, "knee_1_b.yaw": 0.5})
    joints = {j.get("name"): j for j in parse_xml(text).iter("joint")}
    before = {j.get("name"): j for j in parse_xml(urdf).iter("joint")}
    xyz = [float(v) for v in joints["motor_1"].find("origin").get("xyz").split()]
    old = [float(v) for v in before["motor_1"].find("origin").get("xyz").split()]
    assert xyz[1] == 0.2 and (xyz[0], xyz[2]) == (old[0], old[2])
    assert [float(v) for v in joints["knee_1_b"].find("origin").get("rpy").split()][2] == 0.5
    for bad in ("motor_9.x", "motor_1.w", "motor_1"):
        with pytest.raises(UnknownNameError) as info:
            origins_set(urdf, {bad: 0.1})
        assert info.value.name == bad and "motor_1.x" in info.value.valid and "knee_1_b.yaw" in info.value.valid


def test_a_model_family_varies_joint_origins_and_pickles_without_its_mechanism(built):
    """Six parameters a URDF joint ([m] for x y z, [rad] for roll pitch yaw) and ten a body (its inertial
    parameters: kg, kg m, kg m^2); no values: the loaded mechanism itself; pickled: the texts only, rebuilt from
    them; its description fingerprints the files."""
    mech = pkm.load("rrr3")
    fam = ModelFamily(mech)
    assert len(fam.parameters()) == 6 * len(fam.joint_names) + 10 * (mech.model.njoints - 1)
    assert {"motor_1.x", "platform.m", "platform.Izz"} <= set(fam.parameters())
    assert fam.units("motor_1.z") == ({"length"}, "m") and fam.units("motor_1.roll") == ({"angle"}, "rad")
    assert fam.units("platform.m") == ({"mass"}, "kg") and fam.units("platform.Ixy")[1] == "kg m^2"
    with pytest.raises(UnknownNameError):
        fam.units("motor_1.w")
    assert fam.mechanism({}) is mech and fam.params({}) is None and fam.registered is None
    again = pickle.loads(pickle.dumps(fam))
    assert again._base is None and again.describe() == fam.describe()
    same = again.mechanism({"motor_2.x": 1.0})  # (the file's own value: the loops stay closed)
    assert same.model.jointPlacements[same.model.getJointId("motor_2")].translation[0] == 1.0
    with pytest.raises(InvalidInputError, match="give it"):
        from_description(fam.describe())
    with pytest.raises(InvalidInputError, match="not the ones the sweep varied"):
        from_description(fam.describe(), built("delta"))


def test_a_moved_joint_origin_gives_a_closed_mechanism():
    """The Delta's files with motor 1 moved 1 cm inwards: a mechanism whose loops close (1e-9) with that origin."""
    fam = ModelFamily(pkm.load("delta"))
    mech = fam.mechanism({"motor_1.y": 0.14})
    assert mech.model.jointPlacements[mech.model.getJointId("motor_1")].translation[1] == pytest.approx(0.14, abs=1e-15)
    assert abs(constraints.residual(mech, mech.q_reference)).max() < 1e-9


def test_designs_share_one_twin_with_design_inputs_and_score_as_their_own_twins():
    """The 3-RRR's a, b, h move elbow, tip and platform-vertex origins and the links' inertias: the family's kernels
    take those as inputs (found by moving each field), and two designs' generic GCI maps through them equal the maps
    through each design's own compiled twin (``parametric=False``) to 1e-12."""
    fam = RegisteredFamily("rrr3")
    varied = fam.varied(("a", "b", "h"))
    assert {"elbow_1.x", "leg2_tip_fixed.x", "platform_C_fixed.y", "proximal_1.mx"} <= set(varied)
    assert "motor_2.x" not in varied  # (the base triangle is H's)
    spec = "gci:route=generic,region=x=0.3:0.7:9/y=0.1:0.5:9,pose=yaw=0,length=0.1"
    space = sweeps.table([{"a": 0.35, "b": 0.45, "h": 0.12}, {"a": 0.5, "b": 0.3, "h": 0.2}])
    shared = pkm.sweep(fam, space, [spec], scheduler="serial").table.column(spec).to_pylist()
    own = pkm.sweep(RegisteredFamily("rrr3", parametric=False), space, [spec], scheduler="serial")
    assert None not in shared
    assert np.allclose(shared, own.table.column(spec).to_pylist(), rtol=1e-12, atol=0)
    candidate = fam.candidate({"a": 0.35, "b": 0.45, "h": 0.12})
    assert candidate.kernels.design_values.size == len(varied)


def test_a_loaded_mechanism_changed_in_memory_is_refused_and_the_shared_twin_is_the_files():
    """A sweep builds its designs from the files: a model whose inertias were set in memory is refused (naming
    them); the family kernels of the files are not another family's of the same texts."""
    import pinocchio as pin

    mech = pkm.load("rrr3")
    changed = pkm.load("rrr3")
    changed.model.inertias[1] = pin.Inertia.FromDynamicParameters(
        changed.model.inertias[1].toDynamicParameters() * 2.0)
    with pytest.raises(InvalidInputError, match=r"proximal_1\.I"):
        ModelFamily(changed)
    fam = ModelFamily(mech)
    assert fam.kernels(("platform.m",)).design.base[0] == pytest.approx(0.1)


def test_a_design_that_moves_a_number_the_inputs_do_not_hold_gets_its_own_kernels(monkeypatch):
    """Were the varied inputs to miss one number a design moves (an elbow origin, here taken out of them), the
    shared twin would keep the base's: that design gets its own kernels instead; with every moved number it gets
    the shared twin, bound to its values."""
    fam = RegisteredFamily("rrr3")
    full = fam.varied(("a",))
    design = fam.candidate({"a": 0.45})
    assert design.kernels.design.names == full and design.kernels.design_values[full.index("elbow_1.x")] == 0.45
    monkeypatch.setattr(fam, "varied", lambda parameters: tuple(n for n in full if n != "elbow_1.x"))
    assert len(fam.candidate({"a": 0.45}).kernels.design) == 0
