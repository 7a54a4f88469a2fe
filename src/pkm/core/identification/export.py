"""Identified parameters written back as a mechanism pkm loads, and the identified model validated on other data.

:func:`write_identified` writes a closure spec and its URDF (:func:`pkm.save`'s layout) whose bodies carry the
identified standard parameters ``θ`` and whose actuators carry the identified drives:

* each Pinocchio body's ten parameters (about its joint frame) go to the ``<inertial>`` of the link its joint moves
  (mass, centre of mass ``h / m``, the inertia about the centre of mass, in the link's axes); links Pinocchio merged
  into that body (fixed joints) lose theirs, which the body's already holds;
* each actuator's reflected inertia, viscous and Coulomb friction go to the spec's ``[actuators.<joint>]`` table
  (``armature`` = the reflected inertia less the rotor's ``I_r k²``); the effort offset has no place in a model
  (it is the measurement's) and is left out.

With only the base parameters estimated (least squares), :func:`standard_from_base` gives the standard
parameters to write: the model's own, corrected by the smallest change that gives the estimated base values
(``θ = θ_model + P⁺ (β̂ - P θ_model)``); the physically consistent estimate gives them directly.

:func:`validate` predicts the efforts of other measurements and compares: per actuator the RMS error and the
relative error (RMS error over the measured efforts' RMS, %).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin
from lxml import etree
from numpy.typing import ArrayLike

from pkm.core.identification.base import BaseParameters
from pkm.core.identification.estimate import Estimate, _scale
from pkm.core.identification.measurements import Measurements
from pkm.core.identification.regressor import known_efforts, parameters, regressor_batch
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.errors import InvalidInputError
from pkm.validation import instance_of

if TYPE_CHECKING:
    from pkm.core.identification.consistent import ConsistentEstimate


def standard_from_base(mech: Mechanism, base: BaseParameters, values: ArrayLike) -> np.ndarray:
    """Standard parameters with base values ``values``: the model's, changed by the least-norm correction."""
    theta0 = parameters(check_mechanism(mech)).values
    beta = np.asarray(values, dtype=float)
    return theta0 + np.linalg.pinv(base.map) @ (beta - base.map @ theta0)


def _inertial(link: etree._Element, inertia: pin.Inertia) -> None:
    for old in link.findall("inertial"):
        link.remove(old)
    el = etree.SubElement(link, "inertial")
    c = inertia.lever
    etree.SubElement(el, "origin", xyz=" ".join(repr(float(x)) for x in c), rpy="0 0 0")
    etree.SubElement(el, "mass", value=repr(float(inertia.mass)))
    I = inertia.inertia
    etree.SubElement(el, "inertia", ixx=repr(float(I[0, 0])), ixy=repr(float(I[0, 1])), ixz=repr(float(I[0, 2])),
                     iyy=repr(float(I[1, 1])), iyz=repr(float(I[1, 2])), izz=repr(float(I[2, 2])))


#: A body whose ten parameters, its mass included, are all within this fraction of the largest body parameter is
#: written massless: the consistent estimate of a massless body (a mass of 1e-16 kg once projected, its first moment
#: as small and its moments of inertia at the solver's tolerance, Clarabel's 1e-8: 1.4e-9 kg m^2 on the Delta's guides against a largest parameter of 0.2, 7e-9
#: of it), which no body of zero mass can hold.
MASSLESS = 1e-7


def identified_mechanism(mech: Mechanism, theta: ArrayLike, source: str | None = None) -> Mechanism:
    """A copy of ``mech`` whose bodies and drives carry the standard parameters ``theta`` (module doc); ``source``
    names it in its warnings and notes (default ``"the model identified from <mech's source>"``: the identified
    numbers, not ``mech``'s file, are what a plausibility warning is about).

    Raises:
        InvalidInputError: ``theta`` of the wrong length or not finite; a body with a non-positive mass but other
            parameters not zero (beyond :data:`MASSLESS`: no link can hold it; estimate it physically consistent
            instead); a mechanism without URDF text.
    """
    import pkm
    from pkm.core.model.builder import from_strings

    mech = check_mechanism(mech)
    P = parameters(mech)
    th = np.asarray(theta, dtype=float)
    if th.shape != (len(P),) or not np.all(np.isfinite(th)):
        raise InvalidInputError("theta", f"expected {len(P)} finite parameters, got shape {th.shape}", th.shape)
    if mech.urdf is None:
        raise InvalidInputError("mech", "built from a Pinocchio model, not URDF text: no URDF to write", mech.source)
    root = etree.fromstring(mech.urdf.encode(), etree.XMLParser(resolve_entities=False, no_network=True))
    links = {el.get("name"): el for el in root.findall("link")}
    model = mech.model
    scale = float(np.abs(th[:P.n_body]).max(initial=0.0))
    for b, name in enumerate(P.bodies):
        t = th[10 * b:10 * b + 10]
        j = b + 1
        frames = [f for f in model.frames if f.type == pin.FrameType.BODY and f.parentJoint == j]
        for f in frames[1:]:  # (merged links: the body holds them already)
            for old in links[f.name].findall("inertial") if f.name in links else []:
                links[f.name].remove(old)
        if np.abs(t).max() <= MASSLESS * scale:  # (massless, the mass too: no <inertial>)
            for old in links[name].findall("inertial") if name in links else []:
                links[name].remove(old)
            continue
        if t[0] <= 0.0:
            raise InvalidInputError("theta", f"body {name!r}: mass {t[0]:.6g} kg is not positive (write a physically "
                                             f"consistent estimate)", t[0])
        inertia = frames[0].placement.actInv(pin.Inertia.FromDynamicParameters(t)) if frames else \
            pin.Inertia.FromDynamicParameters(t)
        if name in links:
            _inertial(links[name], inertia)
    urdf = etree.tostring(root, encoding="unicode")
    spec = mech.spec
    out = from_strings(urdf, spec.to_toml(), mech.params,
                       source=source or f"the model identified from {mech.source}")
    drives = {}
    for i, a in enumerate(mech.actuators):
        armature, viscous, coulomb = th[P.n_body + 4 * i:P.n_body + 4 * i + 3]
        drives[a.joint] = replace(a, armature=max(float(armature) - a.rotor_inertia * a.gear_ratio ** 2, 0.0),
                                  viscous=max(float(viscous), 0.0), coulomb=max(float(coulomb), 0.0))
    return pkm.with_actuators(out, drives)


def write_identified(mech: Mechanism, theta: ArrayLike, spec_path: str | Path) -> Path:
    """Write :func:`identified_mechanism` as a spec at ``spec_path`` and its URDF beside it (:func:`pkm.save`).

    Examples:
        >>> import tempfile
        >>> from pathlib import Path
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> P = pkm.parameters(delta)
        >>> theta = P.values.copy()
        >>> theta[P.names.index("arm_1.m")] *= 1.1
        >>> path = pkm.write_identified(delta, theta, Path(tempfile.mkdtemp()) / "identified.closures.toml")
        >>> back = pkm.parameters(pkm.load(path))
        >>> k = P.names.index("arm_1.m")
        >>> round(float(back.values[k] / P.values[k]), 9)
        1.1
    """
    import pkm

    return pkm.save(identified_mechanism(mech, theta, source=str(spec_path)), spec_path, to="pkm")


@dataclass(frozen=True)
class Validation:
    """Predicted against measured efforts.

    Attributes:
        rms: Each actuator's RMS error [N m, N].
        relative: ``rms`` over the measured efforts' RMS [%].
        predicted: The predicted efforts (N x na); ``measured``: the measured ones.
        t: The samples' times [s].
    """

    rms: np.ndarray
    relative: np.ndarray
    predicted: np.ndarray
    measured: np.ndarray
    t: np.ndarray


def validate(mech: Mechanism, predict: Estimate | ConsistentEstimate, data: Measurements) -> Validation:
    """Compare the efforts ``predict(Y)`` (an :class:`~pkm.core.identification.estimate.Estimate` or a
    :class:`~pkm.core.identification.consistent.ConsistentEstimate`) with ``data``'s.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> rng = np.random.default_rng(0)
        >>> Q = np.array([pkm.solve_ik(delta, [x, y, -0.36]).q for x, y in 0.05 * rng.standard_normal((60, 2))])
        >>> QD, QDD = rng.standard_normal((60, 3)), 10 * rng.standard_normal((60, 3))
        >>> TAU = np.array([pkm.actuator_model(delta, q, qd).efforts(qdd)
        ...                 for q, qd, qdd in zip(Q, QD, QDD)])
        >>> base = pkm.base_parameters(delta, 50, precise=False)
        >>> est = pkm.estimate(delta, Q[:50], QD[:50], QDD[:50], TAU[:50], base=base)
        >>> check = pkm.Measurements(t=np.arange(10) * 0.01, Q=Q[50:], QD=QD[50:], QDD=QDD[50:], TAU=TAU[50:],
        ...                          cutoff=10.0, rate=100.0, decimate=1)
        >>> val = pkm.validate(delta, est, check)
        >>> val.rms.shape, bool(val.rms.max() < 1e-9)
        ((3,), True)
    """
    from pkm.core.identification.consistent import ConsistentEstimate

    mech = check_mechanism(mech)
    instance_of(predict, (Estimate, ConsistentEstimate), "predict", "a pkm.Estimate or ConsistentEstimate "
                "(pkm.estimate or pkm.consistent_estimate)")
    data = instance_of(data, Measurements, "data", "pkm.Measurements (pkm.measurements)")
    Y = regressor_batch(mech, data.Q, data.QD, data.QDD)
    pred = np.asarray(predict.predict(Y), dtype=float).reshape(data.TAU.shape)
    pred = pred + known_efforts(mech, data.Q, data.QD)  # (the springs' and the passive joints' friction)
    if not np.all(np.isfinite(pred)):
        raise InvalidInputError("predict", "its predicted efforts overflow on these samples", predict)
    s = _scale(max(float(np.abs(pred).max(initial=0.0)), float(np.abs(data.TAU).max(initial=0.0))))
    rms = np.sqrt(np.mean((pred / s - data.TAU / s) ** 2, axis=0))  # (squares beyond 1e154 overflow: divided by s)
    relative = 100.0 * rms / np.maximum(np.sqrt(np.mean((data.TAU / s) ** 2, axis=0)), 1e-300)
    with np.errstate(over="ignore"):
        rms = rms * s
    if not np.all(np.isfinite(rms)):
        raise InvalidInputError("data", "the efforts' errors overflow (beyond 1.8e308 [N m, N])",
                                float(np.abs(data.TAU).max()))
    return Validation(rms, relative, pred, data.TAU, data.t)


__all__ = ["Validation", "identified_mechanism", "standard_from_base", "validate", "write_identified"]
