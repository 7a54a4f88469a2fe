"""Import a gripper as the public model collections write it: two four-bar fingers (<equality><connect>), their
driver joints tied by an <equality><joint> coupling, and one actuator pulling a <tendon><fixed> on both drivers.

pkm reads the coupling as a mimic joint (the right driver follows the left) and the tendon actuator as the one
joint it moves once the coupling is substituted; `mech.notes` says so. Closing the gripper is one input.
Run it from anywhere: python examples/gripper.py
"""

from pathlib import Path

import numpy as np
import pinocchio as pin

import pkm

HERE = Path(__file__).resolve().parent
mech = pkm.load(HERE / "mjcf_gripper" / "gripper.xml")
print(mech)
print("what the reader interpreted:", *mech.notes, sep="\n  ")
print(pkm.diagnose(mech, mech.q_reference))  # one sentence: the class, and any actuator that does not fit

# the tendon from open to closed: both pads move towards each other, mirror images of each other
d = mech.data
for grip in np.linspace(0.0, 0.6, 4):  # the driver angle [rad]
    q = pkm.close_loops(mech, [grip]).q
    pin.framesForwardKinematics(mech.model, d, q)
    right, left = (d.oMf[mech.frame_id(f"{side}_pad")].translation for side in ("right", "left"))
    print(f"driver {grip:.2f} rad: pads {right[0] - left[0]:.4f} m apart, right pad at x {right[0]:+.4f} m, left at "
          f"{left[0]:+.4f} m (the right driver mimics the left: the fingers stay mirror images)")
