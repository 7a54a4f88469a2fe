"""A trajectory's actuator efforts: the two motors of a parallel ankle driving a pitch-roll motion.

The ankle (examples/ankle: URDF + pkm spec) has no end effector: its task is the two ankle angles. Its rods
spin idle between ball joints; pkm lets the dynamics settle those spins. `pkm.follow_task` solves the
inverse kinematics sample by sample (one working mode), then the motor rates, accelerations and torques.
Run it from anywhere: python examples/trajectory_efforts.py
"""

from pathlib import Path

import numpy as np

import pkm

ankle = pkm.load(Path(__file__).resolve().parent / "ankle" / "ankle.closures.toml")
print(ankle)
print("idle motions at the reference:", pkm.diagnose(ankle, ankle.q_reference).idle_joints)

# a 1 s gait-like motion: pitch 0.3 rad at 2 Hz, roll 0.1 rad at 1 Hz (angles, so the task is in rad)
t = np.linspace(0.0, 1.0, 101)
w1, w2 = 2 * np.pi * 2, 2 * np.pi * 1
y = np.column_stack([0.3 * np.sin(w1 * t), 0.1 * np.sin(w2 * t)])
yd = np.column_stack([0.3 * w1 * np.cos(w1 * t), 0.1 * w2 * np.cos(w2 * t)])
ydd = np.column_stack([-0.3 * w1**2 * np.sin(w1 * t), -0.1 * w2**2 * np.sin(w2 * t)])
path = pkm.follow_task(ankle, y, yd, ydd)
print("jumps:", path.jumps or "none", " units:", path.units["actuated"])

power = np.sum(path.efforts * path.actuated_velocity, axis=1)
for k, name in enumerate(ankle.actuated_names):
    print(f"{name}: angle {path.actuated[:, k].min():+.3f}..{path.actuated[:, k].max():+.3f} rad, "
          f"peak torque {np.abs(path.efforts[:, k]).max():.3f} N m, peak speed "
          f"{np.abs(path.actuated_velocity[:, k]).max():.2f} rad/s")
print(f"peak mechanical power {np.abs(power).max():.3f} W")
