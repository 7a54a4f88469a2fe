"""pkm.errors: every exception is a PkmError (and the builtin a caller would catch), carries its data as attributes,
and its one-line message names that data. (The name suggestions of UnknownNameError are tested in
``tests/test_name_suggestions.py``.)"""

from __future__ import annotations

import inspect
import math
import pickle

import pytest

from pkm import errors as E

#: One instance of every exception class, with the attributes it must carry and the texts its message must hold.
CASES = [
    (E.InvalidInputError("q", "expected 3 numbers", [1, 2]), {"name": "q", "value": [1, 2]}, ["q: expected 3 numbers"]),
    (E.UnitError("La", "'3deg' is an angle, not a length", "3deg"), {"name": "La", "value": "3deg"}, ["La: ", "3deg"]),
    (E.InvalidParameterError("Lb", "must be > 0", -1.0), {"name": "Lb", "value": -1.0}, ["Lb: must be > 0"]),
    (E.UnknownNameError("frame", "tool", ["base", "platform"], "delta"),
     {"kind": "frame", "name": "tool", "valid": ("base", "platform"), "suggestions": ()},
     ["frame 'tool' does not exist in delta", "'base', 'platform'"]),
    (E.SpecError("robot.toml", "missing [task]"), {"source": "robot.toml"}, ["robot.toml: missing [task]"]),
    (E.SpecNameError("robot.toml", "joint", "motor_9", ["motor_1"], "actuated"),
     {"source": "robot.toml", "kind": "joint", "name": "motor_9", "valid": ("motor_1",)},
     ["joint 'motor_9'", "robot.toml (actuated)"]),
    (E.UnreachableError(2, 0.0125, "m", "rod too short"), {"leg": 2, "excess": 0.0125, "unit": "m"},
     ["leg 2 misses by 0.0125 m", "rod too short"]),
    (E.AssemblyError(0.5, "rad", "knee", closures=[("ball_1", 0.5)]),
     {"deficit": 0.5, "unit": "rad", "closures": (("ball_1", 0.5),)}, ["short by 0.5 rad", "(knee)"]),
    (E.SingularityError("direct", 1.5e-13, "platform gains a freedom"), {"kind": "direct", "sigma_min": 1.5e-13},
     ["direct singularity", "1.500e-13", "platform gains a freedom"]),
    (E.SingularityError("direct", 1.5e-13, "platform", distance=2e-14), {"kind": "direct", "sigma_min": 1.5e-13,
                                                                         "distance": 2e-14},
     ["(smallest singular value 1.500e-13, 2e-14 of the largest)"]),
    (E.ConvergenceError("loop closure", 2e-3, 50, 1e-10, result="r", detail="stalled"),
     {"what": "loop closure", "residual": 2e-3, "iterations": 50, "tolerance": 1e-10, "result": "r",
      "worst_closure": None, "worst_gap": 0.0},
     ["loop closure did not converge", "2.000e-03", "1.0e-10", "50 iterations", "stalled"]),
    (E.NonFiniteError("tau", [math.nan], "overflow"), {"what": "tau"}, ["tau is not finite", "overflow"]),
    (E.BranchError("knee_out", {"knee_1": -1, "knee_2": -1}, {"knee_1": -1, "knee_2": 1}),
     {"branch": "knee_out", "expected": {"knee_1": -1, "knee_2": -1}, "found": {"knee_1": -1, "knee_2": 1}},
     ["'knee_out'", "['knee_2']"]),
    (E.SweepError("out.parquet holds another sweep", "out.parquet"), {"path": "out.parquet"},
     ["out.parquet holds another sweep"]),
    (E.CompilerError("twin kernels", "no cc on PATH"), {"how": "no cc on PATH"}, ["twin kernels: no cc on PATH"]),
    (E.ControllerError(0.25, "returned shape (2,)"), {"time": 0.25, "reason": "returned shape (2,)"},
     ["t = 0.25 s", "returned shape (2,)"]),
    (E.MissingDependencyError("dask", "sweeps", "pkm.sweep"), {"package": "dask", "extra": "sweeps"},
     ["pkm.sweep needs dask", 'pip install "pkm-robotics[sweeps]"']),
    (E.StructureError("leg 3", "not an arm-and-rod leg"), {"part": "leg 3"}, ["leg 3: not an arm-and-rod leg"]),
    (E.TransmissionError("foot", "singular", "outputs singular", ("ankle_pitch",), 3e-9),
     {"transmission": "foot", "reason": "singular", "joints": ("ankle_pitch",), "value": 3e-9},
     ["transmission 'foot': outputs singular"]),
    (E.NonPhysicalInertiaError("inverse dynamics", ["arm"], ["negative"], [-2e-4], "arm.urdf"),
     {"what": "inverse dynamics", "links": ("arm",), "rules": ("negative",), "values": (-2e-4,)},
     ["arm.urdf: inverse dynamics refused", "'arm' (a negative principal moment -0.0002 kg m^2)"]),
    (E.StiffnessError("free", "a motion no spring resists moves the end effector (it moves leg1)", ["leg1"], 0),
     {"kind": "free", "joints": ("leg1",), "rank": 0}, ["no spring resists", "leg1"]),
    (E.NoCollisionGeometryError("delta", "no_geometry", "delta: its files carry no collision geometry: add ..."),
     {"mechanism": "delta", "kind": "no_geometry"}, ["no collision geometry"]),
    (E.PathError(12, 0.25, "peak effort of motor_1", "needs 5.1 N m to hold still, has 3.9"),
     {"index": 12, "s": 0.25, "limit": "peak effort of motor_1"}, ["path point 12 (s = 0.25)", "needs 5.1 N m"]),
]

#: The builtin exception each class is also, for callers that catch those.
BUILTIN = {E.InvalidInputError: ValueError, E.UnitError: ValueError, E.InvalidParameterError: ValueError,
           E.UnknownNameError: LookupError, E.SpecNameError: LookupError, E.NonFiniteError: ArithmeticError,
           E.CompilerError: RuntimeError, E.MissingDependencyError: ImportError}


def _exception_classes():
    return [c for _, c in inspect.getmembers(E, inspect.isclass)
            if issubclass(c, Exception) and not issubclass(c, Warning) and c.__module__ == E.__name__]


def test_every_exception_of_the_module_is_a_pkm_error_and_has_a_case_here():
    """A walk over the module: every exception class derives from PkmError and is exercised by CASES below (a new
    one fails here until it is added), and PkmWarning is a UserWarning, not an error."""
    classes = set(_exception_classes())
    assert all(issubclass(c, E.PkmError) for c in classes)
    assert classes == {type(err) for err, _, _ in CASES} | {E.PkmError}
    assert issubclass(E.PkmWarning, UserWarning) and not issubclass(E.PkmWarning, E.PkmError)


@pytest.mark.parametrize("err, attributes, texts", CASES, ids=[type(c[0]).__name__ for c in CASES])
def test_each_error_carries_its_data_and_its_message_names_it(err, attributes, texts):
    """The attributes hold the constructor's data (floats as floats, tuples for sequences) and the one-line message
    holds each stated text."""
    for name, expected in attributes.items():
        assert getattr(err, name) == expected, name
        if isinstance(expected, float):
            assert type(getattr(err, name)) is float
    message = str(err)
    assert "\n" not in message
    for text in texts:
        assert text in message, (text, message)


@pytest.mark.parametrize("cls, builtin", BUILTIN.items(), ids=[c.__name__ for c in BUILTIN])
def test_errors_are_also_the_builtin_a_caller_catches(cls, builtin):
    """InvalidInputError is a ValueError, UnknownNameError a LookupError, NonFiniteError an ArithmeticError...:
    an ``except ValueError`` written before pkm had its own errors still catches them."""
    err = next(e for e, _, _ in CASES if type(e) is cls)
    with pytest.raises(builtin):
        raise err
    assert isinstance(err, E.PkmError)


def test_hierarchy_of_the_specialised_errors():
    """UnitError and InvalidParameterError are InvalidInputErrors; SpecNameError is both an UnknownNameError and
    a SpecError (a file naming a missing link is a malformed file); the others are not ValueErrors."""
    assert issubclass(E.UnitError, E.InvalidInputError) and issubclass(E.InvalidParameterError, E.InvalidInputError)
    assert issubclass(E.SpecNameError, E.UnknownNameError) and issubclass(E.SpecNameError, E.SpecError)
    for cls in (E.UnreachableError, E.AssemblyError, E.SingularityError, E.ConvergenceError, E.SweepError):
        assert not issubclass(cls, ValueError), cls


def test_unknown_name_message_is_not_quoted_like_a_key_error():
    """LookupError's str would quote the message as a KeyError does; UnknownNameError's str is the sentence."""
    err = E.UnknownNameError("mechanism", "dleta", ["delta", "rrr3"])
    assert str(err) == "mechanism 'dleta' does not exist; did you mean 'delta'? valid mechanisms: 'delta', 'rrr3'"
    assert str(E.UnknownNameError("branch", "x", ["a"])).endswith("valid branches: 'a'")  # (plural of -ch)


def test_unreachable_without_a_leg_blames_the_task_and_magnitudes_are_floats():
    """leg 0 means no single leg is to blame: the message says the task misses; integer excesses become floats."""
    err = E.UnreachableError(0, 3)
    assert str(err) == "pose unreachable: the task misses by 3 m" and err.excess == 3.0 and type(err.excess) is float
    assert E.SingularityError("inverse", 0).sigma_min == 0.0 and E.SingularityError("inverse", 0).distance is None
    assert E.AssemblyError(1).closures == ()


def test_did_you_mean_phrasing():
    """No names: empty; one: quoted; several: a comma list ending in 'or'."""
    assert E.did_you_mean(()) == ""
    assert E.did_you_mean(("a",)) == "did you mean 'a'?"
    assert E.did_you_mean(("a", "b", "c")) == "did you mean 'a', 'b' or 'c'?"


@pytest.mark.parametrize("err", [c[0] for c in CASES if type(c[0]) is not E.SweepError],
                         ids=[type(c[0]).__name__ for c in CASES if type(c[0]) is not E.SweepError])
def test_errors_survive_pickling_with_their_data(err):
    """An error raised in a worker process reaches the caller as itself: same class, message and attributes."""
    back = pickle.loads(pickle.dumps(err))
    assert type(back) is type(err) and str(back) == str(err)
    assert {k: repr(v) for k, v in vars(back).items()} == {k: repr(v) for k, v in vars(err).items()}


def test_a_sweep_error_survives_pickling():
    """SweepError (one message and a keyword-like path) does pickle: the bug above is in the others' signatures."""
    err = E.SweepError("gone", "out.parquet")
    back = pickle.loads(pickle.dumps(err))
    assert str(back) == "gone" and back.path == "out.parquet"
