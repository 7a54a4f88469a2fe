"""Two models, or two documents, compared as what they mean rather than as text.

A design written on one machine and regenerated on another differs in the last bits of its
numbers: numpy's SIMD kernels for ``sin``/``cos`` round differently on different CPUs (AVX-512,
AVX2 and the baseline give results one ulp apart), and a reference configuration found by an
iterative solve can end a few ulps elsewhere. So the files and the generators are compared after
parsing: the same structure and names, every number equal to

    ``|a - b| <= rtol * max(|a|, |b|) + atol``, by default ``rtol = 1e-12`` and ``atol = 1e-15``

(``atol`` lets a zero computed by round-off from O(1) SI quantities, such as ``-7.7e-18`` rad,
equal ``-0.0``; it is far below any length or angle a design states).

:func:`document_differences` compares URDF and TOML texts element by element;
:func:`mechanism_differences` compares two :class:`~pkm.core.model.mechanism.Mechanism` objects as
Pinocchio models (joints, placements, inertias, limits), closures and reference configurations.
Each returns a list of readable lines, empty when the two agree; every line says where the two
differ and by how much.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from pkm.core.model.spec import parse_toml
from pkm.errors import InvalidInputError

if TYPE_CHECKING:
    from pkm.core.model.mechanism import Mechanism

RTOL = 1e-12
ATOL = 1e-15


def close(a: float, b: float, rtol: float = RTOL, atol: float = ATOL) -> bool:
    """``|a - b| <= rtol * max(|a|, |b|) + atol`` (the comparison of this module)."""
    return abs(a - b) <= rtol * max(abs(a), abs(b)) + atol


def _numbers(text: str) -> tuple[float, ...] | None:
    try:
        return tuple(float(w) for w in text.split()) or None
    except ValueError:
        return None


def _xml_root(text: str) -> Any:  # an lxml element (lxml is untyped)
    from lxml import etree

    parser = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False)
    return etree.fromstring(text.encode("utf-8"), parser)


def _value_diff(where: str, a: Any, b: Any, out: list[str], rtol: float, atol: float) -> None:
    """Numbers (and tuples of numbers) within tolerance; anything else equal."""
    if isinstance(a, bool) or isinstance(b, bool) or not (isinstance(a, (int, float)) and isinstance(b, (int, float))):
        if a != b:
            out.append(f"{where}: {a!r} != {b!r}")
    elif a != b and not (math.isfinite(a) and math.isfinite(b) and close(float(a), float(b), rtol, atol)):
        out.append(f"{where}: {a!r} vs {b!r} (differ by {abs(a - b):.3g}; allowed {rtol:g} relative + {atol:g})")


def _xml_diff(a: Any, b: Any, where: str, out: list[str], rtol: float, atol: float) -> None:
    label = f"{where}/{a.tag}" + (f"[{a.get('name')!r}]" if a.get("name") is not None else "")
    if a.tag != b.tag or a.get("name") != b.get("name"):
        out.append(f"{label}: element <{a.tag} name={a.get('name')!r}> != <{b.tag} name={b.get('name')!r}>")
        return
    for k in sorted(set(a.attrib) ^ set(b.attrib)):
        out.append(f"{label}@{k}: only in the {'first' if k in a.attrib else 'second'}")
    for k in a.attrib:
        if k in b.attrib:
            va, vb = _numbers(a.get(k)), _numbers(b.get(k))
            if va is None or vb is None or len(va) != len(vb):
                _value_diff(f"{label}@{k}", a.get(k), b.get(k), out, rtol, atol)
            else:
                for i, (x, y) in enumerate(zip(va, vb)):
                    _value_diff(f"{label}@{k}[{i}]" if len(va) > 1 else f"{label}@{k}", x, y, out, rtol, atol)
    ca, cb = [c for c in a if isinstance(c.tag, str)], [c for c in b if isinstance(c.tag, str)]
    if len(ca) != len(cb):
        out.append(f"{label}: {len(ca)} child elements vs {len(cb)}")
        return
    for x, y in zip(ca, cb):
        _xml_diff(x, y, label, out, rtol, atol)


def _data_diff(a: Any, b: Any, where: str, out: list[str], rtol: float, atol: float) -> None:
    if isinstance(a, Mapping) and isinstance(b, Mapping):
        for k in sorted(set(a) ^ set(b)):
            out.append(f"{where}.{k}: only in the {'first' if k in a else 'second'}".lstrip("."))
        for k in a:
            if k in b:
                _data_diff(a[k], b[k], f"{where}.{k}".lstrip("."), out, rtol, atol)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out.append(f"{where}: {len(a)} entries vs {len(b)}")
        else:
            for k, (x, y) in enumerate(zip(a, b)):
                _data_diff(x, y, f"{where}[{k}]", out, rtol, atol)
    else:
        _value_diff(where, a, b, out, rtol, atol)


def document_differences(a: str, b: str, kind: str, *, rtol: float = RTOL, atol: float = ATOL) -> list[str]:
    """Where two URDF (``kind="urdf"``) or TOML (``kind="toml"``) texts differ after parsing.

    Elements (in order), attributes, keys and strings must be equal; numbers must be
    :func:`close` (a URDF attribute holding a list of numbers is compared number by number).
    """
    out: list[str] = []
    if kind == "urdf":
        _xml_diff(_xml_root(a), _xml_root(b), "", out, rtol, atol)
    elif kind == "toml":
        _data_diff(parse_toml(a, "<first>"), parse_toml(b, "<second>"), "", out, rtol, atol)
    else:
        raise InvalidInputError("kind", f"must be 'urdf' or 'toml', got {kind!r}", kind)
    return out


def _array_diff(where: str, a: ArrayLike, b: ArrayLike, out: list[str], rtol: float, atol: float) -> None:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.shape != b.shape:
        out.append(f"{where}: shape {a.shape} vs {b.shape}")
        return
    with np.errstate(invalid="ignore"):  # inf - inf: infinite limits compare by equality
        bad = ~((np.abs(a - b) <= rtol * np.maximum(np.abs(a), np.abs(b)) + atol) | (a == b))
    if bad.any():
        k = int(np.argmax(np.where(bad, np.abs(a - b), -1.0)))
        idx = np.unravel_index(k, a.shape) if a.ndim else ()
        out.append(f"{where}: {int(bad.sum())} of {a.size} numbers differ, worst at {tuple(map(int, idx))}: "
                   f"{float(a.flat[k])!r} vs {float(b.flat[k])!r} (by {abs(a.flat[k] - b.flat[k]):.3g})")


def mechanism_differences(a: Mechanism, b: Mechanism, *, rtol: float = RTOL, atol: float = ATOL) -> list[str]:
    """Where two mechanisms differ as models: joints (names, types, placements, limits), bodies
    (inertias), frames, closures, actuation, task and the reference configuration.
    """
    out: list[str] = []
    ma, mb = a.model, b.model
    for what, x, y in (("nq", ma.nq, mb.nq), ("nv", ma.nv, mb.nv), ("joints", list(ma.names), list(mb.names)),
                       ("frames", [f.name for f in ma.frames], [f.name for f in mb.frames]),
                       ("closures", [(c.name, c.type, c.frame_a, c.frame_b) for c in a.spec.closures],
                        [(c.name, c.type, c.frame_a, c.frame_b) for c in b.spec.closures]),
                       ("actuated", a.spec.actuated, b.spec.actuated), ("end effector", a.spec.end_effector,
                                                                          b.spec.end_effector),
                       ("task", a.spec.task, b.spec.task)):
        if x != y:
            out.append(f"{what}: {x!r} != {y!r}")
    if out:
        return out
    for j in range(1, ma.njoints):
        name = ma.names[j]
        if ma.joints[j].shortname() != mb.joints[j].shortname():
            out.append(f"joint {name!r}: {ma.joints[j].shortname()} != {mb.joints[j].shortname()}")
        _array_diff(f"joint {name!r} placement", ma.jointPlacements[j].homogeneous,
                    mb.jointPlacements[j].homogeneous, out, rtol, atol)
        _array_diff(f"body of {name!r} inertia", ma.inertias[j].toDynamicParameters(),
                    mb.inertias[j].toDynamicParameters(), out, rtol, atol)
    for what in ("lowerPositionLimit", "upperPositionLimit", "effortLimit", "velocityLimit"):
        _array_diff(what, getattr(ma, what), getattr(mb, what), out, rtol, atol)
    for fa, fb in zip(ma.frames, mb.frames):
        _array_diff(f"frame {fa.name!r} placement", fa.placement.homogeneous, fb.placement.homogeneous, out,
                    rtol, atol)
    _array_diff("reference configuration", a.q_reference, b.q_reference, out, rtol, atol)
    return out


__all__ = ["ATOL", "RTOL", "close", "document_differences", "mechanism_differences"]
