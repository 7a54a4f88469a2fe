"""The transmission kernels' three targets from one generator: compiled C, JAX (jit, vmap, jacfwd) and Warp (its
CPU device) equal to 1e-12 on every kernel (the humanoid knee: small kernels, one Warp module compiled once; JAX's
``fk`` checked within ``fk_j_dm``, and differentiated at the solution: the ankle's too); the C99 library and the C++17 class built strictly
with gcc/g++ and run (the ankle's round trip); the extras named when missing. (Every test robot's transmissions:
tools/transmission_targets.py; Warp on a GPU: tools/gpu_transmissions.py, not run here.)"""

from __future__ import annotations

import shutil
import subprocess
import sys

import numpy as np
import pytest

from pkm.core.transmissions.kernels import KERNELS, STATUS
from pkm.core.transmissions.targets import write_transmission
from pkm.errors import MissingDependencyError
from tests.core.transmissions.test_kernels import ankle, knee, states


def _inputs(tk, n: int) -> dict[str, list[np.ndarray]]:
    qm, q = states(tk, n, seed=4)
    rng = np.random.default_rng(5)
    warm = q + 1e-3 * rng.standard_normal(q.shape) * (np.arange(q.shape[1]) < 1)  # (a guess off the solution)
    return {"fk": [warm, qm], "ik": [warm, q[:, tk.output_q]], "maps": [q],
            "delta": [q, rng.uniform(-2, 2, (n, tk.k))], "fk_j_dm": [warm, qm]}


def test_c_jax_and_warp_agree_on_every_kernel():
    jax = pytest.importorskip("jax")
    wp = pytest.importorskip("warp")
    from pkm.core.twin.warpgen import warp_module, warp_source

    tk = knee()
    inputs = _inputs(tk, 32)
    module = warp_module([tk.looped(k) for k in KERNELS])  # (as pkm transmission writes it: one compile)
    for name, twin in (("fk", "m"), ("ik", "o")):  # (a solve holds one copy of its Newton step, in a loop)
        lines = warp_source(tk.looped(name)).count("\n")
        assert lines <= tk.step(twin).n_instructions() + tk.finish(name).n_instructions() + 3 * tk.mech.nq + 20
        assert warp_source(tk.function(name)).count("\n") > 2 * lines  # (unrolled: 8 copies)
    jitted: dict = {}
    for name, args in inputs.items():
        fun = tk.function(name)
        c = tk.run(name, *args)
        j = c if name == "fk" else jax.vmap(jitted.setdefault(name, tk.jax(name)))(*args)  # (fk: within fk_j_dm)
        ins = [wp.array(np.ascontiguousarray(a.T), dtype=wp.float64, device="cpu") for a in args]
        outs = [wp.zeros((fun.nnz_out(i), len(args[0])), dtype=wp.float64, device="cpu") for i in range(fun.n_out())]
        wp.launch(getattr(module, fun.name()), dim=len(args[0]), inputs=ins, outputs=outs, device="cpu")
        w = [o.numpy().T for o in outs]
        for i, ref in enumerate(c):
            scale = max(1.0, float(np.abs(ref).max()))
            assert np.abs(np.asarray(j[i]) - ref).max() <= 1e-12 * scale, (name, fun.name_out(i), "jax")
            assert np.abs(w[i] - ref).max() <= 1e-12 * scale, (name, fun.name_out(i), "warp")
        if name in ("fk", "ik", "fk_j_dm"):
            assert (c[KERNELS[name][1].index("status")] == 0).all()
    q, qm = inputs["maps"][0][0], inputs["fk"][1][0]  # (JAX differentiates the solve at its solution: J; and J, ΔM
    D = jax.jacfwd(lambda x: jitted["fk_j_dm"](q, x))(qm)  # move with it: central differences of the C; ik: J_inv)
    J, J_inv, _ = tk.run("maps", q)
    assert np.abs(np.asarray(D[1]).ravel() - J).max() <= 1e-12
    assert np.abs(np.asarray(jax.jacfwd(lambda x: jitted["ik"](q, x)[1])(q[tk.output_q])).ravel() - J_inv).max() <= 1e-12
    assert not np.asarray(jax.jacfwd(lambda w: jitted["fk_j_dm"](w, qm)[0])(q)).any()  # (the warm start: none)
    h = 1e-6
    up, down = tk.run("fk_j_dm", q, qm + h), tk.run("fk_j_dm", q, qm - h)
    for i in (0, 2, 3):  # (q_out, J, ΔM)
        assert np.abs(np.asarray(D[i]).ravel() - (up[i] - down[i]) / (2 * h)).max() <= 1e-8, KERNELS["fk_j_dm"][1][i]


def test_jax_differentiates_the_ankles_fk_at_its_solution():
    """``jax.jacfwd`` of the humanoid ankle's fk (two motors, rods between balls) by the implicit function theorem,
    never through the unrolled Newton (which XLA compiled for over 15 minutes): ``dqo/dqm`` is the C's ``J`` to
    1e-12; the configuration's derivative (the balls' quaternions among it) central differences of the C's fk."""
    jax = pytest.importorskip("jax")
    tk = ankle()
    qm, q = states(tk, 1, seed=6)
    D = jax.jacfwd(lambda x: tk.jax("fk")(q[0], x))(qm[0])
    assert np.abs(np.asarray(D[1]) - tk.run("maps", q[0])[0].reshape(2, 2, order="F")).max() <= 1e-12
    h, fd = 1e-6, []
    for e in np.eye(2):
        fd.append((tk.run("fk", q[0], qm[0] + h * e)[0] - tk.run("fk", q[0], qm[0] - h * e)[0]) / (2 * h))
    assert np.abs(np.asarray(D[0]) - np.array(fd).T).max() <= 1e-8
    assert not np.asarray(D[2]).any() and not np.asarray(D[3]).any()  # (status, residual: constant there)


@pytest.mark.skipif(not (shutil.which("gcc") and shutil.which("g++")), reason="needs gcc and g++")
def test_the_c_library_and_the_cpp_class_round_trip(tmp_path):
    """``gcc -std=c99 -Wall -Wextra -Werror -pedantic`` and ``g++ -std=c++17 -Wall -Wextra -Werror`` build the
    ankle's library and example; actuator positions, velocities and efforts -> joints (FK, J, J_inv^T) -> actuators
    (IK, J_inv, J^T) equal the in-process kernels' and come back to 1e-12, each cycle with one evaluation of the
    maps kernel. Beyond a stated limit (the motors ±1 rad,
    the pitch ±0.6 rad): FK of a motor at 1e6 rad (a closed configuration, 1e6 mod 2π) and IK of a pitch of 0.7 rad
    converge, ``OUTSIDE_LIMITS``, the solution written all the same, in the C as in the in-process kernels."""
    tk = ankle()
    files = write_transmission(tk, tmp_path, ["c"])
    assert set(files) == {"foot.c", "foot.h", "foot_transmission.hpp", "example.cpp", "README.md", "transmission.json"}
    subprocess.run(["gcc", "-std=c99", "-O1", "-Wall", "-Wextra", "-Werror", "-pedantic", "-c", "foot.c"],
                   cwd=tmp_path, check=True, capture_output=True)
    subprocess.run(["g++", "-std=c++17", "-O1", "-Wall", "-Wextra", "-Werror", "-o", "example", "example.cpp",
                    "foot.o", "-lm"], cwd=tmp_path, check=True, capture_output=True)
    symbols = subprocess.run(["nm", "-u", "foot.o"], cwd=tmp_path, capture_output=True, text=True).stdout
    assert not {"malloc", "calloc", "free", "printf", "fprintf"} & {line.split()[-1] for line in symbols.splitlines()}
    qm = tk.mech.actuated_q(tk.mech.q_reference) + np.array([0.12, -0.07])
    qdm, tau_m = np.array([0.3, -1.1]), np.array([2.0, -5.0])
    run = subprocess.run([str(tmp_path / "example"), *(repr(float(x)) for x in (*qm, *qdm, *tau_m))],
                         capture_output=True, text=True, check=True)
    lines = dict(line.split(" ", 1) for line in run.stdout.strip().splitlines())
    joint, back = (np.array(lines[k].split(), dtype=float) for k in ("joint", "actuator"))
    q, qo, _, _ = tk.run("fk", tk.mech.q_reference, qm)
    J, J_inv = (x.reshape(2, 2, order="F") for x in tk.run("maps", q)[:2])
    assert np.abs(joint - np.concatenate([qo, J @ qdm, J_inv.T @ tau_m])).max() <= 1e-12
    assert np.abs(back - np.concatenate([qm, qdm, tau_m])).max() <= 1e-12
    assert lines["maps"].split() == ["1", "1"]  # (a cycle's velocity and effort mapped with one maps evaluation)
    bad = subprocess.run([str(tmp_path / "example"), "nan", *["0"] * 5], capture_output=True, text=True)
    assert bad.returncode == 1 and "fk failed with status 3" in bad.stderr  # (INVALID_INPUT)
    far = subprocess.run([str(tmp_path / "example"), "1e6", *["0"] * 5], capture_output=True, text=True)
    assert far.returncode == 1 and f"fk failed with status {STATUS.index('OUTSIDE_LIMITS')}" in far.stderr

    (tmp_path / "limits.c").write_text("""#include <stdio.h>
#include "foot.h"
int main(void) {
  double q[FOOT_NQ], y[FOOT_K], qm[FOOT_K] = {1e6, 0.0}, qo[FOOT_K] = {0.7, 0.0}, ok[FOOT_K] = {0.12, -0.07};
  double sum = 0.0;
  int i, s[3];
  for (i = 0; i < FOOT_NQ; ++i) q[i] = foot_q_reference[i];
  s[0] = foot_fk(qm, q, y, NULL);
  for (i = 0; i < FOOT_NQ; ++i) sum += q[i];
  printf("%d %.17g\\n", s[0], sum);
  for (i = 0; i < FOOT_NQ; ++i) q[i] = foot_q_reference[i];
  s[1] = foot_ik(qo, q, y, NULL);
  printf("%d %.17g %.17g\\n", s[1], y[0], y[1]);
  for (i = 0; i < FOOT_NQ; ++i) q[i] = foot_q_reference[i];
  s[2] = foot_fk(ok, q, y, NULL);
  printf("%d\\n", s[2]);
  return 0;
}
""")
    subprocess.run(["gcc", "-std=c99", "-O1", "-Wall", "-Wextra", "-Werror", "-pedantic", "-o", "limits", "limits.c",
                    "foot.o", "-lm"], cwd=tmp_path, check=True, capture_output=True)
    lines = subprocess.run([str(tmp_path / "limits")], capture_output=True, text=True, check=True).stdout.split("\n")
    outside = STATUS.index("OUTSIDE_LIMITS")
    fk, ik, ok = (line.split() for line in lines[:3])
    ref = tk.mech.q_reference
    q_fk, _, status, _ = tk.run("fk", ref, np.array([1e6, 0.0]))
    assert int(fk[0]) == outside == int(status[0]) and abs(float(fk[1]) - q_fk.sum()) <= 1e-6  # (1e6 written)
    _, qm_ik, status, _ = tk.run("ik", ref, np.array([0.7, 0.0]))
    assert int(ik[0]) == outside == int(status[0])
    assert np.abs(np.array(ik[1:], dtype=float) - qm_ik).max() <= 1e-12
    assert int(ok[0]) == 0


@pytest.mark.parametrize("target, extra", [("jax", "jax"), ("warp", "warp")])
def test_a_missing_extra_is_named(tmp_path, monkeypatch, target, extra):
    monkeypatch.setitem(sys.modules, extra, None)
    with pytest.raises(MissingDependencyError, match=rf'pkm-robotics\[{extra}\]'):
        write_transmission(knee(), tmp_path, ["c", target])
    assert not any(tmp_path.iterdir())  # (checked before anything is written)
