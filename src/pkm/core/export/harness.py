"""Running an exported library (:func:`pkm.core.export.export_c`) from Python: the harness the tests, the CI check
(``tools/export_harness.py``) and ``pkm bench export`` use.

:func:`build` compiles the library with a strict C99 build (``-std=c99 -Wall -Wextra -Werror -pedantic``: a warning
fails it), checks the object file's undefined symbols (no allocation, no I/O: :data:`FORBIDDEN`), and links it with
a generated ``harness.c`` that reads samples on standard input and writes every function's outputs on standard
output, as doubles. :meth:`Harness.run` feeds a table of inputs (one row per call) and returns a table of outputs;
:meth:`Harness.bench` times the functions in C (``clock_gettime``, the median of blocks of calls).

Row layouts (:func:`layouts`): ``fk`` in ``qa, q_prev, mode`` out ``status, iterations, residual, mode, q, y``;
``ik`` in ``y, q_prev, mode`` out ``status, iterations, residual, mode, q, qa``; ``jacobians`` in ``q`` out
``status, J, K``; ``maps`` in ``q, qd, xd, tau, w`` out four statuses, ``xd = J qd, qd = K xd, w = Kᵀ tau,
tau = Jᵀ w``; ``jdot_qdot`` in ``q, qd`` out ``status, c``; ``inverse_dynamics`` in ``q, qd, qdd`` out
``status, tau``; ``mass_matrix`` in ``q`` out ``status, M``; ``gravity`` in ``q`` out ``status, g``;
``ik_actuators`` (the closed form, where the library has it; status -1 otherwise) in ``y, mode`` out
``status, residual, smallest margin, qa``; ``modes`` in ``q`` out ``fk_mode``'s status and id, ``ik_mode``'s status
and id, ``fk_distance`` (-1 where it fails); ``mode_ids`` in nothing out the header's named mode ids as the C compiler reads them (``<NAME>_FK_MODE_*``
then ``<NAME>_IK_MODE_*``, in :attr:`CLibrary.modes <pkm.core.export.library.CLibrary.modes>`' order).
:func:`check_modes` proves each named id on a configuration in its mode.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pkm.core.export.library import CLibrary
from pkm.core.kinematics.task import TaskMap
from pkm.core.model.mechanism import Mechanism
from pkm.errors import CompilerError

#: The flags every exported library must build with, warning-free.
STRICT = ("-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic")
#: Symbols an exported library must not use: allocation and I/O.
FORBIDDEN = frozenset({"malloc", "calloc", "realloc", "free", "printf", "fprintf", "sprintf", "snprintf", "puts",
                       "putchar", "fputs", "fwrite", "perror", "abort", "exit", "__printf_chk", "__fprintf_chk",
                       "__sprintf_chk", "__snprintf_chk"})
KINDS = ("fk", "ik", "jacobians", "maps", "jdot_qdot", "inverse_dynamics", "mass_matrix", "gravity", "ik_actuators",
         "modes", "mode_ids")


def layouts(lib: CLibrary) -> dict[str, tuple[int, int]]:
    """Per kind, the widths of an input row and an output row."""
    nq, na, ny, nx = (lib.sizes[k] for k in ("NQ", "NA", "NY", "NX"))
    return {"fk": (na + nq + 1, 4 + nq + ny), "ik": (ny + nq + 1, 4 + nq + na), "jacobians": (nq, 1 + 2 * nx * na),
            "maps": (nq + 2 * na + 2 * nx, 4 + 2 * nx + 2 * na), "jdot_qdot": (nq + na, 1 + nx),
            "inverse_dynamics": (nq + 2 * na, 1 + na), "mass_matrix": (nq, 1 + na * na), "gravity": (nq, 1 + na),
            "ik_actuators": (ny + 1, 3 + na), "modes": (nq, 5),
            "mode_ids": (0, sum(len(lib.modes.get(k, {})) for k in ("fk", "ik")))}


_HARNESS = r"""
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "NAME.h"

#define NQ U_NQ
#define NA U_NA
#define NY U_NY
#define NX U_NX

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double) t.tv_sec + 1e-9 * (double) t.tv_nsec;
}

static int cmp(const void* a, const void* b) {
  double x = *(const double*) a, y = *(const double*) b;
  return (x > y) - (x < y);
}

static void one(int kind, const double* in, double* out) {
  NAME_info info;
  int s;
  switch (kind) {
  case 0:
    s = NAME_fk(in, in + NA, (long) in[NA + NQ], out + 4, out + 4 + NQ, &info);
    out[0] = s; out[1] = info.iterations; out[2] = info.residual; out[3] = (double) info.mode;
    break;
  case 1:
    s = NAME_ik(in, in + NY, (long) in[NY + NQ], out + 4, out + 4 + NQ, &info);
    out[0] = s; out[1] = info.iterations; out[2] = info.residual; out[3] = (double) info.mode;
    break;
  case 2:
    out[0] = NAME_jacobians(in, out + 1, out + 1 + NX * NA, &info);
    break;
  case 3:
    out[0] = NAME_task_velocity(in, in + NQ, out + 4, &info);
    out[1] = NAME_actuator_velocity(in, in + NQ + NA, out + 4 + NX, &info);
    out[2] = NAME_task_effort(in, in + NQ + NA + NX, out + 4 + NX + NA, 0);
    out[3] = NAME_actuator_effort(in, in + NQ + 2 * NA + NX, out + 4 + 2 * NX + NA, 0);
    break;
  case 4:
    out[0] = NAME_jdot_qdot(in, in + NQ, out + 1, &info);
    break;
  case 5:
    out[0] = NAME_inverse_dynamics(in, in + NQ, in + NQ + NA, out + 1, &info);
    break;
  case 6:
    out[0] = NAME_mass_matrix(in, out + 1, &info);
    break;
  case 7:
    out[0] = NAME_gravity(in, out + 1, &info);
    break;
  case 9: {
    long mode = -1;
    out[0] = NAME_fk_mode(in, &mode); out[1] = (double) mode;
    mode = -1;
    out[2] = NAME_ik_mode(in, &mode); out[3] = (double) mode;
    if (NAME_fk_distance(in, &out[4]) != U_OK) out[4] = -1.0;
    break;
  }
  case 10: {
    static const long ids[] = {MODE_IDS};
    unsigned i;
    for (i = 0; i < sizeof ids / sizeof ids[0]; ++i) out[i] = (double) ids[i];
    break;
  }
  default:
#if U_HAS_CLOSED_FORM
    out[0] = NAME_ik_actuators(in, (long) in[NY], out + 3, &info);
    out[1] = info.residual; out[2] = info.sigma_min;
#else
    out[0] = -1;
#endif
    break;
  }
}

/* stdin: kind, n, then n rows; kind + 100: time the function over the n rows (fk warm-started along them), in
   blocks of 100 calls, and write the median time per call [s]. */
int main(void) {
  static const int in_w[] = {IN_WIDTHS}, out_w[] = {OUT_WIDTHS};
  double head[2], *in, *out;
  long n, k;
  int kind, bench;
  if (fread(head, sizeof(double), 2, stdin) != 2) return 2;
  kind = (int) head[0]; n = (long) head[1]; bench = kind >= 100; kind %= 100;
  in = malloc(sizeof(double) * (size_t) (n * in_w[kind] + 1));
  out = malloc(sizeof(double) * (size_t) ((n + 1) * out_w[kind] + 1));
  if (!in || !out || fread(in, sizeof(double), (size_t) (n * in_w[kind]), stdin) != (size_t) (n * in_w[kind])) return 2;
  if (!bench) {
    for (k = 0; k < n; ++k) one(kind, in + k * in_w[kind], out + k * out_w[kind]);
    fwrite(out, sizeof(double), (size_t) (n * out_w[kind]), stdout);
  } else {
    long blocks = n / 100, b;
    double* t = malloc(sizeof(double) * (size_t) (blocks + 1));
    double q[NQ], y[NY];
    NAME_info info;
    if (!t) return 2;
    for (b = 0; b < blocks; ++b) {
      double t0 = now();
      for (k = b * 100; k < (b + 1) * 100; ++k) {
        const double* row = in + k * in_w[kind];
        if (kind == 0) {  /* fk along the path: each call from the previous solution */
          NAME_fk(row, k == 0 ? row + NA : q, 0, q, y, &info);
        } else {
          one(kind, row, out);
        }
      }
      t[b] = (now() - t0) / 100.0;
    }
    qsort(t, (size_t) blocks, sizeof(double), cmp);
    fwrite(&t[blocks / 2], sizeof(double), 1, stdout);
    free(t);
  }
  free(in); free(out);
  return 0;
}
"""


def compiler(name: str = "cc") -> str | None:
    """The path of the C compiler ``name`` (``cc``, ``gcc``, ``clang``), None when absent."""
    return shutil.which(name)


@dataclass(frozen=True)
class Harness:
    """A compiled harness of ``lib`` (:func:`build`): :attr:`symbols` are the library object's undefined
    symbols."""

    lib: CLibrary
    executable: Path
    symbols: frozenset[str]

    def _call(self, code: int, rows: np.ndarray) -> bytes:
        data = np.concatenate([[float(code), float(len(rows))], np.ascontiguousarray(rows, dtype=float).ravel()])
        run = subprocess.run([str(self.executable)], input=data.tobytes(), capture_output=True, check=False,
                             timeout=600)
        if run.returncode != 0:
            raise CompilerError(f"the harness of {self.lib.name}", f"exit status {run.returncode}")
        return run.stdout

    def run(self, kind: str, rows: np.ndarray) -> np.ndarray:
        """The outputs (n x output width, :func:`layouts`) of ``kind`` for the input rows (n x input width)."""
        w_in, w_out = layouts(self.lib)[kind]
        rows = np.atleast_2d(np.asarray(rows, dtype=float))
        if rows.shape[1] != w_in:
            raise ValueError(f"{kind}: rows of {w_in} numbers expected, got {rows.shape[1]}")
        return np.frombuffer(self._call(KINDS.index(kind), rows), dtype=float).reshape(len(rows), w_out)

    def bench(self, kind: str, rows: np.ndarray) -> float:
        """The median time of one call of ``kind`` [s] over blocks of 100 calls along ``rows`` (at least 100);
        ``fk`` is warm-started from the previous call's solution (the first from the first row's ``q_prev``)."""
        rows = np.atleast_2d(np.asarray(rows, dtype=float))
        return float(np.frombuffer(self._call(100 + KINDS.index(kind), rows), dtype=float)[0])


def build(lib: CLibrary, cc: str = "cc", *, optimise: str = "-O2", directory: Path | None = None) -> Harness:
    """Compile ``lib`` with :data:`STRICT` flags and ``optimise`` by ``cc``, check its undefined symbols against
    :data:`FORBIDDEN`, and link the harness.

    Raises:
        CompilerError: no such compiler, the strict build fails (its first errors quoted), or the object file uses
            a forbidden symbol.
    """
    path = compiler(cc)
    if path is None:
        raise CompilerError(f"the C library {lib.name}", f"no compiler {cc!r} on the PATH")
    out = Path(directory) if directory is not None else lib.directory
    obj = out / f"{lib.name}-{Path(cc).name}{optimise}.o"
    run = subprocess.run([path, *STRICT, optimise, "-c", str(lib.source), "-o", str(obj)], capture_output=True,
                         text=True, check=False, timeout=1800)
    if run.returncode != 0:
        raise CompilerError(f"the C library {lib.name}", f"{cc} {' '.join(STRICT)} failed: {run.stderr.strip()[:600]}")
    nm = shutil.which("nm")
    symbols: frozenset[str] = frozenset()
    if nm is not None:
        listing = subprocess.run([nm, "-u", str(obj)], capture_output=True, text=True, check=True).stdout
        symbols = frozenset(re.sub(r"@.*", "", line.split()[-1]) for line in listing.splitlines() if line.strip())
        bad = sorted(symbols & FORBIDDEN)
        if bad:
            raise CompilerError(f"the C library {lib.name}", f"the object file references {bad}")
    widths = layouts(lib)
    text = (_HARNESS.replace("NAME", lib.name).replace("U_", f"{lib.name.upper()}_")
            .replace("IN_WIDTHS", ", ".join(str(widths[k][0]) for k in KINDS))
            .replace("OUT_WIDTHS", ", ".join(str(widths[k][1]) for k in KINDS))
            .replace("MODE_IDS", ", ".join(f"{lib.name.upper()}_{kind.upper()}_MODE_{key}" for kind in ("fk", "ik")
                                           for key in lib.modes.get(kind, {})) or "0"))
    source = out / f"harness-{lib.name}.c"
    source.write_text(text)
    exe = out / f"harness-{lib.name}-{Path(cc).name}{optimise}"
    run = subprocess.run([path, "-std=c99", "-O2", f"-I{lib.directory}", str(source), str(obj), "-lm", "-o", str(exe)],
                         capture_output=True, text=True, check=False, timeout=600)
    if run.returncode != 0:
        raise CompilerError(f"the harness of {lib.name}", run.stderr.strip()[:600])
    return Harness(lib, exe, symbols)


def _difference(a: np.ndarray, b: np.ndarray) -> float:
    """The largest entry of ``|a - b|`` relative to ``max(1, |b|)`` (over the whole block)."""
    return float(np.abs(a - b).max() / max(1.0, float(np.abs(b).max()))) if a.size else 0.0


def compare(mech: Mechanism, harness: Harness, samples: int = 4, step: float = 0.03, seed: int = 0
            ) -> dict[str, float]:
    """Every function of ``harness``'s library against pkm's generic core at ``samples`` closed configurations
    (the actuators moved by up to ``step`` from the reference, closed by :func:`pkm.close_loops`; a move it cannot make
    halved): per kind, the
    largest difference relative to ``max(1, largest reference value)``; ``status`` is the number of calls that
    did not return OK (each should be 0).

    The routes compared: :func:`pkm.close_loops` then the task map (fk; the whole configuration too when the
    mechanism has no idle motion), the configuration's actuated coordinates (ik), :func:`pkm.forward_jacobian` and
    :func:`pkm.inverse_jacobian` (jacobians, maps), :func:`pkm.task_acceleration` at zero actuated acceleration
    (jdot_qdot), :func:`pkm.actuator_model` (inverse dynamics ``M_a qdd + h_a``, ``M_a``, ``g_a``).
    """
    import pkm

    rng = np.random.default_rng(seed)
    lib = harness.lib
    na, nq = mech.na, mech.nq
    ref = mech.q_reference
    closed = []
    for _ in range(samples):
        move = step * rng.uniform(-1.0, 1.0, na)
        for _ in range(8):  # (a move the mechanism cannot make is halved)
            solved = pkm.close_loops(mech, mech.actuated_q(ref) + move, ref, tol=1e-14, raise_on_failure=False)
            if solved.converged:
                break
            move = move / 2
        closed.append(solved.q)
    Q = np.array(closed)
    tm = TaskMap.of(mech)
    Y = np.array([tm.value(q) for q in Q])
    QA = np.array([mech.actuated_q(q) for q in Q])
    mode = np.full((samples, 1), -1.0)
    out: dict[str, float] = {"status": 0.0}

    def statuses(x: np.ndarray) -> None:
        out["status"] += float(np.count_nonzero(x))

    fk = harness.run("fk", np.hstack([QA, np.tile(ref, (samples, 1)), mode]))
    statuses(fk[:, 0])
    q_c, y_c = fk[:, 4:4 + nq], fk[:, 4 + nq:]
    errors = [tm.error(y, yc) for y, yc in zip(Y, y_c)]  # (angles wrapped, orientations on SO(3))
    out["fk"] = _difference(np.array(errors), np.zeros((samples, 1)))
    if not lib.idle:
        out["fk_q"] = _difference(q_c, Q)
    ik = harness.run("ik", np.hstack([Y, np.tile(ref, (samples, 1)), mode]))
    statuses(ik[:, 0])
    out["ik"] = _difference(ik[:, 4 + nq:], QA)
    if not lib.closed_form:  # (the closed form, from the same task values)
        direct = harness.run("ik_actuators", np.hstack([Y, np.zeros((samples, 1))]))
        statuses(direct[:, 0])
        out["ik_actuators"] = _difference(direct[:, 3:], QA)
    jac = harness.run("jacobians", Q)
    statuses(jac[:, 0])
    nx = lib.sizes["NX"]
    J = np.array([pkm.forward_jacobian(mech, q) for q in Q])
    K = np.array([pkm.inverse_jacobian(mech, q) for q in Q])
    Jc = jac[:, 1:1 + nx * na].reshape(samples, na, nx).transpose(0, 2, 1)
    Kc = jac[:, 1 + nx * na:].reshape(samples, nx, na).transpose(0, 2, 1)
    out["jacobians"] = max(_difference(Jc, J), _difference(Kc, K))
    qd, xd, tau, w = (rng.standard_normal((samples, n)) for n in (na, nx, na, nx))
    maps = harness.run("maps", np.hstack([Q, qd, xd, tau, w]))
    statuses(maps[:, :4])
    want = np.hstack([np.einsum("kij,kj->ki", J, qd), np.einsum("kij,kj->ki", K, xd),
                      np.einsum("kji,kj->ki", K, tau), np.einsum("kji,kj->ki", J, w)])
    out["maps"] = _difference(maps[:, 4:], want)
    jd = harness.run("jdot_qdot", np.hstack([Q, qd]))
    statuses(jd[:, 0])
    c = []
    models = [pkm.actuator_model(mech, q, v) for q, v in zip(Q, qd)]
    for q, m in zip(Q, models):
        c.append(pkm.task_acceleration(mech, q, m.v, pkm.accelerations(mech, q, m.v, np.zeros(na))))
    out["jdot_qdot"] = _difference(jd[:, 1:], np.array(c))
    qdd = rng.standard_normal((samples, na))
    dyn = harness.run("inverse_dynamics", np.hstack([Q, qd, qdd]))
    statuses(dyn[:, 0])
    out["inverse_dynamics"] = _difference(dyn[:, 1:], np.array([m.M @ a + m.h for m, a in zip(models, qdd)]))
    mm = harness.run("mass_matrix", Q)
    statuses(mm[:, 0])
    out["mass_matrix"] = _difference(mm[:, 1:].reshape(samples, na, na), np.array([m.M for m in models]))
    g = harness.run("gravity", Q)
    statuses(g[:, 0])
    out["gravity"] = _difference(g[:, 1:], np.array([m.g for m in models]))
    return out


def check_modes(mech: Mechanism, harness: Harness, step: float = 0.01) -> list[str]:
    """The header's named mode ids proven in C: the ids as the compiler reads them are :attr:`CLibrary.modes
    <pkm.core.export.library.CLibrary.modes>`; ``fk_mode`` and ``ik_mode`` of the reference configuration return
    the ``REFERENCE`` ids; for each branch of the spec, at its configuration at the reference task value (pkm's
    :func:`~pkm.core.kinematics.solve.branch_seed`, computed here again), ``ik_mode`` returns the branch's constant,
    and ``ik`` asked for that mode from there to the task value of a configuration pkm closes with the actuators
    moved by ``step`` (rad or m) returns OK at a configuration on the branch, in that mode. Returns what went wrong
    (empty when nothing did)."""
    import pkm
    from pkm.core.export.model import c_name
    from pkm.core.kinematics.solve import branch_seed

    lib = harness.lib
    problems = []
    names = [(kind, key) for kind in ("fk", "ik") for key in lib.modes[kind]]
    compiled = harness.run("mode_ids", np.zeros((1, 0)))[0]
    values = {}
    for (kind, key), value in zip(names, compiled):
        values[kind, key] = int(value)
        if value != lib.modes[kind][key]:
            problems.append(f"{lib.name.upper()}_{kind.upper()}_MODE_{key} is {value:g} in C, {lib.modes[kind][key]} "
                            "in pkm")
    ref = harness.run("modes", mech.q_reference[None])[0]
    if not (ref[0] == 0 and ref[2] == 0 and ref[1] == values["fk", "REFERENCE"] and ref[3] == values["ik", "REFERENCE"]):
        problems.append(f"at the reference fk_mode and ik_mode return (status, id) {ref.tolist()}")
    for name in mech.spec.branches:
        key = c_name(name).upper()
        if key not in lib.modes["ik"]:
            continue  # (the header says why it has no constant)
        q = branch_seed(mech, name)
        got = harness.run("modes", q[None])[0]
        if not (got[2] == 0 and got[3] == values["ik", key]):
            problems.append(f"branch {name!r}: ik_mode returns (status, id) {got[2:].tolist()}, the constant is "
                            f"{values['ik', key]}")
            continue
        qa = mech.actuated_q(q) + step * (-1.0) ** np.arange(mech.na)
        moved = pkm.close_loops(mech, qa, q, tol=1e-14, raise_on_failure=False)
        if not (moved.converged and mech.on_branch(moved.q, name)):
            problems.append(f"branch {name!r}: pkm cannot move its configuration by {step} along it")
            continue
        row = np.hstack([TaskMap.of(mech).value(moved.q), q, [values["ik", key]]])
        got = harness.run("ik", row[None])[0]
        q_c = got[4:4 + mech.nq]
        if not (got[0] == 0 and got[3] == values["ik", key] and mech.on_branch(q_c, name)):
            problems.append(f"branch {name!r}: ik in its mode returns status {got[0]:g}, mode {got[3]:g}, "
                            f"{'on' if mech.on_branch(q_c, name) else 'off'} the branch")
    return problems


def domain(mech: Mechanism, harness: Harness, steps: int = 60) -> tuple[list[str], dict[str, int]]:
    """Calls outside the domain, each of which must return a status, never a NaN: NaN and infinite inputs to every
    function and coordinates of 1e308 (beyond :data:`~pkm.validation.ABSURD`: never wrapped) to those taking
    coordinates (``INVALID_INPUT``); the forward kinematics warm-started along a straight motion of the actuators from
    the reference (in mode 0) until far beyond the workspace (``steps`` of 0.05 rad, or 0.05 of the mechanism's
    size, each), through whatever singularity, mode change or limit it meets (a crank that turns fully meets none); the inverse kinematics of targets 10 units (m, rad) away.
    Returns what went wrong (empty when nothing did: a non-finite output, an OK whose configuration does not
    close, checked by pkm to 1e-9, lengths in the characteristic length as the C's tolerance counts them) and how many of the forward kinematics' steps ended in each status."""
    from pkm.core.export.library import STATUS
    from pkm.core.kinematics.constraints import residual, worst_closure
    from pkm.core.model.scale import JacobianScales

    lib = harness.lib
    weights = JacobianScales.of(mech).closure_residual
    na, nq, ny = mech.na, mech.nq, lib.sizes["NY"]
    ref = mech.q_reference
    invalid = STATUS.index("INVALID_INPUT")
    problems = []
    for bad in (np.nan, np.inf, 1e308):  # (1e308: a coordinate beyond pkm.validation.ABSURD, never wrapped)
        rows = {"fk": np.hstack([np.full(na, bad), ref, [-1.0]]), "ik": np.hstack([np.full(ny, bad), ref, [-1.0]]),
                "jacobians": np.full(nq, bad), "jdot_qdot": np.hstack([ref, np.full(na, bad)]),
                "inverse_dynamics": np.hstack([ref, np.zeros(na), np.full(na, bad)]), "mass_matrix": np.full(nq, bad),
                "gravity": np.full(nq, bad), "maps": np.hstack([ref, np.full(2 * na + 2 * lib.sizes["NX"], bad)])}
        if not lib.closed_form:
            rows["ik_actuators"] = np.hstack([np.full(ny, bad), [0.0]])
        for kind, row in rows.items():
            if bad == 1e308 and kind in ("jdot_qdot", "inverse_dynamics", "maps"):  # (rates, efforts: not bounded)
                continue
            got = harness.run(kind, row[None])[0]
            statuses = got[:4] if kind == "maps" else got[:1]
            if not (statuses == invalid).all():
                problems.append(f"{kind}({bad}) returned status {statuses.tolist()}")
    scale = max(float(np.abs(TaskMap.of(mech).value(ref)).max()), 0.05)
    unit = np.array([0.05 if mech.joints[n].revolute else 0.05 * scale for n in mech.actuated_names])
    rng = np.random.default_rng(1)
    direction = rng.uniform(-1.0, 1.0, na)
    direction /= np.abs(direction).max()
    qa0, q = mech.actuated_q(ref), ref.copy()
    seen = []
    for k in range(1, steps + 1):
        row = np.hstack([qa0 + unit * k * direction, q, [0.0]])
        got = harness.run("fk", row[None])[0]
        if not np.isfinite(got).all():
            problems.append(f"fk step {k}: non-finite output (status {got[0]:g})")
            break
        seen.append(STATUS[int(got[0])])
        if got[0] in (0, STATUS.index("OUTSIDE_LIMITS"), STATUS.index("LEFT_MODE")):
            q = got[4:4 + nq]
            if worst_closure(mech, residual(mech, q) * weights)[0] > 1e-9:
                problems.append(f"fk step {k}: OK at a configuration that does not close")
    y0 = TaskMap.of(mech).value(ref)
    for sign in (1.0, -1.0):
        row = np.hstack([y0 + sign * 10.0 * np.eye(ny)[0], ref, [-1.0]])
        got = harness.run("ik", row[None])[0]
        if not np.isfinite(got).all():
            problems.append(f"ik of a target 10 away: non-finite output (status {got[0]:g})")
        if not lib.closed_form:
            got = harness.run("ik_actuators", np.hstack([row[:ny], [0.0]])[None])[0]
            if not (np.isfinite(got).all() and STATUS[int(got[0])] in ("NOT_CONVERGED", "OUTSIDE_LIMITS")):
                problems.append(f"ik_actuators of a target 10 away: status {got[0]:g}, outputs {got.tolist()}")
    return problems, {k: seen.count(k) for k in STATUS if k in seen}


__all__ = ["FORBIDDEN", "KINDS", "STRICT", "Harness", "build", "check_modes", "compare", "compiler", "domain",
           "layouts"]
