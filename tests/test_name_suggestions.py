"""Unknown names are answered with the closest valid ones (pkm.errors.closest): a letter off, an accent, a Cyrillic or
Greek look-alike, the case; the valid names are listed only when there are few of them, or when none is close."""

from __future__ import annotations

import pytest

import pkm
from pkm.errors import SHORT_LIST, SpecError, SpecNameError, UnknownNameError, closest, fold_name

SIXTY = [f"motor_{k}" for k in range(1, 7)] + [f"free_joint_{k}" for k in range(54)]


@pytest.mark.parametrize("typed, meant", [
    ("motör_1", "motor_1"),  # an umlaut
    ("m\u043etor_1", "motor_1"),  # a Cyrillic o
    ("m\u03bftor_1", "motor_1"),  # a Greek omicron
    ("\u041c\u041e\u0422\u041e\u0420_1", "motor_1"),  # Cyrillic capitals that look like MOTOR
    ("\uff4d\uff4f\uff54\uff4f\uff52\uff3f\uff11", "motor_1"),  # full-width
    ("Motor_1", "motor_1"),
    ("motr_3", "motor_3"),  # a letter missing
    ("free-joint-40", "free_joint_40"),  # dashes for underscores
])
def test_the_closest_name_is_the_one_meant(typed, meant):
    assert closest(typed, SIXTY) == (meant,)


def test_no_guess_when_nothing_is_close_or_too_many_are():
    assert closest("gripper", SIXTY) == ()
    assert closest("motor_9", SIXTY) == ()  # motor_1 ... motor_6 are all as close
    assert closest("knee_3", ["knee_1", "knee_2", "motor_1"]) == ("knee_1", "knee_2")  # two as close: both named
    assert closest("knee_3", ["knee_1", "knee_2"]) == ()  # ... unless they are all there is: the list says it
    assert closest(42, SIXTY) == () and closest("x", []) == ()
    assert fold_name("\uff2dot\u00f6r\u20131") == "motor-1"


def test_a_long_list_is_not_repeated_when_a_name_is_close():
    err = UnknownNameError("joint", "motör_1", SIXTY, "robot.yaml")
    assert str(err) == "joint 'motör_1' does not exist in robot.yaml; did you mean 'motor_1'? (60 valid joints)"
    assert err.suggestions == ("motor_1",) and err.valid == tuple(SIXTY)


def test_a_long_list_is_cut_when_nothing_is_close_and_a_short_one_is_given_whole():
    err = UnknownNameError("joint", "gripper", SIXTY)
    assert str(err).endswith(", 'free_joint_13', ... (60 in all)") and str(err).count("'") == 2 * (SHORT_LIST + 1)
    short = SpecNameError("spec.toml", "frame", "platfrom", ["base", "platform"], "end_effector")
    assert str(short) == ("frame 'platfrom' does not exist in spec.toml (end_effector); did you mean "
                          "'platform'? valid frames: 'base', 'platform'")
    assert isinstance(short, SpecError) and short.suggestions == ("platform",)


def test_the_registry_and_a_mechanism_s_names_are_suggested():
    with pytest.raises(UnknownNameError, match=r"did you mean 'delta'\? valid mechanisms: .*'delta'"):
        pkm.load("dleta")
    with pytest.raises(UnknownNameError, match=r"frame 'platfrom' does not exist in delta; did you mean 'platform'\? "
                                               r"\(\d+ valid frames\)$"):
        pkm.build("delta").frame_id("platfrom")
