"""A model whose inertias no distribution of mass has (a negative principal moment; moments that break the triangle
inequality): it loads for its kinematics, which needs no inertia, with an ImplausibleModelWarning naming each body and
rule (:mod:`pkm.core.model.plausibility`); its dynamics is refused by a NonPhysicalInertiaError naming them.

The models: pkm's Gepetto five-bar (``examples/gepetto_fivebar``, a planar five-bar whose links carry physical
inertias) with ``proximal1``'s ``iyy`` made negative, or ``distal1``'s ``izz`` made more than ``ixx + iyy``.
"""

from __future__ import annotations

import pickle
import shutil
from pathlib import Path

import numpy as np
import pytest

import pkm
from pkm.core.model.plausibility import nonphysical
from pkm.errors import ImplausibleModelWarning, NonPhysicalInertiaError, PkmError
from tests import fd

FIVEBAR = Path(__file__).resolve().parents[3] / "examples" / "gepetto_fivebar"
#: ``{case: (text replaced, by, link, rule, value)}``; "products": a tensor of products alone, as Phobos 0.7 wrote
#: hyrodyn's RH5 leg (``LLAnkle_E11_Link``: ixx = iyy = izz = 0, iyz = 0.001; principal moments -0.001, 0, 0.001).
EDITS = {"negative": ('iyy="0.0005208333333333333"', 'iyy="-0.0005208333333333333"', "proximal1", "negative",
                      -0.000520833),
         "products": ('<inertia ixx="0.0" ixy="0.0" ixz="0.0" iyy="0.0005208333333333333" iyz="0.0" '
                      'izz="0.0005208333333333333"/>',
                      '<inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0.001" izz="0"/>', "proximal1", "negative",
                      -0.001),
         "triangle": ('izz="0.0007499999999999999"', 'izz="0.0027499999999999999"', "distal1", "triangle", 0.002)}


def _load(tmp_path_factory, case: str):
    old, new, _, rule, _ = EDITS[case]
    folder = tmp_path_factory.mktemp(case)
    shutil.copy(FIVEBAR / "robot.yaml", folder)
    (folder / "robot.urdf").write_text((FIVEBAR / "robot.urdf").read_text().replace(old, new, 1))
    with pytest.warns(ImplausibleModelWarning) as caught:
        mech = pkm.load(folder)
    found = [w.message for w in caught if isinstance(w.message, ImplausibleModelWarning) and w.message.kind == rule]
    return mech, found


@pytest.fixture(scope="module", params=sorted(EDITS))
def model(request, tmp_path_factory):
    _, _, link, rule, value = EDITS[request.param]
    return (rule, link, value), *_load(tmp_path_factory, request.param)


def test_it_loads_with_a_warning_naming_the_body_and_the_rule(model):
    (rule, link, value), mech, found = model
    (w,) = found
    assert w.names == (link,) and w.values[0] == pytest.approx(value, rel=1e-6) and str(w) in mech.notes
    assert nonphysical(mech) == ((link, rule, pytest.approx(value, rel=1e-6)),)


def test_its_kinematics_is_answered_and_its_jacobian_matches_differences(model):
    _, mech, _ = model
    fk = pkm.close_loops(mech, mech.actuated_q(mech.q_reference) + np.array([0.1, -0.05]))
    assert fk.residual <= 1e-10
    assert fd.forward_jacobian_error(mech, fk.q) <= 1e-6
    qd = np.array([0.3, -0.2])
    assert np.all(np.isfinite(pkm.velocities(mech, fk.q, qd)))


def test_its_dynamics_is_refused_naming_the_body(model):
    (rule, link, value), mech, _ = model
    q, v, na = mech.q_reference, np.zeros(mech.nv), mech.na
    calls = {"inverse dynamics": lambda: pkm.inverse_dynamics(mech, q, v, v),
             "dynamic model": lambda: pkm.mass_matrix(mech, q),
             "forward dynamics": lambda: pkm.forward_dynamics(mech, q, v, np.zeros(na)),
             "simulation": lambda: pkm.simulate(mech, duration=0.01),
             "energy": lambda: pkm.core.dynamics.energy(mech, q, v)}
    for what, call in calls.items():
        with pytest.raises(NonPhysicalInertiaError, match=rf"{what}.* refused: the inertias of '{link}'") as exc:
            call()
        err = exc.value
        assert isinstance(err, PkmError) and err.links == (link,) and err.rules == (rule,)
        assert err.values[0] == pytest.approx(value, rel=1e-6)
        back = pickle.loads(pickle.dumps(err))
        assert back.links == err.links and str(back) == str(err)


def test_the_consistent_identification_and_the_compiled_dynamics_are_refused_too(model):
    """The consistent estimate starts from the model's inertias (its prior); the twin's actuator-space model (the
    compiled kernels' dynamics, the exported C library's) is built from them."""
    from pkm.core.identification.consistent import consistent_estimate
    from pkm.core.twin.kernels import Kernels

    (rule, _, _), mech, _ = model
    z = np.zeros((1, mech.na))
    with pytest.raises(NonPhysicalInertiaError, match="physically consistent estimate"):
        consistent_estimate(mech, np.array([mech.q_reference]), z, z, z)
    with pytest.raises(NonPhysicalInertiaError, match="compiled dynamics") as exc:
        _ = Kernels(mech).dynamics
    assert exc.value.rules == (rule,)


def test_the_regressor_needs_no_inertia_and_is_answered(model):
    """Identifying the inertias needs none: the regressor of the non-physical model is the physical one's (the five-bar
    has no idle motion, so the map Ĝ does not depend on the inertias)."""
    _, mech, _ = model
    good = pkm.load(FIVEBAR)
    q, qd, qdd = good.q_reference, np.array([0.5, -0.2]), np.array([1.0, 2.0])
    assert np.array_equal(pkm.regressor(mech, q, qd, qdd), pkm.regressor(good, q, qd, qdd))


def test_a_design_that_sets_an_inertia_in_place_is_judged_on_its_own_inertias():
    """design_mechanism sets the bodies' parameters in the built model: what was derived from the file's inertias is
    made again, so its dynamics is refused for the design's negative moment, and answered again (the file's own
    efforts) for a design that puts the file's moment back."""
    from pkm.core.twin.design import design_mechanism

    good = pkm.load(FIVEBAR)
    q, v = good.q_reference, np.zeros(good.nv)
    bad = design_mechanism(good, {"proximal1.Iyy": -1.0})
    with pytest.raises(NonPhysicalInertiaError) as exc:
        pkm.inverse_dynamics(bad, q, v, v)
    assert exc.value.links == ("proximal1",) and exc.value.rules == ("negative",)
    fixed = design_mechanism(bad, {"proximal1.Iyy": 5.2083333333333333e-4 + 0.1 * 0.125 ** 2})  # (about the joint)
    a = pkm.accelerations(good, q, v, np.array([1.0, -0.5]))
    tau = pkm.inverse_dynamics(good, q, v, a)
    assert np.abs(tau).max() > 0 and np.allclose(pkm.inverse_dynamics(fixed, q, v, a), tau, rtol=1e-12, atol=0)


def test_the_compiled_kernels_at_a_non_physical_design_refuse_its_dynamics_not_its_kinematics():
    """Kernels.at evaluates the shared kernels at a design's inertias: its dynamics kernels are refused there, its
    kinematics kernels answer (the Jacobian the core's)."""
    from pkm.core.twin.kernels import Kernels

    good = pkm.load(FIVEBAR)
    K = Kernels(good, design=("proximal1.Iyy",), compiled=False)
    bad = K.at({"proximal1.Iyy": -1.0})
    q, qd = good.q_reference, np.zeros(good.na)
    with pytest.raises(NonPhysicalInertiaError, match="compiled inverse dynamics") as exc:
        bad.inverse_dynamics(q, qd, qd)
    assert exc.value.links == ("proximal1",)
    assert np.allclose(bad.forward_jacobian(q), pkm.forward_jacobian(good, q), rtol=1e-12, atol=1e-14)
