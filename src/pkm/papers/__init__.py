"""Paper studies: one module per paper, each reproducing its published numbers and figures.

Every study module ``pkm.papers.<name>`` (``<name>`` one of :func:`names`: the ``paper`` of the
registered mechanisms, :data:`pkm.mechanisms.REGISTRY`) provides

* ``TITLE``: the paper, in one line;
* ``reproduce() -> list[Row]``: the published numbers next to ours;
* ``figures(out_dir) -> list[pathlib.Path]``: the paper's figures redrawn (PNG);
* ``series(out_dir) -> list[pathlib.Path]``: time series or maps as CSV, or ``series = None``;
* ``SERIES``: each figure's file stem -> the stems of the CSV series that hold its numbers (the report links them
  under each figure; the tests check that every figure drawn has its numbers written).

Row ids are a contract (issues name them): keep them stable. ``pkm report`` gathers
the rows of every paper into ``summary.json`` and a table.
"""

from __future__ import annotations

import functools
import importlib
import math
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from types import ModuleType
from typing import Any

from pkm.errors import InvalidInputError, UnknownNameError
from pkm.mechanisms import REGISTRY

RELATIONS = ("==", "<=", ">=")

Value = float | int | bool | str | None


@dataclass(frozen=True)
class Row:
    """One published quantity next to ours.

    Attributes:
        id: Stable identifier, ``<paper>.<figure or case>.<quantity>``.
        published: The paper's value (``None`` where the paper gives none, a string
            for a qualitative claim).
        computed: Ours, in the same unit.
        unit: Unit of both values, as the paper prints it (``"deg"``, ``"N"``, ``""``).
        tolerance: Largest ``|computed - published|`` that counts as a match (numbers),
            ``None`` where only equality (booleans, strings) or nothing can be checked.
        source: Where in the paper (``"Fig. 7"``, ``"Table 3"``, ``"sec. 5, case 2"``).
        note: How ours was computed and, where it differs, why.
        relation: How ours must relate to the published value: ``"=="`` (within ``tolerance``),
            ``"<="`` or ``">="`` (a published bound or a baseline to beat).
        why: One line, for a row that does not match: why (the report's summary quotes it; the note has the
            detail). Every mismatching row states one (tested).
    """

    id: str
    published: Value
    computed: Value
    unit: str
    tolerance: float | None
    source: str
    note: str = ""
    relation: str = "=="
    why: str = ""

    def __post_init__(self):
        if self.relation not in RELATIONS:
            raise InvalidInputError("relation", f"use one of {RELATIONS}", self.relation)

    @property
    def matches(self) -> bool | None:
        """Whether ours reproduces the published value (``None``: nothing to compare)."""
        p, c = self.published, self.computed
        if p is None or c is None:
            return None
        if isinstance(p, bool) or isinstance(c, bool) or isinstance(p, str) or isinstance(c, str):
            return p == c
        if not (math.isfinite(float(p)) and math.isfinite(float(c))):
            return False
        if self.relation == "<=":
            return float(c) <= float(p) + (self.tolerance or 0.0)
        if self.relation == ">=":
            return float(c) >= float(p) - (self.tolerance or 0.0)
        if self.tolerance is None:
            return None
        return abs(float(c) - float(p)) <= self.tolerance

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["matches"] = self.matches
        return d


@functools.cache
def generic_count(mechanism: str):
    """:meth:`pkm.Kernels.operation_count` of a shipped mechanism's generic inverse dynamics."""
    import pkm

    return pkm.Kernels(pkm.load(mechanism)).operation_count()


def opcount_rows(mechanism: str, prefix: str, note: str = "") -> list[Row]:
    """Rows ``<prefix>mul`` and ``<prefix>add``: :func:`generic_count` (the papers publish none), its boundary in
    the note, after ``note``."""
    c = generic_count(mechanism)
    fn = ", ".join(f"{v} {k}" for k, v in sorted(c.functions.items()))
    text = (f"pkm.Kernels(pkm.load({mechanism!r})).operation_count(): the twin of the Pinocchio model after CSE "
            f"({c.mul} mult/div, {c.add} add/sub, {fn}). {note}Boundary: {c.boundary}")
    return [Row(f"{prefix}mul", None, c.mul, "", None, "generic route (no published count)", text),
            Row(f"{prefix}add", None, c.add, "", None, "generic route (no published count)", text)]


def ident_rows(mechanism: str, prefix: str) -> list[Row]:
    """Rows ``<prefix>n_base`` and ``<prefix>n_base_tied``: the number of base parameters of a shipped mechanism
    (:func:`pkm.base_parameters`; the papers publish none), its legs' parameters free and tied (one set per kind of
    leg), each decided by both routes (double precision, and 50 digits on the same samples) and the row saying
    whether they agree; and ``<prefix>routes_agree``: both counts found by both routes."""
    import pkm

    mech = pkm.load(mechanism)
    rows, agree = [], True
    for tie, suffix in ((False, "n_base"), (True, "n_base_tied")):
        b = pkm.base_parameters(mech, tie_legs=tie)
        assert b.precise is not None
        agree = agree and bool(b.routes_agree)
        text = (f"pkm.base_parameters({mechanism!r}{', tie_legs=True' if tie else ''}): {len(b)} of "
                f"{len(b.tied_names or b.parameters.names)} parameters ({b.samples} random states; pivoted QR, gap "
                f"{b.decision.gap:.1e} in double precision). In {50} digits on the same samples: "
                f"{b.precise.decision.rank} (gap {b.precise.decision.gap:.1e}, {b.precise.unrecognised} of "
                f"{b.precise.constants} model constants not recognised, floor {b.precise.floor:.0e}): the routes "
                f"{'agree' if b.routes_agree else 'DISAGREE'}.")
        rows.append(Row(f"{prefix}{suffix}", None, len(b), "", None, "identification (no published count)", text))
    rows.append(Row(f"{prefix}routes_agree", None, agree, "", None, "identification (no published count)",
                    "Both counts above found alike in double precision and in 50-digit arithmetic "
                    "(pkm.core.identification.precise)."))
    return rows


@functools.cache
def modes_row(mechanism: str, row_id: str, compare: Callable[[Any, Any], str] | None = None) -> Row:
    """Row ``row_id``: the number of real assembly modes at the reference design's reference actuators
    (:func:`pkm.assembly_modes`; the papers publish none), with the set's account and, from ``compare(mech,
    modes) -> note``, what another method finds. Without Bertini the row says so (computed None). The row is
    cached on disk (:mod:`pkm.cache`) under its inputs: the mechanism's files, the actuator values, Bertini's
    version and the code that computes it (the homotopy takes seconds, and every ``pkm report`` process would
    solve it again)."""
    import importlib.metadata

    import pkm
    from pkm.cache import cached

    mech = pkm.load(mechanism)
    qa = mech.actuated_q(mech.q_reference)
    try:
        bertini: str | None = importlib.metadata.version("bertini2")
    except importlib.metadata.PackageNotFoundError:
        bertini = None
    key = [row_id, mech.urdf, mech.spec.to_toml(), qa.tolist(), bertini]
    code = ["pkm.core.modes", "pkm.core.kinematics.solve", "pkm.papers",
            *([compare.__module__] if compare is not None else [])]
    row = cached("rows", key, lambda: _modes_row(mech, qa, row_id, compare).to_dict(), code=code)
    row.pop("matches", None)
    return Row(**row)


def _modes_row(mech, qa, row_id: str, compare: Callable[[Any, Any], str] | None) -> Row:
    import pkm
    from pkm.errors import MissingDependencyError

    try:
        modes = pkm.assembly_modes(mech, qa)
    except MissingDependencyError as exc:
        return Row(row_id, None, None, "", None, "reference configuration (no published count)", str(exc))
    poses = "; ".join(", ".join(f"{k} {v:.4g}" for k, v in pkm.TaskMap.of(mech).named(m.q).items()) for m in modes)
    note = compare(mech, modes) if compare is not None else ""
    text = (f"pkm.assembly_modes at the reference actuators: {modes.summary()}; every mode closed by the core "
            f"(worst {max(m.residual for m in modes):.1e}) and certified by Smale's alpha test (largest alpha "
            f"{max(m.certificate.alpha for m in modes):.1e}). Task values [m, rad]: {poses}. {note}")
    return Row(row_id, None, len(modes), "", None, "reference configuration (no published count)", text)


def cached_rows(paper: str) -> Callable[[Callable[[], list[Row]]], Callable[[], list[Row]]]:
    """Decorator of a study's ``reproduce()``: its rows kept on disk (:mod:`pkm.cache`) under the source of the whole
    ``pkm`` package and its shipped data (``urdf/``, ``dynamics/``), Bertini's version and the paper's name, so that
    ``pkm report``, ``make demo`` and the tests, each a process of its own, compute a paper's rows once for a given
    code and data (the 3-RRR's and the Delta's take seconds, the hexapod's homotopy as many). Any change of code or
    data computes them anew; ``PKM_CACHE=0`` always does."""

    def wrap(reproduce: Callable[[], list[Row]]) -> Callable[[], list[Row]]:
        @functools.wraps(reproduce)
        def rows() -> list[Row]:
            import importlib.metadata

            from pkm.cache import cached, file_digest
            from pkm.data import data_dir

            try:
                bertini: str | None = importlib.metadata.version("bertini2")
            except importlib.metadata.PackageNotFoundError:
                bertini = None
            key = [paper, bertini, file_digest([data_dir("urdf"), data_dir("dynamics")])]
            out = cached("papers", key, lambda: [r.to_dict() for r in reproduce()], code=["pkm"])
            return [Row(**{k: v for k, v in d.items() if k != "matches"}) for d in out]

        return rows

    return wrap


#: The servo stiffness the studies' stiffness rows give the drives they name [N m/rad]: an assumed value (no paper
#: states one); every stiffness of those rows scales with it, every natural frequency with its square root.
DRIVE_STIFFNESS = 1000.0


def stiffness_rows(prefix: str, cases: Sequence[tuple[str, str, Any, Any]], drives: Sequence[str]) -> list[Row]:
    """Rows ``<prefix>force_min_<key>`` [N/m] then ``<prefix>f1_<key>`` [Hz] for each case ``(key, label, mech,
    q)``: the smallest principal stiffness of the end effector under a pure force and its first natural frequency
    (:func:`pkm.stiffness`, :meth:`~pkm.core.compliance.stiffness.Stiffness.vibration_modes`; the papers publish
    none) at the closed configuration ``q``, the drives ``drives`` each given the servo stiffness
    :data:`DRIVE_STIFFNESS` as their :attr:`Actuator.stiffness <pkm.core.model.actuators.Actuator.stiffness>`, every
    other drive held rigid, every link rigid, every passive joint free. Each note states these sources (the ones
    :attr:`Stiffness.sources <pkm.core.compliance.stiffness.Stiffness.sources>` gives), the principal stiffnesses under
    a force and a moment and the frequencies."""
    import pkm

    def fmt(values: Any) -> str:
        return ", ".join(f"{float(v):.6g}" for v in values)

    stiff, freq = [], []
    for key, label, mech, q in cases:
        sprung = pkm.with_actuators(mech, {j: {"stiffness": DRIVE_STIFFNESS} for j in drives})
        K = pkm.stiffness(sprung, q)
        k, km = K.principal("force")[0], K.principal("moment")[0]
        f = K.vibration_modes().frequencies
        text = (f"pkm.stiffness at {label}: the drives {', '.join(K.sprung)} each a servo spring of "
                f"{DRIVE_STIFFNESS:g} N m/rad (their Actuator.stiffness: source "
                f"{'/'.join(sorted(set(K.sources.values())))}; assumed, the paper states none: every stiffness "
                "scales with it, every frequency with its square root), "
                + (f"{', '.join(K.locked)} held rigid, " if K.locked else "")
                + "rigid links, every passive joint free (no spring); gravity not counted. Principal stiffnesses at "
                f"the end effector's origin under a force {fmt(k)} N/m, under a moment {fmt(km)} N m/rad (inf: rigid); natural frequencies "
                f"{fmt(f)} Hz (the links' inertias and the drives' reflected inertia; compliance rank {K.rank}).")
        source = "stiffness at the reference pose (no published value)"
        stiff.append(Row(f"{prefix}force_min_{key}", None, float(k[0]), "N/m", None, source, text))
        freq.append(Row(f"{prefix}f1_{key}", None, float(f[0]), "Hz", None, source, text))
    return stiff + freq


def names() -> tuple[str, ...]:
    """The paper studies, in registry order: the ``paper`` of every registered mechanism that has one."""
    return tuple(d.paper for d in REGISTRY.values() if d.paper is not None)


def module(name: str) -> ModuleType:
    """The study module of paper ``name`` (one of :func:`names`)."""
    if name not in names():
        raise UnknownNameError("paper", name, names())
    return importlib.import_module(f"pkm.papers.{name}")


__all__ = ["DRIVE_STIFFNESS", "Row", "cached_rows", "generic_count", "ident_rows", "modes_row", "module", "names",
           "opcount_rows", "stiffness_rows"]
