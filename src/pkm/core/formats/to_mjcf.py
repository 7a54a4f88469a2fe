"""Any mechanism pkm loads written as MuJoCo's MJCF: the Pinocchio tree, its inertias, the loops as equalities.

:func:`mjcf_from_mechanism` writes one body per Pinocchio joint (placement and inertia as Pinocchio has them, after
fixed joints are merged), the joint itself (``hinge``, ``slide``, ``ball``, ``free``; a universal joint as two
hinges of one body, about its first axis and then its second, each with the universal's range; a mimic joint as a
joint of its own tied to its leader by a ``<joint>`` equality ``q = offset + scale q_leader``), a site at each closure
frame, a ``<connect>`` (point closure) or ``<weld>`` (frame closure) between the two sites, a ``<motor>`` on each
actuated joint (a differential's motors, the spec's ``[motors]``: each on a ``<tendon><fixed>`` of its joints and
coefficients, ``gear="1"``; their joints get no motor of their own), and the reference configuration as ``<keyframe><key name="reference">`` (:func:`mjcf_qpos`; MuJoCo's
``mj_resetDataKeyframe(model, data, 0)`` starts from it, closed).
Gravity is the model's, contacts are disabled; a one-coordinate joint with position limits
(:attr:`~pkm.core.Mechanism.limits`) has them as its ``range`` (radians or metres: ``<compiler angle="radian">``).

The loop closures (and mimic equalities) are written stiff, not with MuJoCo's default softness (``solref`` (0.02, 1),
``solimp`` (0.9, 0.95, ...), under which a Delta held at rest opens its loops by 0.4 mm). Why a loaded loop opens at
all: MuJoCo solves each equality row for the acceleration ``a1 = d aref + (1 - d) a0`` (``a0`` the row's acceleration
without the constraint, ``aref = -b v - k r`` its reference, ``d`` the impedance), by regularizing the row with ``R =
(1 - d)/d diagApprox``, where ``diagApprox`` is the row's inverse inertia estimated once, at ``qpos0``, from the two
bodies' ``body_invweight0`` (translational for a ``<connect>``, rotational for a weld's angular rows) or the joints'
``dof_invweight0``. At rest the row carries the force ``f`` its load needs and stands open by ``r = R f / k = (1 - d)
(d timeconst dampratio)^2 diagApprox f``: a light link (small mass, tiny rotational inertia, large inverse weight)
carrying a large force or torque opens most. Neither the solver nor its iterations are the cause (the hexapod and
Gepetto's battobot give the same sag with ``tolerance`` 1e-15 and 1000 iterations), and the sag cannot be bought
back by the stiffness alone: MuJoCo's impedance makes a row's own dynamics mass-free, ``r'' = -d (b r' + k r)``, so
its stability bounds ``k dt^2`` whatever the masses. So each of the four factors is taken at its limit:

* ``d`` = 0.9999 (``solimp`` = :data:`SOLIMP`: constant impedance at MuJoCo's largest, ``mjMAXIMP``; MuJoCo clamps
  larger values);
* ``solref = (2 dt, 0.5)`` with ``dt`` the written ``<option timestep>`` (:data:`TIMESTEP`, 1 ms by default):
  ``timeconst = 2 dt`` is the shortest MuJoCo keeps (its ``refsafe`` clamps shorter ones), and ``dampratio``
  :data:`DAMPRATIO` = 0.5 makes ``b = 1/dt`` and ``k = 1/dt^2`` (times ``1/d``): under MuJoCo's semi-implicit Euler
  step a violation is then removed in one step (both roots of the step's characteristic polynomial at 0, deadbeat),
  and the sag is 4 times smaller than with the critically damped ``(2 dt, 1)`` (``k`` 4 times larger; ``k dt^2`` = 2
  would be the stability limit). Under RK4 the row is a continuous oscillator of damping ratio 0.5 at ``1/dt``,
  well inside RK4's stability region;
* a ``<weld>``'s ``torquescale`` = :data:`TORQUESCALE` (10): MuJoCo multiplies the angular rows (residual and
  Jacobian) by it but not their ``diagApprox``, so the angular rows' regularization is 100 times smaller relative
  to their inertia and their sag 100 times smaller (a weld's rotational inverse weight on a light link is 1e3 to
  1e5 times its translational one: Gepetto's battobot's angular rows opened by 1.8e-5 rad). The weld holds the same
  frames (the angular residual is zero exactly where it was); MuJoCo's ``efc_pos`` on those rows is 10 times the
  angle.

Held at rest under gravity (0.1 s or 0.5 s at 1 ms, ``tests/core/formats/test_to_mjcf.py``), every mechanism of the
round-trip matrix stays closed within 2.7e-7 (the hexapod's mimic equalities on its massless knees [rad]; 1.2e-9 m for
the Delta), Gepetto's battobot within 4.6e-8 (from 1.8e-5 with ``(2 dt, 1)`` and no torquescale). A heavier load on a
lighter link still opens more: write a smaller ``timestep`` (the sag goes as its square).

Each actuated joint's drive (:attr:`~pkm.core.Mechanism.actuators`, :mod:`pkm.core.model.actuators`) is written in
the joint's units: the joint's ``armature`` is :attr:`~pkm.core.model.actuators.Actuator.reflected_inertia`
(``rotor_inertia * gear_ratio**2 + armature``), its ``damping`` the viscous friction, its ``frictionloss`` the
Coulomb friction (each left out when 0); its ``<motor>`` has ``gear="1"`` and, when the drive's effort is bounded,
``forcelimited="true" forcerange="-F F"`` with ``F`` the peak effort if finite, else the continuous limit (what a
simulation may apply, as :func:`pkm.simulate` saturates). MJCF has no joint speed limit and one force range: the
velocity limit is not written, and a drive read back has ``F`` as its (continuous) ``effort_limit``, the rotor's
inertia and ratio folded into ``armature``.

The joint springs (``[springs]``, :mod:`pkm.core.model.springs`) are their joints' ``stiffness``, ``springref`` and
``damping`` (on a driven joint added to its drive's: read back, the sum is the drive's ``viscous``), as MuJoCo
applies them.

pkm's own MJCF reader loads the file back (:mod:`pkm.core.formats.mjcf`), which tests the writer; MuJoCo reads it
for the benchmark baseline (:mod:`pkm.bench.mujoco_baseline`). Not written: planar and other composite joints, a
free-flyer below the root (MuJoCo allows free joints only on top-level bodies); each refusal is a
:class:`~pkm.errors.SpecError`. The collision geometry (the URDF text's ``<collision>`` elements,
:mod:`pkm.core.collision.geometry`) is written as geoms of the bodies, MuJoCo's half-sizes, a mesh as an
``<asset><mesh>`` of the file found (one not found: said by :func:`mjcf_omissions`); the file turns contacts off, so
the geoms change no simulation.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pinocchio as pin
from lxml import etree
from numpy.typing import ArrayLike

from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.errors import InvalidInputError, SpecError

_REVOLUTE = {"RX", "RY", "RZ", "RUBX", "RUBY", "RUBZ"}
_PRISMATIC = {"PX", "PY", "PZ"}
#: MuJoCo refuses moving bodies lighter than this, or with a principal inertia under ``MIN_INERTIA`` (a point
#: mass): the compiler raises them to these bounds (``boundmass``, ``boundinertia``), which changes efforts by
#: about ``MIN_INERTIA`` times an angular acceleration.
MIN_MASS, MIN_INERTIA = 1e-9, 1e-12
#: The written ``<option timestep>`` [s] by default (MuJoCo's own default is 2 ms).
TIMESTEP = 1e-3
#: The loop closures' ``solimp`` (impedance ``d`` from ``dmin`` at no violation to ``dmax`` beyond ``width`` [m],
#: ``midpoint``, ``power``): see the module doc.
SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)
#: The loop closures' ``solref`` damping ratio (their time constant is twice the step): see the module doc.
DAMPRATIO = 0.5
#: A ``<weld>``'s ``torquescale``, the factor on its angular rows (see the module doc).
TORQUESCALE = 10.0


def _num(x: ArrayLike) -> str:
    return " ".join(repr(float(v)) for v in np.atleast_1d(x))


def _pose(el: etree._Element, M: pin.SE3) -> None:
    q = pin.Quaternion(M.rotation)
    el.set("pos", _num(M.translation))
    el.set("quat", _num([q.w, q.x, q.y, q.z]))


def body_names(mech: Mechanism) -> list[str]:
    """The MJCF body of each Pinocchio joint (index 0: ``world``): the joint's name with ``_body``."""
    return ["world"] + [f"{mech.model.names[j]}_body" for j in range(1, mech.model.njoints)]


def joint_axis(jm: pin.JointModel) -> tuple[bool, np.ndarray]:
    """``(revolute, axis)`` of a one-coordinate Pinocchio joint (revolute or prismatic, aligned or not; a mimic
    joint's own motion): its motion subspace's angular part, or its linear part, in the joint frame."""
    jd = jm.createData()
    jm.calc(jd, np.zeros(max(jm.idx_q + jm.nq, jm.idx_q + 1)))  # S does not depend on q for these
    S = np.asarray(jd.S, dtype=float).reshape(6, -1)[:, 0]
    if jm.shortname() == "JointModelMimic":
        S = S / float(jm.extract().scaling)
    revolute = bool(np.abs(S[3:]).max() > 0)
    return revolute, S[3:] if revolute else S[:3]


def _joints(el: etree._Element, jm: pin.JointModel, name: str, source: str) -> list[str]:
    """The MJCF joint elements of one Pinocchio joint; returns their names."""
    kind = jm.shortname().removeprefix("JointModel")
    if kind == "Mimic" or kind in _REVOLUTE or kind in _PRISMATIC or kind.endswith("Unaligned"):
        revolute, axis = joint_axis(jm)
        etree.SubElement(el, "joint", name=name, type="hinge" if revolute else "slide", axis=_num(axis))
        return [name]
    if kind == "Universal":
        u = jm.extract()
        for k, axis in ((1, u.axis1), (2, u.axis2)):
            etree.SubElement(el, "joint", name=f"{name}__{k}", type="hinge", axis=_num(np.asarray(axis, dtype=float)))
        return [f"{name}__1", f"{name}__2"]
    if kind == "Spherical":
        etree.SubElement(el, "joint", name=name, type="ball")
        return [name]
    if kind == "FreeFlyer":
        etree.SubElement(el, "freejoint", name=name)
        return [name]
    raise SpecError(source, f"joint {name!r}: MJCF has no {jm.shortname()} (pkm writes revolute, prismatic, "
                            "universal, spherical, free-flyer and mimic joints)")


def mjcf_from_mechanism(mech: Mechanism, model_name: str | None = None, *, timestep: float = TIMESTEP) -> str:
    """The MJCF text of ``mech`` (see the module doc); ``timestep`` [s]: the written ``<option timestep>``, which
    the loop closures' ``solref`` follows (:func:`closure_softness`).

    Raises:
        SpecError: A joint MJCF cannot express (see the module doc).
        InvalidInputError: ``timestep`` not a positive finite number.
    """
    mech = check_mechanism(mech)
    solref, solimp = closure_softness(timestep)
    model = mech.model
    root = etree.Element("mujoco", model=model_name or model.name or "pkm")
    etree.SubElement(root, "compiler", angle="radian", boundmass=repr(MIN_MASS), boundinertia=repr(MIN_INERTIA))
    option = etree.SubElement(root, "option", timestep=repr(float(timestep)), gravity=_num(model.gravity.linear))
    etree.SubElement(option, "flag", contact="disable")
    world = etree.SubElement(root, "worldbody")
    bodies: list[etree._Element] = [world]
    names = body_names(mech)
    equality = etree.Element("equality")
    for j in range(1, model.njoints):
        jm, parent = model.joints[j], int(model.parents[j])
        if jm.shortname() == "JointModelFreeFlyer" and parent != 0:
            raise SpecError(mech.source, f"joint {model.names[j]!r}: MuJoCo allows free joints only on bodies "
                                         "right below the world")
        body = etree.SubElement(bodies[parent], "body", name=names[j])
        _pose(body, model.jointPlacements[j])
        inertia = model.inertias[j]
        I = inertia.inertia
        etree.SubElement(body, "inertial", pos=_num(inertia.lever), mass=repr(max(float(inertia.mass), MIN_MASS)),
                         fullinertia=_num([I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]]))
        for name in _joints(body, jm, model.names[j], mech.source):
            if name in mech.limits and jm.nq == 1:  # (MuJoCo adds a limit row only where a joint reaches it)
                body.find(f"joint[@name='{name}']").set("range", _num(mech.limits[name]))
            elif model.names[j] in mech.limits and jm.shortname() == "JointModelUniversal":  # (both hinges)
                body.find(f"joint[@name='{name}']").set("range", _num(mech.limits[model.names[j]]))
        if jm.shortname() == "JointModelMimic":
            mimic = jm.extract()
            leader = model.names[mimic_leader(model, j)]
            etree.SubElement(equality, "joint", joint1=model.names[j], joint2=leader,
                             polycoef=_num([mimic.offset, mimic.scaling, 0, 0, 0]), solref=_num(solref),
                             solimp=_num(solimp))
        bodies.append(body)
    assets = _geoms(mech, bodies)
    if len(assets):
        root.insert(list(root).index(world), assets)
    for c, (fa, fb) in zip(mech.spec.closures, mech.closure_frames):
        sites = []
        for side, f in (("a", fa), ("b", fb)):
            frame = model.frames[f]
            site = etree.SubElement(bodies[frame.parentJoint], "site", name=f"{c.name}_{side}")
            _pose(site, frame.placement)
            sites.append(site.get("name"))
        el = etree.SubElement(equality, "connect" if c.type == "point" else "weld", name=c.name, site1=sites[0],
                              site2=sites[1], solref=_num(solref), solimp=_num(solimp))
        if c.type != "point":
            el.set("torquescale", repr(TORQUESCALE))
    root.append(equality)
    keyframe = etree.SubElement(root, "keyframe")
    etree.SubElement(keyframe, "key", name="reference", qpos=_num(mjcf_qpos(mech, mech.q_reference)))
    if mech.spec.motors:  # a differential: each motor on a fixed tendon of its joints (read back as [motors])
        tendon = etree.SubElement(root, "tendon")
        for mname, coefs in mech.spec.motors.items():
            fixed = etree.SubElement(tendon, "fixed", name=mname)
            for jname, coef in coefs.items():
                etree.SubElement(fixed, "joint", joint=jname, coef=repr(float(coef)))
    actuator = etree.SubElement(root, "actuator")
    for mname in mech.spec.motors:
        etree.SubElement(actuator, "motor", name=mname, tendon=mname, gear="1")
    differential = {j for coefs in mech.spec.motors.values() for j in coefs}
    for joint, drive in zip(mech.actuated, mech.actuators):
        name = model.names[joint.id]
        el = next(e for e in world.iter("joint") if e.get("name") == name)
        for key, value in (("armature", drive.reflected_inertia), ("damping", drive.viscous),
                           ("frictionloss", drive.coulomb)):
            if value != 0.0:
                el.set(key, repr(value))
        if name in differential:
            continue
        motor = etree.SubElement(actuator, "motor", name=f"{name}_motor", joint=name, gear="1")
        if np.isfinite(drive.max_effort):  # the peak limit when there is one, else the continuous one
            motor.set("forcelimited", "true")
            motor.set("forcerange", _num([-drive.max_effort, drive.max_effort]))
    for name, spring in mech.spec.springs.items():
        write_spring(next(e for e in world.iter("joint") if e.get("name") == name), spring)
    return etree.tostring(root, pretty_print=True, encoding="unicode")


def _geoms(mech: Mechanism, bodies: list[etree._Element]) -> etree._Element:
    """The collision geometry of ``mech``'s URDF text (:mod:`pkm.core.collision.geometry`) as geoms of the bodies
    (``bodies[j]``: joint ``j``'s), MuJoCo's half-sizes; a mesh's file found (as the geometry reads it) as an
    ``<asset><mesh>``, returned (meshes not found: :func:`mjcf_omissions`). The file turns contacts off
    (``<flag contact="disable">``): the geoms describe the bodies' shapes, they change no simulation."""
    from pkm.core.collision.geometry import model_folders, placed_collisions, resolve_mesh

    assets = etree.Element("asset")
    placed, _ = placed_collisions(mech)
    folders = model_folders(mech)
    for c, j, M in placed:
        name = c.name.replace("/", "_")
        if c.kind == "mesh":
            path = resolve_mesh(str(c.filename), folders)
            if path is None:
                continue
            etree.SubElement(assets, "mesh", name=name, file=str(path.resolve()), scale=_num(c.size))
            geom = etree.SubElement(bodies[j], "geom", name=name, type="mesh", mesh=name)
        else:
            s = np.array(c.size)  # (MuJoCo's half-sizes: a box's half-extents, a capsule's radius and half-length)
            size = s / 2 if c.kind == "box" else [s[0], s[1] / 2] if c.kind in ("cylinder", "capsule") else s
            geom = etree.SubElement(bodies[j], "geom", name=name, type=c.kind, size=_num(size))
        if (c.contype, c.conaffinity) != (1, 1):  # (MuJoCo's filter of the pairs, as read)
            geom.set("contype", str(c.contype))
            geom.set("conaffinity", str(c.conaffinity))
        _pose(geom, M)
    return assets


def write_spring(joint: etree._Element, spring: Mapping[str, float]) -> None:
    """A ``[springs.<joint>]`` table (:mod:`pkm.core.model.springs`) as the MJCF ``joint``'s ``stiffness``,
    ``springref`` and ``damping`` (those not zero; the damping added to a drive's, written there before)."""
    for key, attr in (("stiffness", "stiffness"), ("rest", "springref"), ("damping", "damping")):
        if spring.get(key, 0.0) != 0.0:
            joint.set(attr, repr(float(spring[key]) + (float(joint.get(attr, 0.0)) if key == "damping" else 0.0)))


def mjcf_qpos(mech: Mechanism, q: ArrayLike) -> np.ndarray:
    """Pinocchio's configuration ``q`` (nq,) as MuJoCo's ``qpos`` of the file :func:`mjcf_from_mechanism` writes:
    its joints in the file's (depth-first) order; a free body's world position and quaternion ``w x y z``, a ball's
    quaternion ``w x y z``, an unbounded revolute's angle, a mimic joint's own coordinate ``offset + scale
    q_leader``, a universal joint's two angles.

    Raises:
        InvalidInputError: ``q`` not of shape (nq,) or not finite.
    """
    mech = check_mechanism(mech)
    model = mech.model
    q = np.asarray(q, dtype=float)
    if q.shape != (model.nq,) or not np.all(np.isfinite(q)):
        raise InvalidInputError("q", f"must be {model.nq} finite numbers (Pinocchio's configuration)", q)
    children: list[list[int]] = [[] for _ in range(model.njoints)]
    for j in range(1, model.njoints):
        children[int(model.parents[j])].append(j)
    order, stack = [], list(reversed(children[0]))
    while stack:  # the bodies as the file nests them: MuJoCo's order
        j = stack.pop()
        order.append(j)
        stack.extend(reversed(children[j]))
    return np.array([x for j in order for x in qpos_of(model, j, q)])


def qpos_of(model: pin.Model, j: int, q: np.ndarray) -> list[float]:
    """Joint ``j``'s entries of MuJoCo's ``qpos`` for Pinocchio's configuration ``q`` of ``model``: a free joint's
    position and ``(w, x, y, z)`` quaternion in its parent's frame (its placement folded in), a ball's quaternion
    reordered to ``(w, x, y, z)``, an unbounded revolute's angle, a mimic's value; the others as they are."""
    jm = model.joints[j]
    kind = jm.shortname().removeprefix("JointModel")
    seg = q[jm.idx_q:jm.idx_q + jm.nq]
    if kind == "FreeFlyer":
        X = model.jointPlacements[j] * pin.XYZQUATToSE3(seg)
        quat = pin.Quaternion(X.rotation)
        return [*X.translation, quat.w, quat.x, quat.y, quat.z]
    if kind == "Spherical":
        return [seg[3], seg[0], seg[1], seg[2]]
    if kind in ("RUBX", "RUBY", "RUBZ"):
        return [float(np.arctan2(seg[1], seg[0]))]
    if kind == "Mimic":
        mimic = jm.extract()
        return [float(mimic.offset + mimic.scaling * q[jm.idx_q])]
    return list(seg)


def closure_softness(timestep: float = TIMESTEP) -> tuple[tuple[float, float], tuple[float, ...]]:
    """The ``(solref, solimp)`` written on each loop closure's ``<connect>``/``<weld>`` for a step of ``timestep``
    [s]: ``solref = (2 timestep, DAMPRATIO)`` (the shortest time constant MuJoCo keeps: it clamps shorter ones to
    ``2 timestep``; with :data:`DAMPRATIO` 0.5 a violation is removed in one semi-implicit Euler step) and ``solimp`` =
    :data:`SOLIMP` (see the module doc).

    Raises:
        InvalidInputError: ``timestep`` not a positive finite number.
    """
    dt = float(timestep) if isinstance(timestep, (int, float)) and not isinstance(timestep, bool) else float("nan")
    if not (np.isfinite(dt) and dt > 0.0):
        raise InvalidInputError("timestep", "must be a positive, finite number of seconds", timestep)
    return (2.0 * dt, DAMPRATIO), SOLIMP


def mjcf_omissions(mech: Mechanism) -> tuple[str, ...]:
    """What :func:`mjcf_from_mechanism` cannot write of ``mech``, one line each (pkm's MJCF reader gives a mechanism
    without it): the task and end effector, the spec's working modes and design
    parameters, the drives' speed limits and continuous efforts (when a peak is written), the rotor inertia and
    gear ratio (folded into ``armature``), and universal joints' kind (written as two hinges of one body, read back
    as two revolute joints ``<name>__1``, ``<name>__2``)."""
    import json

    mech = check_mechanism(mech)
    spec, out = mech.spec, []
    if not spec.task_is_actuated:
        out.append(f"task: end effector {spec.end_effector!r}, components {' '.join(spec.task.components) or '-'} "
                   "(read back, the task is the actuated joints)")
    if spec.branches:
        out.append(f"working modes ([branches]): {sorted(spec.branches)}")
    if spec.parameters:
        out.append(f"design parameters ([parameters]): {json.dumps(dict(spec.parameters))}")
    differential = {j for coefs in spec.motors.values() for j in coefs}
    for a in mech.actuators:
        shared = a.joint in differential  # (a differential's joint has no motor of its own, no force range)
        lost = [f"{k} {v!r}" for k, v in (("velocity_limit", a.velocity_limit),
                                          ("effort_limit", a.effort_limit if np.isfinite(a.peak_effort) or shared
                                           else np.inf),
                                          ("peak_effort", a.peak_effort if shared else np.inf),
                                          ("rotor_inertia", a.rotor_inertia),
                                          ("gear_ratio", a.gear_ratio if a.gear_ratio != 1.0 else 0.0))
                if np.isfinite(v) and v != 0.0]
        if lost:
            out.append(f"drive of {a.joint!r}: {', '.join(lost)} (MJCF has one force range" + (
                ", on the differential's motors, not this joint" if shared else "") + ", and armature for the rotor)")
    out += geometry_omissions(mech)
    universal = [mech.model.names[j] for j in range(1, mech.model.njoints)
                 if mech.model.joints[j].shortname() == "JointModelUniversal"]
    if universal:
        out.append(f"universal joints {universal}: written as two hinges <name>__1, <name>__2 of one body each (read "
                   "back as two revolute joints of those names)")
    return tuple(out)


def geometry_omissions(mech: Mechanism, world: bool = False) -> list[str]:
    """The collision geometry a writer of another format than URDF leaves out, one line each: meshes not found (and,
    ``world``, for SDFormat: shapes on the world, which it gives no link, and MJCF's contype and conaffinity); the
    other shapes are moved onto the body of the joint that moves their link (named after it when read back)."""
    from pkm.core.collision.geometry import model_folders, placed_collisions, resolve_mesh

    placed, missing = placed_collisions(mech)
    folders = model_folders(mech)
    lost = [f"{c.link} (mesh {c.filename!r} not found)" for c, _, _ in placed
            if c.kind == "mesh" and resolve_mesh(str(c.filename), folders) is None]
    lost += [f"{c.link} (on the world)" for c, j, _ in placed if world and j == 0]
    lost += [f"{link} (no body of the model)" for link in missing]
    out = [f"collision geometry of {', '.join(dict.fromkeys(lost))}"] if lost else []
    if world and any((c.contype, c.conaffinity) != (1, 1) for c, _, _ in placed):  # (SDFormat's bitmasks differ)
        out.append("the collision shapes' contype and conaffinity (MJCF's filter of the pairs checked): read back, "
                   "every pair of shapes is checked")
    return out


def mimic_leader(model: pin.Model, j: int) -> int:
    """The joint a mimic joint ``j`` follows: the one whose coordinates it reads."""
    idx_q = model.joints[j].idx_q
    for k in range(1, model.njoints):
        if k != j and model.joints[k].shortname() != "JointModelMimic" and model.joints[k].idx_q == idx_q:
            return k
    raise SpecError(model.name, f"mimic joint {model.names[j]!r}: no leader found")


__all__ = ["DAMPRATIO", "MIN_INERTIA", "MIN_MASS", "SOLIMP", "TIMESTEP", "TORQUESCALE", "body_names",
           "closure_softness", "joint_axis", "mimic_leader", "mjcf_from_mechanism", "mjcf_omissions", "mjcf_qpos",
           "qpos_of", "write_spring"]
