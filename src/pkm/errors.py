"""The exceptions pkm raises. Every one derives from :class:`PkmError`.

Each exception carries the data a caller needs to react (the offending value,
the leg, the residual, the valid names) as attributes, and its message says
what was wrong and, where possible, how to fix it.
"""

from __future__ import annotations

import difflib
import unicodedata
from collections.abc import Iterable

#: Letters that look like Latin ones (Cyrillic, Greek, dotless i, dashes), read as those by :func:`fold_name`
#: (written as code points: the look-alikes themselves would be unreadable here).
_CONFUSABLES = str.maketrans({
    **dict(zip("\u0430\u0435\u043e\u0440\u0441\u0443\u0445\u0455\u0456\u0458\u0501\u04bb\u04cf\u043a"  # Cyrillic
               "\u0410\u0412\u0415\u041a\u041c\u041d\u041e\u0420\u0421\u0422\u0425\u0423\u0405\u0406\u0408",
               "aeopcyxsijdhlkABEKMHOPCTXYSIJ")),
    **dict(zip("\u03b1\u03bf\u03c1\u03bd\u03c5\u03b9\u03ba\u03c7"  # Greek
               "\u0391\u0392\u0395\u0396\u0397\u0399\u039a\u039c\u039d\u039f\u03a1\u03a4\u03a5\u03a7",
               "aopvuikxABEZHIKMNOPTYX")),
    "\u0131": "i", **dict.fromkeys("\u2010\u2011\u2012\u2013\u2014\u2212", "-"),  # dotless i; hyphens, dashes, minus
})
#: Up to this many valid names, an :class:`UnknownNameError` lists them all.
SHORT_LIST = 20


def fold_name(name: str) -> str:
    """``name`` as plain lower-case ASCII where it can be: compatibility-decomposed (NFKD: full-width letters,
    ligatures), accents dropped (``ö`` is ``o``), Cyrillic and Greek look-alikes read as the Latin letters they
    resemble (Cyrillic ``\\u043e`` is ``o``), case folded. Two names that fold alike look alike to a reader."""
    text = unicodedata.normalize("NFKD", name)
    return "".join(c for c in text if not unicodedata.combining(c)).translate(_CONFUSABLES).casefold()


def closest(name: object, valid: Iterable[str], *, cutoff: float = 0.75) -> tuple[str, ...]:
    """The valid names ``name`` was most likely meant to be, best first (empty when none is close).

    A valid name that folds to the same text (:func:`fold_name`: one accent, one Cyrillic letter, the case) is the
    answer alone; else the valid names whose folded text is closest by :class:`difflib.SequenceMatcher` ratio
    (at least ``cutoff``), when one is closest or two or three tie (more ties, or ties that are every valid name,
    name none: no guess is better).
    """
    if not isinstance(name, str):
        return ()
    folded: dict[str, str] = {}
    for v in valid:
        if isinstance(v, str) and v != name:
            folded.setdefault(fold_name(v), v)
    key = fold_name(name)
    if key in folded:
        return (folded[key],)
    matcher = difflib.SequenceMatcher(b=key, autojunk=False)
    scored = []
    for f, v in folded.items():
        matcher.set_seq1(f)
        if matcher.real_quick_ratio() >= cutoff and matcher.quick_ratio() >= cutoff and matcher.ratio() >= cutoff:
            scored.append((matcher.ratio(), v))
    if not scored:
        return ()
    best = max(r for r, _ in scored)
    ties = [v for r, v in scored if r >= best - 1e-12]
    return tuple(ties) if len(ties) <= 3 and (len(ties) == 1 or len(ties) < len(folded)) else ()


def did_you_mean(names: tuple[str, ...]) -> str:
    """``"did you mean 'a'?"``, ``"did you mean 'a' or 'b'?"``; empty for no names."""
    if not names:
        return ""
    quoted = [repr(n) for n in names]
    return "did you mean " + (quoted[0] if len(quoted) == 1 else ", ".join(quoted[:-1]) + " or " + quoted[-1]) + "?"


class PkmError(Exception):
    """Base class of every error raised by pkm. Every one pickles with its message and its data (so that it comes
    back whole from a worker process: Dask, multiprocessing)."""

    def __reduce__(self) -> tuple[object, ...]:
        return (_restore, (type(self), self.args, self.__dict__))


def _restore(cls: type[PkmError], args: tuple[object, ...], state: dict[str, object]) -> PkmError:
    """Unpickling: the error with its message and data, without calling its constructor again."""
    err = cls.__new__(cls)
    Exception.__init__(err, *args)
    err.__dict__.update(state)
    return err


class PkmWarning(UserWarning):
    """What pkm accepts but a user should know: a model whose actuators do not fit its mobility, a value read
    as something else. The same sentence is kept in :attr:`pkm.core.Mechanism.notes`."""


class ModeChangeWarning(PkmWarning):
    """A solve ended in another assembly or working mode than its seed: the path from the seed crossed a
    singularity (a Newton block's determinant changed sign, :mod:`pkm.core.kinematics.labels`).

    Attributes:
        solve: ``"loop closure"`` or ``"inverse kinematics"``.
        changed: ``("assembly",)``, ``("working",)`` or both.
        seed: The seed's :class:`~pkm.core.kinematics.labels.ModeLabel`.
        result: The result's.
    """

    def __init__(self, solve: str, changed: tuple[str, ...], seed: object, result: object):
        self.solve, self.changed, self.seed, self.result = solve, changed, seed, result
        super().__init__(f"{solve} ended in another {' and '.join(changed)} mode than its seed's (the path crossed "
                         f"a singularity): seed {seed}, result {result}; seed nearer the target (q0) to stay, or "
                         "pass this mode's configuration as q0 to continue in it")


class PoorIdentificationWarning(PkmWarning):
    """An identification whose data cannot carry its parameters (:func:`pkm.estimate`): fewer equations than three
    per base parameter, or poorly identified base parameters (a relative standard deviation above 100 %, their
    estimate cannot be told from zero, and a deviation worth more than 1 % of the efforts:
    :mod:`pkm.core.identification.estimate`). The same sentence is kept in ``Estimate.warnings``.

    Attributes:
        equations: The rows the estimate stacked (samples times actuators).
        n_base: The number of base parameters.
        poor: ``((name, relative standard deviation [%]), ...)`` of each poorly identified base parameter (may be
            empty).
    """

    def __init__(self, message: str, equations: int, n_base: int, poor: Iterable[tuple[str, float]] = ()):
        self.equations = int(equations)
        self.n_base = int(n_base)
        self.poor = tuple((str(n), float(r)) for n, r in poor)
        super().__init__(message)


class ImplausibleModelWarning(PkmWarning):
    """A model that loads but whose numbers no real mechanism has (:mod:`pkm.core.model.plausibility`: the rules):
    a body far heavier than a steel block enclosing the whole mechanism, an inertia that breaks the triangle
    inequality, drive limits that look like an exporter's placeholders.

    Attributes:
        kind: ``"mass"``, ``"inertia"``, ``"negative"`` (a negative principal moment), ``"triangle"`` or
            ``"limits"``.
        names: The bodies (or, for ``"limits"``, the joints) concerned.
        values: Each one's offending value (the mass [kg], the largest principal inertia [kg m^2], the negative
            principal moment [kg m^2], the triangle inequality's excess [kg m^2]); for ``"limits"`` the effort and the velocity limit every joint shares
            [N m or N, rad/s or m/s].
        bound: The value the rule allows (the mass bound [kg], the largest of the inertia bounds [kg m^2], 0 for the
            negative moments and the triangle); for ``"limits"`` the effort limit shared.
    """

    def __init__(self, message: str, kind: str, names: Iterable[str], values: Iterable[float], bound: float):
        self.kind = kind
        self.names = tuple(names)
        self.values = tuple(float(v) for v in values)
        self.bound = float(bound)
        super().__init__(message)


class NonPhysicalInertiaError(PkmError):
    """Dynamics asked of a mechanism whose bodies' inertias no distribution of mass has (a negative principal moment,
    or principal moments that break the triangle inequality: :mod:`pkm.core.model.plausibility`). Its kinematics
    needs no inertia and is answered; its dynamics (inverse and forward dynamics, the mass matrix, a simulation, an
    identification that starts from the model's inertias) would be numbers of no mechanism, and is refused.

    Attributes:
        what: What was refused (``"inverse dynamics"``...).
        links: The bodies concerned, each named by its first link.
        rules: For each of ``links``, the rule it breaks: ``"negative"`` (a principal moment below zero) or
            ``"triangle"``.
        values: For each, the offending value [kg m^2]: the negative principal moment, or the triangle's excess.
    """

    def __init__(self, what: str, links: Iterable[str], rules: Iterable[str], values: Iterable[float],
                 source: str = ""):
        self.what = what
        self.links = tuple(links)
        self.rules = tuple(rules)
        self.values = tuple(float(v) for v in values)
        said = {"negative": "a negative principal moment", "triangle": "moments that break the triangle inequality"}
        listed = ", ".join(f"{n!r} ({said.get(r, r)} {v:.6g} kg m^2)" for n, r, v in zip(self.links, self.rules,
                                                                                           self.values))
        super().__init__(f"{source + ': ' if source else ''}{what} refused: the inertias of {listed} are not "
                         "physical (no distribution of mass has them); the kinematics needs none, the dynamics does: "
                         "fix ixx..izz in the model file (about the centre of mass, kg m^2)")


class InvalidInputError(PkmError, ValueError):
    """An argument has the wrong shape, is not finite, or is out of range.

    Attributes:
        name: Name of the offending argument.
        value: The offending value (as received).
    """

    def __init__(self, name: str, message: str, value: object = None):
        self.name = name
        self.value = value
        super().__init__(f"{name}: {message}")


class UnitError(InvalidInputError):
    """A quantity's text is not a number with a known unit of the right kind (``"3deg"`` for a length)."""


class InvalidParameterError(InvalidInputError):
    """A mechanism parameter is invalid (negative length, geometry that cannot assemble...)."""


def _plural(noun: str) -> str:
    if noun.endswith("y") and noun[-2:-1] not in ("a", "e", "i", "o", "u", ""):
        return noun[:-1] + "ies"  # (body: bodies; key: keys)
    return noun + ("es" if noun.endswith(("s", "sh", "ch", "x")) else "s")


class UnknownNameError(PkmError, LookupError):
    """A frame, joint, branch or mechanism name does not exist.

    The message names the closest valid names (:func:`closest`: ``"did you mean 'motor_1'?"`` for ``motör_1``
    or a Cyrillic ``\\u043e``), and lists the valid names when there are at most :data:`SHORT_LIST` of them, or when
    none is close (then the first :data:`SHORT_LIST` and their count).

    Attributes:
        kind: What was looked up ("frame", "joint", ...).
        name: The name that was not found.
        valid: The names that exist.
        suggestions: The valid names it was most likely meant to be, best first (may be empty).
    """

    def __init__(self, kind: str, name: str, valid: Iterable[str], where: str = ""):
        self.kind = kind
        self.name = name
        self.valid = tuple(valid)
        self.suggestions = closest(name, self.valid)
        loc = f" in {where}" if where else ""
        hint = f" {did_you_mean(self.suggestions)}" if self.suggestions else ""
        if len(self.valid) <= SHORT_LIST:
            listing = f" valid {_plural(kind)}: " + ", ".join(repr(v) for v in self.valid)
        elif self.suggestions:
            listing = f" ({len(self.valid)} valid {_plural(kind)})"
        else:
            listing = (f" valid {_plural(kind)}: " + ", ".join(repr(v) for v in self.valid[:SHORT_LIST])
                       + f", ... ({len(self.valid)} in all)")
        PkmError.__init__(self, f"{kind} {name!r} does not exist{loc};{hint}{listing}")

    def __str__(self) -> str:  # LookupError would quote the message like a KeyError
        return self.args[0]


class SpecError(PkmError):
    """A URDF or closure-spec file (or string) is malformed or inconsistent.

    Attributes:
        source: Where it came from (a path or "<string>").
    """

    def __init__(self, source: str, message: str):
        self.source = source
        super().__init__(f"{source}: {message}")


class SpecNameError(UnknownNameError, SpecError):
    """A closure spec names a frame, joint or branch that its URDF does not have.

    Both an :class:`UnknownNameError` (``kind``, ``name``, ``valid``) and a :class:`SpecError`
    (``source``): a file that references a missing link or frame is a malformed file.
    """

    def __init__(self, source: str, kind: str, name: str, valid: Iterable[str], where: str = ""):
        self.source = source
        UnknownNameError.__init__(self, kind, name, valid, f"{source} ({where})" if where else source)


class UnreachableError(PkmError):
    """A pose cannot be reached.

    Attributes:
        leg: Index (1-based, as in the papers) of the first leg that cannot reach; 0 when no leg is to blame:
            every loop closes and the task as a whole misses.
        excess: By how much the leg (or the task) misses, in ``unit`` (> 0).
        unit: Unit of ``excess``.
    """

    def __init__(self, leg: int, excess: float, unit: str = "m", detail: str = ""):
        self.leg = leg
        self.excess = float(excess)
        self.unit = unit
        extra = f" ({detail})" if detail else ""
        who = f"leg {leg}" if leg else "the task"
        super().__init__(f"pose unreachable: {who} misses by {self.excess:.6g} {unit}{extra}")


class AssemblyError(PkmError):
    """The given actuated coordinates admit no assembly of the mechanism.

    Attributes:
        deficit: How far the equations are from having a real solution (> 0), in ``unit``.
        unit: Unit of ``deficit``.
        closures: The closures found to stay open, each ``(name, gap)``, worst first (empty when not known).
    """

    def __init__(self, deficit: float, unit: str = "m", detail: str = "", *,
                 subject: str = "these actuated coordinates", closures: Iterable[tuple[str, float]] = ()):
        self.deficit = float(deficit)
        self.unit = unit
        self.closures = tuple(closures)
        extra = f" ({detail})" if detail else ""
        super().__init__(f"no assembly for {subject}: short by {self.deficit:.6g} {unit}{extra}")


class SingularityError(PkmError):
    """A configuration is singular for the requested operation.

    Attributes:
        kind: "inverse" (type 1), "direct" (type 2) or another descriptive kind.
        sigma_min: Smallest singular value of the matrix that lost rank (the Jacobians homogenised by the
            mechanism's characteristic length: [m]).
        distance: ``sigma_min`` over that matrix's largest singular value (dimensionless, the number the
            thresholds ``rtol``, ``singular_tol`` are compared with), or None where not measured.
    """

    def __init__(self, kind: str, sigma_min: float, detail: str = "", *, distance: float | None = None):
        self.kind = kind
        self.sigma_min = float(sigma_min)
        self.distance = None if distance is None else float(distance)
        extra = f": {detail}" if detail else ""
        rel = "" if self.distance is None else f", {self.distance:.3g} of the largest"
        super().__init__(f"{kind} singularity (smallest singular value {self.sigma_min:.3e}{rel}){extra}")


class ConvergenceError(PkmError):
    """An iterative solver did not converge.

    ``message`` replaces the whole message where the failure is not a residual above a tolerance (a budget of
    evaluations spent: ``residual`` and ``tolerance`` then hold what that message names).

    Attributes:
        what: The solver that failed (e.g. "loop closure").
        residual: Final residual norm (infinity norm, SI units of the equations; for pkm's loop closure and inverse
            kinematics the one their tolerance bounds, lengths over the characteristic length, angles in rad:
            :attr:`pkm.core.kinematics.solve.SolveResult.relative_residual`, the message saying so).
        iterations: Iterations performed.
        worst_closure: Name of the loop left most open (None if not applicable).
        worst_gap: Its gap (norm of its residual block, m or rad).
        tolerance: Tolerance that was asked for.
        result: The solver's last result object, for inspection (may be None).
        problem: The problem it was solving, with ``residual(q)`` and ``jacobian(q)``
            (:class:`~pkm.core.kinematics.solve.ClosureProblem`, :class:`~pkm.core.kinematics.solve.IKProblem`), or
            None.
    """

    def __init__(self, what: str, residual: float, iterations: int, tolerance: float, result: object = None,
                 detail: str = "", *, message: str | None = None):
        self.what = what
        self.residual = float(residual)
        self.iterations = int(iterations)
        self.tolerance = float(tolerance)
        self.result = result
        self.worst_closure: str | None = None
        self.worst_gap: float = 0.0
        self.problem: object = None
        extra = f"; {detail}" if detail else ""
        super().__init__(message or (
            f"{what} did not converge: residual {self.residual:.3e} > tolerance {self.tolerance:.1e} "
            f"after {self.iterations} iterations{extra}"
        ))


class NonFiniteError(PkmError, ArithmeticError):
    """A computation produced NaN or infinity from finite inputs (overflow, a vanishing divisor...).

    Raised at the boundary of a public routine instead of returning the non-finite value.

    Attributes:
        what: The quantity that came out non-finite.
        value: The offending value (as computed).
    """

    def __init__(self, what: str, value: object = None, detail: str = ""):
        self.what = what
        self.value = value
        extra = f"; {detail}" if detail else ""
        super().__init__(f"{what} is not finite (NaN or infinity){extra}")


class BranchError(PkmError):
    """A solution lies on another working mode / assembly branch than the one requested.

    Attributes:
        expected: The requested sign for each joint.
        found: The sign found for each joint.
    """

    def __init__(self, branch: str, expected: dict[str, int], found: dict[str, int]):
        self.branch = branch
        self.expected = dict(expected)
        self.found = dict(found)
        diff = [k for k in expected if expected[k] != found.get(k)]
        super().__init__(f"solution is not on branch {branch!r}: joints {diff} have the opposite sign")


class SweepError(PkmError):
    """A design sweep cannot run as asked: its output holds another sweep, or its scheduler cannot be reached.

    Attributes:
        path: The output or scheduler address concerned (None when neither).
    """

    def __init__(self, message: str, path: object = None):
        self.path = path
        super().__init__(message)


class CompilerError(PkmError, RuntimeError):
    """A capability that runs only compiled found no C compiler, or its compiled code failed (a ``RuntimeError`` too,
    as it was before 0.2.0).

    Attributes:
        how: What the compiler search or the compiled code said.
    """

    def __init__(self, what: str, how: str):
        self.how = how
        super().__init__(f"{what}: {how}")


#: The distribution's name on PyPI (``pyproject.toml``'s ``[project] name``), in every ``pip install`` line pkm prints:
#: ``pkm`` there is another project. It installs the ``pkm`` package (``import pkm``) and the ``pkm`` command.
DISTRIBUTION = "pkm-robotics"


class MissingDependencyError(PkmError, ImportError):
    """An optional dependency that a capability needs is not installed (raised where it is used, never at
    ``import pkm``; :mod:`pkm._optional` lists the extras).

    Attributes:
        package: The PyPI package to install.
        extra: The pkm extra that installs it (``pip install "pkm-robotics[extra]"``).
    """

    def __init__(self, package: str, extra: str, what: str):
        self.package = package
        self.extra = extra
        super().__init__(f"{what} needs {package}, which pkm's {extra!r} extra installs: "
                         f"pip install \"{DISTRIBUTION}[{extra}]\"")


class StructureError(PkmError):
    """A mechanism's structure is outside what a method covers (the method says which structures it covers).

    Attributes:
        part: The leg, closure or joint that does not fit.
    """

    def __init__(self, part: str, message: str):
        self.part = part
        super().__init__(f"{part}: {message}")


class ControllerError(PkmError):
    """A simulation's controller raised, or returned efforts of the wrong shape or not finite.

    Attributes:
        time: The simulated time of the call [s].
        reason: What went wrong (the controller's own exception is the ``__cause__``).
    """

    def __init__(self, time: float, reason: str):
        self.time = float(time)
        self.reason = reason
        super().__init__(f"the controller at t = {self.time:.6g} s: {reason}")


class TransmissionError(PkmError):
    """A closed sub-mechanism that cannot be a transmission (:func:`pkm.transmissions`): the robot has no loop, the
    output joints given or chosen do not determine it, or its outputs or motors are singular at the reference.

    Attributes:
        transmission: The transmission's name (its generated one when no name was given).
        reason: ``"no_loop"``, ``"outputs"`` (wrong count, not in the loop, not scalar, not a serial chain) or
            ``"singular"``.
        joints: The joints concerned (the outputs given, the motors, the joints that do not fit).
        value: The number behind a ``"singular"`` refusal: the largest motor component of a motion the outputs
            leave free, or the closures' dependence among the outputs (relative, homogenised), or the motors'
            :attr:`SingularityError.sigma_min`; None for the others.
    """

    def __init__(self, transmission: str, reason: str, message: str, joints: Iterable[str] = (),
                 value: float | None = None):
        self.transmission = transmission
        self.reason = reason
        self.joints = tuple(joints)
        self.value = None if value is None else float(value)
        super().__init__(f"transmission {transmission!r}: {message}")


class PathError(PkmError):
    """A geometric path cannot be timed (:func:`pkm.time_optimal`): it leaves the workspace, crosses a singularity,
    is not smooth, crosses a position limit the model states, or a limit cannot hold the mechanism still on it.

    Attributes:
        index: The path point (0-based, in the planning grid or the waypoints, or the grid's segment whose midpoint
            fails, as ``what`` says) where it fails.
        s: The path parameter there (in [0, 1]).
        limit: What is violated: ``"workspace"``, ``"singularity"``, ``"smoothness"``, ``"position limit of
            motor_1"`` or the limit that cannot hold (``"peak effort of motor_1"``).
        detail: What was measured.
        joint, value, bound: For a position limit crossed: the joint, its coordinate there [rad, m] and its stated
            limits ``(lower, upper)``; else None.
    """

    def __init__(self, index: int, s: float, limit: str, detail: str, what: str = "path point", *,
                 joint: str | None = None, value: float | None = None, bound: tuple[float, float] | None = None):
        self.index = int(index)
        self.s = float(s)
        self.limit = limit
        self.detail = detail
        self.joint, self.value, self.bound = joint, value, bound
        super().__init__(f"{what} {self.index} (s = {self.s:.6g}): {limit}: {detail}")


class StiffnessError(PkmError):
    """A stiffness question with no finite answer (:func:`pkm.stiffness`): a motion that no spring resists moves the
    end effector (``"free"``: the mechanism yields under a load), or the end effector cannot move along some
    directions at all (``"rigid"``: its stiffness there is infinite: the links are rigid and the mechanism has fewer
    degrees of freedom than six).

    Attributes:
        kind: ``"free"`` or ``"rigid"``.
        joints: For ``"free"``: the joints the unresisted motion moves; else empty.
        rank: The rank of the end effector's compliance (0 to 6).
    """

    def __init__(self, kind: str, message: str, joints: Iterable[str] = (), rank: int = 0):
        self.kind = kind
        self.joints = tuple(joints)
        self.rank = int(rank)
        super().__init__(message)


class NoCollisionGeometryError(PkmError):
    """A collision question (:func:`pkm.clearance`) about a mechanism with nothing to check: its files carry no
    collision geometry (``"no_geometry"``: the message says how to add it), or every pair of its bodies is excluded
    (``"no_pairs"``: the message lists the pairs and why, :mod:`pkm.core.collision.geometry`).

    Attributes:
        mechanism: The mechanism's name.
        kind: ``"no_geometry"`` or ``"no_pairs"``.
    """

    def __init__(self, mechanism: str, kind: str, message: str):
        self.mechanism = mechanism
        self.kind = kind
        super().__init__(message)
