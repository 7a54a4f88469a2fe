"""What a sweep varies: a family of designs, and one design of it (a :class:`Candidate`).

* :class:`RegisteredFamily`: a registered mechanism's design dataclass (``pkm list`` shows its fields); the
  parameters are its scalar fields (floats, and integers such as a working mode), the others fixed at the values
  given (the paper's by default). A design is ``Params(**fixed, **values)``; its mechanism ``module.build``.
* :class:`ModelFamily`: a mechanism loaded from one's own files. Its parameters are the origins of its URDF
  joints, ``JOINT.x``, ``JOINT.y``, ``JOINT.z`` [m] and ``JOINT.roll``, ``JOINT.pitch``, ``JOINT.yaw`` [rad]
  (the joint's placement in its parent link, which is where a link's length lives), and its bodies' inertial
  parameters ``BODY.m`` [kg], ``BODY.mx`` ... [kg m], ``BODY.Ixx`` ... [kg m^2] (the regressor's names), set to the
  values given (:func:`pkm.core.twin.design.design_mechanism`); the closure spec is kept as it is. Its compiled
  kernels take the swept parameters as inputs (:meth:`Family.kernels`: designs as kernel inputs), so the
  maps of a thousand designs share one compiled library. Tuple fields of registered designs are not swept (name
  them fixed).

A candidate builds what objectives need on first use and keeps it (:meth:`Candidate.cached`), so that several
objectives of one design share one map or one mechanism. Families pickle small: the mechanism's name and the
fixed values, or the URDF and spec texts; they travel to each worker once per sweep.
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from pkm._moved import renamed_keywords
from pkm.core.model.bodies import BODY_FIELDS, BODY_UNITS, body_names
from pkm.core.model.origins import ORIGIN, origins_set, urdf_joints
from pkm.errors import InvalidInputError, UnknownNameError

_SCALAR_TYPES = ("float", "int")
#: Units of the inertial parameters, by field.
_INERTIAL_UNITS = dict(zip(BODY_FIELDS, BODY_UNITS))
#: Each process's kernels with design inputs, by family and design inputs (:meth:`Family.kernels`): the
#: :data:`KEEP_KERNELS` latest.
_KERNELS: dict[tuple[str, tuple[str, ...]], Any] = {}
KEEP_KERNELS = 8


class Candidate:
    """One design of a family.

    Attributes:
        family: The family.
        values: ``{parameter: value}`` (SI) of this design.
    """

    def __init__(self, family: Family, values: Mapping[str, float]):
        self.family = family
        self.values = dict(values)
        self._cache: dict[Any, Any] = {}

    def cached(self, key, make: Callable[[], Any]):
        """``make()`` once per design and key (a map that several objectives read, the mechanism, ...)."""
        if key not in self._cache:
            self._cache[key] = make()
        return self._cache[key]

    def peek(self, key) -> Any:
        """What :meth:`cached` keeps under ``key``, or None (nothing made)."""
        return self._cache.get(key)

    def forget(self, key) -> None:
        """Drop what :meth:`cached` keeps under ``key`` (to make it again otherwise)."""
        self._cache.pop(key, None)

    @property
    def params(self):
        """The design dataclass (a registered family), or None (a loaded one)."""
        return self.cached("params", lambda: self.family.params(self.values))

    @property
    def mechanism(self):
        """The :class:`pkm.Mechanism` of this design (built on first use)."""
        return self.cached("mechanism", lambda: self.family.mechanism(self.values))

    @property
    def kernels(self):
        """The :class:`pkm.Kernels` of this design: the family's kernels with design inputs bound to it where the
        family has them (:meth:`Family.design_kernels`), else the design's own (compiled per design)."""
        return self.cached("kernels", lambda: self.family.design_kernels(self))


class Family:
    """A family of designs (see the module doc)."""

    #: The mechanism's registered name, or None for a loaded mechanism (objectives' closed forms key on it).
    registered: str | None = None
    #: Deprecated former parameter names -> the new ones (a registered design's ``Params.RENAMED``).
    renamed: Mapping[str, str] = {}

    def units(self, name: str) -> tuple[set[str | None], str]:
        """``(unit kinds, unit)`` of parameter ``name``; UnknownNameError listing the parameters otherwise."""
        raise NotImplementedError

    def parameters(self) -> tuple[str, ...]:
        raise NotImplementedError

    def integer(self, name: str) -> bool:
        """Whether parameter ``name`` takes integers only (a working mode)."""
        return False

    def params(self, values: Mapping[str, float]):
        return None

    def mechanism(self, values: Mapping[str, float]):
        raise NotImplementedError

    def describe(self) -> dict[str, Any]:
        """JSON-able, enough to rebuild the family (:func:`from_description`)."""
        raise NotImplementedError

    #: Whether designs share one compiled twin with design inputs (:meth:`design_kernels`); False compiles each
    #: design's own (the route the shared one is checked against).
    parametric: bool = True

    def design_kernels(self, candidate: Candidate):
        """The kernels of one design (:attr:`Candidate.kernels`): the family's twin with the parameters that
        differ from the base design as inputs (:mod:`pkm.core.twin.design`), bound to this design; the design's own
        when the family is not :attr:`parametric`, the design is the base, or it changes more than origins and
        inertias (joint kinds, the spec: :func:`~pkm.core.twin.design.structure`) or moves a number the inputs do not
        hold (checked at every design: the shared twin would keep the base's). A fixed joint carrying mass
        brings the ten inertial parameters of the body it merges into (:func:`~pkm.core.twin.design.with_merged_bodies`:
        the design mechanism's, as Pinocchio merges them)."""
        from pkm.core.twin import Kernels
        from pkm.core.twin.design import read_design, structure, with_merged_bodies
        from pkm.errors import PkmError

        mech = candidate.mechanism
        names = self.varied(tuple(candidate.values)) if self.parametric and candidate.values else ()
        if not names or structure(mech) != self.cached_structure():
            return Kernels(mech)
        names = with_merged_bodies(mech, names)
        ours = read_design(mech)
        inputs = set(names)
        if any(ours.get(k) != v for k, v in self.base_design().items() if k not in inputs):
            return Kernels(mech)  # (it moved a number the inputs do not hold: the shared twin would keep the base's)
        try:
            shared = self.kernels(names)
        except PkmError:  # (names the shared twin cannot take: the design's own kernels)
            return Kernels(mech)
        return shared.at(np.array([ours[n] for n in names]), mech)

    def varied(self, parameters: tuple[str, ...]) -> tuple[str, ...]:
        """The design inputs (:func:`pkm.core.twin.design.read_design`'s names) that ``parameters`` move."""
        raise NotImplementedError

    def base_mechanism(self):
        """The mechanism of the base design."""
        raise NotImplementedError

    def base_design(self) -> dict[str, float]:
        """The base design's numbers (:func:`pkm.core.twin.design.read_design`), read once."""
        if "_base_design" not in self.__dict__:
            from pkm.core.twin.design import read_design

            self._base_design = read_design(self.base_mechanism())
        return self._base_design

    def cached_structure(self) -> str:
        if "_structure" not in self.__dict__:
            from pkm.core.twin.design import structure

            self._structure = structure(self.base_mechanism())
        return self._structure

    def kernels(self, names: tuple[str, ...]):
        """The :class:`pkm.Kernels` of the base design with ``names`` as design inputs, built once per process
        (their compiled libraries once per machine: :mod:`pkm.core.twin.codegen` caches them by source); bind a
        design with :meth:`pkm.Kernels.at`."""
        from pkm.core.twin import Kernels

        if "_fingerprint" not in self.__dict__:  # (the files, and the base's numbers: a model changed in memory)
            self._fingerprint = repr((sorted(self.describe().items()), sorted(self.base_design().items())))
        key = (self._fingerprint, tuple(names))
        if key not in _KERNELS:
            while len(_KERNELS) >= KEEP_KERNELS:  # (the oldest first: a long-lived process sweeps many families)
                _KERNELS.pop(next(iter(_KERNELS)))
            _KERNELS[key] = Kernels(self.base_mechanism(), design=names)
        return _KERNELS[key]

    def candidate(self, values: Mapping[str, float]) -> Candidate:
        return Candidate(self, values)


class RegisteredFamily(Family):
    """The designs of registered mechanism ``name``, the fields not swept at ``fixed`` (SI or with units)."""

    def __init__(self, name: str, fixed: Mapping[str, Any] | None = None, *, parametric: bool = True):
        import pkm

        self.parametric = bool(parametric)
        self.registered = name
        self.module = pkm.mechanism_module(name)  # UnknownNameError listing the mechanisms
        self.fields = {f.name: f for f in dataclasses.fields(self.module.Params)}
        self.renamed = dict(getattr(self.module.Params, "RENAMED", {}))
        fixed = renamed_keywords(f"pkm.sweep({name!r})", fixed, self.renamed) if isinstance(fixed, Mapping) else fixed
        self.base = pkm.design_params(name, **dict(fixed or {}))  # units converted, validated
        self.fixed = {k: getattr(self.base, k) for k in (fixed or {})}

    def __reduce__(self):  # (the module does not pickle): rebuilt from the name and the fixed values
        return (_registered, (self.registered, self.fixed, self.parametric))

    def parameters(self) -> tuple[str, ...]:
        return tuple(n for n, f in self.fields.items() if f.type in _SCALAR_TYPES)

    def integer(self, name: str) -> bool:
        return self.fields[name].type == "int"

    def units(self, name: str) -> tuple[set[str | None], str]:
        from pkm.units import KIND_OF_UNIT

        if name not in self.parameters():
            raise UnknownNameError("parameter", name, self.parameters(),
                                   f"a sweep of {self.registered} (scalar fields of its Params)")
        units = tuple(self.fields[name].metadata.get("units", ()))
        return {KIND_OF_UNIT.get(u) for u in units} or {None}, "/".join(units) or "-"

    def params(self, values: Mapping[str, float]):
        kw = {}
        for k, v in values.items():
            if self.fields[k].type == "int":
                if not float(v).is_integer():
                    raise InvalidInputError(k, f"{k} takes integers, got {v!r}", v)
                v = int(v)
            kw[k] = v
        return dataclasses.replace(self.base, **kw)

    def mechanism(self, values: Mapping[str, float]):
        return self.module.build(self.params(values))

    def base_mechanism(self):
        if "_base_mech" not in self.__dict__:
            self._base_mech = self.module.build(self.base)
        return self._base_mech

    def varied(self, parameters: tuple[str, ...]) -> tuple[str, ...]:
        """The origins and inertias that move when each of ``parameters`` moves from the base design (a scalar
        field moved by 1 %, and by 1e-3 where it is 0); none when an integer field (a working mode) is swept."""
        from pkm.core.twin.design import read_design
        from pkm.errors import PkmError

        cache: dict[tuple[str, ...], tuple[str, ...]] = self.__dict__.setdefault("_varied", {})
        if parameters not in cache:
            base = self.base_design()
            names: set[str] = set()
            for p in parameters:
                v = float(getattr(self.base, p))
                try:
                    if self.integer(p):
                        raise InvalidInputError(p, "a working mode changes the spec, not the geometry")
                    moved = read_design(self.mechanism({p: v * 1.01 if v else 1e-3}))
                except PkmError:  # (or the moved design does not build): no shared twin, each design its own
                    names = set()
                    break
                names |= {n for n, x in moved.items() if n in base and x != base[n]}
            cache[parameters] = tuple(n for n in base if n in names)
        return cache[parameters]

    def describe(self) -> dict[str, Any]:
        return {"registered": self.registered, "fixed": {k: _jsonable(v) for k, v in self.fixed.items()}}


class ModelFamily(Family):
    """Designs of a loaded mechanism: its URDF joints' origins and its bodies' inertial parameters set to the values
    (see the module doc). ``parametric=False`` compiles each design's kernels apart (:attr:`Family.parametric`)."""

    def __init__(self, mech, *, parametric: bool = True):
        from pkm.core.model.mechanism import check_mechanism

        mech = check_mechanism(mech)
        if mech.urdf is None:
            raise InvalidInputError("mechanism", "built from a Pinocchio model without URDF text: nothing to vary "
                                                 "(load it from files)", mech.source)
        self.urdf, self.spec, self.source = mech.urdf, mech.spec.to_toml(), mech.source
        self._base = None
        files = self.base  # (what every design is built from: the texts)
        from pkm.core.twin.design import read_design

        ours, theirs = read_design(mech), read_design(files)
        changed = sorted(k for k in ours if ours[k] != theirs.get(k))
        if changed:
            raise InvalidInputError("mechanism", f"its model differs from its files ({', '.join(changed[:3])}"
                                                 f"{' ...' if len(changed) > 3 else ''} set in memory): a sweep builds "
                                                 "its designs from the files; write them, or sweep those parameters",
                                    mech.source)
        self._base = mech
        self.joint_names = urdf_joints(self.urdf)
        self.body_names = body_names(mech.model)
        self.parametric = bool(parametric)

    def __getstate__(self):
        return {"urdf": self.urdf, "spec": self.spec, "source": self.source, "joint_names": self.joint_names,
                "body_names": self.body_names, "parametric": self.parametric}

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._base = None

    @property
    def base(self):
        """The mechanism as its files state it (rebuilt once after pickling)."""
        if self._base is None:
            from pkm.core.model.builder import from_strings

            self._base = from_strings(self.urdf, self.spec, source=self.source)
        return self._base

    def parameters(self) -> tuple[str, ...]:
        return (tuple(f"{j}.{c}" for j in self.joint_names for c in ORIGIN)
                + tuple(f"{b}.{f}" for b in self.body_names for f in BODY_FIELDS))

    def units(self, name: str) -> tuple[set[str | None], str]:
        if name not in self.parameters():
            raise UnknownNameError("parameter", name, self.parameters(),
                                   f"a sweep of {self.source} (URDF joint origins JOINT.x/y/z [m], "
                                   f"JOINT.roll/pitch/yaw [rad]; inertial parameters BODY.m [kg], BODY.mx/my/mz "
                                   f"[kg m], BODY.Ixx... [kg m^2])")
        comp = name.rsplit(".", 1)[1]
        if comp in ORIGIN:
            return ({"angle"}, "rad") if ORIGIN[comp][0] == "rpy" else ({"length"}, "m")
        return ({"mass"}, "kg") if comp == "m" else ({None}, _INERTIAL_UNITS[comp])

    def mechanism(self, values: Mapping[str, float]):
        from pkm.core.twin.design import design_mechanism

        if not values:
            return self.base
        return design_mechanism(self.base, values)

    def base_mechanism(self):
        return self.base

    def varied(self, parameters: tuple[str, ...]) -> tuple[str, ...]:
        return parameters

    def describe(self) -> dict[str, Any]:
        return {"source": self.source, "urdf_sha256": hashlib.sha256(self.urdf.encode()).hexdigest(),
                "spec_sha256": hashlib.sha256(self.spec.encode()).hexdigest()}


def _registered(name: str, fixed: Mapping[str, Any], parametric: bool) -> RegisteredFamily:
    return RegisteredFamily(name, fixed, parametric=parametric)


def family_of(mechanism, fixed: Mapping[str, Any] | None = None) -> Family:
    """The family of ``mechanism``: a registered name (fields not swept at ``fixed``), a :class:`pkm.Mechanism`
    or the path of one's own files (:func:`pkm.load`), or a family already."""
    import pkm

    if isinstance(mechanism, Family):
        return mechanism
    if fixed is not None and not isinstance(fixed, Mapping):
        raise InvalidInputError("fixed", f"expected {{parameter: value}}, got {type(fixed).__name__}", fixed)
    if isinstance(mechanism, str) and mechanism in pkm.MECHANISMS:
        return RegisteredFamily(mechanism, fixed)
    if fixed:
        raise InvalidInputError("fixed", "fixed parameters are for registered mechanisms; a loaded one sweeps its "
                                         "joint origins and keeps the others as its files state them", fixed)
    return ModelFamily(mechanism if isinstance(mechanism, pkm.Mechanism) else pkm.load(mechanism))


def from_description(desc: Mapping[str, Any], mechanism=None) -> Family:
    """The family a results file describes (:meth:`Family.describe`); a loaded one needs ``mechanism`` (its files)
    and is checked against the stored fingerprints."""
    if desc.get("registered"):
        return RegisteredFamily(desc["registered"], desc.get("fixed") or {})
    if mechanism is None:
        raise InvalidInputError("mechanism", f"the sweep varied a mechanism loaded from {desc.get('source')}: give "
                                             "it (its spec's path) to rebuild the designs", desc.get("source"))
    family = family_of(mechanism)
    if any(family.describe()[k] != desc.get(k) for k in ("urdf_sha256", "spec_sha256")):
        raise InvalidInputError("mechanism", "these files are not the ones the sweep varied (their URDF or spec "
                                             "differ)", mechanism)
    return family


def _jsonable(v):
    if isinstance(v, tuple):
        return [_jsonable(x) for x in v]
    if isinstance(v, float) and not math.isfinite(v):
        return repr(v)
    return v


__all__ = ["ORIGIN", "Candidate", "Family", "ModelFamily", "RegisteredFamily", "family_of", "from_description",
           "origins_set"]
