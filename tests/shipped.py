"""Checks shared by the tests of the third-party robots pkm ships (tests/test_menagerie_robots.py,
tests/test_published_robots.py): licence and source beside the file, the loops closed again from a moved seed, a
transmission's round trip."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

import pkm
from pkm.core.formats.catalogue import CATALOGUE, catalogue_path


def check_shipped(name: str, model_file: str, holder: str, source: tuple[str, ...]) -> str:
    """``name`` is in the catalogue as ``model_file``, its LICENSE names ``holder``, its SOURCE.txt holds every string
    of ``source`` (repository, path, commit), and the file names no mesh; the file's text."""
    path = catalogue_path(name)
    assert path.name == model_file and name in CATALOGUE
    assert holder in (path.parent / "LICENSE").read_text()
    text = (path.parent / "SOURCE.txt").read_text()
    assert all(s in text for s in source), source
    model = path.read_text()
    assert "<mesh" not in model and 'mesh="' not in model
    return model


def check_closes_from_a_moved_seed(mech: pkm.Mechanism, step: float = 0.02) -> None:
    """The loops close again (1e-10) with the motors held (1e-12) from the reference's passive joints moved by up to
    ``step`` [rad or m]."""
    qa = mech.actuated_q(mech.q_reference)
    moved = step * np.random.default_rng(0).uniform(-1.0, 1.0, mech.nv)
    moved[mech.act_v] = 0.0
    fk = pkm.close_loops(mech, qa, pin.integrate(mech.model, mech.q_reference, moved))
    assert fk.residual <= 1e-10 and np.abs(mech.actuated_q(fk.q) - qa).max() <= 1e-12


def check_round_trip(t, offset: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    """Motors ``offset`` from the reference -> outputs -> motors comes back to 1e-10; ``(qm, q_sub)`` there."""
    qm = t.mechanism.actuated_q(t.q_reference) + offset
    qo, q_sub = t.outputs_from_motors(qm)
    back, _ = t.motors_from_outputs(qo, q_sub)
    assert np.abs(back - qm).max() <= 1e-10, t.name
    return qm, q_sub
