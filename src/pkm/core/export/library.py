"""``pkm export c``: a mechanism's kinematics and dynamics as a self-contained C99 library a controller can link.

:func:`export_c` writes into a folder ``<name>.h``, ``<name>.c``, a ``Makefile``, a ``CMakeLists.txt``, an
example ``main.c`` and a ``README.md`` (how to get a first forward kinematics solution: from the reference
configuration, exported as ``<name>_q_reference``, along a path; what the example prints first). The library's functions (declared and documented in the header): forward kinematics (Newton,
warm-started from the caller's previous solution, a fixed iteration bound), inverse kinematics (Newton, and in
closed form, ``<name>_ik_actuators``, where the mechanism is made of crank legs on a body the task places:
:attr:`~pkm.core.export.model.ExportModel.closed_form`), the assembly and working mode ids of a configuration (the
header names the spec's branches' ids: :func:`mode_constants`), the task value, the forward and inverse Jacobians, the rate and
effort maps between actuators and task, ``J̇ q̇``, inverse dynamics, ``M_a`` and the gravity efforts.

Every function is re-entrant (constant tables only, the caller owns every buffer), allocates nothing, prints
nothing, needs only ``<math.h>``, and returns a status:

* ``OK``; ``NOT_CONVERGED`` (``info.residual``: the largest residual at the last iterate, lengths counted in the
  characteristic length ``L`` and angles in rad, as :func:`pkm.close_loops`' tolerance counts it: the same
  iterations and verdicts for a model in millimetres and the same in metres);
* ``SINGULAR`` (``info.sigma_min``: the Newton or closure matrix's smallest singular value relative to its largest,
  under ``SINGULAR_TOL``, the matrix homogenised by the characteristic length as pkm's singularity measures are,
  :class:`~pkm.core.model.scale.JacobianScales`: its row and column factors are the library's constants
  ``<name>_fk_row_scale``..., so that a model in millimetres and the same in metres get the same verdicts;
  ``<name>_fk_distance`` gives the forward kinematics' one at any closed configuration);
* ``OUTSIDE_LIMITS`` (``info.joint``: which limited joint, an index into ``<name>_limit_names``);
* ``LEFT_MODE`` (``info.mode``: the mode id found, not the one asked for: see :mod:`pkm.core.export.model`);
* ``INVALID_INPUT`` (a NaN or an infinity in an input, or a coordinate (``qa``, ``q``, ``y``) beyond
  :data:`~pkm.validation.ABSURD`, 1e6 m or rad: refused, never wrapped, as the library refuses it);
* ``PIVOT_ORDER``: the fixed elimination order of a kernel fails at this state although the matrix is regular
  (``info.pivot``); the kinematics fall back to a dense solve, the maps and the dynamics report it.

The kernels are the twin's expressions (:mod:`pkm.core.export.model`) written as C by :mod:`pkm.core.export.emit`;
the hand-written parts (the Newton driver, the dense fallbacks) are :mod:`pkm.core.export.runtime`. Operation
counts and the worst-case iteration count are in the header comment.
"""

from __future__ import annotations

import datetime
import os
from dataclasses import dataclass, field
from pathlib import Path

import casadi as cs
import numpy as np

from pkm.core.export import runtime
from pkm.core.export.emit import c_constant, c_function
from pkm.core.export.model import Block, ExportError, ExportModel, Newton, c_name
from pkm.core.kinematics.task import TaskMap
from pkm.core.model.joints import stated_limits
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.scale import JacobianScales
from pkm.core.model.spec import as_path
from pkm.core.twin.codegen import jacobi_sv, paper_counts
from pkm.validation import ABSURD

#: Newton iterations at most (each one evaluation of the step), the convergence tolerance on the largest closure
#: residual or task error (lengths in the characteristic length ``L``, angles in rad: scale-free), the relative pivot under which a solve goes dense, the relative smallest
#: singular value of the homogenised matrix under which it counts as singular, the slack on joint limits [rad, m].
MAX_ITER = 20
TOL = 1e-12
#: The forward kinematics' continuation (:func:`pkm.core.kinematics.solve.close_loops`'s): the largest change of an
#: actuated coordinate per step [rad, or characteristic lengths for a prismatic actuator], the steps at most, and
#: the tolerance of the steps on the way (the last one's is :data:`TOL`; in ``L`` and rad).
FK_STEP = 0.1
MAX_STEPS = 64
PATH_TOL = 1e-9
PIVOT_FLOOR = 1e-6
SINGULAR_TOL = 1e-9
LIMIT_TOL = 1e-9
#: The status codes, in order from 0.
STATUS = ("OK", "NOT_CONVERGED", "SINGULAR", "OUTSIDE_LIMITS", "LEFT_MODE", "INVALID_INPUT", "PIVOT_ORDER")


@dataclass(frozen=True)
class CLibrary:
    """An exported library (:func:`export_c`).

    Attributes:
        name: The C prefix (``<name>_fk``...).
        directory: Where the files are.
        files: The files written.
        sizes: ``NQ, NV, NA, NY, NX`` (configuration, velocity, actuated, task value and task rate sizes).
        operations: Per kernel, ``(mul, add, other functions)`` after CSE (counted as the papers count).
        blocks: ``{"fk": [...], "ik": [...]}``: each mode bit's joints (velocity coordinates named).
        limits: The joints whose limits are checked, in ``info.joint``'s order.
        idle: The velocity coordinates held at the caller's previous solution (one per idle motion).
        closed_form: Why there is no closed-form inverse kinematics (``<name>_ik_actuators``); empty when there is.
        modes: ``{"fk": {...}, "ik": {...}}``: the named mode ids the header defines (``<NAME>_FK_MODE_<KEY>``,
            ``<NAME>_IK_MODE_<KEY>``): ``REFERENCE`` (0) in both, and in ``ik`` one per branch of the spec
            (:func:`mode_constants`).
    """

    name: str
    directory: Path
    files: tuple[Path, ...]
    sizes: dict[str, int]
    operations: dict[str, tuple[int, int, int]]
    blocks: dict[str, list[list[str]]] = field(default_factory=dict)
    limits: tuple[str, ...] = ()
    idle: tuple[str, ...] = ()
    closed_form: str = ""
    modes: dict[str, dict[str, int]] = field(default_factory=dict)

    @property
    def header(self) -> Path:
        return self.directory / f"{self.name}.h"

    @property
    def source(self) -> Path:
        return self.directory / f"{self.name}.c"


def _array(ctype: str, name: str, values: list, fmt: object = str, public: bool = False) -> str:
    values = list(values) or [0]  # (C has no empty arrays: a placeholder the loops never read)
    body = ", ".join(fmt(v) for v in values)  # type: ignore[operator]
    return f"{'' if public else 'static '}const {ctype} {name}[{len(values)}] = {{{body}}};\n"


def _blocks(kind: str, blocks: tuple[Block, ...]) -> str:
    start = np.cumsum([0] + [len(b.rows) for b in blocks]).tolist()
    return (f"#define {kind.upper()}_NBLOCKS {len(blocks)}\n"
            + _array("int", f"p_{kind}_block_start", start)
            + _array("int", f"p_{kind}_block_rows", [r for b in blocks for r in b.rows])
            + _array("int", f"p_{kind}_block_cols", [c for b in blocks for c in b.cols])
            + _array("int", f"p_{kind}_block_sign", [b.sign for b in blocks]))


def _velocity_names(mech: Mechanism) -> list[str]:
    """A name per velocity coordinate: the joint's, suffixed by the coordinate for multi-DOF joints."""
    names = [""] * mech.nv
    for name, j in mech.joints.items():
        for k in range(j.nv):
            names[j.idx_v + k] = name if j.nv == 1 else f"{name}[{k}]"
    return names


def _limits(mech: Mechanism) -> list[tuple[str, int, float, float]]:
    """``(joint, q index, low, high)`` of the one-coordinate joints with finite limits."""
    lo, hi = stated_limits(mech.model)
    out = []
    for name, j in mech.joints.items():
        if j.nq != 1:
            continue
        a, b = float(lo[j.idx_q]), float(hi[j.idx_q])
        if np.isfinite(a) and np.isfinite(b) and max(abs(a), abs(b)) < 1e10:
            out.append((name, j.idx_q, a, b))
    return out


def _quote(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def export_c(mech: Mechanism, directory: str | os.PathLike[str], *, name: str | None = None) -> CLibrary:
    """Write ``mech``'s C library into ``directory`` (created): see the module doc.

    Args:
        mech: Any mechanism pkm loads (without a ``[task]``, its task is its actuated joints).
        directory: The output folder.
        name: The C prefix (default: the mechanism's name as a C identifier).

    Raises:
        ExportError: the mechanism cannot be exported, and why: a joint kind the twin does not write; the closures
            (or closures and task) do not fix the joints at the reference; no passive joint for the forward
            kinematics to solve for (every joint actuated); two branches that make one C name (or a
            branch named ``reference`` in another mode, :func:`mode_constants`); a Newton solve that does not converge
            at the reference; a non-finite kernel value at the reference.

    Examples:
        >>> import tempfile
        >>> import pkm
        >>> rrr3 = pkm.load("rrr3")
        >>> lib = pkm.export_c(rrr3, tempfile.mkdtemp())
        >>> lib.name, sorted(f.name for f in lib.files)
        ('rrr3', ['CMakeLists.txt', 'Makefile', 'README.md', 'main.c', 'rrr3.c', 'rrr3.h'])
        >>> lib.sizes
        {'NQ': 7, 'NV': 7, 'NA': 3, 'NY': 3, 'NX': 3}
    """
    from pkm import __version__

    mech, out = check_mechanism(mech), as_path(directory, "directory")
    prefix = c_name(name or mech.name)
    model = ExportModel(mech)
    modes, mode_lines = mode_constants(mech, model)
    fk, ik = model.fk, model.ik
    kernels = [fk.step, fk.system, fk.retract, ik.step, ik.system, ik.retract, model.task_value(), model.jacobians(), model.jdot_qdot(),
               model.inverse_dynamics(), model.mass_matrix(), model.gravity()]
    closed, closed_signs, no_closed_form = model.closed_form
    if closed is not None:
        kernels.append(closed)
    _check_at_reference(mech, model, kernels)
    task = TaskMap.of(mech)
    sizes = {"NQ": mech.nq, "NV": mech.nv, "NA": mech.na, "NY": task.value_size, "NX": task.size}
    ops = {}
    for fun in kernels:
        mul, add, other = paper_counts(fun)
        ops[fun.name()] = (mul, add, sum(other.values()))
    vnames = _velocity_names(mech)
    blocks = {kind: [[vnames[newton.columns[c]] for c in b.cols] for b in newton.blocks]
              for kind, newton in (("fk", fk), ("ik", ik))}
    limits = _limits(mech)
    out.mkdir(parents=True, exist_ok=True)
    nfk, nik = len(fk.columns), len(ik.columns)
    fill = {"FKN": str(nfk), "IKN": str(nik), "FKB": str(max(len(fk.blocks), 1)), "IKB": str(max(len(ik.blocks), 1))}

    def prefixed(text: str) -> str:
        for key, value in fill.items():
            text = text.replace(key, value)
        return text.replace("p_", f"{prefix}_").replace("P_", f"{prefix.upper()}_")

    stamp = datetime.date.today().isoformat()
    qa_first = first_target(mech)
    header = _header(mech, prefix, sizes, ops, blocks, limits, fk, ik, __version__, stamp, no_closed_form, modes,
                     mode_lines)
    unit = JacobianScales.of(mech).actuated  # (a prismatic actuator's step in characteristic lengths)
    tables = (_array("int", "p_actuated_q", [int(i) for i in mech.act_q], public=True)
              + _array("int", "p_actuated_revolute", [int(j.revolute) for j in mech.actuated])
              + _array("double", "p_actuated_unit", [float(u) for u in unit], c_constant)
              + f"#define P_ABSURD {ABSURD!r}\n#define P_NLIMITS {len(limits)}\n"
              + _array("int", "p_limit_q", [q for _, q, _, _ in limits])
              + _array("double", "p_limit_low", [lo for _, _, lo, _ in limits], c_constant)
              + _array("double", "p_limit_high", [hi for _, _, _, hi in limits], c_constant)
              + _blocks("fk", fk.blocks) + _blocks("ik", ik.blocks)
              + "".join(_array("double", f"p_{kind}_{side}_scale", [float(x) for x in values], c_constant)
                        for kind, newton in (("fk", fk), ("ik", ik))
                        for side, values in (("row", newton.row_scale), ("col", newton.column_scale)))
              + (_array("int", "p_actuated_limit", [next((k for k, (_, qi, _, _) in enumerate(limits)
                                                           if qi == int(i)), -1) for i in mech.act_q])
                 + _array("int", "p_task_limit", [next((k for k, (name, *_) in enumerate(limits) if name == j.name), -1)
                                                   for j in mech.task_joints])
                 + _array("double", "p_closed_sign", list(closed_signs), c_constant) if closed else "")
              + f"#define P_NMAX {max(nfk, nik)}\n"
              + f"#define P_BMAX {max([len(b.rows) for b in fk.blocks + ik.blocks] + [1])}\n")
    limit_names = [n for n, *_ in limits] or [""]
    # (the names are the file's: written with the prefix already, never through prefixed(), which would rewrite a
    # "p_" inside a joint's name)
    constants = (f"const char* const {prefix}_limit_names[{len(limit_names)}] = {{"
                 + ", ".join(_quote(n) for n in limit_names) + "};\n"
                 + f"const char* const {prefix}_task_names[{prefix.upper()}_NY] = {{"
                 + ", ".join(_quote(n) for n in TaskMap.of(mech).value_names) + "};\n"
                 + _array("double", f"{prefix}_q_reference", [float(x) for x in mech.q_reference], c_constant,
                          public=True)
                 + f"const char* const {prefix}_motor_names[{prefix.upper()}_NA] = {{"
                 + ", ".join(_quote(n) for n in mech.motor_map.names) + "};\n"
                 + _array("double", f"{prefix}_motor_map", [float(x) for x in mech.motor_map.matrix.ravel(order="F")],
                          c_constant, public=True))
    functions = "".join(c_function(fun, f"p_k_{fun.name()}") for fun in kernels)
    newton = "".join(runtime.NEWTON.replace("$KNBLOCKS", f"{k.upper()}_NBLOCKS").replace("$kind", k)
                     .replace("$NX", str(n)).replace("$NB", str(max(len(b), 1)))
                     for k, n, b in (("fk", nfk, fk.blocks), ("ik", nik, ik.blocks)))
    sv = jacobi_sv("p_sv", 1e-17, 1e-16).replace("casadi_real", "double").replace("casadi_int", "int")
    source = (f"/* {prefix}: generated by pkm {__version__} on {stamp}; see {prefix}.h. */\n"
              f'#include "{prefix}.h"\n#include <math.h>\n\n'
              + prefixed(tables) + constants + "\n/* ---------------------------------------------------------------- kernels (the twin's expressions) */\n"
              + prefixed(functions) + prefixed(runtime.HELPERS.replace("JACOBI_SV", sv)) + prefixed(newton)
              + prefixed(runtime.PUBLIC) + (prefixed(runtime.CLOSED_FORM) if closed else ""))
    files = {f"{prefix}.h": header, f"{prefix}.c": source, "Makefile": _MAKEFILE.replace("NAME", prefix),
             "CMakeLists.txt": _CMAKE.replace("NAME", prefix), "main.c": _main(prefix, mech, qa_first),
             "README.md": _readme(mech, prefix, qa_first, no_closed_form)}
    written = []
    for fname, text in files.items():
        path = out / fname
        path.write_text(text)
        written.append(path)
    return CLibrary(prefix, out, tuple(written), sizes, ops, blocks, tuple(n for n, *_ in limits),
                    tuple(vnames[c] for c in model.idle), no_closed_form, modes)


def mode_id(newton: Newton, q: np.ndarray, target: np.ndarray) -> tuple[int, float]:
    """The mode id of ``q`` for the Newton system ``newton`` (``ExportModel.fk`` or ``.ik``) and its target, from
    the dense determinants of the diagonal blocks (numpy's, not the kernel's fixed pivots: a second route to the
    C's ids), and the square matrix's smallest singular value relative to its largest, the matrix homogenised
    (:meth:`Newton.homogenised`: scale-free, the C's singularity test's)."""
    A = np.array(newton.system(q, target)[0])
    ident = 0
    for k, b in enumerate(newton.blocks):
        if not np.linalg.det(A[np.ix_(b.rows, b.cols)]) * b.sign > 0:
            ident |= 1 << k
    s = np.linalg.svd(newton.homogenised(A), compute_uv=False) if A.size else np.ones(1)
    return ident, float(s[-1] / s[0])


def mode_constants(mech: Mechanism, model: ExportModel) -> tuple[dict[str, dict[str, int]], list[str]]:
    """The mode ids the header names, and the header's lines about them.

    ``REFERENCE``: the reference configuration's id, 0 for both kinematics. The spec's branches (working modes,
    ``[branch.<name>]``: signs of joint coordinates) are the inverse kinematics' named modes: each one's id is the
    working-mode id of its configuration at the reference task value (:func:`pkm.core.kinematics.solve.branch_seed`).
    A spec names no assembly mode: the forward kinematics has ``REFERENCE`` only. A branch pkm cannot reach at the
    reference task value, or reaches at a singular configuration, gets no constant (a line and a
    :class:`~pkm.errors.PkmWarning` say so); two branches with one id (the blocks' determinants do not tell them
    apart) are said so too.

    Raises:
        ExportError: two branches' names make the same C identifier, or a branch called ``reference`` is not the
            reference's mode.
    """
    import warnings

    from pkm.core.kinematics.solve import branch_seed
    from pkm.errors import PkmError, PkmWarning

    modes: dict[str, dict[str, int]] = {"fk": {"REFERENCE": 0}, "ik": {"REFERENCE": 0}}
    on = [b for b in mech.spec.branches if mech.on_branch(mech.q_reference, b)]
    lines = ["FK_MODE_REFERENCE = 0: the reference configuration's assembly mode. The spec names no assembly mode; "
             "fk_mode gives any closed configuration's id.",
             "IK_MODE_REFERENCE = 0: the reference configuration's working mode"
             + (f" (on branch {', '.join(on)})." if on else
                (" (on none of the spec's branches)." if mech.spec.branches else "; the spec names no branch."))]
    owner: dict[str, str] = {}
    for name in mech.spec.branches:
        key = c_name(name).upper()
        if key in owner:
            raise ExportError(mech.name, f"branches {owner[key]!r} and {name!r} make the same C name {key}")
        owner[key] = name
    for key, name in owner.items():
        branch = mech.spec.branches[name]
        signs = ", ".join(f"{j} {'>' if s > 0 else '<'} 0" for j, s in branch.signs.items())
        try:
            q = branch_seed(mech, name)
        except PkmError as e:
            why = (f"branch {name!r} ({signs}): no constant, pkm finds no configuration on it at the reference task "
                   f"value ({e})")
            warnings.warn(why, PkmWarning, stacklevel=3)
            lines.append(why + ".")
            continue
        ident, sigma = mode_id(model.ik, q, TaskMap.of(mech).value(q))
        if not sigma > SINGULAR_TOL:
            why = (f"branch {name!r} ({signs}): no constant, its configuration at the reference task value is singular "
                   f"(relative smallest singular value {sigma:.3g})")
            warnings.warn(why, PkmWarning, stacklevel=3)
            lines.append(why + ".")
            continue
        if key == "REFERENCE" and ident != 0:
            raise ExportError(mech.name, f"branch {name!r} is not the reference's working mode (id {ident}) but its C "
                                         "name is REFERENCE's")
        modes["ik"][key] = ident
        lines.append(f"IK_MODE_{key} = {ident}: branch {name!r} ({signs}"
                     + (f"; {branch.description}" if branch.description else "")
                     + "): the working-mode id of its configuration at the reference task value.")
    seen: dict[int, list[str]] = {}
    for key, ident in modes["ik"].items():
        if key != "REFERENCE":
            seen.setdefault(ident, []).append(key)
    for ident, keys in seen.items():
        if len(keys) > 1:
            why = (f"branches {', '.join(keys)} share the id {ident}: the blocks' determinants do not tell them apart, "
                   "and asking ik for that mode does not keep a solution on one of them")
            warnings.warn(why, PkmWarning, stacklevel=3)
            lines.append(why[0].upper() + why[1:] + ".")
    return modes, lines


def _check_at_reference(mech: Mechanism, model: ExportModel, kernels: list[cs.Function]) -> None:
    """Each kernel finite at the reference and both Newton solves converged there (the reference is closed: its
    step is a zero step)."""
    q = mech.q_reference
    qa, y = mech.actuated_q(q), TaskMap.of(mech).value(q)
    zeros = np.zeros(mech.na)
    for newton, target, what in ((model.fk, qa, "forward"), (model.ik, y, "inverse")):
        q_next, r, pivot, *_ = (np.array(x).ravel() for x in newton.step(q, target))
        if not (np.isfinite(q_next).all() and r[0] <= 1e-9 and pivot[0] >= PIVOT_FLOOR):
            raise ExportError(mech.name, f"the {what} kinematics' Newton step does not converge at the reference "
                                         f"(residual {r[0]:.3g}, smallest relative pivot {pivot[0]:.3g})")
    args = {"task_value": (q,), "jacobians": (q,), "ik_closed": (y, model.closed_form[1]),
            "jdot_qdot": (q, zeros + 0.1), "inverse_dynamics": (q, zeros, zeros),
            "mass_matrix": (q,), "gravity": (q,)}
    for fun in kernels:
        if fun.name() not in args:
            continue
        values = [np.array(x) for x in fun.call([cs.DM(a) for a in args[fun.name()]])]
        if not all(np.isfinite(v).all() for v in values):
            raise ExportError(mech.name, f"{fun.name()} is not finite at the reference")
        if fun.name_out(fun.n_out() - 1) == "pivot" and not values[-1].ravel()[0] >= PIVOT_FLOOR:
            raise ExportError(mech.name, f"{fun.name()}'s factorisation fails at the reference (an idle motion "
                                         "without inertia of its own?)")


def _motors_line(mech: Mechanism, prefix: str) -> str:
    """The header's paragraph on the motors (:attr:`Mechanism.motor_map`): one per actuated joint, or ``[motors]``
    that drive them through a constant map (a differential: each motor by its name and coefficients)."""
    if mech.motor_map.identity:
        return (f"Motors: one per actuated joint, named as it ({prefix}_motor_names; {prefix}_motor_map the identity); "
                "tau is their efforts.")
    return (f"Motors ({prefix}_motor_names), driving the actuated joints through a constant map (a differential: "
            f"u = C qa, C = {prefix}_motor_map, NA x NA column-major, its rows the motors, its columns the actuated "
            "joints; the motors' efforts f act on the actuated joints as tau = C^T f, so f = C^-T tau): "
            + "; ".join(mech.motor_map.equations(mech.actuated_names)) + ".")


def _header(mech: Mechanism, prefix: str, sizes: dict[str, int], ops: dict[str, tuple[int, int, int]],
            blocks: dict[str, list[list[str]]], limits: list, fk: object, ik: object, version: str, stamp: str,
            no_closed_form: str, modes: dict[str, dict[str, int]], mode_lines: list[str]) -> str:
    U = prefix.upper()
    step = lambda k: ops[k][0] + ops[k][1] + ops[k][2]
    lines = [
        f"{prefix}: the kinematics and dynamics of the mechanism {mech.name!r} as C99, generated by pkm {version}",
        f"on {stamp} from {mech.source}.",
        "",
        f"Sizes: configuration q {sizes['NQ']} (Pinocchio's layout: a ball joint's quaternion x y z w), velocity "
        f"{sizes['NV']}, actuated {sizes['NA']} ({', '.join(mech.actuated_names)}), task value {sizes['NY']} "
        f"({', '.join(TaskMap.of(mech).value_names)}), task rate {sizes['NX']}. SI units: m, rad, N, N m, kg.",
        "",
        _motors_line(mech, prefix),
        "",
        "Operations after common-subexpression elimination (multiplications, additions, other functions):",
    ]
    for k, (mul, add, other) in ops.items():
        lines.append(f"  {k:18s} {mul:6d} mul {add:6d} add {other:5d} functions")
    lines += [
        "",
        f"Forward kinematics: a path from q_prev in steps of at most {U}_FK_STEP = {FK_STEP:g} per actuator (rad, or "
        f"characteristic lengths), one step where q_prev is that near (a warm start), {U}_MAX_STEPS = {MAX_STEPS} "
        f"at most; per step at most {U}_MAX_ITER = {MAX_ITER} evaluations of fk_step ({step('fk_step')} operations "
        f"each), so at most {MAX_ITER * step('fk_step')} operations a step where the fixed pivots hold; an iteration where "
        f"they fail also evaluates fk_system ({step('fk_system')} operations), a Jacobi SVD and a dense "
        f"{len(fk.columns)} x {len(fk.columns)} solve.",  # type: ignore[attr-defined]
        f"Inverse kinematics: at most {MAX_ITER} evaluations of ik_step ({step('ik_step')} operations each), at "
        f"most {MAX_ITER * step('ik_step')} operations where the fixed pivots hold; an iteration where they fail also "
        f"evaluates ik_system ({step('ik_system')} operations), a Jacobi SVD and a dense {len(ik.columns)} x "  # type: ignore[attr-defined]
        f"{len(ik.columns)} solve.",  # type: ignore[attr-defined]
        f"Converged when the largest closure residual (and task error) is at most {U}_TOL = {TOL:g}, lengths counted "
        f"in the characteristic length L = {mech.characteristic_length:.6g} m and angles in rad (scale-free).",
        (f"Closed-form inverse kinematics of the actuators ({prefix}_ik_actuators): {step('ik_closed')} operations, "
         "no iteration." if not no_closed_form else f"No closed-form inverse kinematics: {no_closed_form}."),
        "",
        "Mode ids: bit k set when the k-th diagonal block of the Newton matrix has the determinant sign opposite to",
        "the reference configuration's; 0 is the reference's mode. Blocks (their coordinates):",
    ]
    for kind in ("fk", "ik"):
        for bit, cols in enumerate(blocks[kind]):
            lines.append(f"  {kind} bit {bit}: {', '.join(cols)}")
        if not blocks[kind]:
            lines.append(f"  {kind}: none (one mode)")
    lines += ["", f"Named mode ids ({U}_FK_MODE_*, {U}_IK_MODE_*, defined below; {prefix}_fk and {prefix}_ik take "
              "them as mode):"]
    lines += [f"  {U}_" + line.replace("fk_mode", f"{prefix}_fk_mode") if line.startswith(("FK_", "IK_"))
              else f"  {line}" for line in mode_lines]
    lines += ["", "Joint limits checked: " + (", ".join(f"{n} [{lo:.6g}, {hi:.6g}]" for n, _, lo, hi in limits)
                                              or "none")]
    comment = "/*\n" + "".join(f" * {line}".rstrip() + "\n" for line in lines) + " */\n"
    guard = f"{U}_H"
    defs = [f"#define {U}_{k} {v}" for k, v in sizes.items()]
    defs.append(f"#define {U}_HAS_CLOSED_FORM {0 if no_closed_form else 1}")
    defs += [f"#define {U}_{kind.upper()}_MODE_{key} {ident}" for kind in ("fk", "ik")
             for key, ident in modes[kind].items()]
    defs += [f"#ifndef {U}_MAX_ITER\n#define {U}_MAX_ITER {MAX_ITER}\n#endif",
             f"#ifndef {U}_TOL\n#define {U}_TOL {TOL!r}\n#endif",
             f"#ifndef {U}_FK_STEP\n#define {U}_FK_STEP {FK_STEP!r}\n#endif",
             f"#ifndef {U}_MAX_STEPS\n#define {U}_MAX_STEPS {MAX_STEPS}\n#endif",
             f"#ifndef {U}_PATH_TOL\n#define {U}_PATH_TOL {PATH_TOL!r}\n#endif",
             f"#ifndef {U}_PIVOT_FLOOR\n#define {U}_PIVOT_FLOOR {PIVOT_FLOOR!r}\n#endif",
             f"#ifndef {U}_SINGULAR_TOL\n#define {U}_SINGULAR_TOL {SINGULAR_TOL!r}\n#endif",
             f"#ifndef {U}_LIMIT_TOL\n#define {U}_LIMIT_TOL {LIMIT_TOL!r}\n#endif"]
    status = "\n".join(f"  {U}_{s} = {i}," for i, s in enumerate(STATUS))
    info = (f"typedef struct {{\n  int status;        /* the status returned */\n"
            "  int iterations;    /* Newton step evaluations */\n"
            "  double residual;   /* the largest closure residual or task error at the last iterate (lengths in L, rad) */\n"
            "  double sigma_min;  /* SINGULAR, PIVOT_ORDER: the matrix's relative smallest singular value, homogenised */\n"
            "  double pivot;      /* the smallest relative pivot of the fixed elimination order */\n"
            "  int joint;         /* OUTSIDE_LIMITS: the joint (index into limit_names), else -1 */\n"
            "  long mode;         /* the mode id of the solution */\n"
            f"}} {prefix}_info;\n")
    decls = (f"extern const char* const {prefix}_limit_names[{max(len(limits), 1)}];\n"
             f"extern const char* const {prefix}_task_names[{U}_NY];\n"
             f"extern const double {prefix}_q_reference[{U}_NQ];  /* the reference configuration (mode 0) */\n"
             f"extern const int {prefix}_actuated_q[{U}_NA];  /* where the actuated coordinates are in q */\n"
             f"extern const char* const {prefix}_motor_names[{U}_NA];  /* the motors (see above) */\n"
             f"extern const double {prefix}_motor_map[{U}_NA * {U}_NA];  /* u = C qa, column-major (see above) */\n")
    body = (runtime.HEADER_FUNCTIONS + ("" if no_closed_form else runtime.HEADER_CLOSED_FORM)) \
        .replace("p_", f"{prefix}_").replace("P_", f"{U}_")
    return (comment + f"#ifndef {guard}\n#define {guard}\n\n#ifdef __cplusplus\nextern \"C\" {{\n#endif\n\n"
            + "\n".join(defs) + f"\n\nenum {{\n{status}\n}};\n\n" + info + "\n" + decls + body
            + "\n#ifdef __cplusplus\n}\n#endif\n\n#endif\n")


def _readme(mech: Mechanism, prefix: str, qa_first: np.ndarray, no_closed_form: str) -> str:
    """The library's README: the files, the build, how to get a first forward kinematics solution, and what the
    example prints first (pkm's own answer, :func:`pkm.core.kinematics.solve.close_loops` from the reference)."""
    from pkm.core.kinematics.solve import close_loops

    U, closed = prefix.upper(), not no_closed_form
    task = TaskMap.of(mech)
    y = task.value(close_loops(mech, qa_first).q)
    shown = " ".join(f"{n}={v}" for n, v in zip(task.value_names, _show(y)))
    qa_text = ", ".join(f"{x:.9g}" for x in qa_first)
    seed = (f"""
From a task value instead (the closed form, no iteration): `{prefix}_ik_actuators(y_goal, 0, qa, &info)` gives the actuated
coordinates of the reference's leg branches; then `{prefix}_fk(qa, {prefix}_q_reference, {U}_FK_MODE_REFERENCE, q, y, &info)`
gives the whole configuration in the reference's assembly mode.
""" if closed else f"""
From a task value instead: the actuated coordinates `qa` for it (pkm's `pkm.solve_ik(mech, y_goal)` in Python, or a
closed form of your own: this library has none, {no_closed_form}), then `{prefix}_fk(qa, {prefix}_q_reference,
{U}_FK_MODE_REFERENCE, q, y, &info)` gives the whole configuration in the reference's assembly mode.
""")
    return f"""# `{prefix}`: the C99 library of the mechanism `{mech.name}` (generated by pkm)

Files: `{prefix}.h` (every function documented, the sizes, the status codes, the mode ids), `{prefix}.c`, `main.c`
(the example below), `Makefile`, `CMakeLists.txt`. SI units (m, rad), arrays column-major, `q` in Pinocchio's layout.

```sh
make && ./example
```

## A first forward kinematics solution

`{prefix}_fk(qa, q_prev, mode, q, y, &info)` solves from the caller's previous solution `q_prev`. For the first one,
start from the reference configuration, exported as the constant `{prefix}_q_reference` (its assembly mode is
`{U}_FK_MODE_REFERENCE` = 0): where `qa` is more than `{U}_FK_STEP` from the reference's actuated coordinates, `fk`
follows a path of steps to it (as `pkm.close_loops` does), so that the solution stays in the reference's assembly mode
(or answers `NOT_CONVERGED` or `SINGULAR` where that mode cannot reach `qa` without crossing a singularity), then warm
starts from each solution:

```c
double q[{U}_NQ], y[{U}_NY];
{prefix}_info info;
int status = {prefix}_fk(qa, {prefix}_q_reference, {U}_FK_MODE_REFERENCE, q, y, &info);
```
{seed}
`main.c` does this for qa = ({qa_text}) and prints first (pkm's own answer, `pkm.close_loops` from the reference):

```text
first fk: status 0, {shown}
```
"""


_MAKEFILE = """# Builds libNAME.a and the example. Override CC or CFLAGS as you like.
CC ?= cc
CFLAGS ?= -std=c99 -O2 -Wall -Wextra -pedantic

all: libNAME.a example

NAME.o: NAME.c NAME.h
\t$(CC) $(CFLAGS) -c NAME.c -o NAME.o

libNAME.a: NAME.o
\tar rcs libNAME.a NAME.o

example: main.c libNAME.a
\t$(CC) $(CFLAGS) main.c libNAME.a -lm -o example

clean:
\trm -f NAME.o libNAME.a example

.PHONY: all clean
"""

_CMAKE = """cmake_minimum_required(VERSION 3.10)
project(NAME C)
set(CMAKE_C_STANDARD 99)
set(CMAKE_C_STANDARD_REQUIRED ON)
add_library(NAME NAME.c)
target_include_directories(NAME PUBLIC ${CMAKE_CURRENT_SOURCE_DIR})
find_library(MATH_LIBRARY m)
if(MATH_LIBRARY)
  target_link_libraries(NAME PUBLIC ${MATH_LIBRARY})
endif()
add_executable(NAME_example main.c)
target_link_libraries(NAME_example NAME)
"""


def first_target(mech: Mechanism) -> np.ndarray:
    """The actuated coordinates of the example's first solution (``main.c``, the README): the reference's moved by
    0.5, 0.2, 0.1 or 0.05 (rad, or characteristic lengths for a prismatic actuator; alternating signs), the first
    that :func:`pkm.core.kinematics.solve.close_loops` reaches from the reference in its assembly and working mode
    and inside every limit; the reference's own where none does."""
    import warnings

    from pkm.core.kinematics.solve import close_loops
    from pkm.errors import ModeChangeWarning, PkmError

    qa0 = mech.actuated_q(mech.q_reference)
    signs = np.where(np.arange(mech.na) % 2, -1.0, 1.0)
    for step in (0.5, 0.2, 0.1, 0.05):
        qa = qa0 + step * signs * JacobianScales.of(mech).actuated
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error", ModeChangeWarning)
                res = close_loops(mech, qa)
        except (PkmError, ModeChangeWarning):
            continue
        if not res.outside_limits:
            return qa
    return qa0


def _show(values: np.ndarray) -> list[str]:
    """Task values as the example prints them (``%.6f``, a value within 5e-10 of zero as 0)."""
    return [f"{0.0 if abs(v) < 5e-10 else float(v):.6f}" for v in values]


def _main(prefix: str, mech: Mechanism, qa_first: np.ndarray) -> str:
    U = prefix.upper()
    first = ", ".join(repr(float(x)) for x in qa_first)
    return f"""/* An example: a first forward kinematics solution from the reference configuration (exported as
   {prefix}_q_reference, in the assembly mode {U}_FK_MODE_REFERENCE), the forward kinematics along a short motion of
   the actuators, warm-started from the previous solution, then the inverse kinematics and the inverse dynamics at the
   last pose. Build: make; run: ./example (README.md shows what it prints) */
#include <stdio.h>
#include "{prefix}.h"

static double shown(double v) {{ return v > -5e-10 && v < 5e-10 ? 0.0 : v; }}  /* (no "-0.000000") */

int main(void) {{
  static const double qa_first[{U}_NA] = {{{first}}};
  double q_prev[{U}_NQ], q[{U}_NQ], y[{U}_NY], qa[{U}_NA], qa_ik[{U}_NA], qd[{U}_NA], qdd[{U}_NA], tau[{U}_NA];
  {prefix}_info info;
  int k, i, status = {U}_OK;
  long mode;
  /* a first solution: from the reference configuration, in its assembly mode (fk follows a path to qa_first) */
  status = {prefix}_fk(qa_first, {prefix}_q_reference, {U}_FK_MODE_REFERENCE, q, y, &info);
  printf("first fk: status %d,", status);
  for (i = 0; i < {U}_NY; ++i) printf(" %s=%.6f", {prefix}_task_names[i], shown(y[i]));
  printf("\\n");
  if (status != {U}_OK) return 1;
  for (i = 0; i < {U}_NQ; ++i) q_prev[i] = q[i];
  for (k = 1; k <= 10; ++k) {{
    for (i = 0; i < {U}_NA; ++i) qa[i] = q_prev[{prefix}_actuated_q[i]] + 0.002 * (i % 2 ? -1.0 : 1.0);
    status = {prefix}_fk(qa, q_prev, {U}_FK_MODE_REFERENCE, q, y, &info);  /* (stay in the reference's assembly mode) */
    if (status != {U}_OK) {{ printf("fk: status %d (residual %g)\\n", status, info.residual); return 1; }}
    for (i = 0; i < {U}_NQ; ++i) q_prev[i] = q[i];
  }}
  printf("fk after 10 steps (%d iterations at the last):", info.iterations);
  for (i = 0; i < {U}_NY; ++i) printf(" %s=%.9g", {prefix}_task_names[i], y[i]);
  printf("\\n");
  status = {prefix}_ik(y, q, {U}_IK_MODE_REFERENCE, q_prev, qa_ik, &info);  /* (in the reference's working mode) */
  printf("ik: status %d, mode %ld, actuated error %.3g\\n", status, info.mode, qa_ik[0] - qa[0]);
  if ({prefix}_ik_mode(q, &mode) == {U}_OK)
    printf("working mode id %ld%s\\n", mode, mode == {U}_IK_MODE_REFERENCE ? " (the reference's)" : "");
  for (i = 0; i < {U}_NA; ++i) {{ qd[i] = 0.1; qdd[i] = 1.0; }}
  status = {prefix}_inverse_dynamics(q, qd, qdd, tau, &info);
  printf("inverse dynamics: status %d, tau[0] = %.9g\\n", status, tau[0]);
  return status;
}}
"""


__all__ = ["MAX_ITER", "STATUS", "TOL", "CLibrary", "ExportError", "export_c", "mode_constants", "mode_id"]
