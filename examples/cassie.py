"""Load a model an installed package ships, by name: Agility Robotics' Cassie biped from example-robot-data.

The SDF file is read where the package installed it: its loops (each leg's achilles and plantar rods) and
gearboxes (each motor's rotor, a mimic joint of its output) are the file's own; the ten motors come from the
small closure spec pkm ships for it (pkm.core.formats.packages). Run it from anywhere: python examples/cassie.py
"""

import numpy as np
import pinocchio as pin

import pkm
from pkm.core.formats.packages import PACKAGE_MODELS

print("models of installed packages:", ", ".join(PACKAGE_MODELS))
cassie = pkm.load("example-robot-data:cassie")
print(cassie)
diag = pkm.diagnose(cassie, cassie.q_reference)
print(f"mobility {diag.mobility} for {cassie.na} motors ({diag.summary})")

# the left knee bent by 0.2 rad: the achilles loop turns the tarsus, the heel spring takes up the rest
qa = cassie.actuated_q(cassie.q_reference)
qa[cassie.actuated_names.index("left-knee-op")] -= 0.2
q = pkm.close_loops(cassie, qa).q
joints = cassie.q_to_dict(q)
print(f"knee -0.2 rad: tarsus {float(joints['left-shin-tarsus-joint']):+.3f} rad, "
      f"heel spring {float(joints['left-tarsus-spring-joint']):+.3f} rad")
d = cassie.data
pin.framesForwardKinematics(cassie.model, d, q)
print("left foot at", np.round(d.oMf[cassie.frame_id("left-foot")].translation, 4), "m")

# each rotor turns -1/ratio times its output (the knee's ratio is 0.0625): at 1 rad/s of the knee, the rotor
# spins at -16 rad/s and its inertia counts 256 times in the knee's entry of the mass matrix
v = np.zeros(cassie.nv)
v[cassie.joints["left-knee-op"].idx_v] = 1.0
pin.forwardKinematics(cassie.model, d, q, v)
rotor = cassie.model.getJointId("left-knee-ip")
M = pin.crba(cassie.model, d, q)
knee = cassie.joints["left-knee-op"].idx_v
print(f"left knee rotor at {np.linalg.norm(d.v[rotor].angular):.1f} rad/s;"
      f" mass matrix at the knee {M[knee, knee]:.4f} kg m^2, of which the rotor "
      f"{cassie.model.inertias[rotor].vtiv(d.v[rotor]):.4f}")
