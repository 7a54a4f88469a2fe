"""The ten robots of Gepetto's example-parallel-robots (URDF + robot.yaml, exported from Onshape), shipped unmodified
in ``urdf/gepetto/`` with their licence and loaded by name from pkm's catalogue (``pkm.load("gepetto:<robot>")``:
:mod:`pkm.core.formats.catalogue`), so that a clone with nothing beside it runs these tests.

Nine load and are given every generic answer: assembled (closure residual <= 1e-10); their loops closed again from
a perturbed seed (every joint moved by up to 0.05 rad or m) with the actuators held; the forward Jacobian equal to
Richardson-extrapolated finite differences of the loop closure (<= 1e-6 relative); the inverse dynamics fed to
Pinocchio's ``constraintDynamics`` giving back the actuated and task accelerations (<= 1e-8 relative), as in
``tests/test_acceptance.py``. ``kangaroo_like`` cannot be assembled as a whole (its 6-D loops do not close): it must be
refused with a message that names a closure.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.formats.catalogue import CATALOGUE, catalogue_path
from pkm.core.kinematics import constraints
from pkm.errors import PkmError
from tests.fd import forward_jacobian_error
from tests.test_acceptance import check_efforts_give_back_accelerations, moved

#: The robots that load and answer, and the one that must be refused.
ROBOTS = ("5bar_linkage", "5bar_linkage_iso3d", "battobot_6d", "cassie_like", "digit_like", "disney_like",
          "robot_delta", "talos_like", "wl16_like")
UNCLOSABLE = "kangaroo_like"
_CACHE: dict[str, pkm.Mechanism] = {}


def gepetto(name: str) -> pkm.Mechanism:
    """Gepetto's robot ``name``, loaded once per test process."""
    if name not in _CACHE:
        _CACHE[name] = pkm.load(f"gepetto:{name}")
    return _CACHE[name]


def test_the_catalogue_is_sorted_and_ships_the_ten_robots_with_their_licence():
    assert list(CATALOGUE) == sorted(CATALOGUE)
    gepetto_names = [n for n in CATALOGUE if n.startswith("gepetto:")]
    assert gepetto_names == sorted(f"gepetto:{n}" for n in (*ROBOTS, UNCLOSABLE))
    for name in gepetto_names:
        folder = catalogue_path(name)
        assert (folder / "robot.urdf").is_file() and (folder / "robot.yaml").is_file()
    root = catalogue_path("gepetto:robot_delta").parent
    assert "BSD 3-Clause License" in (root / "LICENSE").read_text()
    assert "52e64b3" in (root / "SOURCE.txt").read_text()


@pytest.mark.parametrize("name", ROBOTS)
def test_it_loads_assembled(name):
    mech = gepetto(name)
    assert mech.na >= 2 and len(mech.spec.closures) >= 1
    assert constraints.worst_closure(mech, constraints.residual(mech, mech.q_reference))[0] <= 1e-10


@pytest.mark.parametrize("name", ROBOTS)
def test_its_loops_close_again_from_a_perturbed_seed(name):
    mech = gepetto(name)
    qa = mech.actuated_q(mech.q_reference)
    step = 0.05 * np.random.default_rng(0).uniform(-1.0, 1.0, mech.nv)
    step[mech.act_v] = 0.0
    fk = pkm.close_loops(mech, qa, pin.integrate(mech.model, mech.q_reference, step))
    assert fk.residual <= 1e-10 and np.abs(mech.actuated_q(fk.q) - qa).max() <= 1e-12


@pytest.mark.parametrize("name", ROBOTS)
def test_the_forward_jacobian_matches_finite_differences(name):
    mech = gepetto(name)
    assert forward_jacobian_error(mech, moved(mech)) <= 1e-6


@pytest.mark.parametrize("name", ROBOTS)
def test_constraint_dynamics_gives_back_the_accelerations_the_efforts_were_computed_for(name):
    mech = gepetto(name)
    check_efforts_give_back_accelerations(mech, moved(mech))


def test_battobot_saved_as_a_pkm_spec_loads_back_the_same(tmp_path):
    """Its universal joints (UJOINT_ZY, UJOINT_YZ) written as [joint_types] and read back: the same model."""
    from pkm.core.model.compare import mechanism_differences

    mech = gepetto("battobot_6d")
    text = pkm.save(mech, tmp_path / "battobot.closures.toml").read_text()
    assert 'left_spherical_ankle_1 = "universal_zy"' in text and 'free_knee_left = "universal_yz"' in text
    assert mechanism_differences(pkm.load(tmp_path / "battobot.closures.toml"), mech) == []


def test_kangaroo_is_refused_naming_the_closures_their_gaps_and_the_fix():
    """Five of its eleven 6-D loops cannot close even alone (their frames' axes cannot be aligned; each closes as a
    point closure, the toolbox's '3d'): a PkmError (not a traceback) naming them in the user's terms (the YAML's
    frame pairs), with their gaps, and what would close each one."""
    with pytest.raises(PkmError) as info:
        pkm.load(f"gepetto:{UNCLOSABLE}")
    text = str(info.value)
    assert "the loops cannot be closed" in text and "[reference]" not in text  # (the user wrote none)
    assert "5 closure(s) cannot close even alone" in text and "each closes alone as a point closure" in text
    for k in (2, 7, 8, 9, 10):
        assert f"'closedloop{k}_A'" in text and f"'closedloop{k}_B'" in text
    names = [name for name, _ in info.value.__cause__.closures]
    assert sorted(names) == sorted(f"loop{k}" for k in (2, 7, 8, 9, 10))
    assert all(gap > 1e-4 for _, gap in info.value.__cause__.closures)
