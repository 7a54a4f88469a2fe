"""pkm.core.model.plausibility: the warnings a model no real mechanism has gets on load (issue 41), checked on
Gepetto's robots, the acceptance set and pkm's own mechanisms (which fire, with which values), scale-aware (a body
too heavy for a small Delta is not for one ten times larger), on an inertia that breaks the triangle inequality and
on placeholder limits."""

from __future__ import annotations

import dataclasses
import re
import warnings

import numpy as np
import pytest

import pkm
from pkm.core.model.plausibility import DENSITY, findings, size
from pkm.errors import ImplausibleModelWarning
from pkm.mechanisms import module
from tests.test_acceptance import ACCEPTANCE
from tests.test_acceptance import load as acceptance
from tests.test_gepetto_robots import ROBOTS, gepetto

#: What fires (kind of rule per model): Gepetto's five-bar alone, its two 654,498 kg links; every other model of the
#: three sets, pkm's own mechanisms among them, fires nothing.
FIRES = {"gepetto:5bar_linkage": {"mass"}}


def test_which_models_fire_and_the_gepetto_five_bar_s_links(built):
    found = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ImplausibleModelWarning)
        models = {**{f"gepetto:{n}": gepetto(n) for n in ROBOTS}, **{f"acceptance:{n}": acceptance(n) for n in ACCEPTANCE},
                  **{n: built(n) for n in ("delta", "prs3", "rrr3", "hexapod", "gough_stewart", "fivebar")}}
    for name, mech in models.items():
        kinds = {w.kind for w in findings(mech)}
        if kinds:
            found[name] = kinds
    assert found == FIRES
    (w,) = findings(models["gepetto:5bar_linkage"])
    L = size(models["gepetto:5bar_linkage"])
    assert w.names == ("sphere", "sphere_2") and np.allclose(w.values, 654498.4694978736, rtol=1e-9)
    assert w.bound == pytest.approx(DENSITY * L ** 3, rel=1e-12) and 0.9 < L < 1.0  # (7205 kg: 91 times less)
    assert str(w) in models["gepetto:5bar_linkage"].notes and "654498 kg" in str(w)


def test_the_mass_rule_is_scale_aware():
    """An 800 kg platform is heavier than a steel cube enclosing the reference Delta (0.45 m: 731 kg), not than one
    enclosing a Delta ten times larger (731 t); masses scaled by 10^3 with the lengths keep a design as plausible."""
    delta = module("delta")
    small = delta.Params(m_platform=800.0)
    large = dataclasses.replace(small, La=1.1, Lb=3.3, r=0.5, R=1.5)
    with pytest.warns(ImplausibleModelWarning, match=r"'platform' 800 kg") as w:
        mech = delta.build(small)
    L = size(mech)
    assert w[0].message.kind == "mass" and w[0].message.bound == pytest.approx(DENSITY * L ** 3, rel=1e-12)
    assert 0.45 <= L < 0.451 and w[0].message.names == ("platform",) and w[0].message.values == (800.0,)
    assert findings(delta.build(large)) == []


def test_triangle_inequality_and_placeholder_limits(built):
    delta = built("delta")
    urdf = re.sub(r'(<link name="platform">.*?<inertia )[^/]*/>',
                  r'\1ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.003"/>', delta.urdf, flags=re.S)
    with pytest.warns(ImplausibleModelWarning, match="triangle inequality") as w:
        pkm.from_strings(urdf, delta.spec)
    assert w[0].message.kind == "triangle" and w[0].message.names == ("platform",)
    assert w[0].message.values[0] == pytest.approx(0.001, rel=1e-9)
    same = {j: {"effort_limit": 1000.0, "velocity_limit": 100.0} for j in delta.actuated_names}
    with pytest.warns(ImplausibleModelWarning, match="placeholders") as w:
        pkm.with_actuators(delta, same)
    assert w[0].message.kind == "limits" and w[0].message.values == (1000.0, 100.0)
    assert w[0].message.names == delta.actuated_names
    with warnings.catch_warnings():
        warnings.simplefilter("error", ImplausibleModelWarning)
        pkm.with_actuators(delta, {**same, "motor_2": {"effort_limit": 999.0}})  # (not all alike: no warning)
        assert findings(delta) == []  # (the Delta's motors: a servo's 3.9 N m and 2.974 rad/s)
    assert delta.actuators[0].effort_limit == 3.9 and delta.actuators[0].velocity_limit == pytest.approx(2.974, abs=1e-3)


def test_an_identified_body_far_off_is_judged_by_the_mechanism_s_size_once_naming_the_identified_model(built):
    """Issue 52: an identified body of almost no mass with a first moment (its centre of mass 5 m out) made the
    Delta's extent 5 m (the centres of mass counted), and the warning fired twice (the identified model built, then
    rebuilt with its drives), naming the shipped spec. Now: one warning, against the Delta's 0.45 m, naming the
    identified model."""
    from pkm.core.identification.export import identified_mechanism
    from pkm.core.identification.regressor import parameters

    delta = built("delta")
    P = parameters(delta)
    theta = P.values.copy()
    k = P.names.index("forearm_1.m")
    theta[k:k + 10] = [1e-6, 5e-6, 0.0, 0.0, 1e-3, 0.0, 1e-3, 0.0, 0.0, 1e-3]  # (m, m c, inertia about the joint)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = identified_mechanism(delta, theta, source="out/delta.closures.toml")
    found = [w.message for w in caught if isinstance(w.message, ImplausibleModelWarning)]
    assert len(found) == 1 and found[0].kind == "inertia" and found[0].names == ("forearm_1",)
    assert str(found[0]).startswith("out/delta.closures.toml: ") and "extent squared (0.4503 m)" in str(found[0])
    assert size(out) == pytest.approx(size(delta), rel=1e-12) and out.notes.count(str(found[0])) == 1
    with pytest.warns(ImplausibleModelWarning, match=r"^the model identified from .*delta"):
        identified_mechanism(delta, theta)


def test_a_negligible_body_is_not_judged_by_the_inertia_rules(built):
    """The consistent estimate's massless links of the identification tour (issue 52): 1.6e-7 kg carrying 2.9e-6
    kg m^2, another breaking the triangle inequality by 4e-14 kg m^2, on a Delta whose M L^2 is 0.13 kg m^2: no
    measurement sees them; inertias 1000 and 1e9 times larger are judged."""
    from pkm.core.identification.export import identified_mechanism
    from pkm.core.identification.regressor import parameters

    delta = built("delta")
    P = parameters(delta)
    for scales, fired in (((1.0, 1.0), set()), ((1e3, 1e9), {"inertia", "triangle"})):
        theta = P.values.copy()
        for body, m, moments, scale in (("knee_cross_2", 1.6e-7, (2.9e-6, 2.9e-6, 2.9e-6), scales[0]),
                                        ("knee_cross_3", 1e-3, (1e-13, 1e-13, 2.4e-13), scales[1])):
            k = P.names.index(f"{body}.m")
            theta[k:k + 10] = [m, 0, 0, 0, moments[0] * scale, 0, moments[1] * scale, 0, 0, moments[2] * scale]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ImplausibleModelWarning)
            out = identified_mechanism(delta, theta)
        assert {w.kind for w in findings(out)} == fired
