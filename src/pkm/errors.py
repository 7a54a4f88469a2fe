"""The exceptions pkm raises. Every one derives from :class:`PkmError`.

Each exception carries the data a caller needs to react (the offending value,
the leg, the residual, the valid names) as attributes, and its message says
what was wrong and, where possible, how to fix it.
"""

from __future__ import annotations

from collections.abc import Iterable


class PkmError(Exception):
    """Base class of every error raised by pkm."""


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
    return noun + ("es" if noun.endswith(("s", "sh", "ch", "x")) else "s")


class UnknownNameError(PkmError, LookupError):
    """A frame, joint, branch or mechanism name does not exist.

    Attributes:
        kind: What was looked up ("frame", "joint", ...).
        name: The name that was not found.
        valid: The names that exist.
    """

    def __init__(self, kind: str, name: str, valid: Iterable[str], where: str = ""):
        self.kind = kind
        self.name = name
        self.valid = tuple(valid)
        loc = f" in {where}" if where else ""
        shown = ", ".join(repr(v) for v in self.valid[:40])
        more = f", ... ({len(self.valid)} in all)" if len(self.valid) > 40 else ""
        PkmError.__init__(self, f"{kind} {name!r} does not exist{loc}; valid {_plural(kind)}: {shown}{more}")

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
    """

    def __init__(self, deficit: float, unit: str = "m", detail: str = ""):
        self.deficit = float(deficit)
        self.unit = unit
        extra = f" ({detail})" if detail else ""
        super().__init__(f"no assembly for these actuated coordinates: short by {self.deficit:.6g} {unit}{extra}")


class SingularityError(PkmError):
    """A configuration is singular for the requested operation.

    Attributes:
        kind: "inverse" (type 1), "direct" (type 2) or another descriptive kind.
        sigma_min: Smallest singular value of the matrix that lost rank.
    """

    def __init__(self, kind: str, sigma_min: float, detail: str = ""):
        self.kind = kind
        self.sigma_min = float(sigma_min)
        extra = f": {detail}" if detail else ""
        super().__init__(f"{kind} singularity (smallest singular value {self.sigma_min:.3e}){extra}")


class ConvergenceError(PkmError):
    """An iterative solver did not converge.

    Attributes:
        what: The solver that failed (e.g. "loop closure").
        residual: Final residual norm (infinity norm, SI units of the equations).
        iterations: Iterations performed.
        worst_closure: Name of the loop left most open (None if not applicable).
        worst_gap: Its gap (norm of its residual block, m or rad).
        tolerance: Tolerance that was asked for.
        result: The solver's last result object, for inspection (may be None).
    """

    def __init__(self, what: str, residual: float, iterations: int, tolerance: float, result: object = None,
                 detail: str = ""):
        self.what = what
        self.residual = float(residual)
        self.iterations = int(iterations)
        self.tolerance = float(tolerance)
        self.result = result
        self.worst_closure: str | None = None
        self.worst_gap: float = 0.0
        extra = f"; {detail}" if detail else ""
        super().__init__(
            f"{what} did not converge: residual {self.residual:.3e} > tolerance {self.tolerance:.1e} "
            f"after {self.iterations} iterations{extra}"
        )


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


class MissingDependencyError(PkmError, ImportError):
    """An optional dependency that a capability needs is not installed.

    Attributes:
        package: The PyPI package to install.
        extra: The pkm extra that installs it (``pip install "pkm[extra]"``).
    """

    def __init__(self, package: str, extra: str, what: str):
        self.package = package
        self.extra = extra
        super().__init__(f"{what} needs {package}: pip install {package} (or pip install \"pkm[{extra}]\")")


class StructureError(PkmError):
    """A mechanism's structure is outside what a method covers (the method says which structures it covers).

    Attributes:
        part: The leg, closure or joint that does not fit.
    """

    def __init__(self, part: str, message: str):
        self.part = part
        super().__init__(f"{part}: {message}")
