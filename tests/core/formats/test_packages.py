"""pkm.core.formats.packages: models of installed packages by name (example-robot-data's Cassie SDF files, read
where the package installed them, with the closure specs pkm ships)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.formats.imported import import_model, with_file
from pkm.core.formats.packages import PACKAGE_MODELS, PACKAGES, model_file, package_dir
from pkm.core.kinematics.constraints import residual, worst_closure
from pkm.core.model.spec import ClosureSpec
from pkm.errors import PkmWarning, SpecError, UnknownNameError

MOTORS = tuple(f"{side}-{joint}-op" for side in ("left", "right") for joint in ("roll", "yaw", "pitch", "knee", "foot"))


def test_the_registry_is_sorted_and_every_entry_names_its_files():
    assert list(PACKAGE_MODELS) == sorted(PACKAGE_MODELS)
    for name, entry in PACKAGE_MODELS.items():
        assert name.partition(":")[0] == entry.package and entry.package in PACKAGES
        spec_path, path = model_file(name)
        assert spec_path.is_file() and path.is_file() and path.is_relative_to(package_dir(entry.package))


@pytest.fixture(scope="module", params=sorted(PACKAGE_MODELS))
def cassie(request) -> pkm.Mechanism:
    return pkm.load(request.param)


def test_cassie_loads_by_name_assembled_with_as_many_degrees_of_freedom_as_motors(cassie):
    """The SDF's own pose closes its loops (1e-10 m); the knee spring held rigid, the ten motors fit the mobility."""
    assert cassie.actuated_names == MOTORS
    assert worst_closure(cassie, residual(cassie, cassie.q_reference))[0] <= 1e-10
    diag = pkm.diagnose(cassie, cassie.q_reference)
    assert (diag.mobility, diag.idle_motions) == (10, 0)


def test_cassie_closes_its_loops_from_a_perturbed_seed(cassie):
    """Knees bent by 0.2 rad and the left toe by 0.3 rad, from the reference perturbed by 0.02 rad on every
    passive joint: Newton converges (1e-10), the actuators where asked; the heel spring follows the knee."""
    rng = np.random.default_rng(7)
    seed = pin.integrate(cassie.model, cassie.q_reference, 0.02 * rng.standard_normal(cassie.nv))
    seed = cassie.with_actuated(seed, cassie.actuated_q(cassie.q_reference))
    qa = cassie.actuated_q(cassie.q_reference) + np.array([0, 0, 0, -0.2, -0.3, 0, 0, 0, -0.2, 0])
    res = pkm.close_loops(cassie, qa, seed, tol=1e-10)
    assert res.converged and worst_closure(cassie, residual(cassie, res.q))[0] <= 1e-10
    assert np.allclose(cassie.actuated_q(res.q), qa, atol=1e-12)
    assert abs(cassie.q_to_dict(res.q)["left-tarsus-spring-joint"]) > 0.1


def test_cassie_v2_right_toe_loop_is_closed_to_1e_9_only():
    """cassie_v2.sdf rounds its right foot's poses (roll 1.5708, pitches 1.3439 and 1.364): the toe motor's axis is
    7.4e-8 rad off the foot crank's, so the plantar loop moves only by opening about 1e-9 m (the left one, exactly
    parallel, closes to round-off), 2.3e-9 of its characteristic length (0.388 m), the measure of close_loops'
    tolerance. A fixed file would fail this test: then drop it."""
    mech = pkm.load("example-robot-data:cassie_v2")
    qa = mech.actuated_q(mech.q_reference) + np.array([0, 0, 0, 0, 0, 0, 0, 0, 0, -0.3])
    res = pkm.close_loops(mech, qa, tol=1e-12, raise_on_failure=False)
    assert not res.converged and 1e-10 < res.residual < 2e-9
    assert worst_closure(mech, residual(mech, res.q))[2] == "right-plantar-foot-joint"
    assert not res.converged and 1e-9 < res.relative_residual < 5e-9
    assert pkm.close_loops(mech, qa, tol=5e-9).converged


def test_cassie_rotors_are_mimic_joints_of_the_motor_outputs():
    """cassie.sdf's gearboxes: rotor angle = -output / ratio (ratios 0.04 hip roll and yaw, 0.0625 hip pitch and
    knee, 0.02 foot; every axis pair in the same sense)."""
    mech = pkm.load("example-robot-data:cassie")
    for joint, ratio in (("roll", 0.04), ("yaw", 0.04), ("pitch", 0.0625), ("knee", 0.0625), ("foot", 0.02)):
        for side in ("left", "right"):
            jm = mech.model.joints[mech.model.getJointId(f"{side}-{joint}-ip")]
            assert jm.shortname() == "JointModelMimic"
            assert jm.extract().scaling == pytest.approx(-1 / ratio, rel=1e-12)
            assert jm.idx_q == mech.joints[f"{side}-{joint}-op"].idx_q
    assert "gearbox 'left-knee-joint' read as a mimic joint: left-knee-ip = -16 left-knee-op" in mech.notes
    assert any("left-knee-shin-joint (stiffness 1500, rest 0); left-tarsus-spring-joint (stiffness 1250" in n
               for n in mech.notes)
    assert mech.spec.springs["left-tarsus-spring-joint"] == {"stiffness": 1250.0, "rest": 0.0}
    assert "left-knee-shin-joint" not in mech.spec.springs  # (pkm's spec holds the knee spring rigid: fixed)


def test_an_unknown_model_or_package_lists_the_valid_names():
    with pytest.raises(UnknownNameError, match="did you mean 'example-robot-data:cassie'") as info:
        pkm.load("example-robot-data:casie")
    assert set(info.value.valid) == set(PACKAGE_MODELS)
    with pytest.raises(UnknownNameError, match="valid packages: 'example-robot-data'"):
        package_dir("example_robot_data")
    with pytest.raises(UnknownNameError, match="mechanism 'no-such-package:cassie'"):
        pkm.load("no-such-package:cassie")


def test_a_package_that_is_not_installed_says_how_to_install_it(monkeypatch):
    monkeypatch.setitem(PACKAGES, "pkm-no-such-distribution", "robots")
    with pytest.raises(SpecError, match="not installed: pip install pkm-no-such-distribution"):
        package_dir("pkm-no-such-distribution")


def test_cassie_v2_with_both_springs_rigid_reports_its_knees_dependent():
    """Each achilles loop (knee motor, knee-tarsus joint, a revolute at the heel 4.5 degrees out of the leg's plane,
    a ball at the hip) has no motion left once both springs are rigid: mobility 8, the knee motors locked, which
    the load reports (a PkmWarning naming them) and diagnose states."""
    spec_path, path = model_file("example-robot-data:cassie_v2")
    imported = import_model(path)
    rigid = {f"{side}-{joint}": "fixed" for side in ("left", "right")
             for joint in ("knee-shin-joint", "tarsus-spring-joint")}
    spec = with_file(dataclasses.replace(ClosureSpec.load(spec_path), joint_types=rigid), imported, str(spec_path))
    with pytest.warns(PkmWarning, match=r"\['left-knee-op', 'right-knee-op'\] depend on the others \(mobility 8"):
        mech = pkm.from_strings(imported.urdf, spec, source="cassie_v2, springs rigid")
    diag = pkm.diagnose(mech, mech.q_reference)
    assert (diag.mobility, diag.dependent_actuators) == (8, ("left-knee-op", "right-knee-op"))
    qa = mech.actuated_q(mech.q_reference) + np.array([0, 0, 0, -0.05, 0] * 2)
    assert not pkm.close_loops(mech, qa, max_iter=10, raise_on_failure=False).converged


def test_a_package_file_is_read_once_per_process_while_unchanged(monkeypatch):
    """Two loads of Cassie read its SDF once (half a load's time) and give the same mechanism; the cache is keyed
    by the file's path, modification time and size."""
    from pkm.core.formats import load

    reads = []
    monkeypatch.setattr(load, "_PACKAGE_FILES", {})
    monkeypatch.setattr(load, "import_model", lambda path: reads.append(path) or import_model(path))
    a, b = pkm.load("example-robot-data:cassie"), pkm.load("example-robot-data:cassie")
    assert len(reads) == 1 and a is not b and a.urdf == b.urdf and np.array_equal(a.q_reference, b.q_reference)
    ((path, mtime, size),) = load._PACKAGE_FILES
    assert path == str(reads[0]) and (mtime, size) == (reads[0].stat().st_mtime_ns, reads[0].stat().st_size)
