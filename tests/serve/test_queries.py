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


def test_positions_take_units_and_a_configuration_q_or_qa():
    """``"10deg"`` and ``"-35cm"`` are the SI numbers (pkm.units); a unit of the wrong kind is refused naming the entry;
    the Jacobians at ``qa`` are those at the configuration the FK closes; q and qa together, or neither, are refused
    naming both."""
    import numpy as np
    import pytest

    from pkm.errors import InvalidInputError, UnitError

    mech = pkm.load("delta")
    qa = mech.actuated_q(mech.q_reference)
    plain = queries.fk(mech, {"qa": [np.deg2rad(-30.0), qa[1], qa[2]]})
    with_unit = queries.fk(mech, {"qa": ["-30deg", qa[1], qa[2]]})
    assert np.abs(with_unit["q"] - plain["q"]).max() <= 1e-14 and with_unit["iterations"].dtype.kind == "i"
    ik = queries.ik(mech, {"y": [0.0, "0mm", "-35cm"]})
    assert np.abs(ik["q"] - queries.ik(mech, {"y": [0.0, 0.0, -0.35]})["q"]).max() <= 1e-12
    with pytest.raises(UnitError, match=r"qa\[1\]"):
        queries.fk(mech, {"qa": [0.0, "3mm", 0.0]})
    with pytest.raises(InvalidInputError, match="positions"):  # (no unit suffix for a rate: said, not numpy's words)
        queries.velocities(mech, {"qa": qa, "qd": ["1deg", 0.0, 0.0]})
    at_qa = queries.jacobians(mech, {"qa": [qa, qa + 0.01]})
    at_q = queries.jacobians(mech, {"q": queries.fk(mech, {"qa": [qa, qa + 0.01]})["q"]})
    assert np.abs(at_qa["J"] - at_q["J"]).max() <= 1e-12 and at_qa["units"]["J"][0][0] == "m/rad"
    for body in ({"q": mech.q_reference, "qa": qa}, {}):
        with pytest.raises(InvalidInputError, match="q, qa"):
            queries.dynamics(mech, body)


def test_a_sample_outside_the_limits_is_not_ok_in_every_query():
    """The humanoid ankle at pitch 0.8 rad (range +-0.6; the motors then 1.047 and 1.032 rad, range +-1): ik and fk
    answer status outside_limits with the joints named, their values those of the answer's own q; the queries at a
    configuration (jacobians) and a stream's sample say the same; a failed sample has none (null), a sample inside
    them is ok."""
    import numpy as np

    from tests.test_humanoid import EXAMPLES

    mech = pkm.load(EXAMPLES / "humanoid_ankle" / "ankle.closures.toml")
    ik = queries.ik(mech, {"y": [0.8, 0.0]})
    assert ik["status"] == ["outside_limits"] and ik["units"]["outside_limits"].startswith("m or rad")
    (outside,) = ik["outside_limits"]
    assert [o["joint"] for o in outside] == ["ankle_pitch", "motor_left", "motor_right"]
    for o in outside:
        assert o["value"] == ik["q"][0][mech.joints[o["joint"]].idx_q] and not o["limit"][0] <= o["value"] <= o["limit"][1]
    qa = ik["qa"][0]
    fk = queries.fk(mech, {"qa": [qa.tolist(), [0.1, 0.1], [5.0, -5.0]]})
    assert fk["status"] == ["outside_limits", "ok", "failed"] and fk["outside_limits"][1:] == [[], None]
    assert [o["joint"] for o in fk["outside_limits"][0]] == ["ankle_pitch", "motor_left", "motor_right"]
    assert np.isclose(fk["outside_limits"][0][0]["value"], 0.8, atol=1e-9)
    assert queries.jacobians(mech, {"q": ik["q"][0]})["status"] == ["outside_limits"]
    from pkm.serve.stream import Stream

    stream = Stream(mech)  # (the WebSocket's samples: the same report)
    assert stream.step({"qa": [0.1, 0.1]})["status"] == "ok"
    step = stream.step({"qa": qa.tolist()})
    assert step["status"] == "outside_limits"
    for a, b in zip(step["outside_limits"], fk["outside_limits"][0], strict=True):
        assert a["joint"] == b["joint"] and a["limit"] == b["limit"] and abs(a["value"] - b["value"]) <= 1e-9


def test_a_floating_base_s_batched_dynamics_is_the_model_s():
    """The compiled kernels hold a floating base, the model lets it move free (pkm.core.dynamics.model): a batch on
    a floating robot is answered by the model (the kernels are not asked), as one state is."""
    import numpy as np

    from tests.core.dynamics.floating import floating

    class Held:  # (kernels that must not be asked)
        def __getattr__(self, name):
            raise AssertionError(f"the kernels were asked for {name}")

    mech = floating("fourbar")
    q = pkm.close_loops(mech, [0.4], mech.q_reference).q
    out = queries.dynamics(mech, {"q": [q, q], "qd": [[0.3], [0.3]]}, Held())
    model = pkm.actuator_model(mech, q, [0.3])
    assert model.base == "free" and np.abs(out["h"][1] - model.h).max() <= 1e-12 * np.abs(model.h).max()
