r"""A whole robot split into its serial tree and its closed sub-mechanisms (:func:`transmissions`).

The rules, in order:

1. **Loops.** Each closure of the spec closes a loop: the joints on the two chains from its frames' joints up to
   their deepest common ancestor (``model.supports``). Loops that share a joint are one **sub-mechanism** (a
   union-find over the closures); its **root** is the deepest joint every one of its loops hangs from, and
   :attr:`Transmission.root` names that joint's body (the body the sub-mechanism's first joints are attached to). Two
   loops that meet only at a body (a knee four-bar carrying an ankle's loops) are two sub-mechanisms, the second
   rooted at a body the first moves. The joints of no loop are the **serial tree**.
2. **Motors**: the robot's actuated joints in the sub-mechanism. A sub-mechanism with none is refused.
3. **Outputs** (the serial joints the serial-equivalent model keeps), by the first rule that applies:

   * named: ``outputs={name: [joint, ...]}``, else the spec's ``[transmission.<name>] outputs = [...]`` tables,
     give the transmission that contains those joints its name and its outputs;
   * else the joints of the **chain**: (a) the sub-mechanism's joints that carry the rest of the robot (a joint
     outside the sub-mechanism hangs below them: a knee four-bar's knee), every one of them; else (b) for every
     closure, the side whose path from the root crosses no motor (the foot hanging from the shank by pitch and
     roll), the first ``k`` joints of those paths in the model's order, ``k`` the number of motors (a rod's own
     joints, modelled on the foot's side, come after). Its name is the body the chain ends on (the foot), made
     unique with ``_2``, ``_3``, ... in the model's order.

   Every output is a one-coordinate joint of the sub-mechanism whose path to the root crosses outputs only (the
   serial model keeps it with the bodies it carries), there are as many as motors, and at the reference the outputs
   determine every joint of the sub-mechanism but the idle ones (a rod's spin between two balls) and the motors
   determine the outputs: otherwise :class:`~pkm.errors.TransmissionError` (``reason`` ``"outputs"`` or
   ``"singular"``, naming the transmission, its joints and the smallest relative singular value).
4. **The sub-mechanism alone** (:attr:`Transmission.mechanism`): the robot's Pinocchio model with every joint outside
   the sub-mechanism locked at the robot's reference (``pinocchio.buildReducedModel``: the locked bodies welded to
   their parents, so that the root is fixed where the reference puts it, gravity as the whole robot's at its
   reference and a floating base held there), written as URDF (:func:`~pkm.core.model.urdf.urdf_from_model`) and
   built from it with a spec of its own: its closures, its motors as the actuated joints with the robot's drives
   (every field in ``[actuators.<motor>]``), its outputs as the task (``TaskSpec(components=(), joints=outputs)``),
   the robot's reference. It has files and pickles. A joint whose position limits are an empty interval (``lower >=
   upper``: Pinocchio's placeholder where a file states none) is unlimited there.
5. **Constant maps** (a differential: the spec's ``[motors.<name>]`` tables, :mod:`pkm.core.model.motors`; MuJoCo's
   motors on fixed tendons over several joints). The motors whose tables share joints (transitively) are one group;
   its map ``C`` (``u = C q_a``, the motors' coordinates from the actuated joints') is constant. A group whose joints
   lie in no loop is a transmission of its own: its sub-mechanism is those joints alone (no closure, the rest locked
   at the reference, rooted as rule 1's), its outputs those joints, its motors the group's motors, its maps constant
   (:class:`Transmission`: ``qo = C⁻¹ u``, ``J = C⁻¹``, efforts ``τ_m = C⁻ᵀ τ_o``, ``ΔM = 0``, ``Δh = 0``), named by
   the chain rule's body. A group whose joints are motors of one closed sub-mechanism drives it: that
   transmission's motors are the group's (its maps composed with ``C``). A group that spans a loop and other joints,
   or two sub-mechanisms, is refused (``reason="outputs"``).
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence

import numpy as np
import pinocchio as pin

from pkm.core.formats.to_mjcf import mimic_leader
from pkm.core.model.actuators import NUMBERS
from pkm.core.model.builder import from_strings
from pkm.core.model.joints import reduced_model, stated_limits
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.spec import Closure, ClosureSpec, TaskSpec
from pkm.core.model.urdf import urdf_from_model
from pkm.core.transmissions.transmission import Transmission
from pkm.errors import InvalidInputError, PkmError, PkmWarning, TransmissionError, UnknownNameError


def _loop(model: pin.Model, ja: int, jb: int) -> tuple[int, set[int]]:
    """The deepest common ancestor of joints ``ja`` and ``jb`` and the joints of the loop they close."""
    sa, sb = list(model.supports[ja]), list(model.supports[jb])
    common = [j for j in sa if j in sb]
    return common[-1], (set(sa) | set(sb)) - set(common)


def _groups(mech: Mechanism) -> list[tuple[list[int], set[int], int]]:
    """The sub-mechanisms: ``(closure indices, joint ids, root joint id)``, in the order of their first closure."""
    model = mech.model
    loops = []
    for c, (fa, fb) in enumerate(mech.closure_frames):
        root, joints = _loop(model, model.frames[fa].parentJoint, model.frames[fb].parentJoint)
        if joints:  # (a closure between two frames of one body closes no loop)
            loops.append((c, root, joints))
    parent = list(range(len(loops)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for i in range(len(loops)):
        for k in range(i):
            if loops[i][2] & loops[k][2]:
                parent[find(i)] = find(k)
    out: dict[int, tuple[list[int], set[int], int]] = {}
    for i, (c, root, joints) in enumerate(loops):
        g = find(i)
        if g not in out:
            out[g] = ([], set(), root)
        members, js, r = out[g]
        members.append(c)
        js |= joints
        # the group's root: the deepest joint that supports both roots (one supports the other when loops share a
        # joint)
        sr, sn = list(model.supports[r]), list(model.supports[root])
        out[g] = (members, js, [j for j in sr if j in sn][-1])
    return list(out.values())


def _differentials(mech: Mechanism, loops: list[tuple[list[int], set[int], int]]
                   ) -> list[tuple[list[int], set[int], int]]:
    """Rule 5: the groups of ``[motors]`` (motors that share joints, transitively) whose joints lie in no loop of
    ``loops``, each as a sub-mechanism ``([], its joints, its root)``: the root the deepest joint above every one of
    them that is none of them."""
    model = mech.model
    groups: list[set[int]] = []
    for coefs in mech.spec.motors.values():
        ids = {mech.joints[j].id for j in coefs}
        touching = [g for g in groups if g & ids]
        for g in touching:
            ids |= g
            groups.remove(g)
        groups.append(ids)
    out: list[tuple[list[int], set[int], int]] = []
    in_loops = set().union(*(js for _, js, _ in loops))
    for ids in sorted(groups, key=min):
        if ids & in_loops:
            continue  # (rule 5: it drives a closed sub-mechanism, or spans one and is refused there)
        common = [j for j in model.supports[min(ids)] if all(j in model.supports[i] for i in ids) and j not in ids]
        out.append(([], ids, common[-1]))
    return out


def _root_body(model: pin.Model, joints: set[int], root: int) -> str:
    """The body the sub-mechanism's first joints hang from: the frame the first of them is attached to (Pinocchio's
    readers attach a joint's frame to its parent link's frame)."""
    first = min((j for j in joints if model.parents[j] == root), default=None)
    if first is None:  # (a differential's joints below serial joints of their own root: rule 5)
        return _distal_body(model, root) if root else model.names[0]
    fid = model.getFrameId(model.names[first], pin.FrameType.JOINT)
    frame = model.frames[model.frames[fid].parentFrame]
    if frame.parentJoint == root:
        return frame.name
    return model.names[root]  # (a model built by hand: the joint's name)


def _distal_body(model: pin.Model, joint: int) -> str:
    """The body a joint carries: the first BODY frame attached to it, else the joint's name."""
    for f in model.frames:
        if f.parentJoint == joint and f.type == pin.FrameType.BODY:
            return f.name
    return model.names[joint]


def _chain_outputs(mech: Mechanism, closures: list[int], joints: set[int], k: int) -> tuple[list[int], int | None]:
    """Rule 3's chain: ``(outputs, the joint whose body names the transmission)`` (module doc)."""
    model = mech.model
    motors = {mech.joints[n].id for n in mech.actuated_names}
    below = {j: {i for i in range(1, model.njoints) if j in model.supports[i]} for j in joints}
    carrying = sorted(j for j in joints if below[j] - joints)
    if carrying:  # (a): the joints that carry the rest of the robot, every one of them
        return carrying, max(carrying, key=lambda j: len(model.supports[j]))
    sides: set[int] = set()
    for i in closures:
        for f in mech.closure_frames[i]:
            path = [j for j in model.supports[model.frames[f].parentJoint] if j in joints]
            if path and not motors & set(path):
                sides |= set(path)
    chain = sorted(sides)[:k]  # (b): the motor-free sides' first k joints (the rods' own joints come after)
    return chain, (chain[-1] if chain else None)


def _unique(names: list[str]) -> list[str]:
    seen: dict[str, int] = {}
    out = []
    for n in names:
        seen[n] = seen.get(n, 0) + 1
        out.append(n if seen[n] == 1 else f"{n}_{seen[n]}")
    return out


def _idle_closure(urdf: str) -> tuple[Closure]:
    """A differential's sub-mechanism (rule 5: no loop) holds one closure that closes nothing: its root link's frame
    on itself (no equation any motion moves: a pkm mechanism has a closure)."""
    from lxml import etree

    links = {el.get("name") for el in etree.fromstring(urdf.encode()).iter("link")}
    children = {el.find("child").get("link") for el in etree.fromstring(urdf.encode()).iter("joint")}
    root = sorted(links - children)[0]
    return (Closure(name="differential", type="point", frame_a=root, frame_b=root),)


def _sub_mechanism(mech: Mechanism, name: str, closures: list[int], joints: set[int], motors: tuple[str, ...],
                   outputs: tuple[str, ...]) -> Mechanism:
    """Rule 4: the sub-mechanism alone, rooted where the robot's reference puts its root, built from its own URDF
    (so that it has files, :func:`~pkm.core.transmissions.serial.write_serial_equivalent`, and pickles)."""
    model = mech.model
    keep = {model.names[j] for j in joints}
    lock = [j for j in range(1, model.njoints) if model.names[j] not in keep]
    reduced = reduced_model(model, lock, mech.q_reference) if lock else model.copy()
    stated = {n: lim for n, lim in mech.limits.items() if n in keep}
    urdf, types = urdf_from_model(reduced, name=name, limits=stated, source=mech.source)
    q_ref = mech.q_to_dict(mech.q_reference)
    tables = {m: dict(c) for m, c in mech.spec.motors.items() if set(c) & set(motors)}
    split = {m: sorted(set(c) - set(motors)) for m, c in tables.items() if not set(c) <= set(motors)}
    if split:
        m, rest = next(iter(split.items()))
        raise TransmissionError(name, "outputs", f"its motor {m!r} ([motors]: a constant map) also drives {rest}, "
                                f"joints outside its motors {list(motors)}: a differential across a closed "
                                "sub-mechanism and other joints is no transmission", (m, *rest))
    spec = ClosureSpec(
        mechanism=name, urdf=f"{name}.urdf", end_effector=None, actuated=motors,
        closures=tuple(mech.spec.closures[i] for i in closures) or _idle_closure(urdf),
        task=TaskSpec(components=(), joints=outputs),
        reference={n: tuple(np.atleast_1d(q_ref[n]).tolist()) for n in sorted(keep) if n in q_ref},
        joint_types=types, actuators={a.joint: {f: float(getattr(a, f)) for f in NUMBERS}
                                      for a in mech.actuators if a.joint in motors},
        springs={n: v for n, v in mech.spec.springs.items() if n in keep}, motors=tables,
        description=f"the closed sub-mechanism {name!r} of {mech.name!r}")
    with warnings.catch_warnings():  # (what the robot's loading said already: kept in the notes, not said twice)
        warnings.simplefilter("ignore", PkmWarning)
        sub = from_strings(urdf, spec, source=f"{mech.source} [{name}]")
    sub.model.lowerPositionLimit, sub.model.upperPositionLimit = stated_limits(sub.model)
    return sub


def transmissions(mech: Mechanism, outputs: Mapping[str, Sequence[str]] | None = None, *,
                  skip_unfit: bool = False) -> list[Transmission]:
    """The closed sub-mechanisms of a whole robot, each a :class:`Transmission` (the rules: module doc).

    Args:
        mech: The whole robot (fixed or floating base, any number of loops, serial joints between them).
        outputs: ``{transmission name: output joints}`` for the transmissions whose outputs the chain rule would not
            choose (or to name them); a transmission not listed gets the chain rule and a generated name. Default:
            the spec's ``[transmission.<name>]`` tables (:attr:`pkm.ClosureSpec.transmissions`).
        skip_unfit: Leave out a sub-mechanism that cannot be a transmission (its :class:`TransmissionError` said in a
            :class:`~pkm.errors.PkmWarning`) instead of raising: the others of a robot one of whose loops is no
            transmission (Gepetto's ``cassie_like``: its ankle, not its knee).

    Returns:
        The transmissions, in the order of their first closure in the spec, then the differentials over serial
        joints (rule 5), in the model's order.

    Raises:
        TransmissionError: no closure and no differential; a sub-mechanism with no motor; a differential across a
            loop and other joints (rule 5); outputs that do not determine their
            sub-mechanism (count, not in a loop, not scalar, below a joint that is not an output), or singular at the
            reference (``reason`` and the joints on the error).
        UnknownNameError: an output joint the robot does not have.

    Examples:
        >>> import pkm
        >>> talos = pkm.load("gepetto:talos_like")  # (a leg whose ankle a motor on the shin drives through rods)
        >>> [(t.name, t.root, t.motors, t.outputs) for t in pkm.transmissions(talos)]
        [('ankle', 'knee', ('motor_shin',), ('free_ankle',))]
    """
    mech = check_mechanism(mech)
    model = mech.model
    named: dict[str, tuple[str, ...]] = {}
    if outputs is None:
        outputs = mech.spec.transmissions
    if not isinstance(outputs, Mapping):
        raise InvalidInputError("outputs", "expected {transmission name: [output joint, ...]}", outputs)
    for tname, joints in outputs.items():
        if isinstance(joints, str) or not isinstance(joints, Sequence):
            raise InvalidInputError("outputs", f"transmission {tname!r}: expected a list of joint names", joints)
        for j in joints:
            mech.joint(j)  # (UnknownNameError naming the valid joints)
        named[str(tname)] = tuple(joints)
    groups = _groups(mech)
    groups += _differentials(mech, groups)
    actuated = {mech.joints[n].id for n in mech.actuated_names}
    claimed: dict[str, int] = {}
    for tname, joints in named.items():
        ids = {mech.joints[j].id for j in joints}
        hits = [g for g, (_, js, _) in enumerate(groups) if ids & js]
        if len(hits) != 1 or not ids <= groups[hits[0]][1]:
            where = [sorted(model.names[j] for j in groups[g][1] & ids) for g in hits]
            raise TransmissionError(tname, "outputs", f"the outputs {list(joints)} must all be joints of one closed "
                                    f"sub-mechanism (loop joints found: {where}; joints outside every loop: "
                                    f"{sorted(set(joints) - {model.names[j] for g in hits for j in groups[g][1]})})",
                                    joints)
        claimed[tname] = hits[0]
    by_group = {g: t for t, g in claimed.items()}
    plans: list[tuple[str, list[int], set[int], int, set[int], list[int]]] = []
    for g, (closures, members, root) in enumerate(groups):
        motor_ids = actuated & members
        if g in by_group:
            out_ids = [mech.joints[j].id for j in named[by_group[g]]]
            plans.append((by_group[g], closures, members, root, motor_ids, out_ids))
        elif not closures:  # (rule 5: a differential's outputs are its joints)
            out_ids = sorted(members)
            plans.append((_distal_body(model, max(out_ids, key=lambda j: len(model.supports[j]))), closures,
                          members, root, motor_ids, out_ids))
        else:
            out_ids, deepest = _chain_outputs(mech, closures, members, len(motor_ids))
            label = _distal_body(model, deepest) if deepest is not None else model.names[min(members)]
            plans.append((label, closures, members, root, motor_ids, out_ids))
    generated = _unique([p[0] for p in plans])
    result = []
    for g, p in enumerate(plans):
        try:
            result.append(_transmission(mech, by_group.get(g) or generated[g], *p[1:]))
        except TransmissionError as exc:
            if not skip_unfit:
                raise
            warnings.warn(PkmWarning(f"{exc}: left out (skip_unfit)"), stacklevel=2)
    if not result:
        raise TransmissionError(mech.name, "no_loop", "the robot has no closed sub-mechanism that is a transmission"
                                if plans else "the robot has no closure and no differential ([motors]): no "
                                "closed sub-mechanism")
    return result


def _transmission(mech: Mechanism, name: str, closures: list[int], joints: set[int], root: int,
                  motor_ids: set[int], out_ids: list[int]) -> Transmission:
    model = mech.model
    order = sorted(joints)  # (the model's order)
    motors = tuple(n for n in mech.actuated_names if mech.joints[n].id in motor_ids)
    outputs = tuple(model.names[j] for j in out_ids)
    if not motors:
        driven = [f"{model.names[j]!r} follows {model.names[lead]!r}" for j in order
                  if model.joints[j].shortname() == "JointModelMimic"
                  and model.names[lead := mimic_leader(model, j)] in mech.actuated_names]
        why = (f" (its joint {', '.join(driven)}, an actuated joint of another sub-mechanism, by a coupling: a loop "
               "driven through a coupling is not decomposed)" if driven else "")
        raise TransmissionError(name, "outputs", f"its loops ({[mech.spec.closures[i].name for i in closures]}) hold "
                                f"no actuated joint: a passive closed chain is no transmission{why}", outputs)
    bad = [model.names[j] for j in out_ids if mech.joints[model.names[j]].nv != 1]
    if bad:
        raise TransmissionError(name, "outputs", f"outputs {bad} have more than one coordinate: outputs are "
                                "one-coordinate serial joints", bad)
    carries = sorted(j for j in joints if {i for i in range(1, model.njoints) if j in model.supports[i]} - joints)
    if len(carries) > len(motors):
        names = [model.names[j] for j in carries]
        raise TransmissionError(name, "outputs", f"{names} carry the rest of the robot, so that a serial model must "
                                f"keep every one of them as an output, but its loops hold {len(motors)} motor(s) "
                                f"{list(motors)}: no choice of outputs makes it a transmission; leave it out with "
                                "skip_unfit=True (pkm transmission --skip-unfit) to get the robot's other "
                                "transmissions", names)
    carrying = [j for j in carries if j not in out_ids]
    if carrying:
        raise TransmissionError(name, "outputs", f"{[model.names[j] for j in carrying]} carry the rest of the robot "
                                f"but are no outputs {list(outputs)}: a serial model cannot keep the rest of the robot "
                                "on them", [model.names[j] for j in carrying])
    if not outputs:
        raise TransmissionError(name, "outputs", f"no one-coordinate serial joint hangs from its root through a "
                                f"motor-free chain (a parallel mechanism whose output is a frame, not a joint): name "
                                f"its {len(motors)} outputs (outputs={{{name!r}: [...]}})", motors)
    if len(outputs) != len(motors):
        raise TransmissionError(name, "outputs", f"{len(outputs)} outputs {list(outputs)} for {len(motors)} motors "
                                f"{list(motors)}: give as many outputs as motors (outputs={{{name!r}: [...]}})",
                                outputs)
    for j in out_ids:
        above = [k for k in model.supports[j] if k in joints and k not in out_ids]
        if above:
            raise TransmissionError(name, "outputs", f"output {model.names[j]!r} hangs below {model.names[above[0]]!r}, "
                                    "which is no output: the serial model keeps only the outputs' chain",
                                    (model.names[j], model.names[above[0]]))
    passive = tuple(model.names[j] for j in order if j not in motor_ids and j not in out_ids)
    try:
        sub = _sub_mechanism(mech, name, closures, joints, motors, outputs)
    except UnknownNameError:
        raise
    except PkmError as exc:
        raise TransmissionError(name, "outputs", f"its sub-mechanism cannot be built: {exc}", outputs) from exc
    t = Transmission(name=name, mechanism=sub, root=_root_body(model, joints, root), motors=sub.motor_map.names,
                     outputs=outputs, passive=passive)
    t.check()  # (the rank conditions at the reference: TransmissionError "singular")
    return t


__all__ = ["transmissions"]
