"""The humanoid ankle's transmission kernel ``fk_j_dm`` (FK + J + ΔM) on a GPU: Warp on ``"cuda"`` against a
straight-line CUDA kernel of the same instructions, and the CPU's C vector batch, in one run.

For the device machine (an NVIDIA GPU, CUDA's ``nvcc`` on the PATH); never run by the tests. Written in a session
without a GPU: it was checked there only as far as a machine without one allows (the CUDA source compiles with
``nvcc``; the Warp path runs on ``"cpu"`` with ``--device cpu``), NOT timed on a GPU.

* ``warp``: :func:`pkm.core.twin.warpgen.warp_kernel` of the kernel, one thread a sample, structure-of-arrays
  ``(size, n)`` float64 arrays resident on the device, launched ``--repeat`` times (best kept, synchronised);
* ``cuda``: the same SX instruction list written as one ``__global__`` function (the C99 emitter's expressions,
  :mod:`pkm.core.export.emit`, each work variable a register), the same layout and block size (256), compiled with
  ``nvcc -O3`` and timed with CUDA events;
* ``c_vector``: the CPU's vector batch (:mod:`pkm.core.twin.simd`), one core, for scale.

Outputs are compared with the CPU's C (1e-12 expected in double precision). Goal (issue 44): Warp within 2x of the
straight-line CUDA kernel.

Usage: ``python tools/gpu_transmissions.py [-n 1000000] [--repeat 20] [--iterations 3] [--json FILE]``.
"""

from __future__ import annotations

import argparse
import ctypes
import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

import pkm  # noqa: E402
from pkm.bench.transmissions import MECHANISMS, samples  # noqa: E402
from pkm.core.export.emit import _C, c_constant  # noqa: E402
from pkm.core.transmissions.kernels import TransmissionKernels  # noqa: E402
from pkm.core.twin.codegen import instructions  # noqa: E402

BLOCK = 256


def cuda_source(fun) -> str:
    """``fun`` as a straight-line CUDA kernel (one thread a sample, structure-of-arrays) and a host driver
    ``run(n, ins, outs, repeat, *ms)`` that copies in, launches ``repeat`` times (the best in ``ms``) and copies out."""
    ins = [f"const double* __restrict__ {fun.name_in(j)}" for j in range(fun.n_in())]
    outs = [f"double* __restrict__ {fun.name_out(j)}" for j in range(fun.n_out())]
    body: list[str] = []
    used: set[int] = set()
    for kind, value, i, o in instructions(fun, _C, "CUDA"):
        if kind == "output":
            body.append(f"  {fun.name_out(o[0])}[(size_t) {o[1]} * n + t] = w{i[0]};")
            continue
        if kind == "input":
            body.append(f"  w{o[0]} = {fun.name_in(i[0])}[(size_t) {i[1]} * n + t];")
        elif kind == "const":
            body.append(f"  w{o[0]} = {c_constant(float(value))};")  # type: ignore[arg-type]
        else:
            body.append(f"  w{o[0]} = {value};")
        used.add(o[0])
    order = sorted(used)
    decl = ["  double " + ", ".join(f"w{k}" for k in order[a:a + 16]) + ";" for a in range(0, len(order), 16)]
    nin, nout = fun.n_in(), fun.n_out()
    isz = ", ".join(str(fun.nnz_in(j)) for j in range(nin))
    osz = ", ".join(str(fun.nnz_out(j)) for j in range(nout))
    args = ", ".join([f"d_in[{j}]" for j in range(nin)] + [f"d_out[{j}]" for j in range(nout)])
    return f"""#include <cuda_runtime.h>
#include <math.h>
#include <stddef.h>

extern "C" __global__ void kernel(int n, {', '.join(ins + outs)}) {{
  const int t = blockIdx.x * blockDim.x + threadIdx.x;
  if (t >= n) return;
{chr(10).join(decl)}
{chr(10).join(body)}
}}

extern "C" int run(int n, const double** in, double** out, int repeat, float* ms) {{
  const int isz[] = {{{isz}}}, osz[] = {{{osz}}};
  double* d_in[{nin}]; double* d_out[{nout}];
  for (int j = 0; j < {nin}; ++j) {{
    if (cudaMalloc(&d_in[j], sizeof(double) * isz[j] * n)) return 1;
    cudaMemcpy(d_in[j], in[j], sizeof(double) * isz[j] * n, cudaMemcpyHostToDevice);
  }}
  for (int j = 0; j < {nout}; ++j) if (cudaMalloc(&d_out[j], sizeof(double) * osz[j] * n)) return 1;
  cudaEvent_t a, b; cudaEventCreate(&a); cudaEventCreate(&b);
  const int blocks = (n + {BLOCK} - 1) / {BLOCK};
  kernel<<<blocks, {BLOCK}>>>(n, {args});
  cudaDeviceSynchronize();
  *ms = 1e30f;
  for (int r = 0; r < repeat; ++r) {{
    float t;
    cudaEventRecord(a);
    kernel<<<blocks, {BLOCK}>>>(n, {args});
    cudaEventRecord(b); cudaEventSynchronize(b);
    cudaEventElapsedTime(&t, a, b);
    if (t < *ms) *ms = t;
  }}
  int failed = cudaGetLastError() != cudaSuccess;
  for (int j = 0; j < {nout}; ++j) cudaMemcpy(out[j], d_out[j], sizeof(double) * osz[j] * n, cudaMemcpyDeviceToHost);
  for (int j = 0; j < {nin}; ++j) cudaFree(d_in[j]);
  for (int j = 0; j < {nout}; ++j) cudaFree(d_out[j]);
  return failed;
}}
"""


def cuda_run(fun, arrays: list[np.ndarray], repeat: int, folder: Path) -> tuple[float, list[np.ndarray]]:
    """Build :func:`cuda_source` with nvcc and run it: ``(best ms, outputs sample-major)``."""
    cu = folder / "kernel.cu"
    cu.write_text(cuda_source(fun))
    lib = folder / "kernel.so"
    for arch in (["-arch=native"], []):
        done = subprocess.run(["nvcc", "-O3", *arch, "-shared", "-Xcompiler", "-fPIC", "-o", str(lib), str(cu)],
                              capture_output=True, text=True, check=False)
        if done.returncode == 0:
            break
    else:
        raise RuntimeError(f"nvcc failed: {done.stderr[-2000:]}")
    so = ctypes.CDLL(str(lib))
    n = arrays[0].shape[0]
    ins = [np.ascontiguousarray(a.T) for a in arrays]
    outs = [np.zeros((fun.nnz_out(j), n)) for j in range(fun.n_out())]
    P = ctypes.POINTER(ctypes.c_double)
    in_p = (P * len(ins))(*[a.ctypes.data_as(P) for a in ins])
    out_p = (P * len(outs))(*[a.ctypes.data_as(P) for a in outs])
    ms = ctypes.c_float()
    if so.run(ctypes.c_int(n), in_p, out_p, ctypes.c_int(repeat), ctypes.byref(ms)):
        raise RuntimeError("the CUDA run failed")
    return ms.value, [o.T for o in outs]


def warp_run(tk, fun, arrays: list[np.ndarray], repeat: int, device: str) -> tuple[float, float, list[np.ndarray]]:
    """Warp on ``device``: ``(compile s, best ms, outputs sample-major)``."""
    import warp as wp

    wp.config.log_level = wp.LOG_WARNING
    t0 = time.perf_counter()
    kern = tk.warp("fk_j_dm")
    n = arrays[0].shape[0]
    ins = [wp.array(np.ascontiguousarray(a.T), dtype=wp.float64, device=device) for a in arrays]
    outs = [wp.zeros((fun.nnz_out(j), n), dtype=wp.float64, device=device) for j in range(fun.n_out())]
    wp.launch(kern, dim=n, inputs=ins, outputs=outs, device=device, block_dim=BLOCK)
    wp.synchronize_device(device)
    compile_s = time.perf_counter() - t0
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        wp.launch(kern, dim=n, inputs=ins, outputs=outs, device=device, block_dim=BLOCK)
        wp.synchronize_device(device)
        best = min(best, time.perf_counter() - t0)
    return compile_s, best * 1e3, [o.numpy().T for o in outs]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("-n", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=20)
    ap.add_argument("--iterations", type=int, default=3)
    ap.add_argument("--device", default="cuda", help="Warp's device (default cuda; cpu to check the script)")
    ap.add_argument("--json", type=Path, help="write the results here too")
    args = ap.parse_args()
    [t] = pkm.transmissions(pkm.load(ROOT / MECHANISMS["ankle"]))
    tk = TransmissionKernels.of(t, iterations=args.iterations)
    fun = tk.function("fk_j_dm")
    Q0, QM = samples(tk, args.n)
    kernel = tk.kernel("fk_j_dm")
    kernel(Q0[:300], QM[:300])
    t0 = time.perf_counter()
    ref = kernel(Q0, QM)
    out: dict = {"mechanism": "ankle", "kernel": "fk_j_dm", "instructions": fun.n_instructions(),
                 "iterations": tk.iterations, "samples": args.n, "block": BLOCK,
                 "ns_per_sample": {"c_vector_cpu_all_cores": (time.perf_counter() - t0) / args.n * 1e9},
                 "largest_difference": {}, "status_counts": {int(s): int(c) for s, c in
                                                             zip(*np.unique(ref[-1], return_counts=True))}}
    compile_s, ms, w = warp_run(tk, fun, [Q0, QM], args.repeat, args.device)
    out["ns_per_sample"][f"warp_{args.device}"] = ms * 1e6 / args.n
    out["warp_compile_s"] = compile_s
    out["largest_difference"]["warp"] = max(float(np.abs(a - b).max()) for a, b in zip(w, ref))
    if args.device.startswith("cuda") and shutil.which("nvcc"):
        with tempfile.TemporaryDirectory() as tmp:
            ms_c, c = cuda_run(fun, [Q0, QM], args.repeat, Path(tmp))
        out["ns_per_sample"]["cuda_straight_line"] = ms_c * 1e6 / args.n
        out["largest_difference"]["cuda"] = max(float(np.abs(a - b).max()) for a, b in zip(c, ref))
        out["ratio_warp_to_cuda"] = ms / ms_c
        out["goal"] = "ratio_warp_to_cuda <= 2"
    else:
        out["cuda_straight_line"] = "skipped: needs a cuda device and nvcc"
    text = json.dumps(out, indent=2)
    print(text)
    if args.json:
        args.json.write_text(text + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
