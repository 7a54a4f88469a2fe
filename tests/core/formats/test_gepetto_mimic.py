"""Gepetto's convention with URDF mimic followers named among the motors (as Gepetto's ``true_talos_2_legs`` names
its grippers' joints in ``name_mot``): loaded as the toolbox loads them, each follower named as a motor a joint of its
own (Pinocchio's URDF parser ignores ``<mimic>`` by default), with a warning naming each coupling dropped; a follower
no motor names keeps its coupling.

The model: pkm's Gepetto five-bar (``examples/gepetto_fivebar``) with a gripper on its base, a leader ``grip`` and two
followers, ``grip_inner`` (named in ``name_mot``) and ``grip_outer`` (not named).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import pkm
from pkm.core.formats.load import load_texts
from pkm.errors import PkmWarning
from tests import fd

FIVEBAR = Path(__file__).resolve().parents[3] / "examples" / "gepetto_fivebar"
GRIPPER = """
  <link name="finger"/><link name="inner"/><link name="outer"/>
  <joint name="grip" type="revolute"><parent link="base_link"/><child link="finger"/>
    <origin xyz="0 0.1 0"/><axis xyz="0 0 1"/><limit effort="1" velocity="1"/></joint>
  <joint name="grip_inner" type="revolute"><parent link="finger"/><child link="inner"/>
    <origin xyz="0.02 0 0"/><axis xyz="0 0 1"/><limit effort="1" velocity="1"/>
    <mimic joint="grip" multiplier="-1" offset="0.1"/></joint>
  <joint name="grip_outer" type="revolute"><parent link="finger"/><child link="outer"/>
    <origin xyz="0.04 0 0"/><axis xyz="0 0 1"/><limit effort="1" velocity="1"/>
    <mimic joint="grip" multiplier="2"/></joint>
</robot>"""
YAML = "closed_loop: [['closedloop1_A', 'closedloop1_B']]\ntype: ['3d']\nname_mot: ['mot1', 'mot2', 'grip', 'grip_inner']\n"


def _texts() -> dict[str, str]:
    urdf = (FIVEBAR / "robot.urdf").read_text().replace("</robot>", GRIPPER)
    return {"robot.urdf": urdf, "robot.yaml": YAML}


@pytest.fixture(scope="module")
def gripper(tmp_path_factory):
    folder = tmp_path_factory.mktemp("gripper")
    for name, text in _texts().items():
        (folder / name).write_text(text)
    with pytest.warns(PkmWarning, match=r"mimic coupling dropped: 'grip_inner' = -1 'grip' \+ 0.1") as caught:
        mech = pkm.load(folder)
    return mech, caught


def test_a_follower_named_as_a_motor_is_its_own_joint_and_the_others_keep_their_coupling(gripper):
    mech, caught = gripper
    assert mech.actuated_names == ("mot1", "mot2", "grip", "grip_inner")
    assert mech.joints["grip_inner"].nq == 1 and mech.joints["grip_inner"].kind != "JointModelMimic"
    assert mech.joints["grip_outer"].kind == "JointModelMimic"
    assert sum("grip_outer" in str(w.message) for w in caught) == 0
    assert any("'grip_inner' = -1 'grip' + 0.1" in n and "toolbox" in n for n in mech.notes)


def test_the_motors_drive_the_follower_independently_and_the_jacobian_matches_differences(gripper):
    mech, _ = gripper
    qa = mech.actuated_q(mech.q_reference) + np.array([0.05, -0.04, 0.3, -0.2])
    fk = pkm.close_loops(mech, qa)
    assert fk.residual <= 1e-10
    q = fk.q
    grip, inner = (mech.joints[n].idx_q for n in ("grip", "grip_inner"))
    assert abs(q[grip] - qa[2]) <= 1e-12 and abs(q[inner] - qa[3]) <= 1e-12  # (no longer -grip + 0.1)
    assert fd.forward_jacobian_error(mech, q) <= 1e-6


def test_an_upload_reads_it_alike():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mech = load_texts(_texts())
    assert any("mimic coupling dropped" in str(w.message) for w in caught)
    assert mech.actuated_names == ("mot1", "mot2", "grip", "grip_inner")


def test_a_closure_spec_naming_a_follower_as_actuated_says_what_it_is():
    """pkm's own spec keeps the file's couplings: a follower named as actuated is refused, saying why and what to name."""
    from pkm.errors import SpecError

    spec = ('format = "pkm.closures/1"\nmechanism = "g"\nurdf = "robot.urdf"\nactuated = ["mot1", "grip_inner"]\n'
            '[[closure]]\nname = "loop1"\ntype = "point"\nframe_a = "closedloop1_A"\nframe_b = "closedloop1_B"\n')
    with pytest.raises(SpecError, match=r"actuated: joint 'grip_inner' follows another joint \(a URDF <mimic>\)"):
        pkm.from_strings(_texts()["robot.urdf"], spec)
