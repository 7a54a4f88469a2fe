"""pkm.serve.queries called in process: what the service answers, without a server."""

from __future__ import annotations

import re

import numpy as np
import pytest

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
    with pytest.raises(UnitError, match=r"'deg' is an angle unit but qd\[0\] is in \[rad/s\]"):  # (a position's unit)
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


def test_a_floating_base_s_streamed_efforts_are_the_model_s():
    """The WebSocket's efforts on a floating robot are the model's (the base free), as HTTP's are: the compiled
    inverse dynamics (which holds the base) is not asked; its kinematics kernels may be."""
    import numpy as np

    from pkm.serve.stream import Stream
    from tests.core.dynamics.floating import floating

    class Kinematics:  # (kernels whose dynamics must not be asked; their closure declines, the library closes)
        def kernel(self, name):
            if name == "closure_newton":
                return type("Follow", (), {"follow": lambda self, q, qa, n, tol: (q[None], [np.inf], [[0.0]], None)})()
            if name == "forward_jacobian":
                return lambda Q: pkm.forward_jacobian(mech, Q[0]).reshape(1, -1, order="F")
            raise AssertionError(f"the kernels were asked for {name}")

    mech = floating("fourbar")
    out = Stream(mech, kernels=Kinematics()).step({"qa": [0.4], "qd": [0.3], "qdd": [1.0]})
    model = pkm.actuator_model(mech, out["q"], [0.3])
    assert model.base == "free" and np.abs(out["tau"] - (model.M @ [1.0] + model.h)).max() <= 1e-12


def test_rates_and_accelerations_take_their_units_as_the_library_and_the_cli_do():
    """A rate is ``"-30deg/s"`` (or ``"300rpm"``) over HTTP as in :func:`pkm.actuator_model` and ``pkm dynamics
    --rates``: the answer is the SI number's to 1e-12; an acceleration has no suffix (``rad/s^2``), so ``"1deg"``
    there is refused naming its unit, and a numpy array of strings (a msgpack body's) is read as the list."""
    import numpy as np
    import pytest

    from pkm.errors import UnitError

    mech = pkm.load("delta")
    qa = mech.actuated_q(mech.q_reference)
    si = [0.0, 0.0, -np.pi / 6]
    plain = queries.dynamics(mech, {"qa": qa, "qd": si, "qdd": [1.0, 0.0, 0.0]})
    for qd in (["0", "0rpm", "-30deg/s"], np.array(["0", "0", "-30deg/s"])):
        units = queries.dynamics(mech, {"qa": qa, "qd": qd, "qdd": [1.0, 0.0, 0.0]})
        assert np.abs(units["tau"] - plain["tau"]).max() <= 1e-12 * np.abs(plain["tau"]).max()
    library = pkm.actuator_model(mech, plain["q"][0], ["0", "0", "-30deg/s"])
    assert np.abs(library.h - plain["h"][0]).max() <= 1e-12 * np.abs(plain["h"]).max()
    v = queries.velocities(mech, {"qa": qa, "qd": ["300rpm", 0.0, 0.0]})["v"]
    assert np.abs(v - queries.velocities(mech, {"qa": qa, "qd": [10 * np.pi, 0.0, 0.0]})["v"]).max() <= 1e-12
    with pytest.raises(UnitError, match=r"qdd\[0\].*\[rad/s\^2\]"):
        queries.dynamics(mech, {"qa": qa, "qdd": ["1deg", 0.0, 0.0]})


def test_a_map_job_takes_units_as_pkm_map_does():
    """A map job's axes ``["-40cm", "-30cm", 3]``, ``fixed`` and ``length`` with units (``pkm map --axis
    z=-40cm:-30cm:3`` takes them so): the same nodes and condition indices as the SI numbers', to 1e-12; an angle
    unit on a length axis refused naming it."""
    import numpy as np
    import pytest

    from pkm.errors import UnitError
    from pkm.serve import jobs

    mech = pkm.load("delta")
    units, _ = jobs._map(mech, {"axes": {"z": ["-40cm", "-30cm", 3]}, "fixed": {"x": "1cm"}, "length": "5cm"},
                         jobs.Job("a", "map", "delta"))
    si, _ = jobs._map(mech, {"axes": {"z": [-0.4, -0.3, 3]}, "fixed": {"x": 0.01}, "length": 0.05},
                      jobs.Job("b", "map", "delta"))
    assert np.allclose(units["axes"]["z"], si["axes"]["z"], rtol=1e-15, atol=0)
    assert np.allclose(units["condition_index"], si["condition_index"], rtol=1e-12, atol=0)
    assert np.array_equal(si["feasible"], si["reachable"] & si["within_limits"] & ~si["interferes"])
    assert si["units"]["clearance"] == "m" and np.all(si["clearance"][si["reachable"]] > 0.0)  # (the Delta's bodies)
    with pytest.raises(UnitError, match=r"axes\.z"):
        jobs._map(mech, {"axes": {"z": ["-40deg", "-30cm", 3]}}, jobs.Job("c", "map", "delta"))


def test_the_stiffness_query_is_the_librarys():
    """POST /models/{model}/stiffness: the compliance, rank, principal compliances (1 / the principal stiffnesses,
    0 along rigid directions), a wrench's deflection and tangent compliance are pkm.stiffness's, and its links of a
    material on the Gough-Stewart; a joint that does not exist, a material unknown, is pkm's error."""
    from pkm.errors import InvalidInputError, UnknownNameError

    QUERIES = queries.QUERIES
    delta = pkm.load("delta")
    qa = delta.actuated_q(delta.q_reference).tolist()
    out = QUERIES["stiffness"](delta, {"qa": [qa, qa], "drives": 400.0, "springs": {"motor_2": 800.0},
                                       "wrench": [1.0, 0.0, -10.0, 0.0, 0.0, 0.0]})
    K = pkm.stiffness(delta, delta.q_reference, joints={"motor_1": 400.0, "motor_2": 800.0, "motor_3": 400.0})
    assert out["status"] == ["ok", "ok"] and list(out["rank"]) == [3, 3]
    assert out["sprung"] == K.sprung and out["sources"] == dict.fromkeys(delta.actuated_names, "joints")
    assert np.allclose(out["compliance"][1], K.compliance, rtol=1e-12, atol=1e-18)
    assert np.allclose(1.0 / out["force_compliance"][0], K.principal("force")[0], rtol=1e-9)
    assert not np.any(out["moment_compliance"][0]) and out["units"]["force_compliance"] == "m/N"
    d = K.deflection([1.0, 0.0, -10.0, 0.0, 0.0, 0.0])
    assert np.allclose(out["displacement"][0], d.displacement, rtol=1e-9, atol=1e-15)
    assert out["gap"][0] == pytest.approx(d.gap, rel=1e-6)  # (q closed from qa by the service: 1e-13 apart)
    loaded = K.loaded([1.0, 0.0, -10.0, 0.0, 0.0, 0.0]).compliance
    assert np.allclose(out["loaded_compliance"][0], loaded, rtol=1e-6, atol=1e-9 * np.abs(loaded).max())
    assert out["links"] == {} and out["rigid_links"] == {}
    with pytest.raises(UnknownNameError):
        QUERIES["stiffness"](delta, {"qa": qa, "springs": {"motor_9": 1.0}})
    gs = pkm.load("gough_stewart")
    steel = QUERIES["stiffness"](gs, {"q": gs.q_reference.tolist(), "drives": 2e6, "links": {"E": 2.1e11, "G": 8.1e10}})
    K = pkm.stiffness(gs, gs.q_reference, joints=dict.fromkeys(gs.actuated_names, 2e6), links=pkm.Material(2.1e11, 8.1e10))
    assert np.allclose(steel["compliance"][0], K.compliance, rtol=1e-12, atol=1e-15 * np.abs(K.compliance).max())
    assert steel["links"]["cylinder_1"]["radius"] == 0.03 and steel["rigid_links"] == K.rigid_links
    with pytest.raises(InvalidInputError, match="steel"):
        QUERIES["stiffness"](gs, {"q": gs.q_reference.tolist(), "drives": 2e6, "links": "wood"})


def test_the_clearance_query_is_the_librarys():
    """POST /models/{model}/clearance: pkm.clearance's distances, minimum, closest pair and gradient per sample; a
    model whose files carry no collision geometry is refused whole (pkm's error: 422)."""
    from pkm.core.collision import CollisionModel
    from pkm.errors import NoCollisionGeometryError

    gs = pkm.load("gough_stewart")
    qa = gs.actuated_q(gs.q_reference)
    out = queries.QUERIES["clearance"](gs, {"qa": [qa.tolist(), (qa + 0.05).tolist()]})
    assert out["status"] == ["ok", "ok"] and out["pairs"] == [list(p) for p in CollisionModel.of(gs).pairs]
    c = pkm.clearance(gs, out["q"][1])
    # (coal's GJK starts from the last call's support points: a disc's distance, approached iteratively, agrees to
    # its tolerance, 1e-12 of the size)
    assert np.allclose(out["distances"][1], [c.pairs[tuple(p)] for p in out["pairs"]], rtol=0, atol=1e-10)
    assert abs(out["minimum"][1] - c.minimum) <= 1e-10 and tuple(out["pairs"][out["closest"][1]]) == c.closest
    assert np.allclose(out["gradient"][1], c.gradient, rtol=1e-9, atol=1e-12) and not out["interferes"][1]
    assert out["units"]["gradient"] == ["m/m"] * 6
    bare = pkm.from_strings(re.sub(r"<collision.*?</collision>", "", gs.urdf, flags=re.DOTALL), gs.spec)
    with pytest.raises(NoCollisionGeometryError):
        queries.QUERIES["clearance"](bare, {"qa": qa.tolist()})
