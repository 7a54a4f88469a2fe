"""Files that name no actuators, loaded with the actuated joints and task given in code
(:func:`pkm.core.formats.load.given`, ``pkm.load(path, actuated=..., task=...)``) or on the command line
(``--actuated``, ``--task``): a passive MJCF four-bar written here (a ``<connect>`` loop, no ``<actuator>``), as
MuJoCo's closed-chain test models are."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import pkm
from pkm.core.formats.load import given, given_task
from pkm.errors import InvalidInputError, PkmWarning, SpecError, SpecNameError

# Crank 0.1 m and rocker pivots 0.3 m apart; coupler tip (0.3, 0, 0.1) from the crank's tip; closed at q = 0.
FOURBAR = """<mujoco model="passive_fourbar">
  <worldbody>
    <body name="crank">
      <joint name="crank_joint" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0.1 0 0" size="0.01" mass="0.1"/>
      <body name="coupler" pos="0.1 0 0">
        <joint name="coupler_joint" type="hinge" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 0.3 0 0.1" size="0.01" mass="0.2"/>
        <site name="coupler_tip" pos="0.3 0 0.1"/>
      </body>
    </body>
    <body name="rocker" pos="0.3 0 0">
      <joint name="rocker_joint" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0.1 0 0.1" size="0.01" mass="0.1"/>
      <site name="rocker_tip" pos="0.1 0 0.1"/>
    </body>
  </worldbody>
  <equality>
    <connect name="pin" site1="coupler_tip" site2="rocker_tip"/>
  </equality>
  ACTUATORS
</mujoco>
"""


@pytest.fixture(scope="module")
def passive(tmp_path_factory):
    path = tmp_path_factory.mktemp("given") / "fourbar.xml"
    path.write_text(FOURBAR.replace("ACTUATORS", ""))
    return path


def test_a_passive_file_is_refused_without_actuated_and_says_how_to_give_them(passive):
    with pytest.raises(SpecError, match=r"names no actuated joint: no actuators named: give actuated=\[\.\.\.\]"):
        pkm.load(passive)


def test_actuated_and_task_in_code_load_it_and_fk_ik_round_trip(passive):
    """The crank driven, the coupler tip's z the task: FK at a crank angle, then IK of that z gives the angle back
    (1e-9 rad), and the loop is closed (1e-10 m); the three forms of ``task`` give the same task."""
    mech = pkm.load(passive, actuated=["crank_joint"], task="coupler_tip:z")
    assert mech.actuated_names == ("crank_joint",) and mech.spec.end_effector == "coupler_tip"
    assert list(pkm.TaskMap.of(mech).kinds) == ["z"] and [c.name for c in mech.spec.closures] == ["pin"]
    fk = pkm.close_loops(mech, [0.2])
    assert fk.residual < 1e-10
    z = pkm.TaskMap.of(mech).named(fk.q)["z"]
    ik = pkm.solve_ik(mech, {"z": z}, fk.q + 0.05)
    assert abs(ik.q[0] - 0.2) < 1e-9 and ik.residual < 1e-10
    for form in (("coupler_tip", "z"), ("coupler_tip", ["z"]), {"end_effector": "coupler_tip", "components": ["z"]}):
        assert given("crank_joint", form) == given(["crank_joint"], "coupler_tip:z")
    assert given_task("tip") == ("tip", pkm.core.model.spec.TaskSpec(("x", "y", "z")))  # a frame: its origin
    plain = pkm.load(passive, actuated="crank_joint")  # no task: the actuated joint
    assert plain.spec.task.joints == ("crank_joint",) and plain.spec.end_effector is None


def test_bad_names_and_forms_are_pkm_errors_listing_the_valid_ones(passive):
    with pytest.raises(SpecNameError, match="valid joints: 'crank_joint', 'coupler_joint', 'rocker_joint'"):
        pkm.load(passive, actuated=["crank"])
    with pytest.raises(SpecNameError, match="frame 'nope' does not exist"):
        pkm.load(passive, actuated=["crank_joint"], task="nope:x")
    with pytest.raises(InvalidInputError, match=r"task: task.components \['w'\] unknown"):
        pkm.load(passive, actuated=["crank_joint"], task="coupler_tip:w")
    with pytest.raises(InvalidInputError, match="actuated: name at least one joint, each once"):
        pkm.load(passive, actuated=["crank_joint", "crank_joint"])
    with pytest.raises(InvalidInputError, match="'delta' is a shipped mechanism"):
        pkm.load("delta", actuated=["motor_1"])


def test_actuated_in_code_replaces_the_files_with_a_warning(tmp_path):
    """A file naming the crank's motor, loaded with the rocker driven: the code wins, the warning says what it
    replaced; the file's drive values go with the joint it no longer drives."""
    path = tmp_path / "driven.xml"
    path.write_text(FOURBAR.replace("ACTUATORS", '<actuator><motor joint="crank_joint" gear="2"/></actuator>'))
    assert pkm.load(path).actuated_names == ("crank_joint",)
    with pytest.warns(PkmWarning, match=r"actuated=\['rocker_joint'\] given in code replaces the actuated joints "
                                        r"the files name, \['crank_joint'\]"):
        mech = pkm.load(path, actuated=["rocker_joint"])
    assert mech.actuated_names == ("rocker_joint",) and mech.spec.task.joints == ("rocker_joint",)
    assert "actuated=['rocker_joint'] given in code replaces the actuated joints the files name, ['crank_joint']" \
        in mech.notes
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert pkm.load(path, actuated=["crank_joint"]).actuated_names == ("crank_joint",)  # the same: silent


def test_a_spec_with_no_actuated_joints_takes_them_from_code(passive):
    """A closure spec naming the file and ``actuated = []`` (its loops only): actuated= fills it in."""
    spec = passive.parent / "fourbar.closures.toml"
    spec.write_text('format = "pkm.closures/1"\nmechanism = "fb"\nurdf = "fourbar.xml"\nactuated = []\n')
    with pytest.raises(SpecError, match="'actuated' must name at least one joint"):
        pkm.load(spec)
    mech = pkm.load(spec, actuated=["crank_joint"], task=("coupler_tip", "x"))
    assert mech.actuated_names == ("crank_joint",) and list(pkm.TaskMap.of(mech).kinds) == ["x"]


def test_the_command_line_takes_actuated_and_task(passive, capsys):
    from pkm.cli.app import main

    assert main(["fk", str(passive), "--actuated", "crank_joint", "--task", "coupler_tip:z",
                 "--joints", "crank_joint=0.2"]) == 0
    out = json.loads(capsys.readouterr().out)
    mech = pkm.load(passive, actuated=["crank_joint"], task="coupler_tip:z")
    assert np.isclose(out["task"]["z"], pkm.TaskMap.of(mech).named(pkm.close_loops(mech, [0.2]).q)["z"], atol=1e-12)


@pytest.mark.filterwarnings("ignore::pkm.errors.ImplausibleModelWarning")  # (the file's 654 t spheres)
def test_a_gepetto_yaml_without_name_mot_takes_them_from_code(tmp_path):
    """Gepetto's five-bar with ``name_mot: []``: refused alone, loaded with its motors given in code as its own
    ``name_mot`` loads it (the same mechanism)."""
    from pkm.core.formats.catalogue import catalogue_path
    from pkm.core.model.compare import mechanism_differences

    source = catalogue_path("gepetto:5bar_linkage")
    (tmp_path / "robot.urdf").write_text((source / "robot.urdf").read_text())
    (tmp_path / "robot.yaml").write_text((source / "robot.yaml").read_text().replace("['mot1', 'mot2']", "[]"))
    with pytest.raises(SpecError):
        pkm.load(tmp_path)
    mech = pkm.load(tmp_path, actuated=["mot1", "mot2"])
    assert mech.actuated_names == ("mot1", "mot2")
    assert mechanism_differences(mech, pkm.load(source)) == []


def test_pkm_list_says_to_give_actuated(passive, capsys):
    from pkm.cli.app import main

    assert main(["list", str(passive)]) != 0
    assert "no actuators named: give actuated=[...]" in capsys.readouterr().err


def test_an_upload_takes_actuated_and_task_as_pkm_load_does(passive):
    """load_texts (the service's uploads): the passive MJCF alone is refused without actuated=, loads with it as
    pkm.load loads the file (same actuators, task and reference, 1e-12); a spec with ``actuated = []`` and a Gepetto
    YAML with ``name_mot: []`` sent with their model files take them too; a bad form is an InvalidInputError."""
    from pkm.core.formats.catalogue import catalogue_path
    from pkm.core.formats.load import load_texts

    files = {"fourbar.xml": passive.read_text()}
    with pytest.raises(SpecError, match=r"names no actuated joint: give actuated=\[\.\.\.\]"):
        load_texts(files)
    mech = load_texts(files, actuated="crank_joint", task="coupler_tip:z")
    ref = pkm.load(passive, actuated=["crank_joint"], task="coupler_tip:z")
    assert mech.actuated_names == ref.actuated_names and mech.spec.end_effector == "coupler_tip"
    assert mech.spec.task == ref.spec.task and np.abs(mech.q_reference - ref.q_reference).max() <= 1e-12
    spec = 'format = "pkm.closures/1"\nmechanism = "fb"\nurdf = "fourbar.xml"\nactuated = []\n'
    assert load_texts({**files, "fb.toml": spec}, actuated=["rocker_joint"]).actuated_names == ("rocker_joint",)
    source = catalogue_path("gepetto:5bar_linkage")
    pair = {"robot.urdf": (source / "robot.urdf").read_text(),
            "robot.yaml": (source / "robot.yaml").read_text().replace("['mot1', 'mot2']", "[]")}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pkm.errors.ImplausibleModelWarning)  # (the file's 654 t spheres)
        assert load_texts(pair, actuated=["mot1", "mot2"]).actuated_names == ("mot1", "mot2")
    with pytest.raises(InvalidInputError, match="actuated"):
        load_texts(files, actuated=[])
