"""What a sweep varies: a family of designs, and one design of it (a :class:`Candidate`).

* :class:`RegisteredFamily`: a registered mechanism's design dataclass (``pkm list`` shows its fields); the
  parameters are its scalar fields (floats, and integers such as a working mode), the others fixed at the values
  given (the paper's by default). A design is ``Params(**fixed, **values)``; its mechanism ``module.build``.
* :class:`ModelFamily`: a mechanism loaded from one's own files. Its parameters are the origins of its URDF
  joints, ``JOINT.x``, ``JOINT.y``, ``JOINT.z`` [m] and ``JOINT.roll``, ``JOINT.pitch``, ``JOINT.yaw`` [rad]
  (the joint's placement in its parent link, which is where a link's length lives), set to the values given; the
  closure spec is kept as it is. Tuple fields of registered designs are not swept (name them fixed).

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

from pkm._moved import renamed_keywords
from pkm.errors import InvalidInputError, UnknownNameError

ORIGIN = {"x": ("xyz", 0), "y": ("xyz", 1), "z": ("xyz", 2), "roll": ("rpy", 0), "pitch": ("rpy", 1), "yaw": ("rpy", 2)}
_SCALAR_TYPES = ("float", "int")


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

    @property
    def params(self):
        """The design dataclass (a registered family), or None (a loaded one)."""
        return self.cached("params", lambda: self.family.params(self.values))

    @property
    def mechanism(self):
        """The :class:`pkm.Mechanism` of this design (built on first use)."""
        return self.cached("mechanism", lambda: self.family.mechanism(self.values))


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

    def candidate(self, values: Mapping[str, float]) -> Candidate:
        return Candidate(self, values)


class RegisteredFamily(Family):
    """The designs of registered mechanism ``name``, the fields not swept at ``fixed`` (SI or with units)."""

    def __init__(self, name: str, fixed: Mapping[str, Any] | None = None):
        import pkm

        self.registered = name
        self.module = pkm.mechanism_module(name)  # UnknownNameError listing the mechanisms
        self.fields = {f.name: f for f in dataclasses.fields(self.module.Params)}
        self.renamed = dict(getattr(self.module.Params, "RENAMED", {}))
        fixed = renamed_keywords(f"pkm.sweep({name!r})", fixed, self.renamed) if isinstance(fixed, Mapping) else fixed
        self.base = pkm.design_params(name, **dict(fixed or {}))  # units converted, validated
        self.fixed = {k: getattr(self.base, k) for k in (fixed or {})}

    def __reduce__(self):  # (the module does not pickle): rebuilt from the name and the fixed values
        return (RegisteredFamily, (self.registered, self.fixed))

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

    def describe(self) -> dict[str, Any]:
        return {"registered": self.registered, "fixed": {k: _jsonable(v) for k, v in self.fixed.items()}}


class ModelFamily(Family):
    """Designs of a loaded mechanism: its URDF joints' origins set to the values (see the module doc)."""

    def __init__(self, mech):
        from pkm.core.model.mechanism import check_mechanism

        mech = check_mechanism(mech)
        if mech.urdf is None:
            raise InvalidInputError("mechanism", "built from a Pinocchio model without URDF text: nothing to vary "
                                                 "(load it from files)", mech.source)
        self.urdf, self.spec, self.source = mech.urdf, mech.spec.to_toml(), mech.source
        self._base = mech
        self.joint_names = tuple(_joints(self.urdf)[1])

    def __getstate__(self):
        return {"urdf": self.urdf, "spec": self.spec, "source": self.source, "joint_names": self.joint_names}

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._base = None

    def parameters(self) -> tuple[str, ...]:
        return tuple(f"{j}.{c}" for j in self.joint_names for c in ORIGIN)

    def units(self, name: str) -> tuple[set[str | None], str]:
        if name not in self.parameters():
            raise UnknownNameError("parameter", name, self.parameters(),
                                   f"a sweep of {self.source} (URDF joint origins JOINT.x/y/z [m], "
                                   f"JOINT.roll/pitch/yaw [rad])")
        return ({"angle"}, "rad") if ORIGIN[name.rsplit(".", 1)[1]][0] == "rpy" else ({"length"}, "m")

    def mechanism(self, values: Mapping[str, float]):
        import dataclasses

        from pkm.core.model.builder import from_strings
        from pkm.core.model.spec import ClosureSpec

        if not values and self._base is not None:
            return self._base
        # the moved origins no longer close the file's reference: the actuators are held, the other joints assembled
        # from their former values (the same assembly mode)
        spec = ClosureSpec.from_toml(self.spec, self.source)
        held = {n: v for n, v in spec.reference.items() if n in spec.actuated}
        return from_strings(origins_set(self.urdf, values), dataclasses.replace(spec, reference=held),
                            source=self.source, seed=spec.reference)

    def describe(self) -> dict[str, Any]:
        return {"source": self.source, "urdf_sha256": hashlib.sha256(self.urdf.encode()).hexdigest(),
                "spec_sha256": hashlib.sha256(self.spec.encode()).hexdigest()}


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


def _joints(urdf: str):
    """The URDF's root and its joints by name (pkm's hardened parser, :func:`pkm.core.model.urdf.parse_xml`)."""
    from pkm.core.model.urdf import parse_xml

    root = parse_xml(urdf)
    return root, {j.get("name"): j for j in root.iter("joint") if j.get("name") and j.getparent() is root}


def origins_set(urdf: str, values: Mapping[str, float]) -> str:
    """The URDF text with the joint origins named by ``values`` (``JOINT.x`` ... ``JOINT.yaw``, SI) set."""
    from lxml import etree

    root, joints = _joints(urdf)
    for name, value in values.items():
        joint, _, comp = name.rpartition(".")
        if joint not in joints or comp not in ORIGIN:
            raise UnknownNameError("parameter", name, [f"{j}.{c}" for j in joints for c in ORIGIN], "the URDF")
        origin = joints[joint].find("origin")
        if origin is None:
            origin = etree.SubElement(joints[joint], "origin")
        attr, k = ORIGIN[comp]
        parts = (origin.get(attr) or "0 0 0").split()
        parts[k] = repr(float(value))
        origin.set(attr, " ".join(parts))
    return etree.tostring(root, encoding="unicode")


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
