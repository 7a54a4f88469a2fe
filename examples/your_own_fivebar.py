"""Your own five-bar from a plain URDF: the tree in a URDF file (here the one of examples/gepetto_fivebar), the loop
and what drives it in a closure spec you write beside it, then every generic answer.

`pkm spec init fivebar.urdf` writes a commented spec to start from; this script writes the filled-in one.
Run from anywhere: ``python examples/your_own_fivebar.py``.
"""

from pathlib import Path
from tempfile import TemporaryDirectory

import numpy as np

import pkm

SPEC = """\
format = "pkm.closures/1"
mechanism = "my_fivebar"
urdf = "fivebar.urdf"
end_effector = "closedloop1_A"   # the tip of distal link 1
actuated = ["mot1", "mot2"]

[task]
components = ["x", "y"]

[[closure]]                      # the two distal links meet at the tip: a revolute, in the plane a point
name = "tip"
type = "point"
frame_a = "closedloop1_A"
frame_b = "closedloop1_B"
"""

with TemporaryDirectory() as tmp:
    folder = Path(tmp)
    (folder / "fivebar.urdf").write_text((Path(__file__).resolve().parent / "gepetto_fivebar" / "robot.urdf").read_text())
    (folder / "fivebar.closures.toml").write_text(SPEC)
    mech = pkm.load(folder / "fivebar.closures.toml")  # no [reference]: pkm assembles one
    print(mech)
    home = pkm.task_values(mech, mech.q_reference)
    print("assembled at", {k: round(v, 4) for k, v in home.items()}, "m")

    ik = pkm.solve_ik(mech, {"x": home["x"] + 0.01, "y": f"{home['y'] * 1000 + 5:.3f}mm"})  # 1 cm right, 5 mm up
    print("motors for it:", {n: round(float(v), 6) for n, v in zip(mech.actuated_names, mech.actuated_q(ik.q))}, "rad")
    fk = pkm.close_loops(mech, mech.actuated_q(ik.q))
    print("FK back:", {k: round(v, 9) for k, v in pkm.task_values(mech, fk.q).items()}, f"m (residual {fk.residual:.1e})")

    J = pkm.forward_jacobian(mech, ik.q)
    d = pkm.diagnose(mech, ik.q)
    print(f"forward Jacobian (m/rad):\n{np.round(J, 4)}\n{d.classification}; distance to a direct singularity "
          f"{d.direct_distance:.3g}, to an inverse one {d.inverse_distance:.3g}")

    try:
        pkm.solve_ik(mech, {"x": home["x"] + 5.0})  # 5 m away: out of reach
    except pkm.errors.UnreachableError as exc:
        print("5 m away:", exc)

    page = folder / "fivebar.html"
    from pkm import viz

    page.write_text(viz.snapshot_html(mech, ik.q))
    print(f"preview: {page.stat().st_size // 1024} kB of self-contained HTML (pkm preview fivebar.closures.toml "
          "--html FILE does the same)")
