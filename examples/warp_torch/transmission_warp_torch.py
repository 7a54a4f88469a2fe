"""The humanoid ankle's transmission kernel on PyTorch tensors through Warp, without a copy (wp.from_torch /
wp.to_torch): a batch of simulated robots' motor positions -> ankle pitch/roll, J and ΔM, on the GPU where there is
one.

NOT run by the tests (tests/test_examples.py runs examples/*.py only, not this folder): PyTorch from the package
index pulls several GB of CUDA libraries, so it is not in pkm's extras nor installed where pkm is tested. Needs
``pip install "pkm-robotics[warp]" torch``; run from the checkout:
``python examples/warp_torch/transmission_warp_torch.py``.

Layout: pkm's Warp kernels take structure-of-arrays float64 arrays ``(size, n)``: one row per entry, one column per
robot. A sample-major tensor ``(n, size)`` (PyTorch's usual batch layout) is made so by ``.T.contiguous()`` (one copy
on the device); keep the tensors ``(size, n)`` to avoid even that.
"""

from pathlib import Path

import numpy as np
import torch
import warp as wp

import pkm
from pkm.core.transmissions.kernels import TransmissionKernels

ANKLE = Path(__file__).resolve().parents[1] / "humanoid_ankle" / "ankle.closures.toml"

mech = pkm.load(ANKLE)
tk = TransmissionKernels(mech, ("ankle_pitch", "ankle_roll"), iterations=5)  # (5: from the reference, ±0.25 rad)
fun = tk.function("fk_j_dm")  # (q, qm) -> (q_out, qo, J, dM, status)
kernel = tk.warp("fk_j_dm")

device = "cuda" if torch.cuda.is_available() else "cpu"
n = 4096
qm0 = torch.tensor(mech.actuated_q(mech.q_reference), dtype=torch.float64, device=device)
qm = (qm0[:, None] + 0.25 * (2 * torch.rand(2, n, dtype=torch.float64, device=device) - 1)).contiguous()  # (2, n)
q = torch.tensor(mech.q_reference, dtype=torch.float64, device=device)[:, None].repeat(1, n).contiguous()  # warm start
outs = [torch.zeros(fun.nnz_out(j), n, dtype=torch.float64, device=device) for j in range(fun.n_out())]

wp_device = "cuda:0" if device == "cuda" else "cpu"
wp.launch(kernel, dim=n, inputs=[wp.from_torch(q), wp.from_torch(qm)],  # (zero-copy views of the tensors)
          outputs=[wp.from_torch(o) for o in outs], device=wp_device)
wp.synchronize_device(wp_device)
q_out, qo, J, dM, status = outs  # torch tensors, written in place by the kernel
# (the other way, wp.to_torch(array) is a tensor view of a Warp array: no copy either)

print(f"{n} samples on {device}: statuses {torch.unique(status).tolist()} (0: converged), "
      f"pitch/roll in [{qo.min().item():.3f}, {qo.max().item():.3f}] rad")
# check a sample against pkm's own route
k = 7
closed = pkm.close_loops(mech, qm[:, k].cpu().numpy(), mech.q_reference).q
print("largest difference to pkm.close_loops:", float(np.abs(closed[tk.output_q] - qo[:, k].cpu().numpy()).max()))
print("J (column-major) at sample 7:", J[:, k].cpu().numpy(), "ΔM:", dM[:, k].cpu().numpy())
