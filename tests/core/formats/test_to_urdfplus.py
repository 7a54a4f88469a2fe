"""pkm.core.formats.to_urdfplus: a mechanism written as URDF+ (pkm.save to a .urdf) reads back as the same mechanism;
the four-bars of test_urdfplus, Gepetto's 5-bar."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.errors import ImplausibleModelWarning, PkmWarning
from tests.core.formats.test_urdfplus import ANGLES, CONSTRAINT, TREE, loaded, tip


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
