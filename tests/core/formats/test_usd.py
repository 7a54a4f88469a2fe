"""pkm.core.formats.usd and to_usd: USD in and out (usd-core). The round-trip matrix (test_roundtrip.py) has the usd
row (every case to 1e-12, through pkm's double-precision attributes); here: what another reader sees (the standard
single-precision attributes alone), a hand-written four-bar in centimetres, grams and degrees against its closed-form
kinematics and its unit conversions, the serial-equivalent model, and the files refused by name."""

from __future__ import annotations

import json
import math
import sys
import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.kinematics import constraints
from pkm.errors import MissingDependencyError, PkmWarning, SpecError
from tests.core.formats.test_roundtrip import _moved, original

pytest.importorskip("pxr")  # (the usd extra; make test installs it)

FOURBAR = Path(__file__).parents[2] / "data" / "usd_fourbar.usda"
#: The four-bar's lengths in the file [cm]: crank, coupler, rocker, ground.
A, B, C, D = 2.0, 7.0, 5.0, 6.0
#: float32 (UsdPhysics' standard attributes) against float64: relative agreement measured 3.7e-8 (ankle), 8.3e-8
#: (Delta) on M_a; bounded here with margin.
SINGLE = 1e-6


def _closed_state(mech: pkm.Mechanism) -> np.ndarray:
    return pkm.close_loops(mech, mech.actuated_q(mech.q_reference) + 0.05).q


@pytest.mark.parametrize(("case", "suffix"), [("delta", ".usda"), ("humanoid_ankle", ".usdc")])
def test_round_trip_gives_the_same_mass_matrix_closures_actuators_limits(case, suffix, tmp_path):
    """pkm.save then pkm.load (text and binary crate files): M_a at a closed configuration to 1e-9 (measured 1.2e-17,
    0), the closures, the actuated joints and drives, the limits."""
    src = original(case)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PkmWarning)
        dst = pkm.load(pkm.save(src, tmp_path / f"robot{suffix}"))
    q = _closed_state(src)
    qb = _moved(src, dst, q, "q")
    order = [dst.actuated_names.index(n) for n in src.actuated_names]
    Ma, Mb = pkm.mass_matrix(src, q), pkm.mass_matrix(dst, qb)[np.ix_(order, order)]
    assert np.abs(Ma - Mb).max() <= 1e-9 * np.abs(Ma).max()
    assert [(c.name, c.type) for c in dst.spec.closures] == [(c.name, c.type) for c in src.spec.closures]
    assert dst.actuated_names == src.actuated_names  # (pkm:actuated keeps the order)
    assert [dst.actuators[k] for k in order] == list(src.actuators)
    assert dst.limits == src.limits


@pytest.mark.parametrize("case", ["delta", "humanoid_ankle"])
def test_standard_attributes_alone_give_the_mechanism_to_single_precision(case, tmp_path):
    """What Newton or Isaac reads: the file without pkm's attributes reads back with M_a, limits and drives to float32
    (:data:`SINGLE`), the same closures and actuated joints; a note says which bodies are massless (USD: unauthored)."""
    from pxr import Usd

    src = original(case)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PkmWarning)
        path = pkm.save(src, tmp_path / "robot.usda")
    stage = Usd.Stage.Open(str(path))
    removed = 0
    for prim in stage.Traverse():
        for a in prim.GetAuthoredAttributes():
            if a.GetName().startswith("pkm:") and a.GetName() != "pkm:frame":
                prim.RemoveProperty(a.GetName())
                removed += 1
    assert removed > 0
    stage.GetRootLayer().Export(str(tmp_path / "standard.usda"))
    dst = pkm.load(tmp_path / "standard.usda")
    q = _closed_state(src)
    qb = pkm.close_loops(dst, dst.actuated_q(_moved(src, dst, q, "q")), _moved(src, dst, q, "q")).q
    order = [dst.actuated_names.index(n) for n in src.actuated_names]
    Ma, Mb = pkm.mass_matrix(src, q), pkm.mass_matrix(dst, qb)[np.ix_(order, order)]
    assert np.abs(Ma - Mb).max() <= SINGLE * np.abs(Ma).max()
    assert [(c.name, c.type) for c in dst.spec.closures] == [(c.name, c.type) for c in src.spec.closures]
    assert sorted(dst.actuated_names) == sorted(src.actuated_names)
    assert dst.limits.keys() == src.limits.keys()
    for name, (lo, hi) in src.limits.items():
        assert np.allclose(dst.limits[name], (lo, hi), rtol=SINGLE, atol=SINGLE * max(1.0, abs(lo), abs(hi)))
    for a in src.actuators:
        b = dst.actuators[dst.actuated_names.index(a.joint)]
        assert math.isclose(b.reflected_inertia, a.reflected_inertia, rel_tol=SINGLE)
        assert math.isclose(b.viscous, a.viscous, rel_tol=SINGLE)
    light = [src.model.names[j] for j in range(1, src.model.njoints) if src.model.inertias[j].mass == 0.0]
    assert bool(light) == any("no authored mass" in n for n in dst.notes)


def test_fourbar_in_centimetres_grams_and_degrees_reads_in_si():
    """The hand-written four-bar (tests/data/usd_fourbar.usda): its loop joint (a revolute excluded from the
    articulation) is two point closures, its lengths, masses, inertias, limits and drive converted from cm, g and
    degrees (each expected value from the file's literal numbers and the unit factors)."""
    mech = pkm.load(FOURBAR)
    assert [(c.name, c.type) for c in mech.spec.closures] == [("loop", "point"), ("loop_axis", "point")]
    assert mech.actuated_names == ("crank_joint",)
    cm, g = 0.01, 1e-3
    torque = g * cm * cm  # (g cm^2 / s^2 in N m)
    (drive,) = mech.actuators
    assert math.isclose(drive.viscous, 1000 * torque * 180 / math.pi, rel_tol=1e-12)  # (per degree -> per rad)
    assert math.isclose(drive.effort_limit, 2e7 * torque, rel_tol=1e-12)
    assert math.isclose(drive.armature, 300 * torque, rel_tol=1e-12)
    assert drive.stiffness == math.inf  # (stiffness 0: no servo stiffness stated)
    assert mech.limits["crank_joint"] == pytest.approx((-math.pi, math.pi), rel=1e-12)
    assert mech.limits["rocker_joint"] == pytest.approx((0.0, math.radians(150)), rel=1e-12)
    coupler = mech.model.inertias[mech.joints["coupler_joint"].id]
    assert math.isclose(coupler.mass, 70 * g, rel_tol=1e-12)
    assert np.allclose(coupler.lever, [3.5 * cm, 0, 0], rtol=1e-12, atol=0)
    assert np.allclose(np.diag(coupler.inertia), np.array([2, 286, 286]) * g * cm * cm, rtol=1e-7, atol=0)
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, mech.q_reference)
    pin_frame = mech.model.getFrameId("pin")  # (a pkm:frame Xform on the crank, at its tip)
    assert np.allclose(data.oMf[pin_frame].translation,
                       A * cm * np.array([math.cos(math.pi / 3), 0, -math.sin(math.pi / 3)]), atol=1e-9 * cm)


@pytest.mark.parametrize("crank_deg", [40.0, 60.0, 100.0])
def test_fourbar_closes_as_its_closed_form(crank_deg):
    """pkm.close_loops on the USD four-bar against the circle intersection of the coupler's and the rocker's ends,
    in metres (the same branch: the file's pose is the upper one): the rocker angle to 1e-9 rad."""
    mech = pkm.load(FOURBAR)
    th = math.radians(crank_deg)
    q = pkm.close_loops(mech, [th], mech.q_reference).q
    Bp = np.array([A * math.cos(th), A * math.sin(th)])  # (the plane x, -z: a positive angle about y turns x to -z)
    Dp = np.array([D, 0.0])
    d = Dp - Bp
    L = float(np.linalg.norm(d))
    along = (B * B - C * C + L * L) / (2 * L)
    h = math.sqrt(B * B - along * along)
    Cp = Bp + along * d / L + h * np.array([-d[1], d[0]]) / L
    rocker = math.atan2(Cp[1] - Dp[1], Cp[0] - Dp[0])
    assert abs(float(q[mech.joints["rocker_joint"].idx_q]) - rocker) <= 1e-9
    assert np.abs(constraints.residual(mech, q)).max() <= 1e-12


def test_serial_equivalent_is_an_articulation_with_its_transmissions(tmp_path):
    """to_usd.serial_usd: the ankle's serial-equivalent model reads back (pkm's reader) with the same joint-space
    inertia, ΔM's diagonal as each output's armature, to 1e-12; the transmissions' data as the pkm:transmissions
    attribute (JSON: SerialEquivalent.data)."""
    from pxr import Usd

    from pkm.core.formats.to_usd import serial_usd
    from pkm.core.formats.usd import read_usd
    from pkm.core.model.joints import retype_joints
    from pkm.core.model.urdf import load_model

    se = pkm.serial_equivalent(original("humanoid_ankle"), limits=False)
    path = tmp_path / "serial.usda"
    serial_usd(se, path)
    imp = read_usd("", str(path))
    assert imp.actuated == se.outputs and not imp.closures
    model = retype_joints(load_model(imp.urdf, str(path)), imp.joint_types, str(path))
    q = se.q_reference
    M = pin.crba(se.model, se.model.createData(), q)  # (Pinocchio adds the model's armature: se.armature)
    Mb = pin.crba(model, model.createData(), q)
    for out in se.outputs:
        Mb[model.joints[model.getJointId(out)].idx_v, model.joints[model.getJointId(out)].idx_v] += \
            imp.actuators[out]["armature"]
    assert np.abs(np.triu(M) - np.triu(Mb)).max() <= 1e-12 * np.abs(M).max()
    stage = Usd.Stage.Open(str(path))
    assert json.loads(stage.GetDefaultPrim().GetAttribute("pkm:transmissions").Get()) == json.loads(json.dumps(se.data(), default=float))


def _edit(old: str, new: str) -> str:
    text = FOURBAR.read_text()
    assert old in text
    return text.replace(old, new, 1)


@pytest.mark.parametrize(("old", "new", "where"), [
    ('def PhysicsRevoluteJoint "coupler_joint"', 'def PhysicsJoint "coupler_joint"', "/fourbar/coupler_joint"),
    ("rel physics:body1 = </fourbar/rocker>\n        uniform token physics:axis = \"Y\"\n        point3f "
     "physics:localPos0 = (7", "rel physics:body1 = </fourbar/nothing>\n        uniform token physics:axis = \"Y\"\n"
     "        point3f physics:localPos0 = (7", "/fourbar/loop"),
    ("rel physics:body1 = </fourbar/rocker>\n        uniform token physics:axis = \"Y\"\n        point3f "
     "physics:localPos0 = (7", "rel physics:body1 = </fourbar/coupler>\n        uniform token physics:axis = \"Y\"\n"
     "        point3f physics:localPos0 = (7", "/fourbar/loop"),
    ('def PhysicsRevoluteJoint "loop"', 'def PhysicsPrismaticJoint "loop"', "/fourbar/loop"),
    ('quatd xformOp:orient = (0.79', 'float3 xformOp:scale = (2, 2, 2)\n        quatd xformOp:orient = (0.79',
     "/fourbar/rocker"),
    ("#usda 1.0", "#usda 1.0\ndef Xform (", "not a USD stage pkm can open: .*parse error"),
    ('def Xform "rocker" (', 'def Xform "rocker" (\n        references = @/etc/hosts.usda@', "names other files"),
])
def test_bad_files_are_refused_naming_the_prim(old, new, where):
    """A D6 joint, a joint naming a missing prim or one body twice, a prismatic loop joint, a scaled body, malformed
    text, text (an upload) naming a file of the machine: a SpecError naming the prim (or saying what)."""
    from pkm.core.formats.usd import read_usd

    text = _edit(old, new)
    if "xformOp:scale" in new:  # (the scale in the rocker's op order)
        text = text.replace('uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:orient"]\n    }\n\n'
                            '    def PhysicsRevoluteJoint "crank_joint"',
                            'uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:orient", "xformOp:scale"]\n'
                            '    }\n\n    def PhysicsRevoluteJoint "crank_joint"')
    with pytest.raises(SpecError, match=where):
        read_usd(text, "bad.usda")


def test_without_usd_core_the_extra_is_named(monkeypatch):
    """No pxr: pkm.load and pkm.save of USD raise MissingDependencyError naming pip install "pkm-robotics[usd]"."""
    monkeypatch.setitem(sys.modules, "pxr", None)
    with pytest.raises(MissingDependencyError, match=r"pkm-robotics\[usd\]"):
        pkm.load(FOURBAR)
    with pytest.raises(MissingDependencyError, match=r"pkm-robotics\[usd\]"):
        pkm.save(original("delta"), Path("/nonexistent/robot.usda"))
