"""pkm.core.compliance.links: the links as beams of their collision primitive and a material (the Gough-Stewart's
capsule legs: the same as the beams given by name, and Gosselin's J^T diag(k_eff) J with each leg's axial compliance
L / (E A) in series with its drive); links taken rigid named with their reason; no beam at all refused."""

from __future__ import annotations

import math

import numpy as np
import pytest

import pkm
from pkm.core.compliance import stiffness
from pkm.core.compliance.links import ALUMINIUM, STEEL, Beam, Material
from pkm.errors import InvalidInputError
from tests.core.compliance.conftest import legs as anchors

K_LEG = 2.0e6  # N/m: each drive's axial stiffness


def test_the_legs_capsules_are_beams_in_series_with_the_drives(gs, pose):
    """links=Material: each leg's cylinder (a capsule of cylinder_radius, carrying the leg joint at the ball: a span
    of the whole leg) a steel beam, the same stiffness as those Beams given by name (1e-12 relative); the rods (the
    ball at their origin), the platform (a disc) and the base (no geometry) taken rigid and said so; the stiffness is
    Gosselin's J^T diag(k_eff) J, 1/k_eff = 1/k + L/(E A) from the legs' anchors (1e-9 relative), softer than the
    rigid legs'."""
    legs = {j: K_LEG for j in gs.actuated_names}
    K = stiffness(gs, pose, joints=legs, links=STEEL)
    radius = gs.params.cylinder_radius
    named = stiffness(gs, pose, joints=legs, links={f"cylinder_{n}": Beam(E=2.1e11, radius=radius, G=8.1e10)
                                                     for n in range(1, 7)})
    assert set(K.links) == {f"cylinder_{n}" for n in range(1, 7)}
    assert np.abs(K.matrix - named.matrix).max() <= 1e-12 * np.abs(named.matrix).max()
    assert set(K.rigid_links) == {"base", "platform_link"} | {f"rod_{n}" for n in range(1, 7)}
    assert "disc" in K.rigid_links["platform_link"] or "diameter" in K.rigid_links["platform_link"]
    assert "no length" in K.rigid_links["rod_1"] and "no collision geometry" in K.rigid_links["base"]

    b, p, P, _ = anchors(gs, pose)
    length = np.linalg.norm(p - b, axis=1)
    u = (p - b) / length[:, None]
    r = np.hstack([u, np.cross(p - P, u)])
    k_eff = 1.0 / (1.0 / K_LEG + length / (STEEL.E * math.pi * radius**2))
    gosselin = r.T @ (k_eff[:, None] * r)
    assert np.abs(K.matrix - gosselin).max() <= 1e-9 * np.abs(gosselin).max()
    assert np.all(np.linalg.eigvalsh(stiffness(gs, pose, joints=legs).matrix - K.matrix) > 0.0)


def test_a_material_with_no_beam_is_refused_and_bad_materials_too():
    """A mechanism none of whose links is a beam of its collision geometry (the 3-RRR has none): refused, each link
    named with its reason; a modulus not positive refused."""
    rrr3 = pkm.load("rrr3")
    with pytest.raises(InvalidInputError, match="no collision geometry") as err:
        stiffness(rrr3, rrr3.q_reference, joints={j: 2e3 for j in rrr3.actuated_names}, links=ALUMINIUM)
    assert "proximal_1" in str(err.value)
    for bad in (dict(E=0.0), dict(E=7e10, G=-1.0), dict(E=math.nan)):
        with pytest.raises(InvalidInputError):
            Material(**bad)
    assert Material(E=7e10).beam(0.01) == Beam(E=7e10, radius=0.01)


def test_a_spec_states_a_links_compliance():
    """[links.<link>] compliance = 6 x 6 in the spec: written and read back equal, taken by pkm.stiffness by default
    as the same compliance given by name (exactly), links="rigid" overriding it; a 6 x 6 asymmetric by 1e-6 of its
    largest entry refused whatever its scale (a steel bar's: once passed by an absolute 1e-8 test)."""
    import dataclasses

    from pkm.core.model.builder import from_strings
    from pkm.core.model.spec import ClosureSpec

    rrr3 = pkm.load("rrr3")
    q, motors = rrr3.q_reference, {j: 2e3 for j in rrr3.actuated_names}
    C = Beam(E=7e10, radius=0.004).compliance(0.2)
    spec = dataclasses.replace(rrr3.spec, links={"proximal_1": tuple(map(tuple, C))})
    assert ClosureSpec.from_toml(spec.to_toml()) == spec
    stated = from_strings(rrr3.urdf, spec, rrr3.params, "rrr3")
    K = stiffness(stated, q, joints=motors)
    assert set(K.links) == {"proximal_1"}
    assert np.array_equal(K.compliance, stiffness(rrr3, q, joints=motors, links={"proximal_1": C}).compliance)
    assert np.array_equal(stiffness(stated, q, joints=motors, links="rigid").compliance,
                          stiffness(rrr3, q, joints=motors).compliance)
    skew = Beam(E=2.1e11, radius=0.02).compliance(0.2)  # (a steel bar: entries 8e-10 m/N to 1e-5 rad/(N m))
    skew[0, 1] += 1e-6 * np.abs(skew).max()
    with pytest.raises(InvalidInputError, match="symmetric positive definite"):
        stiffness(rrr3, q, joints=motors, links={"proximal_1": skew})


def test_a_box_and_a_capsule_across_the_leg_are_taken_rigid(gs, pose):
    """The Gough-Stewart's files edited: the first leg's capsule a box, the second's turned across the leg (90 deg
    about x, past AXIS_TOL_DEG): both legs rigid with their reasons, the four others still beams."""
    from pkm.core.model.builder import from_strings

    urdf = gs.urdf.replace('<capsule radius="0.03" length="0.25"/>', '<box size="0.06 0.06 0.25"/>', 1)
    head, sep, tail = urdf.partition('<collision name="cylinder_2_0">\n      <origin xyz="0.0 0.0 0.125" rpy="0.0')
    assert sep
    edited = from_strings(head + sep.replace('rpy="0.0', 'rpy="1.5708') + tail, gs.spec, gs.params, "gs")
    K = stiffness(edited, pose, joints={j: K_LEG for j in gs.actuated_names}, links=STEEL)
    assert "box, not one cylinder or capsule" in K.rigid_links["cylinder_1"]
    assert "off its span to joint leg2" in K.rigid_links["cylinder_2"]
    assert set(K.links) == {f"cylinder_{n}" for n in range(3, 7)}
