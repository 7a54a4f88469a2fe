"""Plausibility of a model's numbers: what loads but no real mechanism has (issue 41).

Checked on every mechanism built (:func:`pkm.core.model.builder.build`), each finding a
:class:`~pkm.errors.ImplausibleModelWarning` (its bodies or joints and values as attributes) and a line of
:attr:`~pkm.core.Mechanism.notes`. The rules, all scale-aware (a mechanism of 5 cm and one of 5 m are judged alike):

* **size** ``L`` [m]: the largest extent, along x, y or z, of the joint origins, the frames' origins and the
  centres of mass of the bodies that weigh at least :data:`MASS_SHARE` of the whole at the reference configuration
  (no rule of size below applies when ``L`` is 0). A lighter body's centre of mass (its first moment over its mass)
  says nothing of the mechanism's extent: an identified body of almost no mass and a finite first moment has it
  metres away (a Delta of 0.45 m measured 4.1 m so). An extent, not the
  :attr:`~pkm.core.Mechanism.characteristic_length` that thresholds scale by (an RMS spread of the joints), since a
  bound must enclose the whole mechanism; both come from :func:`pkm.core.model.mechanism.reference_points`;
* **mass** (``kind="mass"``): a body heavier than a solid steel cube of side ``L`` (:data:`DENSITY` ``L³``), the
  heaviest solid that fits in a cube enclosing the whole mechanism;
* **inertia** (``kind="inertia"``): a body whose largest principal moment about its centre of mass exceeds
  ``m L²`` (its radius of gyration beyond the whole mechanism's extent);
* **negative** (``kind="negative"``): a principal moment about the centre of mass below zero by more than
  :data:`TRIANGLE_TOL` times the body's largest one in magnitude (no distribution of mass has it);
* **triangle** (``kind="triangle"``): principal moments ``I1 <= I2 <= I3`` about the centre of mass with
  ``I3 > I1 + I2`` by more than :data:`TRIANGLE_TOL` ``I3`` (no distribution of mass has them; a body with a negative
  moment is named by the rule above only);
* the inertia, negative and triangle rules leave out a body whose ``I3`` is under :data:`NEGLIGIBLE` ``M L²`` (``M`` the
  whole mass): no measurement sees it (an identified massless link: the consistent estimate's 1e-7 kg and 3e-6
  kg m² on a Delta whose ``M L²`` is 0.13 kg m², its triangle broken by 4e-14 kg m²);
* **limits** (``kind="limits"``): every actuated joint with the same effort limit and the same velocity limit,
  each a power of ten (``10^k``, ``k`` an integer: 1000 N m and 100 rad/s, an exporter's or a template's
  placeholders). A limit of 0 or of at least 1e6 in a file already reads as none (:mod:`pkm.core.model.actuators`).

The negative and triangle rules name the bodies whose inertias are not physical (:func:`nonphysical`): such a model
loads for its kinematics, which needs no inertia, and its dynamics is refused (:func:`require_physical`: a
:class:`~pkm.errors.NonPhysicalInertiaError` naming them), by inverse and forward dynamics, the mass matrix and the
actuator-space model, the simulation, the energy, the transmissions' serial-equivalent model, the twin's
actuator-space model (the compiled dynamics kernels, a :meth:`~pkm.core.twin.kernels.Kernels.at` design view judged
on its own inertias, and the exported C library) and the consistent identification (which starts from the model's
inertias). The regressor needs no inertia and is answered.

Measured on pkm's shipped mechanisms, the acceptance set and Gepetto's examples: the heaviest body weighs at most
1.2 % of the mass bound (Gepetto's ``5bar_linkage_iso3d``) and a radius of gyration at most 0.53 ``L`` (the knee
example), except Gepetto's ``5bar_linkage``, whose links of 654,498 kg weigh 91 times the bound.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from pkm._derived import derived
from pkm.core.model.mechanism import Mechanism, reference_points
from pkm.errors import ImplausibleModelWarning, NonPhysicalInertiaError

DENSITY = 8000.0  # [kg/m^3] steel: the mass bound is a steel cube of side L
TRIANGLE_TOL = 1e-4  # relative slack of the triangle inequality (a file's rounding of a flat body's moments)
MASS_SHARE = 1e-2  # a body's centre of mass counts in the size where it weighs at least this share of the total
NEGLIGIBLE = 1e-4  # a body's largest principal moment under this times M L^2: left out of the inertia rules


def size(mech: Mechanism) -> float:
    """The mechanism's extent [m] (module doc): the largest width of :func:`~pkm.core.model.mechanism.reference_points`
    (joints, frames, the centres of mass of bodies of at least :data:`MASS_SHARE` of the whole) at the reference.
    Not :attr:`~pkm.core.Mechanism.characteristic_length` (the RMS spread of the joints about their centroid, what
    thresholds scale by): a bound on a body's mass or inertia must enclose the whole mechanism."""
    model = mech.model
    points = np.vstack(reference_points(model, mech.q_reference, min_mass=MASS_SHARE * _total_mass(model)))
    return float(np.ptp(points, axis=0).max()) if len(points) > 1 else 0.0


def _total_mass(model: pin.Model) -> float:
    return sum(max(float(model.inertias[j].mass), 0.0) for j in range(1, model.njoints))


def _body_names(model: pin.Model) -> list[str]:
    """Each joint's body by the name of its first link (the joint's name where it has none)."""
    names = [model.names[j] for j in range(model.njoints)]
    for f in reversed(list(model.frames)):
        if f.type == pin.FrameType.BODY and f.parentJoint > 0:
            names[f.parentJoint] = f.name
    return names


def _fmt(names: tuple[str, ...], values: tuple[float, ...], unit: str) -> str:
    return ", ".join(f"{n!r} {v:.6g} {unit}" for n, v in zip(names, values))


def findings(mech: Mechanism) -> list[ImplausibleModelWarning]:
    """Every rule's finding on ``mech`` (module doc), one warning per rule that fires, in the module doc's order."""
    model = mech.model
    names = _body_names(model)
    L = size(mech)
    floor = NEGLIGIBLE * _total_mass(model) * L * L
    heavy, spread = [], []
    for j in range(1, model.njoints):
        inertia = model.inertias[j]
        m = float(inertia.mass)
        if m <= 0.0:
            continue
        e = np.linalg.eigvalsh(np.asarray(inertia.inertia, dtype=float))
        if L > 0.0 and m > DENSITY * L ** 3:
            heavy.append((names[j], m))
        if e[2] > floor and L > 0.0 and e[2] > m * L * L:
            spread.append((names[j], float(e[2]), m * L * L))
    bad = nonphysical(mech)
    negative = [(n, v) for n, r, v in bad if r == "negative"]
    skew = [(n, v) for n, r, v in bad if r == "triangle"]
    out = []
    where = mech.source
    if heavy:
        n, v = zip(*heavy)
        bound = DENSITY * L ** 3
        out.append(ImplausibleModelWarning(
            f"{where}: bodies heavier than a solid steel cube enclosing the whole mechanism ({bound:.4g} kg: "
            f"{DENSITY:g} kg/m^3 times its extent {L:.4g} m cubed): {_fmt(n, v, 'kg')}; check the masses (units: "
            f"kg, not g)", "mass", n, v, bound))
    if spread:
        n, v, b = zip(*spread)
        out.append(ImplausibleModelWarning(
            f"{where}: bodies whose largest principal moment of inertia exceeds their mass times the mechanism's "
            f"extent squared ({L:.4g} m): {_fmt(n, v, 'kg m^2')} (above {', '.join(f'{x:.4g}' for x in b)}); check "
            f"the inertias (units: kg m^2; about the centre of mass)", "inertia", n, v, float(max(b))))
    if negative:
        n, v = zip(*negative)
        out.append(ImplausibleModelWarning(
            f"{where}: inertias with a negative principal moment (about the centre of mass): {_fmt(n, v, 'kg m^2')}; "
            f"no distribution of mass has them: the kinematics is answered, the dynamics refused", "negative", n, v,
            0.0))
    if skew:
        n, v = zip(*skew)
        out.append(ImplausibleModelWarning(
            f"{where}: inertias that break the triangle inequality (the largest principal moment exceeds the sum of "
            f"the two others by): {_fmt(n, v, 'kg m^2')}; no distribution of mass has them: the kinematics is answered, "
            f"the dynamics refused", "triangle", n, v, 0.0))
    acts = mech.actuators
    effort = {a.effort_limit for a in acts}
    speed = {a.velocity_limit for a in acts}
    if acts and len(effort) == 1 and len(speed) == 1 and _power_of_ten(*effort) and _power_of_ten(*speed):
        tau, vel = effort.pop(), speed.pop()
        joints = tuple(a.joint for a in acts)
        out.append(ImplausibleModelWarning(
            f"{where}: every actuator's limits are {tau:g} (N m or N) and {vel:g} (rad/s or m/s), round powers of ten "
            f"alike on all of {', '.join(joints)}: placeholders, not a drive's; give the motors' values "
            f"([actuators.<joint>] effort_limit, peak_effort, velocity_limit in the closure spec, or "
            f"pkm.with_actuators)", "limits", joints, (tau, vel), tau))
    return out


def nonphysical(mech: Mechanism) -> tuple[tuple[str, str, float], ...]:
    """``((body, rule, value), ...)``: the bodies whose inertias no distribution of mass has (the module doc's
    negative and triangle rules), each named by its first link, with the rule (``"negative"``, ``"triangle"``) and
    the offending value [kg m^2] (the negative moment; the triangle's excess); made once per mechanism."""
    return derived(mech, _nonphysical)


def _nonphysical(mech: Mechanism) -> tuple[tuple[str, str, float], ...]:
    model = mech.model
    moments = [np.linalg.eigvalsh(np.asarray(model.inertias[j].inertia, dtype=float)) for j in range(1, model.njoints)]
    if all(e[0] >= -TRIANGLE_TOL * np.abs(e).max() and e[2] - e[0] - e[1] <= TRIANGLE_TOL * e[2] for e in moments):
        return ()  # (every body physical: the size, a forward kinematics, not needed)
    names = _body_names(model)
    L = size(mech)
    floor = NEGLIGIBLE * _total_mass(model) * L * L
    out = []
    for j, e in enumerate(moments, 1):
        largest = float(np.abs(e).max())
        if largest <= floor:
            continue
        if e[0] < -TRIANGLE_TOL * largest:
            out.append((names[j], "negative", float(e[0])))
        elif float(model.inertias[j].mass) > 0.0 and e[2] - e[0] - e[1] > TRIANGLE_TOL * e[2]:
            out.append((names[j], "triangle", float(e[2] - e[0] - e[1])))
    return tuple(out)


def require_physical(mech: Mechanism, what: str) -> None:
    """Nothing where every body's inertia is physical; else a :class:`~pkm.errors.NonPhysicalInertiaError` saying
    that ``what`` (``"inverse dynamics"``...) is refused and naming the bodies (:func:`nonphysical`).

    Raises:
        NonPhysicalInertiaError: a body's inertia has a negative principal moment or breaks the triangle inequality.
    """
    bad = nonphysical(mech)
    if bad:
        links, rules, values = zip(*bad)
        raise NonPhysicalInertiaError(what, links, rules, values, mech.source)


def _power_of_ten(x: float) -> bool:
    if not (math.isfinite(x) and x > 0.0):
        return False
    k = round(math.log10(x))
    return x == float(10.0 ** k) or math.isclose(x, 10.0 ** k, rel_tol=1e-12)


__all__ = ["DENSITY", "MASS_SHARE", "NEGLIGIBLE", "TRIANGLE_TOL", "findings", "nonphysical", "require_physical", "size"]
