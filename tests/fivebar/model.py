"""The five-bar as a Pinocchio tree plus one point closure."""

from __future__ import annotations

import math

from pkm.core.model.spec import Branch, Closure, ClosureSpec, TaskSpec
from pkm.core.model.urdf import UrdfBuilder
from pkm.mechanisms._common import PM54_040, make_mechanism, rod_inertia, spec_parameters
from tests.fivebar.kinematics import inverse_kinematics, reference_pose
from tests.fivebar.params import BRANCHES, NAME, FiveBarParams


def urdf_xml(p: FiveBarParams, *, spinning_rod: bool = False) -> str:
    """The tree; ``spinning_rod``: distal link 1 may also spin about its own axis (joint ``spin_1`` after
    ``elbow_1``), an idle motion like a rod's between two ball joints (for the tests of idle motions)."""
    b = UrdfBuilder(NAME)
    b.link("base")
    for i, x in enumerate((-p.d / 2.0, p.d / 2.0)):
        n = i + 1
        b.link(f"proximal_{n}", p.m_link, (p.l1 / 2.0, 0.0, 0.0), rod_inertia(p.m_link, p.l1, 0))
        b.joint(f"motor_{n}", "revolute", "base", f"proximal_{n}", (x, 0.0, 0.0), effort=PM54_040.effort, velocity=PM54_040.speed)
        b.link(f"distal_{n}", p.m_link, (p.l2 / 2.0, 0.0, 0.0), rod_inertia(p.m_link, p.l2, 0))
        if spinning_rod and n == 1:
            b.link("hub_1")
            b.joint("elbow_1", "revolute", "proximal_1", "hub_1", (p.l1, 0.0, 0.0))
            b.joint("spin_1", "revolute", "hub_1", "distal_1", axis=(1.0, 0.0, 0.0))
        else:
            b.joint(f"elbow_{n}", "revolute", f"proximal_{n}", f"distal_{n}", (p.l1, 0.0, 0.0))
        b.frame(f"tip_{n}", f"distal_{n}", (p.l2, 0.0, 0.0))
    return b.to_xml()


def closure_spec(p: FiveBarParams) -> ClosureSpec:
    reference = {k: tuple(v) for k, v in inverse_kinematics(p, reference_pose(p)).items()}
    branches = {}
    for name in BRANCHES:
        q = inverse_kinematics(p, reference_pose(p), name)
        branches[name] = Branch(name, {f"elbow_{n}": int(math.copysign(1, q[f"elbow_{n}"][0])) for n in (1, 2)})
    return ClosureSpec(mechanism=NAME, description="toy planar five-bar (tests only)", urdf=f"{NAME}.urdf",
                       end_effector="tip_1", actuated=("motor_1", "motor_2"),
                       closures=(Closure("tip", "point", "tip_1", "tip_2"),), task=TaskSpec(("x", "y")),
                       reference=reference, branches=branches, default_branch="elbows_out",
                       parameters=spec_parameters(p))


def build(p: FiveBarParams | None = None):
    p = FiveBarParams() if p is None else p
    return make_mechanism(urdf_xml(p), closure_spec(p), p)
