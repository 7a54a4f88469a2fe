"""pkm.units: quantities with units wherever the Python API takes a value (joints, task coordinates, parameters)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import pkm
from pkm.errors import InvalidInputError, UnitError
from pkm.units import parse_joint_value, parse_quantity


@pytest.mark.parametrize("text,kinds,expected", [
    ("120mm", {"length"}, 0.12), ("81cm", {"length"}, 0.81), ("0.2", {"length"}, 0.2), ("-11deg", {"angle"},
     math.radians(-11)), ("2.5e-1 rad", {"angle"}, 0.25), ("500g", {"mass"}, 0.5), ("3", {None}, 3.0)])
def test_quantities_convert_to_si(text, kinds, expected):
    """Unit suffixes convert to SI (mm, cm, deg, g); a plain number is taken as SI."""
    assert math.isclose(parse_quantity(text, kinds, "v", "?"), expected, rel_tol=1e-12)


@pytest.mark.parametrize("text,kinds,message", [
    ("3deg", {"length"}, "'deg' is an angle unit but R is in [m]; use m, cm, mm or no unit"),
    ("3in", {"length"}, "unknown unit 'in'"), ("abc", {"length"}, "is not a number"),
    ("1g", {None}, "give the number in that unit")])
def test_bad_quantities_are_refused(text, kinds, message):
    """A suffix of the wrong kind, an unknown suffix or a non-number raise UnitError saying so."""
    with pytest.raises(UnitError) as exc:
        parse_quantity(text, kinds, "R", "m")
    assert message in str(exc.value)



def test_quantity_converts_and_checks_the_kind():
    assert pkm.quantity("20mm") == pytest.approx(0.02, rel=1e-15)
    assert pkm.quantity("5deg", "angle") == pytest.approx(math.radians(5), rel=1e-15)
    assert pkm.quantity(0.3, "length") == 0.3
    with pytest.raises(UnitError, match="'deg' is an angle unit"):
        pkm.quantity("5deg", "length")
    with pytest.raises(InvalidInputError, match="kind"):
        pkm.quantity(1.0, "volume")
    for bad in ([1.0, 2.0], float("inf"), None):
        with pytest.raises(InvalidInputError):
            pkm.quantity(bad)


def test_joint_values_task_targets_and_parameters_take_units():
    """close_loops takes "-30deg"; solve_ik a partial mapping with units (the rest from the reference); build a
    parameter in mm, and a tuple parameter with one unit per entry."""
    delta = pkm.build("delta", R="120mm", La="0.11")  # (a string without unit is SI)
    assert (delta.params.R, delta.params.La) == pytest.approx((0.12, 0.11), rel=1e-15)
    fk = pkm.close_loops(delta, ["-30deg", "-25deg", -0.6])
    assert np.allclose(delta.actuated_q(fk.q), [math.radians(-30), math.radians(-25), -0.6], atol=1e-12)
    ik = pkm.solve_ik(delta, {"z": "-36cm", "x": "1cm"})
    assert pkm.task_values(delta, ik.q) == pytest.approx({"x": 0.01, "y": 0.0, "z": -0.36}, abs=1e-10)
    with pytest.raises(UnitError, match="'deg' is an angle unit"):
        pkm.solve_ik(delta, {"z": "3deg"})
    with pytest.raises(InvalidInputError, match="unknown task coordinates"):
        pkm.solve_ik(delta, {"w": 0.0})
    prs3 = pkm.build("prs3", reference=("95cm", "1deg", "0deg"))
    assert prs3.params.reference == pytest.approx((0.95, math.radians(1), 0.0), rel=1e-15)
    hexapod = pkm.load("hexapod")
    ref = pkm.task_values(hexapod, hexapod.q_reference)
    ik = pkm.solve_ik(hexapod, {"yaw": "2deg"})
    assert pkm.task_values(hexapod, ik.q) == pytest.approx({**ref, "yaw": math.radians(2)}, abs=1e-9)


def test_rates_and_efforts_take_their_own_units_in_the_library():
    """A rate takes a rate's unit (``"-30deg/s"``, ``"300rpm"``), an effort a torque's or a force's (``"2 N m"``), as
    positions take theirs; a position's unit for a rate is refused (rad/s is not rad); the answers equal the SI
    numbers' (factors written out here)."""
    delta = pkm.load("delta")
    q = delta.q_reference
    v = pkm.velocities(delta, q, ["300rpm", "-30deg/s", 0.0])
    assert np.allclose(v, pkm.velocities(delta, q, [10 * math.pi, -math.pi / 6, 0.0]), rtol=1e-15, atol=0)
    model = pkm.actuator_model(delta, q, [0.0, "90deg/s", 0.0])
    assert model.qd == pytest.approx([0.0, math.pi / 2, 0.0], rel=1e-15)
    as_array = pkm.actuator_model(delta, q, np.array(["0", "90deg/s", "0"]))  # (numpy's strings: the list's)
    assert np.array_equal(as_array.qd, model.qd)
    assert np.allclose(model.accelerations(["2 N m", "500mN m", 0.0]), model.accelerations([2.0, 0.5, 0.0]),
                       rtol=1e-15, atol=0)
    with pytest.raises(UnitError, match=r"'deg' is an angle unit but qd_actuated\[0\] is in \[rad/s\]"):
        pkm.velocities(delta, q, ["5deg", 0.0, 0.0])
    with pytest.raises(UnitError, match=r"'N' is a force unit but tau\[0\] is in \[N m\]"):
        model.accelerations(["2N", 0.0, 0.0])
    assert parse_joint_value("-30deg/s", True, "rate", "m") == pytest.approx(-math.pi / 6, rel=1e-15)
    assert parse_joint_value("50mm/s", False, "rate", "s") == pytest.approx(0.05, rel=1e-15)
    with pytest.raises(UnitError, match=r"s2 is in \[rad/s\^2\]; give the number in that unit"):
        parse_joint_value("1deg", True, "acceleration", "s2")


@pytest.mark.parametrize("text,kind,expected", [
    ("2.5 N m", "torque", 2.5), ("2.5N*m", "torque", 2.5), ("2.5 N * m", "torque", 2.5), ("2.5Nm", "torque", 2.5),
    ("300 mN m", "torque", 0.3), ("1.2kN m", "torque", 1200.0), ("40 N", "force", 40.0),
    ("3 rad/s", "angular velocity", 3.0), ("90deg/s", "angular velocity", math.pi / 2),
    ("60 rpm", "angular velocity", 2 * math.pi), ("0.5m/s", "velocity", 0.5), ("250 mm/s", "velocity", 0.25)])
def test_torques_and_rates_convert_to_si(text, kind, expected):
    """An actuator's effort and speed limits take their units: torques (N m, N*m, Nm, mN m, kN m), forces, angular
    velocities (rad/s, deg/s, rpm) and velocities (m/s, mm/s); against factors written out here (1 rpm = 2 pi / 60
    rad/s)."""
    assert math.isclose(parse_quantity(text, {kind}, "v", "?"), expected, rel_tol=1e-12)
    assert math.isclose(pkm.quantity(text, kind), expected, rel_tol=1e-12)


def test_torques_and_rates_are_refused_where_another_kind_is_expected():
    with pytest.raises(UnitError, match="'N m' is a torque unit but tau is in \\[N\\]; use N, mN, kN or no unit"):
        parse_quantity("2 Nm", {"force"}, "tau", "N")
    with pytest.raises(UnitError, match="'rpm' is an angular velocity unit"):
        pkm.quantity("100rpm", "velocity")
    with pytest.raises(UnitError, match="unknown unit 'N mm'"):
        parse_quantity("2 N mm", {"torque"}, "tau", "N m")
