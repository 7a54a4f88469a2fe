"""A singularity check of your own design: a planar 3-RPR over its workspace.

For platform positions on a grid (orientation fixed), solve the inverse kinematics from the neighbouring
solution and grade the configuration: distance to a direct singularity (locked legs, the platform can still
move) and to an inverse one (the platform held, a leg can still move), with the 'near' band. Change the
geometry in examples/rpr3/rpr3.urdf (or write your own URDF + spec) and run it again.
Run it from anywhere: python examples/singularity_check.py
"""

from pathlib import Path

import numpy as np

import pkm

rpr = pkm.load(Path(__file__).resolve().parent / "rpr3" / "rpr3.closures.toml")
home = pkm.task_values(rpr, rpr.q_reference)
print(rpr, "\nhome:", {k: round(v, 4) for k, v in home.items()})

xs = np.linspace(-0.3, 0.3, 9)
worst = (np.inf, None)
print("   x \\ y  " + " ".join(f"{y:+.2f}" for y in xs))
for x in xs:
    row, q = [], rpr.q_reference
    for y in xs:
        try:
            q = pkm.solve_ik(rpr, {"x": x, "y": y}, q).q
        except pkm.errors.PkmError:
            row.append("  -- ")  # out of reach (a leg too short or too long)
            continue
        d = pkm.diagnose(rpr, q)
        row.append(" near" if d.near else f"{d.direct_distance:5.3f}")
        if d.direct_distance < worst[0]:
            worst = (d.direct_distance, (x, y))
    print(f"  {x:+.2f}   " + " ".join(row))
x, y = worst[1]
print(f"closest to a direct singularity: distance {worst[0]:.3g} at x = {x:+.3f} m, y = {y:+.3f} m")
