"""Import a MuJoCo model: a four-bar whose loop is an <equality><connect> and whose crank is a <motor>.

pkm reads the loop, the actuator, the joint ranges (degrees in MJCF) and the site from the file, assembles
the mechanism, and answers the generic questions; `pkm.save` writes it as a pkm closure spec + URDF.
Run it from anywhere: python examples/mjcf_import.py
"""

import tempfile
from pathlib import Path

import numpy as np
import pinocchio as pin

import pkm

HERE = Path(__file__).resolve().parent
mech = pkm.load(HERE / "mjcf_fourbar" / "fourbar.xml")
print(mech)
print("loops from the file:", [(c.name, c.type) for c in mech.spec.closures])
print("actuated (from <actuator>):", mech.actuated_names, " limits [rad]:", mech.limits)

# the coupler point's path over a turn of the crank, tracking one assembly mode
crank = np.linspace(-np.pi, np.pi, 73)
path = pkm.follow_actuators(mech, crank, np.full(73, 2.0), efforts=True)  # 2 rad/s, gravity acts
print("jumps along the turn:", path.jumps or "none")
d = mech.data
points = []
for q in path.q:
    pin.framesForwardKinematics(mech.model, d, q)
    points.append(d.oMf[mech.frame_id("coupler_point")].translation.copy())
points = np.array(points)
print(f"coupler point: x in [{points[:, 0].min():.3f}, {points[:, 0].max():.3f}] m, "
      f"z in [{points[:, 2].min():.3f}, {points[:, 2].max():.3f}] m")
print(f"crank torque at 2 rad/s: {path.efforts.min():.3f} .. {path.efforts.max():.3f} N m")

with tempfile.TemporaryDirectory() as tmp:
    spec = pkm.save(mech, Path(tmp) / "fourbar.closures.toml")
    again = pkm.load(spec)
    print("saved as", spec.name, "and loaded back:", again)
