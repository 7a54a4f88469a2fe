"""pkm.serve.queries called in process: what the service answers, without a server."""

from __future__ import annotations

import pkm
from pkm.serve import queries


def test_every_entry_of_a_pose_task_value_has_its_unit():
    """The Gough-Stewart's task value is x y z and a quaternion (7 entries): the forward kinematics' ``y`` came with
    the six units of the task's tangent coordinates (roll pitch yaw in rad, qw with none); each entry now has its
    own, the quaternion's unitless, as ``describe`` lists them beside ``task_value_names``."""
    mech = pkm.load("gough_stewart")
    fk = queries.fk(mech, {"qa": mech.actuated_q(mech.q_reference)})
    assert fk["y"].shape == (1, 7) and fk["units"]["y"] == ["m", "m", "m", "1", "1", "1", "1"]
    about = queries.describe(mech)
    assert len(about["task_value_units"]) == len(about["task_value_names"]) == 7
    hexapod = queries.describe(pkm.load("hexapod"))
    assert dict(zip(hexapod["task_value_names"], hexapod["task_value_units"]))["beta_1"] == "rad"
