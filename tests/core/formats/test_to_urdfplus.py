"""pkm.core.formats.to_urdfplus: a mechanism written as URDF+ (pkm.save to a .urdf) reads back as the same mechanism;
the four-bars of test_urdfplus, Gepetto's 5-bar."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.errors import ImplausibleModelWarning, PkmWarning
from tests.core.formats.test_urdfplus import ANGLES, CONSTRAINT, LOOP, TREE, loaded, tip


def test_urdfplus_writer_round_trip(tmp_path):
    """A URDF+ four-bar written back (pkm.save, by suffix) reads as the same mechanism: its revolute loop, actuator
    and FK to 1e-12; a spherical cut (a lone point closure) is written as a pkm extension, and said."""
    mech = loaded("urdfplus")
    with pytest.warns(PkmWarning, match="reference configuration"):
        path = pkm.save(mech, tmp_path / "out.urdf")
    text = path.read_text()
    assert '<loop name="cut" type="revolute">' in text and "cut_predecessor" not in text
    back = pkm.load(path)
    assert [(c.name, c.type) for c in back.spec.closures] == [("cut", "point"), ("cut_axis", "point")]
    assert back.spec.actuated == ("crank_joint",) and back.limits == mech.limits
    for angle in ANGLES:
        X = tip(mech, pkm.close_loops(mech, [angle], tol=1e-13).q)
        Y = tip(back, pkm.close_loops(back, [angle], tol=1e-13).q)
        assert np.linalg.norm(X.translation - Y.translation) < 1e-12
        assert np.linalg.norm(X.rotation - Y.rotation) < 1e-12
    sph = tmp_path / "sph.urdf"
    sph.write_text(TREE.format(extra=CONSTRAINT.replace('name="cut" type="revolute"', 'name="ball" type="spherical"')))
    with pytest.warns(PkmWarning, match=r"point closures \['ball'\] are written as <loop type=\"spherical\">, a pkm ext"):
        out = pkm.save(pkm.load(sph, actuated=["crank_joint"]), tmp_path / "sph_out.urdf")
    assert '<loop name="ball" type="spherical">' in out.read_text()
    assert [(c.name, c.type) for c in pkm.load(out).spec.closures] == [("ball", "point")]


def test_gepetto_five_bar_written_as_urdfplus_keeps_its_frame_closure(tmp_path):
    """Gepetto's 5-bar (a 6-D closure) written as URDF+ (a fixed <loop>) and read back: the same joints, and at the
    original's closed reference the loop holds (1e-12) and every shared frame is in place (1e-12)."""
    from pkm.core.kinematics.constraints import residual
    from tests.test_gepetto_robots import gepetto

    with warnings.catch_warnings():  # (the file's own masses, pinned below on the written file)
        warnings.simplefilter("ignore", ImplausibleModelWarning)
        mech = gepetto("5bar_linkage")
    with pytest.warns(PkmWarning):
        path = pkm.save(mech, tmp_path / "five.urdf", to="urdfplus")
    assert 'type="fixed">' in path.read_text()
    with pytest.warns(ImplausibleModelWarning, match="'sphere' 654498 kg"):  # (as the original: its masses kept)
        back = pkm.load(path, actuated=list(mech.spec.actuated))
    assert list(back.model.names) == list(mech.model.names) and [c.type for c in back.spec.closures] == ["frame"]
    q = mech.q_reference
    assert np.max(np.abs(residual(back, q))) < 1e-12
    pin.framesForwardKinematics(mech.model, mech.data, q)
    pin.framesForwardKinematics(back.model, back.data, q)
    shared = {f.name for f in back.model.frames} & {f.name for f in mech.model.frames}
    assert len(shared) > 5
    for name in shared:
        X, Y = mech.data.oMf[mech.frame_id(name)], back.data.oMf[back.frame_id(name)]
        assert np.linalg.norm(X.homogeneous - Y.homogeneous) < 1e-12, name


def test_the_springs_are_written_with_gazebo_s_urdf_extension_and_read_back(tmp_path):
    """URDF+ has no spring: the writer uses Gazebo's ``<gazebo reference><springStiffness><springReference>``, the
    damping URDF's ``<dynamics damping>``; pkm.load gives back the springs (1e-12) and the joints' damping (1e-15);
    a spring on a continuous joint is refused by name, a ``<gazebo>`` naming a link states none."""
    from tests.core.formats.test_to_sdf import _sprung_delta

    mech = _sprung_delta()
    with pytest.warns(PkmWarning):
        path = pkm.save(mech, tmp_path / "delta.urdf")
    text = path.read_text()
    assert text.count("<springStiffness>") == 2
    back = pkm.load(path)
    assert back.springs.names == mech.springs.names
    assert np.abs(back.springs.stiffness - mech.springs.stiffness).max() <= 1e-12
    assert np.abs(back.springs.rest - mech.springs.rest).max() <= 1e-12
    for name in ("knee_1", "knee_2_b", "motor_2"):
        assert abs(back.model.damping[back.joints[name].idx_v] - mech.model.damping[mech.joints[name].idx_v]) <= 1e-15
    spring = "<gazebo reference='{0}'><springStiffness>2.0</springStiffness></gazebo>"
    link = tmp_path / "link.urdf"
    link.write_text(TREE.format(extra=LOOP + spring.format("crank")))
    assert not pkm.load(link).springs
    bad = tmp_path / "bad.urdf"
    bad.write_text(TREE.format(extra=LOOP + spring.format("coupler_joint")))
    with pytest.raises(pkm.errors.SpecError, match="a spring on a continuous joint"):
        pkm.load(bad)
