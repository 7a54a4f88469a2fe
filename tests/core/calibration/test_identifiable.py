"""Base geometric parameters: the Gough-Stewart's classical count by both routes, and what each model cannot see."""

from __future__ import annotations

import numpy as np
import pytest

from pkm.core.calibration.identifiable import base_geometry
from pkm.core.calibration.measurement import CalibrationModel
from pkm.core.calibration.parameters import calibration_parameters
from pkm.core.calibration.poses import candidates
from tests.core.calibration.conftest import mechanism, model, simulated


def test_gough_stewart_classical_42_by_both_routes() -> None:
    """Six legs x (3 base + 3 platform joint coordinates + 1 leg-length offset) = 42, with the tracker's and the
    target's frames unknown too (12 more): they are absorbed exactly by the base's and the platform's frames (each
    a rigid motion of six), so the count stays 42, by double precision and by the exact route alike. With positions
    only, the target's orientation is invisible: 36 + 6 + 6 + 3 - 12 = 39 (the full run with every origin component
    and the gains, 48 and 45, is tools/calibration_acceptance.py's)."""
    mech = mechanism("gough_stewart")
    joints = [f"u{i}" for i in range(1, 7)] + [f"socket_{i}_fixed" for i in range(1, 7)]
    m = CalibrationModel(mech, "pose", calibration_parameters(mech, "pose", joints=joints, origins="position",
                                                              gains=False))
    assert len(m.names) == 42 + 12
    base = base_geometry(m, candidates(m, 12, spread=0.1), precise=True, precise_poses=9)
    assert len(base) == 42 and base.routes_agree and not base.decision.ambiguous
    # (the tracker's position is absorbed by the base joints', which it shifts alike; each leg's offset is seen)
    assert "tracker.x" in base.absorbed and "tracker.x" in base.names[base.independent.index(m.names.index("u1.x"))]
    assert all(any(n.startswith(f"leg{i}.offset") for n in base.names) for i in range(1, 7))


def test_position_only_sees_three_fewer() -> None:
    mech = mechanism("gough_stewart")
    joints = [f"u{i}" for i in range(1, 7)] + [f"socket_{i}_fixed" for i in range(1, 7)]
    m = CalibrationModel(mech, "position", calibration_parameters(mech, "position", joints=joints,
                                                                  origins="position", gains=False))
    assert len(base_geometry(m, candidates(m, 20, spread=0.1), precise=False)) == 39


def test_what_a_model_cannot_see_is_stated() -> None:
    base = simulated("prs3").cal.base
    assert "knee_1.pitch" in base.unseen  # (a revolute knee's origin turned about its own axis: no effect)
    assert set(base.absorbed) | set(base.unseen) | {base.parameters[k] for k in base.independent} \
        == set(base.parameters)
    with pytest.raises(Exception, match="idle motion"):
        base_geometry(model("gepetto:5bar_linkage"), simulated("gepetto:5bar_linkage").readings, precise=True)
    assert np.allclose(base.map[:, list(base.independent)], np.eye(len(base)))
