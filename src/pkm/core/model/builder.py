"""Building a :class:`~pkm.core.model.mechanism.Mechanism`: the tree and spec put together, the reference
configuration assembled where the spec leaves joints out and checked where it states them all, the actuators
weighed against the mobility.

* :func:`build`: a Pinocchio model and a spec;
* :func:`from_strings`: URDF text and a spec (object or TOML text);
* :func:`from_files`: a closure spec and the model file it names (URDF, MJCF, SDF: :mod:`pkm.core.formats`);
* :func:`with_actuators`: a copy with other drives (:mod:`pkm.core.model.actuators`);
* :func:`scaled_mechanism`: a copy with every length scaled (:mod:`pkm.core.model.scale`);
* :func:`rebuild`: unpickling (a mechanism pickles as its URDF and spec texts).

The reference configuration, by a stated rule: the files' own where they state one (the spec's ``[reference]``, a
robot.yaml's or MJCF's keyframe read into it), which must close every loop to :data:`REFERENCE_TOL`; else the
assembly :func:`pkm.core.kinematics.solve.assemble` reaches from the joints the files state (held) and the zero pose
(Pinocchio's neutral configuration) for the others: Levenberg-Marquardt from there, then seeded restarts, the first
that closes (the same every run; a closed configuration near the zero pose, not the nearest, and not chosen for
symmetry; scale-free: the same files with every length scaled assemble to the same angles, by a metric in the
spread of the joints at the zero pose, :func:`~pkm.core.model.mechanism.spread`, known before the reference).
:func:`pkm.core.kinematics.solve.nearest_assembly` gives the nearest (a symmetric one where a symmetry
of the mechanism fixes the zero pose); it is not the default because the nearest is often near a singularity (a
URDF's zero pose with aligned links): Gepetto's disney_like and wl16_like would get references 3 and 2 mrad from one.
Write a ``[reference]`` (or ``pkm.save`` a mechanism whose ``q_reference`` was set) to choose. An assembled reference
outside a joint's position limits is assembled again from those joints at the middle of their ranges
(:data:`LIMIT_ROUNDS`), else kept with a :class:`~pkm.errors.PkmWarning` naming them; where the files state a pose
whose loops are open (an MJCF keyframe), a note says by how much and how far closing them moved the joints.
Actuators that depend on the others, or freedom no actuator drives (:func:`pkm.core.differential.velocity.actuation`),
are reported by a :class:`~pkm.errors.PkmWarning` and in :attr:`Mechanism.notes`; so are masses, inertias and
drive limits no real mechanism has (:mod:`pkm.core.model.plausibility`: an
:class:`~pkm.errors.ImplausibleModelWarning`).
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm.core.differential.velocity import actuation
from pkm.core.formats.base import Imported
from pkm.core.formats.imported import import_model, with_file
from pkm.core.kinematics import constraints
from pkm.core.kinematics.solve import assemble
from pkm.core.model import mechanism as _mechanism
from pkm.core.model import plausibility
from pkm.core.model.actuators import NUMBERS, Actuator, as_actuators
from pkm.core.model.joints import retype_joints
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.scale import JacobianScales, length_entries, scale_urdf
from pkm.core.model.spec import ClosureSpec, as_path
from pkm.core.model.urdf import load_model
from pkm.errors import AssemblyError, InvalidInputError, PkmWarning, SpecError
from pkm.validation import as_scalar

#: A spec's [reference] must close every loop to this, relative to the mechanism's characteristic length for a
#: translation gap (:attr:`Mechanism.characteristic_length` at that reference), in rad for a rotation: the same
#: verdict on the files in millimetres and in metres. One that lacks joints is assembled.
REFERENCE_TOL = 1e-9


def build(model: pin.Model, spec: ClosureSpec, params: Any = None, urdf: str | None = None,
          source: str = "<model>", notes: tuple[str, ...] = (), *,
          seed: Mapping[str, Any] | None = None, hold: tuple[str, ...] = ()) -> Mechanism:
    """The mechanism of ``model`` and ``spec``, its reference assembled or checked (module doc).

    ``seed``: values of joints the ``[reference]`` leaves out, where the assembly starts instead of the neutral
    configuration (a design whose geometry moved, started from its former reference: the same assembly mode).
    ``hold``: joints of ``seed`` the assembly holds where the loops allow it (the actuated joints of an MJCF keyframe:
    values the model files state, not the spec); where they over-determine the loops (redundant actuators whose
    stated values disagree), the assembly holds only the ``[reference]``, starting from them, and a note and a
    :class:`~pkm.errors.PkmWarning` say how far it moved them.

    Raises:
        SpecError: the spec does not fit the model; no assembly keeps the joints a partial ``[reference]`` states
            (or, with none stated but the floating base's pose, the loops cannot close: each open loop named with its
            gap, the :class:`~pkm.errors.AssemblyError` as the cause); a complete ``[reference]`` leaves a loop open.
    """
    mech = Mechanism(model, spec, params, urdf, source, notes)
    if seed:
        mech.q_reference = mech.q_from_dict({n: v for n, v in seed.items() if n not in spec.reference})
    missing = [n for n, j in mech.joints.items() if j.nq > 0 and n not in spec.reference]
    if missing:  # a partial (or no) reference: assembled from it, the other joints from the neutral configuration
        start = mech.q_reference.copy()
        held = tuple(spec.reference)
        soft = tuple(n for n in hold if n in missing and seed and n in seed)
        try:
            try:
                mech.q_reference = assemble(mech, start, hold=held + soft, tol=1e-12).q
                held += soft
            except AssemblyError as exc:
                if not soft:
                    raise
                loose = assemble(mech, start, hold=held, tol=1e-12)  # (all released; then only the redundant ones:)
                redundant = set(actuation(mech, loose.q).dependent) & set(soft)
                kept = tuple(n for n in soft if n not in redundant)
                again = assemble(mech, start, hold=held + kept, tol=1e-12, raise_on_failure=False) \
                    if redundant else None
                if again is None or not again.converged:
                    again, kept = loose, ()
                mech.q_reference, held = again.q, held + kept
                released = [n for n in soft if n not in kept]
                moved = max(float(np.abs(pin.difference(model, start, mech.q_reference)[
                    mech.joints[n].idx_v:mech.joints[n].idx_v + mech.joints[n].nv]).max()) for n in released)
                release = (f"the values the model file states for {list(soft)} over-determine the loops (no "
                           f"assembly holds them all: {exc}): assembled from them holding {list(held) or 'nothing'}, "
                           f"which moved {released} by {moved:.3g} at most (rad or m)")
                mech.notes += (release,)
                warnings.warn(f"{source}: {release}", PkmWarning, stacklevel=3)
        except AssemblyError as exc:
            hint = _redundancy(mech, start)
            if not set(spec.reference) - {spec.floating_base}:  # (the files state no joint: the loops do not close)
                raise SpecError(source, f"the loops cannot be closed: {exc}{hint}") from exc  # (its closures, gaps)
            raise SpecError(source, f"[reference] lacks joints {missing} and no assembly was found that keeps the "
                                    f"joints it states, the others starting from the neutral configuration "
                                    f"({exc}){hint}; give an assembled [reference]") from None
        rel, index, raw = 0.0, 0, np.zeros(0)
        if seed:  # (the pose the files state: how far open, relative to the mechanism's size)
            raw = constraints.residual(mech, start)
            rel, index, _ = constraints.worst_closure(mech, raw * JacobianScales.of(mech).closure_residual)
        mech.q_reference = _inside_limits(mech, start, held, source)
        if rel > REFERENCE_TOL:  # (where it was open: its worst closure's gap, how far the reference kept moved it)
            gap = constraints.block_gap(mech, raw, index)
            moved = float(np.abs(pin.difference(model, start, mech.q_reference)).max())
            mech.notes += (f"the loops open by {gap:.3g} (m or rad) at the pose the files state were closed by "
                           f"assembly, which moved the joints by {moved:.3g} at most (rad or m)",)
    else:
        raw = constraints.residual(mech, mech.q_reference)
        L = mech.characteristic_length
        rel, index, closure = constraints.worst_closure(mech, raw * JacobianScales.of(mech).closure_residual)
        if rel > REFERENCE_TOL:
            gap = constraints.block_gap(mech, raw, index)
            raise SpecError(source, f"the [reference] configuration leaves closure {closure!r} open by {gap:.3g} "
                                    f"(m or rad; {rel:.3g} relative to the mechanism's size {L:.3g} m, closed means "
                                    f"<= {REFERENCE_TOL:g}): fix it, or leave joints out of [reference] to have pkm "
                                    "assemble the mechanism (pkm.assemble)")
    fit = actuation(mech)
    mech.dependent_actuators = fit.dependent
    said = set(notes)  # (a rebuild of a mechanism, pkm.with_actuators: its notes told already, not warned again)
    if fit.problem and f"at the reference configuration, {fit.problem}" not in said:
        mech.notes += (f"at the reference configuration, {fit.problem}",)
        warnings.warn(f"{source}: at the reference configuration, {fit.problem}", PkmWarning, stacklevel=3)
    for finding in plausibility.findings(mech):  # (masses, inertias, limits no real mechanism has)
        if str(finding) not in said:
            mech.notes += (str(finding),)
            warnings.warn(finding, stacklevel=3)
    return mech


def _redundancy(mech: Mechanism, q: np.ndarray) -> str:
    """Where the closures' rows are redundant at ``q`` (their Jacobian, the floating base held, has a smaller rank
    than rows: over-constrained or planar loops), a sentence saying that such loops close only where their geometry
    agrees exactly (MuJoCo's soft equalities absorb a disagreement that rigid loops cannot); else ``""``."""
    J = constraints.jacobian(mech, q)[:, np.setdiff1d(np.arange(mech.nv), mech.base_v)]
    s = np.linalg.svd(J, compute_uv=False)
    rank = int(np.sum(s > 1e-9 * s[0])) if len(s) and s[0] > 0.0 else 0
    if rank >= J.shape[0]:
        return ""
    return (f"; the closures' {J.shape[0]} equations have rank {rank} there: redundant (over-constrained or planar) "
            "loops close only where their geometry agrees exactly, which MuJoCo's soft equalities do not require (a "
            "site or anchor off by a rounding error is enough)")


#: Rounds of :func:`_inside_limits`: each assembles once more (one Levenberg-Marquardt run, no restarts).
LIMIT_ROUNDS = 3


def _inside_limits(mech: Mechanism, start: np.ndarray, hold: tuple[str, ...], source: str) -> np.ndarray:
    """The assembled reference ``mech.q_reference`` if it lies inside every position limit. Else the assembly from
    ``start`` with the joints it put outside their limits (those not held) moved to the middle of their ranges, and
    again with those the last assembly put outside, :data:`LIMIT_ROUNDS` times at most: the first inside every limit
    (a note says which joints were moved), else the first assembly, with a :class:`~pkm.errors.PkmWarning` naming the
    joints outside."""
    q = mech.q_reference
    outside = mech.outside_limits(q)
    if not outside:
        return q
    moved: list[str] = []
    last = outside
    for _ in range(LIMIT_ROUNDS):
        more = [n for n in last if n not in hold and n not in moved]
        if not more:
            break
        moved += more
        retry = start.copy()
        for n in moved:
            retry[mech.joints[n].idx_q] = 0.5 * sum(mech.limits[n])
        again = assemble(mech, retry, hold=hold, tol=1e-12, restarts=0, raise_on_failure=False)
        if again.converged and not again.outside_limits:
            mech.notes += (f"the first assembly left {list(outside)} outside their position "
                           f"limits: assembled again from {moved} at the middle of their ranges, inside every limit",)
            return again.q
        last = again.outside_limits
    said = (f"the assembled reference configuration lies outside the position limits of {list(outside)} (state a "
            "[reference], or a keyframe, inside them)")
    mech.notes += (said,)
    warnings.warn(f"{source}: {said}", PkmWarning, stacklevel=4)
    return q


def from_strings(urdf: str, spec: ClosureSpec | str, params: Any = None, source: str = "<string>",
                 notes: tuple[str, ...] = (), *, seed: Mapping[str, Any] | None = None,
                 hold: tuple[str, ...] = ()) -> Mechanism:
    """Build from URDF text and a spec (object or TOML text); ``notes``: what the reader of its files interpreted
    or ignored (:attr:`Mechanism.notes`).

    Raises:
        SpecError: The URDF or the spec is malformed, or they do not fit together (see
            :mod:`pkm.core.model.urdf` and :mod:`pkm.core.model.spec` for what the loaders refuse), or as
            :func:`build`.
        InvalidInputError: ``urdf`` is not a string, ``spec`` neither a string nor a ClosureSpec.

    Examples:
        >>> import pkm
        >>> five = pkm.load("gepetto:5bar_linkage_iso3d")
        >>> spec = '''
        ... format = "pkm.closures/1"
        ... mechanism = "my_fivebar"
        ... urdf = "fivebar.urdf"
        ... end_effector = "closedloop3D_1A"
        ... actuated = ["mot1", "mot2"]
        ... [task]
        ... components = ["x", "z"]
        ... [[closure]]
        ... name = "tip"
        ... type = "point"
        ... frame_a = "closedloop3D_1A"
        ... frame_b = "closedloop3D_1B"
        ... '''
        >>> mech = pkm.from_strings(five.urdf, spec)
        >>> mech.name, mech.na, pkm.TaskMap.of(mech).keys
        ('my_fivebar', 2, ('x', 'z'))
        >>> {k: round(v, 4) for k, v in pkm.task_values(mech, mech.q_reference).items()}
        {'x': 0.1371, 'z': -0.6192}
        >>> print(pkm.diagnose(mech, mech.q_reference))  # doctest: +NORMALIZE_WHITESPACE
        regular: mobility 2 (constraint rank 3 of 3 equations); distance to a direct singularity 0.244,
        to an inverse one 0.0658 (0: singular, 1: far)
    """
    if not isinstance(urdf, str):
        raise InvalidInputError("urdf", f"expected the URDF text as a str, got {type(urdf).__name__}", urdf)
    if not isinstance(spec, (str, ClosureSpec)):
        raise InvalidInputError("spec", f"expected a ClosureSpec or its TOML text, got {type(spec).__name__}",
                                spec)
    if isinstance(spec, str):
        spec = ClosureSpec.from_toml(spec, source + " (closures)")
    return build(retype_joints(load_model(urdf, source), spec.joint_types, source), spec, params, urdf, source,
                 notes, seed=seed, hold=hold)


def from_files(spec_path: str | Path, spec: ClosureSpec | None = None) -> Mechanism:
    """Load ``<name>.closures.toml`` and the model file it names (path relative to the spec): a URDF, or an
    MJCF or SDF file whose own loops and joint types are added to the spec's (:mod:`pkm.core.formats`).
    ``spec``: the spec file already read (and changed: :func:`pkm.core.formats.load.load_spec_file`).

    The spec's ``urdf`` must stay inside the spec's folder once symbolic links are resolved;
    nothing else is read (see :mod:`pkm.core.model.spec`).

    Raises:
        SpecError: A file is missing, too large, malformed, or the URDF path leaves the folder; or as :func:`build`.
    """
    spec_path = as_path(spec_path, "spec_path")
    spec = ClosureSpec.load(spec_path) if spec is None else spec
    try:
        folder = spec_path.parent.resolve()
        urdf_path = (folder / spec.urdf).resolve()
    except (OSError, RuntimeError) as exc:  # a loop of symbolic links
        raise SpecError(str(spec_path), f"cannot resolve urdf = {spec.urdf!r}: {exc}") from None
    if not urdf_path.is_relative_to(folder):
        raise SpecError(str(spec_path), f"urdf = {spec.urdf!r} resolves to {urdf_path}, outside the spec's folder "
                                        f"{folder}; copy the URDF next to the spec")
    return from_imported(spec, import_model(urdf_path), str(spec_path))


def from_imported(spec: ClosureSpec, imported: Imported, source: str) -> Mechanism:
    """A closure spec and the model file it names, read (:class:`~pkm.core.formats.base.Imported`): what the file
    states added to the spec, then built (as :func:`from_files` does once it has read both)."""
    spec = with_file(spec, imported, source)
    model = retype_joints(load_model(imported.urdf, source), spec.joint_types, source)
    return build(model, spec, None, imported.urdf, source, imported.notes, seed=imported.seed, hold=imported.hold)


def with_actuators(mech: Mechanism, actuators: Mapping[str, Any]) -> Mechanism:
    """A copy of ``mech`` whose drives are changed: ``{joint: Actuator}`` replaces a drive, ``{joint: {field:
    value}}`` changes those fields (:mod:`pkm.core.model.actuators`). The values go into the spec's
    ``[actuators]`` tables, so that :func:`pkm.save` writes them and the copy pickles with them.

    Raises:
        InvalidInputError: a joint that is not actuated, an unknown field, a negative or non-finite value.
        SpecError: the values contradict the model file's drives (a peak effort below the file's continuous limit).

    Examples:
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> geared = pkm.with_actuators(delta, {"motor_1": {"rotor_inertia": 1e-5, "gear_ratio": 10.0}})
        >>> geared.actuators[0].gear_ratio, geared.actuators[0].rotor_inertia
        (10.0, 1e-05)
        >>> M0, M1 = pkm.mass_matrix(delta, delta.q_reference), pkm.mass_matrix(geared, geared.q_reference)
        >>> round(float(M1[0, 0] - M0[0, 0]), 9)  # the reflected inertia 1e-5 kg m^2 x 10^2
        0.001
    """
    if not isinstance(mech, Mechanism):
        raise InvalidInputError("mech", f"expected a pkm Mechanism, got {type(mech).__name__}", mech)
    given = as_actuators(actuators, mech.actuated_names, {j.name: j.revolute for j in mech.actuated})
    tables = {j: dict(t) for j, t in mech.spec.actuators.items()}
    for joint, act in given.items():
        if isinstance(actuators[joint], Actuator):
            tables[joint] = {f: getattr(act, f) for f in NUMBERS}
        else:
            tables[joint] = {**tables.get(joint, {}), **{str(k): getattr(act, str(k)) for k in actuators[joint]}}
    spec = dataclasses.replace(mech.spec, actuators=tables)
    seed = mech.q_to_dict(mech.q_reference)
    if mech.urdf is not None:
        return from_strings(mech.urdf, spec, mech.params, mech.source, mech.notes, seed=seed)
    return build(pin.Model(mech.model), spec, mech.params, None, mech.source, mech.notes, seed=seed)


def scaled_mechanism(mech: Mechanism, factor: float) -> Mechanism:
    """A copy of ``mech`` with every length multiplied by ``factor`` (> 0): its URDF
    (:func:`~pkm.core.model.scale.scale_urdf`: origins, prismatic limits, geometry, centres of mass, inertias times
    ``factor^2``) and the spec's reference values of prismatic joints (and their springs' rest lengths) and of a
    floating base's position, assembled from the scaled reference configuration
    (:func:`~pkm.core.model.scale.scale_configuration` maps any configuration onto the copy). Masses, angles, the
    actuators' efforts and the springs' stiffnesses are unchanged; the copy has no
    ``params`` (a mechanism's own parameters describe the original). Every singularity measure of the copy equals
    the original's (:mod:`pkm.core.model.scale`).

    Raises:
        InvalidInputError: ``factor`` is not a finite number > 0; ``mech`` has no URDF text (built from a
            ``pinocchio.Model``).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> big = pkm.scaled_mechanism(delta, 2.0)  # every length doubled
        >>> z0, z1 = pkm.task_values(delta, delta.q_reference)["z"], pkm.task_values(big, big.q_reference)["z"]
        >>> round(z1 / z0, 9)
        2.0
        >>> d0, d1 = pkm.diagnose(delta, delta.q_reference), pkm.diagnose(big, big.q_reference)
        >>> bool(np.isclose(d0.direct_distance, d1.direct_distance))
        True
    """
    mech = check_mechanism(mech)
    s = as_scalar(factor, "factor", low=0.0, strict_low=True)
    if mech.urdf is None:
        raise InvalidInputError("mech", "a mechanism built from a pinocchio.Model (no URDF text) cannot be scaled",
                                mech.name)

    def lengths(name: str, values: ArrayLike) -> tuple[float, ...]:
        k = length_entries(mech.joints[name].kind)
        return tuple(float(v) * s if i < k else float(v) for i, v in enumerate(np.atleast_1d(values)))

    springs = {n: {k: lengths(n, v)[0] if k == "rest" else v for k, v in table.items()}
               for n, table in mech.spec.springs.items()}  # (a prismatic spring's rest length)
    spec = dataclasses.replace(mech.spec, reference={n: lengths(n, v) for n, v in mech.spec.reference.items()},
                               springs=springs)
    seed = {n: np.array(lengths(n, v)) for n, v in mech.q_to_dict(mech.q_reference).items()}
    return from_strings(scale_urdf(mech.urdf, s), spec, None, f"{mech.source} (scaled by {s:g})", mech.notes,
                        seed=seed)


def rebuild(urdf: str, spec: str, params: Any, source: str, seed: Mapping[str, Any] | None = None) -> Mechanism:
    """Unpickling: the mechanism again from its URDF and spec texts, assembled from ``seed`` (its reference
    configuration: the one that the model files' values, which the spec does not keep, gave)."""
    return from_strings(urdf, spec, params, source=source, seed=seed)


def _reduce(mech: Mechanism) -> tuple[Any, tuple[Any, ...]]:
    """Pickling (:data:`pkm.core.model.mechanism.REDUCE`): the URDF and spec texts and the reference configuration,
    rebuilt by :func:`rebuild`."""
    seed = {n: tuple(float(x) for x in np.atleast_1d(v)) for n, v in mech.q_to_dict(mech.q_reference).items()}
    return rebuild, (mech.urdf, mech.spec.to_toml(), mech.params, mech.source, seed)


_mechanism.REDUCE = _reduce


__all__ = ["REFERENCE_TOL", "build", "from_files", "from_strings", "rebuild", "scaled_mechanism", "with_actuators"]
