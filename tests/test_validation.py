"""pkm.validation, function by function: what each converter accepts and returns (type, shape, copy), where its
bounds lie (inclusive or not), and what its refusal says. (Refusals of strings, booleans, ragged and complex
inputs by as_vector, and the core's use of the helpers, are in ``tests/core/test_input_validation.py``.)"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

import pkm.validation as V
from pkm.errors import InvalidInputError, NonFiniteError
from pkm.validation import as_array, as_count, as_scalar, as_tolerance, as_vector, finite_result, wrap_angle


# ---------------------------------------------------------------------- wrap_angle
def test_wrap_angle_lands_in_the_half_open_interval_and_keeps_the_angle():
    """Every result lies in (-pi, pi] and differs from its input by a whole number of turns (to 1e-12 rad)."""
    x = np.linspace(-20.0, 20.0, 4001)
    w = wrap_angle(x)
    assert w.shape == x.shape and np.all(w > -np.pi) and np.all(w <= np.pi)
    turns = (x - w) / (2 * np.pi)
    assert np.abs(turns - np.round(turns)).max() < 1e-12


def test_wrap_angle_at_the_ends_and_on_scalars_and_stacks():
    """pi stays pi and -pi becomes pi (the interval is closed above); 0 and small angles are unchanged; a
    scalar gives a 0-d array, an int list a float array of the same shape; wrapping twice changes nothing."""
    assert float(wrap_angle(np.pi)) == np.pi and float(wrap_angle(-np.pi)) == np.pi
    assert float(wrap_angle(3 * np.pi)) == pytest.approx(np.pi, abs=1e-12)
    assert float(wrap_angle(0.0)) == 0.0 and float(wrap_angle(-0.25)) == -0.25
    stack = wrap_angle([[0, 7], [-7, 4]])
    assert stack.dtype == np.float64 and stack.shape == (2, 2)
    np.testing.assert_array_equal(wrap_angle(stack), stack)


# ---------------------------------------------------------------------- as_array
@pytest.mark.parametrize("good, shape", [(2, ()), ([[1, 2], [3, 4]], (2, 2)), (np.arange(6, dtype=np.uint8), (6,)),
                                         (np.array([1.0, 2.0], dtype=object), (2,)), ([], (0,))])
def test_as_array_takes_real_numbers_of_any_shape(good, shape):
    """Ints, unsigned ints, numbers held in an object array, empty lists: a float64 array of the same shape."""
    out = as_array(good, "x")
    assert out.dtype == np.float64 and out.shape == shape


def test_as_array_leaves_finiteness_to_the_caller_and_names_what_was_expected():
    """NaN and inf pass as_array (finiteness is as_vector's and as_scalar's check); a refusal says what was
    expected, in the caller's words, and the dtype it got."""
    assert np.isnan(as_array([np.nan, np.inf], "x")).sum() == 1
    with pytest.raises(InvalidInputError, match=r"^x: expected a pose, got an array of complex128$"):
        as_array(np.ones(2, dtype=complex), "x", "a pose")
    with pytest.raises(InvalidInputError, match="got booleans") as info:
        as_array(np.array([True, False]), "mask")
    assert info.value.name == "mask"
    with pytest.raises(InvalidInputError, match="non-numbers"):
        as_array(np.array([1.0, True], dtype=object), "x")


# ---------------------------------------------------------------------- as_vector
def test_as_vector_returns_a_copy_and_refuses_other_shapes_with_the_shape():
    """The result is a fresh float64 array (changing it leaves the caller's untouched); a column, a scalar or a
    vector of another length is refused naming the shape found and the one expected."""
    given = np.array([1.0, 2.0, 3.0])
    out = as_vector(given, 3, "y")
    out[0] = 99.0
    assert given[0] == 1.0
    for bad, shape in ((np.ones((3, 1)), "(3, 1)"), (1.0, "()"), ([1.0, 2.0], "(2,)")):
        with pytest.raises(InvalidInputError, match=rf"expected shape \(3,\), got {re.escape(shape)}"):
            as_vector(bad, 3, "y")


def test_as_vector_names_the_non_finite_positions():
    """NaN and infinities are refused with their indices, so that a user finds them in a long vector."""
    with pytest.raises(InvalidInputError, match=r"^q: holds non-finite values at \[1, 3\]") as info:
        as_vector([0.0, np.nan, 1.0, -np.inf], 4, "q")
    assert info.value.name == "q" and len(info.value.value) == 4


def test_as_vector_takes_large_but_finite_ints():
    """An int beyond 2^53 but within the float range is a number (rounded); 10^309 overflows and is refused."""
    assert as_vector([10**300, 0, 1], 3, "q")[0] == 1e300
    with pytest.raises(InvalidInputError, match="not a \\(regular\\) array"):
        as_vector([10**309, 0, 1], 3, "q")


# ---------------------------------------------------------------------- bounded
def test_bounded_keeps_the_bound_and_names_the_first_entry_beyond():
    """1e6 (SI) itself is kept (the same array, NaN left to the caller); beyond it the error names the argument, the
    value and its entry, and carries what was given."""
    a = np.array([[0.0, -V.ABSURD], [np.nan, V.ABSURD]])
    assert V.bounded(a, "q") is a
    with pytest.raises(InvalidInputError, match=r"holds -1e\+308 at entry \[1, 0\], beyond 1e\+06") as info:
        V.bounded(np.array([[0.0, 1.0], [-1e308, 2e6]]), "qa", "given")
    assert info.value.name == "qa" and info.value.value == "given"


def test_a_coordinate_beyond_the_bound_is_refused_by_library_command_line_and_service(built, capsys):
    """Issue 52's repro: the service's fk of qa = [1e308, 0.2, 0.3] on the Delta answered 200 "ok" with motor_1
    echoed as 2.58 rad (1e308 wrapped). One rule (:func:`pkm.validation.bounded`) now refuses it everywhere: the
    library's loop closure, a configuration q (a Jacobian), the command line's fk (one line, exit 1) and the
    service's fk as one sample or in a batch (an InvalidInputError: its 422); 1e6 rad itself is still solved, its
    wrap exact to the float spacing there (2e-10 rad)."""
    import pkm
    from pkm import cli
    from pkm.serve import queries

    delta = built("delta")
    beyond = "beyond 1e+06 (SI units: m, rad)"
    q = delta.q_reference.copy()
    q[0] = 1e308
    for call in (lambda: pkm.close_loops(delta, [1e308, 0.2, 0.3]), lambda: pkm.forward_jacobian(delta, q),
                 lambda: queries.fk(delta, {"qa": [1e308, 0.2, 0.3]}),
                 lambda: queries.fk(delta, {"qa": [[0.1, 0.2, 0.3], [1e308, 0.2, 0.3]]}),
                 lambda: queries.jacobians(delta, {"qa": [0.1, 0.2, 0.3], "seed": q.tolist()})):
        with pytest.raises(InvalidInputError) as info:
            call()
        assert beyond in str(info.value) and "1e+308" in str(info.value)
    assert cli.main(["fk", "delta", "--joints", "motor_1=1e308", "motor_2=0.2", "motor_3=0.3"]) == 1
    err = capsys.readouterr().err.strip()
    assert err.startswith("pkm: error: ") and beyond in err and len(err.splitlines()) == 1
    near = pkm.close_loops(delta, [V.ABSURD, -0.8, -0.9]).q[delta.act_q[0]]
    assert abs(near - math.remainder(V.ABSURD, 2 * math.pi)) <= 1e-9 and math.isclose(
        near, pkm.close_loops(delta, [math.remainder(V.ABSURD, 2 * math.pi), -0.8, -0.9]).q[delta.act_q[0]],
        abs_tol=1e-9)


# ---------------------------------------------------------------------- as_scalar
def test_as_scalar_returns_a_python_float_from_any_one_element_input():
    """A number, a numpy scalar, and one-element arrays of any dimension become a plain float."""
    for good in (2, np.float32(2.0), np.array(2.0), [2.0], np.full((1, 1, 1), 2.0)):
        out = as_scalar(good, "x")
        assert type(out) is float and out == 2.0


def test_as_scalar_bounds_are_inclusive_unless_strict_and_the_message_has_the_unit():
    """low and high are inclusive; strict_low excludes low; the refusal states the bound, the unit and the value."""
    assert as_scalar(0.0, "x", low=0.0) == 0.0 and as_scalar(5.0, "x", high=5.0) == 5.0
    with pytest.raises(InvalidInputError, match=r"^step: must be > 0 m, got 0\.0$"):
        as_scalar(0.0, "step", low=0.0, strict_low=True, unit="m")
    with pytest.raises(InvalidInputError, match=r"^step: must be <= 0\.5 m, got 0\.75$"):
        as_scalar(0.75, "step", high=0.5, unit="m")
    with pytest.raises(InvalidInputError, match=r"^x: must be >= -1, got -2\.0$"):
        as_scalar(-2, "x", low=-1.0)


@pytest.mark.parametrize("bad, match", [(np.inf, "finite number"), (-np.inf, "finite number"), (np.nan, "finite"),
                                        (True, "booleans"), (None, "got NoneType"), ([1.0, 2.0], r"shape \(2,\)"),
                                        ([], r"shape \(0,\)"), (10**400, "not a \\(regular\\)")])
def test_as_scalar_refusals(bad, match):
    """Non-finite values, booleans, None, several or no numbers and ints beyond the float range are refused."""
    with pytest.raises(InvalidInputError, match=match) as info:
        as_scalar(bad, "x")
    assert info.value.name == "x"


# ---------------------------------------------------------------------- as_count
def test_as_count_takes_python_and_numpy_ints_within_inclusive_bounds():
    """Both ends are allowed; a numpy integer comes back as a Python int."""
    assert as_count(1, "n") == 1 and as_count(10**7, "n") == 10**7
    out = as_count(np.int64(5), "n", low=5, high=5)
    assert type(out) is int and out == 5


@pytest.mark.parametrize("bad", [0, 10**7 + 1, 10**100, 3.0, np.float64(3.0), np.bool_(True), False, "3", None])
def test_as_count_refusals_name_the_range(bad):
    """Out of range (huge ints too), floats even when whole, booleans (numpy's too), strings and None are refused
    stating the range."""
    with pytest.raises(InvalidInputError, match=r"^n: expected an integer in \[1, 10000000\]"):
        as_count(bad, "n")


# ---------------------------------------------------------------------- as_tolerance
def test_as_tolerance_is_a_number_in_zero_excluded_to_high_included():
    """(0, high]: 0 and negatives refused, high accepted, above refused; the default name is 'tol'."""
    assert as_tolerance(1e-300) == 1e-300 and as_tolerance(1.0) == 1.0 and as_tolerance(2.0, high=2.0) == 2.0
    for bad in (0.0, -1e-12, 1.5, math.nan):
        with pytest.raises(InvalidInputError) as info:
            as_tolerance(bad)
        assert info.value.name == "tol"
    with pytest.raises(InvalidInputError, match=r"^max_step: must be <= 0\.1"):
        as_tolerance(0.2, "max_step", high=0.1)


# ---------------------------------------------------------------------- finite_result
def test_finite_result_returns_its_argument_itself():
    """A finite result is passed through as the same object (no copy, no conversion): tuples, arrays, floats."""
    for x in (np.arange(3.0), (np.ones(2), [0.0, 1.0]), 3.5):
        assert finite_result(x, "thing") is x


def test_finite_result_checks_results_made_of_parts_of_different_shapes():
    """A (value, vector) result is passed through when finite and refused when a part is not."""
    ok = (1.0, np.zeros(2))
    assert finite_result(ok, "pair") is ok
    with pytest.raises(NonFiniteError):
        finite_result((1.0, np.array([0.0, np.nan])), "pair")


def test_finite_result_raises_with_the_value_and_a_hint_or_the_given_detail():
    """A NaN or infinity anywhere is a NonFiniteError (an ArithmeticError) carrying the value; its message says to
    check the units unless the caller gives its own detail."""
    bad = np.array([1.0, np.inf])
    with pytest.raises(NonFiniteError, match=r"^tau is not finite \(NaN or infinity\); .*check the units") as info:
        finite_result(bad, "tau")
    assert info.value.value is bad and isinstance(info.value, ArithmeticError)
    with pytest.raises(NonFiniteError, match=r"; the divisor vanished$"):
        finite_result(math.nan, "x", "the divisor vanished")
