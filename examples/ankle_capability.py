"""A humanoid's parallel ankle under its motors' limits: the joint torques it can hold, pose by pose.

Two motors on the shank push rods down to the foot (``examples/ankle``). Hand-written ankle code caps pitch and
roll with a box (``MAX_PITCH_DEG 35``) and assumes the torques a box too; the torque set is a polygon that turns and
stretches with the pose. This script gives each motor a continuous limit of 30 N m and 12 rad/s (a typical
humanoid ankle drive: the values are this example's, not the file's), then asks pkm for the ankle's capability:

* at the neutral pose: the largest pitch and roll torque each way, the largest torque in every direction, the joint
  speeds and accelerations from rest;
* over a pitch-roll grid: the largest pure-pitch and pure-roll torques, which a box would hold constant;
* the feasible pitch-roll region with the motors' travel at ±0.7 rad: a polygon, each vertex with the limit that
  stops it, against the largest box inside it;
* the rotors' inertia as the ankle joints feel it, ``J⁻ᵀ diag(I_r k²) J⁻¹`` (rotor 3.3e-5 kg m^2 geared 50:1),
  against the constant "armature" that hand-written controllers put on the joints' diagonal.
"""

from pathlib import Path

import numpy as np

import pkm
from pkm.core.analysis.capability import capability_map

ANKLE = Path(__file__).resolve().parent / "ankle" / "ankle.closures.toml"

ankle = pkm.load(ANKLE)
ankle = pkm.with_actuators(ankle, {name: {"effort_limit": 30.0, "velocity_limit": 12.0, "rotor_inertia": 3.3e-5,
                                          "gear_ratio": 50.0} for name in ankle.actuated_names})
reflected = 3.3e-5 * 50.0**2  # [kg m^2] on each motor's axis

print("at the neutral pose:")
for kind in ("wrench", "twist", "acceleration"):
    c = pkm.capability(ankle, ankle.q_reference, kind)
    units = dict(zip(c.polytope.axes, c.polytope.units))
    along = ", ".join(f"{axis} +{plus:.4g}/-{minus:.4g} {units[axis]}" for axis, (plus, minus) in c.along.items())
    iso = ", ".join(f"{v:.4g} {u}" for u, v in c.isotropic.items())
    print(f"  {kind:12s} {along}; every direction: {iso}")

pitch = np.radians(np.linspace(-30.0, 30.0, 7))
roll = np.radians(np.linspace(-15.0, 15.0, 5))
cm = capability_map(ankle, {"ankle_pitch": pitch, "ankle_roll": roll})
plus_pitch, _ = cm.along["ankle_pitch"]
plus_roll, _ = cm.along["ankle_roll"]
print(f"over pitch -30..30 deg x roll -15..15 deg ({int(cm.reachable.sum())} of {cm.reachable.size} poses "
      "solved):")
print(f"  largest pure-pitch torque: {np.nanmin(plus_pitch):.4g} to {np.nanmax(plus_pitch):.4g} N m")
print(f"  largest pure-roll torque:  {np.nanmin(plus_roll):.4g} to {np.nanmax(plus_roll):.4g} N m")
print("  pitch [deg] ->  " + "  ".join(f"{np.degrees(p):6.1f}" for p in pitch))
for j, r in enumerate(roll):
    print(f"  roll {np.degrees(r):5.1f}:  +pitch " + "  ".join(f"{v:6.1f}" for v in plus_pitch[j]))
try:  # (the figures: pip install "pkm[figures]")
    import matplotlib  # noqa: F401
except ImportError:
    pass
else:
    for axis in ("ankle_pitch", "ankle_roll"):
        print("  figure:", cm.figure(f"ankle_{axis.split('_')[1]}_torque.png", along=axis))

print(f"the rotors' inertia at the ankle joints (each motor {reflected:.4g} kg m^2 on its own axis):")
neutral = None
for p_deg, r_deg in ((0.0, 0.0), (30.0, 0.0), (-30.0, 0.0), (0.0, 15.0), (30.0, 15.0)):
    q = pkm.solve_ik(ankle, {"ankle_pitch": np.radians(p_deg), "ankle_roll": np.radians(r_deg)}).q
    J = pkm.forward_jacobian(ankle, q)  # (joint rates from motor rates)
    Jinv = np.linalg.inv(J)
    rotors = Jinv.T @ (reflected * np.eye(ankle.na)) @ Jinv
    neutral = rotors if neutral is None else neutral
    print(f"  pitch {p_deg:5.1f} deg, roll {r_deg:5.1f} deg: pitch {rotors[0, 0]:.4g}, roll {rotors[1, 1]:.4g}, "
          f"coupling {rotors[0, 1]:.3g} kg m^2 ({100 * (rotors[0, 0] / neutral[0, 0] - 1):+.0f} % on pitch)")

region = pkm.feasible_region(ankle, ("ankle_pitch", "ankle_roll"), directions=16,
                             limits={name: (-0.7, 0.7) for name in ankle.actuated_names})
half = np.degrees(region.box())
print(f"the feasible pitch-roll region (motors within ±0.7 rad, singularity distance >= {region.singularity:g}): "
      f"{region.area:.3g} rad^2, the largest box inside it ±{half[0]:.1f} deg pitch x ±{half[1]:.1f} deg roll")
for (p_, r_), why in zip(np.degrees(region.vertices), region.binding):
    print(f"  pitch {p_:6.1f} deg, roll {r_:6.1f} deg: {why}")
