"""What a sweep scores: objectives taken from the library's analyses, and user callables.

An objective is named by a spec ``NAME`` or ``NAME:OPTION=VALUE,...`` (``gci:step=1cm``,
``condition:pose=x=2cm/z=-36cm,kind=fro``), optionally given a column name of its own (``centre=condition:...``);
:data:`OBJECTIVES` lists them. Each has a generic route, which works on any mechanism pkm loads (the task-space
maps of :func:`pkm.task_map`, the inverse Jacobian at a pose, the trajectory follower, the symbolic twin), and,
for some registered mechanisms, a closed-form fast path that is also the papers' route (the 3-RRR's vectorised CI
maps, the Delta's workspace grid and K(R), the hexapod's reachable beta intervals); ``route=generic`` or
``route=closed_form`` forces one (the default, ``auto``, takes the closed form where there is one).

The fast paths belong to the mechanisms: a registry entry's ``sweeps`` (:class:`pkm.mechanisms.MechanismDefinition`)
names the module of its package whose ``CLOSED_FORMS`` maps objective names to closed forms (:class:`ClosedForm`:
the function, the options it reads, the unit of its value); this module names no mechanism and finds them through
:data:`pkm.mechanisms.REGISTRY`, so that a mechanism registered at run time brings its own. A region is
``region=x=-5cm:5cm:11/y=-5cm:5cm:11`` (1 to 3 task coordinates, ``START:STOP:COUNT``), a pose
``pose=x=2cm/y=0/z=-36cm`` (the other coordinates from the reference).

A user callable ``f(design) -> float | None`` receives the :class:`~pkm.sweeps.family.Candidate` (``design.mechanism``,
``design.params``, ``design.values``); :func:`objective` wraps it (``objective(f, sense="max")``), and the command
line takes ``path/to/file.py:function`` or ``module:function``, with ``@max`` or ``@min`` for its sense.

An objective returns a float, or None where it has no value (an empty workspace has no GCI): a null in the results,
not a failure. Any exception fails the design (recorded with its class and message), never the sweep.
"""

from __future__ import annotations

import importlib
import importlib.util
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from pkm.errors import InvalidInputError, PkmError, UnknownNameError
from pkm.sweeps.family import Candidate
from pkm.units import SI_UNITS, parse_quantity, split_range

SENSES = ("max", "min", "")
ROUTES = ("auto", "closed_form", "generic")


@dataclass(frozen=True)
class ClosedForm:
    """A registered mechanism's closed-form route of one objective (declared in the module its registry entry's
    ``sweeps`` names, under ``CLOSED_FORMS[objective name]``).

    Attributes:
        function: ``(design, options) -> value`` (None where the design has no value).
        options: The options it reads beyond the objective's own: ``{option: (kind, default, doc[, check])}`` (as
            :attr:`Definition.options`); an objective takes those of every registered mechanism's closed form.
        unit: Of its value, where not the objective's (a planar closed form's area is ``m^2``); ``""``: the
            objective's.
    """

    function: Callable[[Candidate, Mapping[str, Any]], float | None]
    options: Mapping[str, tuple[Any, ...]] = field(default_factory=dict)
    unit: str = ""


def closed_forms(objective_name: str) -> dict[str, ClosedForm]:
    """``{registered mechanism: its closed form of objective_name}``, in registry order (each mechanism's ``sweeps``
    module imported on first use)."""
    from pkm.mechanisms import REGISTRY

    out = {}
    for name, entry in list(REGISTRY.items()):
        if entry.sweeps is not None:
            found = getattr(importlib.import_module(entry.sweeps), "CLOSED_FORMS", {}).get(objective_name)
            if found is not None:
                out[name] = found
    return out


@dataclass(frozen=True)
class Definition:
    """One objective of :data:`OBJECTIVES`.

    Attributes:
        name: Its name in a spec.
        sense: ``"max"`` or ``"min"``: which way is better (Pareto fronts, best designs).
        unit: Of its value (SI).
        doc: One line.
        generic_options: ``{option: (kind, default, doc[, check])}`` of the objective itself; kinds ``length``
            (> 0), ``angle``, ``float``, ``int`` (``check``: a lower bound), ``text`` (``check``: the choices),
            ``range`` (``START:STOP:COUNT``), and ``pose`` / ``region`` (read against the mechanism's task).
        generic: ``(design, options) -> value`` on any mechanism, or None.
    """

    name: str
    sense: str
    unit: str
    doc: str
    generic_options: Mapping[str, tuple[Any, ...]]
    generic: Callable[[Candidate, Mapping[str, Any]], float | None] | None

    @property
    def closed_forms(self) -> dict[str, ClosedForm]:
        """``{registered mechanism: closed form}`` (:func:`closed_forms`)."""
        return closed_forms(self.name)

    @property
    def options(self) -> dict[str, tuple[Any, ...]]:
        """Every option a spec may give: the objective's own, then those of the registered mechanisms' closed
        forms (registry order; an option two of them declare is the first's)."""
        out = dict(self.generic_options)
        for closed in self.closed_forms.values():
            for key, spec in closed.options.items():
                out.setdefault(key, spec)
        return out

    def route(self, family, route: str) -> Callable[[Candidate, Mapping[str, Any]], float | None]:
        forms = self.closed_forms
        closed = forms.get(family.registered or "")
        if route in ("auto", "closed_form") and closed is not None:
            return closed.function
        if route in ("auto", "generic") and self.generic is not None:
            return self.generic
        which = "closed form" if route == "closed_form" else "route"
        has = sorted(forms) + (["any mechanism (generic)"] if self.generic else [])
        raise InvalidInputError("objective", f"{self.name} has no {which} for {family.registered or 'this mechanism'}"
                                             f" (it has: {', '.join(has) or 'none'})", self.name)

    def unit_of(self, registered: str | None) -> str:
        """The unit of the route ``auto`` takes for a registered mechanism (its closed form's, else :attr:`unit`)."""
        closed = self.closed_forms.get(registered or "")
        return closed.unit or self.unit if closed is not None else self.unit


@dataclass(frozen=True)
class Objective:
    """An objective with its options, as a sweep evaluates it.

    Attributes:
        column: The results' column.
        spec: Its spec text (``gci:step=1cm``), or ``module:function`` for a callable.
        sense: ``"max"``, ``"min"`` or ``""`` (unknown: a callable given none).
        unit: Its unit.
        definition: The library objective, or None for a callable.
        options: Its options (SI), for a library objective.
        function: The callable, or None.
    """

    column: str
    spec: str
    sense: str
    unit: str
    definition: Definition | None = None
    options: Mapping[str, Any] = field(default_factory=dict)
    function: Callable[[Candidate], Any] | None = None

    def bind(self, family) -> Callable[[Candidate], float | None]:
        """The function that scores one design of ``family`` (the route chosen once, here)."""
        if self.function is not None:
            return self.function
        assert self.definition is not None
        fn = self.definition.route(family, self.options.get("route", "auto"))
        return lambda c: fn(c, self.options)

    def describe(self, family) -> dict[str, str]:
        """JSON-able, with the unit this family's route gives (a volume is m^2 for a planar closed form)."""
        unit = self.unit
        if self.definition is not None and self.options.get("route") != "generic":
            unit = self.definition.unit_of(family.registered)
        out = {"column": self.column, "spec": self.spec, "sense": self.sense, "unit": unit}
        if self.options.get("motions"):  # (what the file said: a resumed sweep must read the same cases)
            out["motions"] = repr(sorted(self.options["motions"].items()))
        return out


def objective(spec, *, column: str | None = None, sense: str | None = None, unit: str = "") -> Objective:
    """An :class:`Objective` from a spec (``"gci:step=1cm"``, ``"name=spec"``, ``"file.py:function"``), a callable
    (``column`` default its ``__name__``; ``sense`` ``"max"``/``"min"`` for fronts and best designs), or itself.

    Raises:
        UnknownNameError: an unknown objective or option (the valid ones listed).
        InvalidInputError, UnitError: a malformed option value.
    """
    if isinstance(spec, Objective):
        return spec
    if callable(spec):
        name = str(column or getattr(spec, "__name__", ""))
        _check_column(name)
        return Objective(name, f"{getattr(spec, '__module__', '?')}:{getattr(spec, '__qualname__', name)}",
                         _sense(sense or ""), unit, function=spec)
    if not isinstance(spec, str) or not spec.strip():
        raise InvalidInputError("objective", "give an objective's name (see pkm.sweeps.OBJECTIVES), a spec such as "
                                             "'gci:step=1cm', or a callable", spec)
    spec = spec.strip()
    head = spec.split(":", 1)[0]
    if "=" in head:  # column=spec
        column, spec = (s.strip() for s in spec.split("=", 1))
        head = spec.split(":", 1)[0]
    if head.endswith(".py") or (":" in spec and head not in OBJECTIVES and "=" not in spec.split(":", 1)[1]):
        where, at, given = spec.rpartition("@")  # file.py:function@max
        if at and given in ("max", "min"):
            spec, sense = where, sense or given
        fn = load_callable(spec)
        return objective(fn, column=column, sense=sense, unit=unit)
    if head not in OBJECTIVES:
        raise UnknownNameError("objective", head, OBJECTIVES, "pkm.sweeps (or path/to/file.py:function)")
    d = OBJECTIVES[head]
    options = _options(d, spec.split(":", 1)[1] if ":" in spec else "")
    column = str(column or spec)
    _check_column(column)
    return Objective(column, spec, _sense(d.sense if sense is None else sense), d.unit, d, options)


def load_callable(spec: str) -> Callable:
    """``path/to/file.py:function`` or ``package.module:function``."""
    where, _, name = spec.rpartition(":")
    if not where or not name.isidentifier():
        raise InvalidInputError("objective", f"{spec!r}: expected path/to/file.py:function or module:function", spec)
    if where.endswith(".py"):
        path = Path(where)
        if not path.is_file():
            raise InvalidInputError("objective", f"{spec!r}: no such file {path}", spec)
        mod_spec = importlib.util.spec_from_file_location(f"pkm_user_{path.stem}", path)
        assert mod_spec is not None and mod_spec.loader is not None
        module = importlib.util.module_from_spec(mod_spec)
        try:
            mod_spec.loader.exec_module(module)
        except Exception as exc:  # the user's file: its own error, named, as a pkm error
            raise InvalidInputError("objective", f"{spec!r}: running {path} raised {type(exc).__name__}: {exc} (a "
                                                 "file objective may import installed packages only)", spec) from None
    else:
        try:
            module = importlib.import_module(where)
        except ImportError as exc:
            raise InvalidInputError("objective", f"{spec!r}: cannot import {where} ({exc})", spec) from None
    fn = getattr(module, name, None)
    if not callable(fn):
        raise InvalidInputError("objective", f"{spec!r}: {where} has no function {name}", spec)
    return fn


def _check_column(name: str) -> None:
    if not name or name in RESERVED:
        raise InvalidInputError("objective", f"{name!r} cannot name a column (empty, or one of {sorted(RESERVED)})",
                                name)


def _sense(sense: str) -> str:
    if sense not in SENSES:
        raise InvalidInputError("sense", f"one of 'max', 'min' (or '' for neither), got {sense!r}", sense)
    return sense


def _options(d: Definition, text: str) -> dict[str, Any]:
    out: dict[str, Any] = {"route": "auto"}
    valid = d.options  # (the objective's own and its closed forms')
    for item in filter(None, (s.strip() for s in text.split(","))):
        key, eq, value = item.partition("=")
        key = key.strip()
        if key == "route":
            if value not in ROUTES:
                raise InvalidInputError("route", f"one of {', '.join(ROUTES)}, got {value!r}", value)
            out["route"] = value
            continue
        if not eq or key not in valid:
            raise UnknownNameError("option", key, list(valid) + ["route"], f"objective {d.name}")
        out[key] = _option(key, valid[key], value.strip())
    for key, spec in valid.items():
        out.setdefault(key, spec[1])
    if out.get("file"):  # a motion file: read here, where its path means something (the workers may not share it)
        from pkm.motion import load_motions

        out["motions"] = load_motions(out["file"])
        out["file"] = str(Path(out["file"]).resolve()) if Path(out["file"]).exists() else out["file"]
    return out


def _option(key: str, spec: tuple, value: str):
    """An option's text read as its kind (``spec``: ``(kind, default, doc[, check])``; ``check`` the choices of a
    text option or the lower bound of a number, lengths being > 0 unless told)."""
    kind, check = spec[0], spec[3] if len(spec) > 3 else None
    if kind in ("length", "angle"):
        v = parse_quantity(value, {kind}, key, SI_UNITS[kind])
        if kind == "length" and not v > 0.0:
            raise InvalidInputError(key, f"{key}={value!r}: a length > 0", value)
        return v
    if kind in ("float", "int"):
        try:
            v = int(value) if kind == "int" else float(value)
        except ValueError:
            raise InvalidInputError(key, f"{key}={value!r}: expected {'an integer' if kind == 'int' else 'a number'}",
                                    value) from None
        if not math.isfinite(v) or (check is not None and v < check):
            raise InvalidInputError(key, f"{key}={value!r}: a finite number >= {check}", value)
        return v
    if kind == "pose":
        return dict(_split_items(key, value))
    if kind == "range":
        return split_range(value, key)
    if kind == "region":
        axes = {name: split_range(text, f"{key}: {name}") for name, text in _split_items(key, value)}
        if not 1 <= len(axes) <= 3:
            raise InvalidInputError(key, f"{key}: 1 to 3 task coordinates", value)
        return axes
    if check is not None and value not in check:
        raise InvalidInputError(key, f"{key}={value!r}: one of {', '.join(check)}", value)
    return value


def _split_items(key: str, value: str) -> list[tuple[str, str]]:
    out = []
    for item in filter(None, value.split("/")):
        name, eq, text = item.partition("=")
        if not eq or not name:
            raise InvalidInputError(key, f"{key}={value!r}: expected NAME=VALUE/NAME=VALUE...", value)
        out.append((name.strip(), text.strip()))
    return out


# ---------------------------------------------------------------------- generic routes
def _task_value(mech, name: str, text: str) -> float:
    import pkm

    task = pkm.TaskMap.of(mech)
    if name not in task.kinds:
        raise UnknownNameError("task coordinate", name, list(task.keys), mech.name)
    kind = task.kinds[name]
    return parse_quantity(text, {kind}, name, SI_UNITS[kind])


#: A sweep's map of at most this many nodes keeps its nodes' configurations (nq numbers a node), so that a capability
#: objective reads the same map as the others; a larger one keeps them only for a capability objective.
KEEP_CONFIGURATIONS = 100_000


def _generic_map(c: Candidate, o: Mapping[str, Any], configurations: bool = False, collisions: bool = False):
    """The :func:`pkm.workspace_map` of the design over ``region`` (cached per design and region), through the
    design's kernels (:attr:`Candidate.kernels`: one compiled twin for every design of a family that has one); with
    ``collisions``, its interference too where the design has collision geometry (the other objectives' maps leave
    it out: no cost where it is not asked for)."""
    if not o.get("region"):
        raise InvalidInputError("region", "the generic route maps a region: give region=x=START:STOP:COUNT/...")
    nodes = int(np.prod([k for _, _, k in o["region"].values()]))

    def make():
        import pkm
        from pkm.core.analysis.maps import workspace_map

        mech = c.mechanism
        axes = {n: np.linspace(_task_value(mech, n, a), _task_value(mech, n, b), k)
                for n, (a, b, k) in o["region"].items()}
        fixed = {n: _task_value(mech, n, v) for n, v in (o.get("pose") or {}).items()}
        length = pkm.TaskMap.of(mech).default_length(o.get("length"))  # (None: the design's own, on a mixed task)
        return workspace_map(mech, axes, fixed, length=length, branch=o.get("branch") or None,
                             kernels=c.kernels, configurations=configurations or nodes <= KEEP_CONFIGURATIONS,
                             collisions=collisions)

    key = _map_key(o)
    found = c.cached(key, make)
    if (configurations and found.q is None) or (collisions and found.clearance is None and _collides(c)):
        c.forget(key)  # (a large map made without them, or one made without interference, for another objective)
        found = c.cached(key, make)
    return found


def _collides(c: Candidate) -> bool:
    from pkm.core.collision.interference import checks_collisions

    return checks_collisions(c.mechanism)


def _map_key(o: Mapping[str, Any]) -> tuple:
    """A design's map, as the options name it (the key it is cached under)."""
    return ("task_map", tuple(o["region"].items()), tuple((o.get("pose") or {}).items()), o.get("length"),
            o.get("branch"))


def _capability(c: Candidate, o: Mapping[str, Any]) -> float | None:
    """The smallest (or mean) isotropic capability of one unit group over the regular reachable nodes of the map
    (:func:`pkm.core.analysis.capability.map_capability`, through the design's kernels); None where no node is."""
    from pkm.core.analysis.capability import UNITS, map_capability

    m = _generic_map(c, o, configurations=True)
    kind = o["kind"]
    cap = c.cached(("capability", _map_key(o), kind, o["gravity"]),
                   lambda: map_capability(c.mechanism, m, kind, gravity=o["gravity"] == "on", kernels=c.kernels))
    groups = list(cap.isotropic)
    unit = o.get("unit") or groups[0]
    if unit not in groups:
        raise InvalidInputError("unit", f"this task's {kind} capability has the unit groups {groups} "
                                        f"({UNITS[kind]})", unit)
    values = cap.isotropic[unit][cap.reachable]
    if not values.size:
        return None
    return float(values.min() if o["stat"] == "min" else values.mean())


def _stiffness(c: Candidate, o: Mapping[str, Any]) -> float | None:
    """The smallest (or mean) principal stiffness under a pure force or moment over the map's nodes, every actuated
    joint a spring of ``drives`` (:func:`pkm.core.compliance.maps.stiffness_map`); None where no node has one."""
    from pkm.core.compliance.maps import stiffness_map

    m = _generic_map(c, o, configurations=True)
    joints = dict.fromkeys(c.mechanism.actuated_names, o["drives"])
    sm = c.cached(("stiffness", _map_key(o), o["drives"]), lambda: stiffness_map(c.mechanism, m, joints=joints))
    values = (sm.force_min if o["load"] == "force" else sm.moment_min)[sm.reachable]
    if not values.size:
        return None
    return float(values.min() if o["stat"] == "min" else values.mean())


def _generic_gci(c, o):
    return _generic_map(c, o).gci(o["kind"])


def _generic_coverage(c, o):
    m = _generic_map(c, o)
    return float(np.count_nonzero(m.reachable) / m.reachable.size)


def _generic_min_ci(c, o):
    m = _generic_map(c, o)
    return float(np.min(m.condition_index(o["kind"])[m.reachable])) if m.reachable.any() else None


def _generic_volume(c, o):
    return float(_generic_map(c, o).size)


def _limits_volume(c, o):
    m = _generic_map(c, o, configurations=True)
    assert m.within_limits is not None  # (the configurations kept: the limits checked)
    return float(m.measure(m.reachable & m.within_limits))


def _interference_free_volume(c, o):
    """The reachable size within the joints' limits where no two checked bodies interpenetrate (the map's
    :attr:`~pkm.core.analysis.maps.WorkspaceMap.feasible`); a design without collision geometry is refused: its
    value would be the limits' alone, said as if checked."""
    from pkm.core.collision import CollisionModel

    CollisionModel.of(c.mechanism).require()
    m = _generic_map(c, o, configurations=True, collisions=True)
    return float(m.measure(m.feasible))


def _generic_conditioned_volume(c, o):
    m = _generic_map(c, o)
    return float(m.measure(m.reachable & (m.condition_index(o["kind"]) >= 1.0 / o["k_max"])))


def _generic_weighted_volume(c, o):
    m = _generic_map(c, o)
    ci = m.condition_index(o["kind"])[m.reachable]
    return float(np.sum(ci) * m.cell if m.uniform else np.sum(ci * m.cells[m.reachable]))


def _generic_condition(c, o):
    """``kappa`` of the inverse Jacobian at the pose, the angular rates divided by ``length`` (as the maps do)."""
    import pkm
    from pkm.core.differential.indices import condition_number
    from pkm.errors import SingularityError

    mech = c.mechanism
    target = {n: _task_value(mech, n, v) for n, v in (o.get("pose") or {}).items()}
    res = pkm.solve_ik(mech, target, branch=o.get("branch") or None)
    task = pkm.TaskMap.of(mech)
    scale = task.rate_scale(task.default_length(o.get("length")))  # (as the maps do)
    try:
        K = pkm.inverse_jacobian(mech, res.q)
    except SingularityError:
        return math.inf
    return float(condition_number(K * scale, o["kind"]))


def _motion(c: Candidate, o: Mapping[str, Any]):
    """The :class:`pkm.Trajectory` (efforts included) of the design along its motion case (cached)."""
    def make():
        import pkm
        from pkm.motion import load_motions

        mech = c.mechanism
        if not o.get("file") and not c.family.registered:
            raise InvalidInputError("file", "name the motion file (file=path/to/motions.toml) of a loaded mechanism")
        file = o.get("file") or f"{c.family.registered}_motions.toml"
        motions = o.get("motions") or load_motions(file)  # (a given file was read where the sweep was started)
        if o["motion"] not in motions:
            raise UnknownNameError("motion case", o["motion"], motions, str(file))
        motion = motions[o["motion"]]
        coords = tuple(o["coordinates"].split("/")) if o.get("coordinates") else motion.coordinates
        if len(coords) != len(motion.coordinates):
            raise InvalidInputError("coordinates", f"name the motion's {len(motion.coordinates)} coordinates "
                                                   f"{motion.coordinates} as task coordinates", o.get("coordinates"))
        task = pkm.TaskMap.of(mech)
        missing = [k for k in coords if k not in task.value_names]
        if missing or len(coords) != len(task.keys):
            raise InvalidInputError("coordinates", f"the motion's coordinates {coords} must be the task's "
                                                   f"{task.keys} (rename them: coordinates={'/'.join(task.keys)})",
                                    coords)
        _, Y, Yd, Ydd = motion.sample(None if not o.get("samples") else np.linspace(0.0, motion.duration,
                                                                                   int(o["samples"])))
        order = [coords.index(k) for k in task.keys]
        traj = pkm.follow_task(mech, Y[:, order], Yd[:, order], Ydd[:, order], efforts=True)
        if traj.jumps:  # (NaN efforts, or a motion on another branch: no peak of this design's)
            j = traj.jumps[0]
            raise PkmError(f"the design does not follow motion {o['motion']!r}: at sample {j.index} of {len(traj)}, "
                           f"{j.reason} ({j.detail})" + (f"; {len(traj.jumps) - 1} more jump(s)"
                                                         if len(traj.jumps) > 1 else ""))
        return traj

    return c.cached(("motion", o.get("file"), o["motion"], o.get("coordinates"), o.get("samples")), make)


def _peak_effort(c, o):
    return float(np.max(np.abs(_motion(c, o).efforts)))


def _peak_power(c, o):
    traj = _motion(c, o)
    return float(np.max(np.abs(traj.efforts * traj.actuated_velocity)))


def _operation_count(c, o):
    import pkm

    count = c.cached(("opcount", o["kernel"]), lambda: pkm.Kernels(c.mechanism).operation_count(o["kernel"]))
    return float({"total": count.mul + count.add, "mul": count.mul, "add": count.add}[o["count"]])


def _generic_interval(c, o):
    """Length of the reachable part of ``parameter`` (a task joint) over ``range`` at the pose: a 1-D map, each gap
    between two neighbouring reachable nodes counted (nodes times the step overstated each reachable run by a step)."""
    name = o.get("parameter")
    if not name or not o.get("range"):
        raise InvalidInputError("parameter", "give parameter=TASK_JOINT and range=START:STOP:COUNT")
    m = _generic_map(c, {**o, "region": {name: o["range"]}, "length": o.get("length") or 1.0})  # (reach only)
    (_, values), = m.axes
    reach = m.reachable.ravel()
    return float(np.sum(np.abs(np.diff(values))[reach[1:] & reach[:-1]]))


_REGION_UNIT = "m^i rad^j"  # (the product of the region's axes' units)
_MAP = {"region": ("region", None, "task coordinates mapped (generic): x=START:STOP:COUNT/y=..."),
        "pose": ("pose", None, "the other task coordinates (generic): x=2cm/z=-36cm"),
        "length": ("length", None, "characteristic length dividing angular rates (generic), e.g. 5cm; default "
                                   "where the task mixes lengths and angles: each design's characteristic length"),
        "branch": ("text", "", "working mode (default: the spec's; a closed form may name its own modes)"),
        "kind": ("text", "2", "condition-index convention: 2 or fro_normalized", ("2", "fro_normalized"))}

#: name -> :class:`Definition`: every library objective (the registered mechanisms' closed forms found through
#: the registry: :func:`closed_forms`).
OBJECTIVES: dict[str, Definition] = {d.name: d for d in (
    Definition("gci", "max", "-", "global condition index: mean 1/kappa over the reachable nodes", _MAP,
               _generic_gci),
    Definition("gci_area", "max", "-", "GCI over the area of interest (generic: the region)", _MAP, _generic_gci),
    Definition("coverage", "max", "-", "reachable fraction of the area of interest (generic: the region)", _MAP,
               _generic_coverage),
    Definition("min_area_ci", "max", "-", "smallest 1/kappa over the reachable nodes of the area (generic: region)",
               _MAP, _generic_min_ci),
    Definition("workspace_volume", "max", _REGION_UNIT, "reachable length, area or volume (generic: of the region)",
               _MAP, _generic_volume),
    Definition("limits_volume", "max", _REGION_UNIT, "reachable length, area or volume within the joints' stated "
               "position limits (generic: of the region)", _MAP, _limits_volume),
    Definition("interference_free_volume", "max", _REGION_UNIT, "reachable size within the joints' limits where no "
               "two bodies interpenetrate (collision geometry needed; beside limits_volume)", _MAP,
               _interference_free_volume),
    Definition("conditioned_volume", "max", _REGION_UNIT, "volume of the reachable nodes with kappa <= k_max",
               {**_MAP, "k_max": ("float", 3.0, "bound on kappa", 1.0)}, _generic_conditioned_volume),
    Definition("weighted_volume", "max", _REGION_UNIT, "integral of 1/kappa over the workspace (volume x GCI)",
               _MAP, _generic_weighted_volume),
    Definition("condition", "min", "-", "condition number kappa at a pose (default: the reference)",
               {**{k: _MAP[k] for k in ("pose", "length", "branch")},
                "kind": ("text", "2", "2, fro or fro_normalized", ("2", "fro", "fro_normalized"))}, _generic_condition),
    Definition("reachable_interval", "max", "m or rad", "reachable length of a task joint's range at a pose "
               "(generic: parameter=beta_1,range=-90deg:90deg:181; a closed form: its exact intervals)",
               {**_MAP, "parameter": ("text", "", "the task joint (generic)"),
                "range": ("range", None, "its range START:STOP:COUNT (generic)")}, _generic_interval),
    Definition("beta_gain", "max", "-", "index at the best reconfiguration beta* over the index at the reference "
               "beta, minus 1 (closed forms only)",
               {"pose": _MAP["pose"], "index": ("text", "w_rot", "w_rot or w_tras", ("w_rot", "w_tras"))}, None),
    Definition("peak_effort", "min", "N or N m", "largest |actuator effort| along a motion case",
               {"motion": ("text", "1", "the case's name"), "file": ("text", "", "motion file (default: "
                "<mechanism>_motions.toml)"), "coordinates": ("text", "", "the motion's coordinates as task "
                "coordinates, z/pitch/roll"), "samples": ("int", 0, "samples (default: the case's dt)", 0)},
               _peak_effort),
    Definition("peak_power", "min", "W", "largest |effort x actuator rate| along a motion case",
               {"motion": ("text", "1", "the case's name"), "file": ("text", "", "motion file"),
                "coordinates": ("text", "", "as peak_effort"), "samples": ("int", 0, "as peak_effort", 0)},
               _peak_power),
    Definition("capability", "max", "N, N m, m/s, rad/s, m/s^2 or rad/s^2", "smallest (stat=mean: mean) isotropic "
               "wrench, twist or acceleration capability under the actuators' limits over the map's regular nodes",
               {**_MAP, "kind": ("text", "wrench", "wrench, twist or acceleration", ("wrench", "twist", "acceleration")),
                "unit": ("text", "", "the unit group of a mixed task (N or N m ...; default the first)"),
                "stat": ("text", "min", "min or mean over the nodes", ("min", "mean")),
                "gravity": ("text", "on", "wrenches and accelerations against gravity (on) or not (off)",
                            ("on", "off"))},
               _capability),
    Definition("stiffness", "max", "N/m or N m/rad", "smallest (stat=mean: mean) principal stiffness under a pure "
               "force (load=moment: moment) over the map's nodes, every actuated joint a spring of drives (inf along "
               "a direction the mechanism cannot move)",
               {**_MAP, "drives": ("float", 1.0, "every actuated joint's stiffness, N m/rad or N/m (default 1: the "
                                   "stiffness per unit drive stiffness)", 0.0),
                "load": ("text", "force", "force or moment", ("force", "moment")),
                "stat": ("text", "min", "min or mean over the nodes", ("min", "mean"))},
               _stiffness),
    Definition("operation_count", "min", "operations", "operations of a generated kernel after CSE",
               {"kernel": ("text", "inverse_dynamics", "the kernel"),
                "count": ("text", "total", "total, mul, add", ("total", "mul", "add"))},
               _operation_count),
)}

RESERVED = frozenset({"design", "status", "error", "message"})

__all__ = ["OBJECTIVES", "ROUTES", "SENSES", "ClosedForm", "Definition", "Objective", "closed_forms", "load_callable",
           "objective"]
