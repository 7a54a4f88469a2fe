"""A humanoid's parallel ankle and four-bar knee, from the files such robots come in, under their motors' limits.

The ankle (``humanoid_ankle/ankle.xml``) is MJCF as legged-robot teams ship it: two motors on the shank with their
rotors' inertia as ``armature`` and their torque limits as ``ctrlrange``, cranks and rods to ball joints on the heel,
the loops as ``<equality><connect>``; a four-line spec adds that pitch and roll are the outputs and the motors'
speed limit. The knee (``humanoid_knee``) is URDF + spec: a motor high on the thigh drives the shank through a
four-bar. Hand-written ankle code caps pitch and roll with a box (``MAX_PITCH_DEG 35``), converts torques with a
Jacobian it derived once, and puts a constant "2x armature" on the joints' diagonal; pkm answers, for any such file:

* the actuator <-> joint maps and their mode id (the exported C's: 0 is the assembly the file was drawn in);
* the feasible pitch-roll region (every leg closes within motor and joint limits, 1e-2 from any singularity) as a
  polygon, each vertex naming what stops it, against the largest box inside it;
* the joint torques the motors can hold (exact polygons) and their largest pure-pitch and pure-roll values over the
  region; the joint speeds the motors' speed limit allows;
* the rotors' inertia as the joints feel it, ``J⁻ᵀ diag(armature) J⁻¹``, against the constant "2x armature";
* for the knee, the motor-to-knee ratio, the largest knee torque and speed, and the reflected inertia over flexion;
* the ankle's maps as a C library a controller links (``pkm export c``), when a C compiler is present.

Figures go to ``humanoid_figures/`` (or the folder given as the first argument) when matplotlib is installed.
"""

import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

import pkm
from pkm.core.analysis.capability import capability_map

HERE = Path(__file__).resolve().parent
OUT = Path(sys.argv[1] if len(sys.argv) > 1 else "humanoid_figures")
ankle = pkm.load(HERE / "humanoid_ankle" / "ankle.closures.toml")
knee = pkm.load(HERE / "humanoid_knee" / "knee.closures.toml")
AXES = ("ankle_pitch", "ankle_roll")
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:  # (the figures: pip install "pkm-robotics[figures]")
    plt = None
else:
    OUT.mkdir(parents=True, exist_ok=True)


def reflected(mech, q):
    """The motors' armature as the task joints feel it: ``J⁻ᵀ diag(armature) J⁻¹`` [kg m^2]."""
    K = pkm.inverse_jacobian(mech, q)  # (motor rates per joint rate)
    return K.T @ np.diag([a.armature + a.rotor_inertia * a.gear_ratio ** 2 for a in mech.actuators]) @ K


# ------------------------------------------------------------------ the ankle
print(ankle)
print("  from the MJCF: motors", ankle.actuated_names, "limits", {k: v for k, v in ankle.limits.items()},
      "effort limits", [a.effort_limit for a in ankle.actuators], "N m")
region = pkm.feasible_region(ankle, AXES, directions=24, singularity=1e-2)
half = region.box()
print(f"feasible pitch-roll region: {region.area:.3f} rad^2; the largest box inside it ±{np.degrees(half[0]):.1f} deg "
      f"pitch x ±{np.degrees(half[1]):.1f} deg roll ({4 * half[0] * half[1]:.3f} rad^2); what stops it:")
for (p, r), why in zip(np.degrees(region.vertices[::3]), region.binding[::3]):
    print(f"  pitch {p:6.1f} deg, roll {r:6.1f} deg: {why}")

c = pkm.capability(ankle, ankle.q_reference, "wrench")
print("joint torques at neutral: " + ", ".join(f"{a} +{p:.1f}/-{m:.1f} N m" for a, (p, m) in c.along.items())
      + f"; in every direction {c.isotropic['N m']:.1f} N m")
pitch = np.linspace(region.vertices[:, 0].min(), region.vertices[:, 0].max(), 13)
roll = np.linspace(region.vertices[:, 1].min(), region.vertices[:, 1].max(), 9)
torques = capability_map(ankle, {AXES[0]: pitch, AXES[1]: roll})
speeds = capability_map(ankle, {AXES[0]: pitch, AXES[1]: roll}, kind="twist")
for name, cm, unit in (("torque", torques, "N m"), ("speed", speeds, "rad/s")):
    for axis in AXES:
        plus = np.where(cm.reachable, cm.along[axis][0], np.nan)
        print(f"  largest pure-{axis.split('_')[1]} {name} over the grid: {np.nanmin(plus):.3g} to "
              f"{np.nanmax(plus):.3g} {unit}")

neutral = reflected(ankle, ankle.q_reference)
armature = ankle.actuators[0].armature
print(f"reflected rotor inertia at neutral: pitch {neutral[0, 0]:.4f} kg m^2 (= {neutral[0, 0] / armature:.2f} x one "
      f"motor's {armature} armature: the '2x armature' rule holds here), roll {neutral[1, 1]:.4f}")
sweep = np.linspace(-0.55, 0.55, 23)
q, inertia = ankle.q_reference, []
for p in sweep:
    q = pkm.solve_ik(ankle, [p, 0.0], q).q
    inertia.append(np.diag(reflected(ankle, q)))
inertia = np.array(inertia)
print(f"  over pitch ±0.55 rad: pitch {inertia[:, 0].min():.4f} to {inertia[:, 0].max():.4f} kg m^2 "
      f"({100 * (inertia[:, 0].min() / (2 * armature) - 1):+.0f} % to {100 * (inertia[:, 0].max() / (2 * armature) - 1):+.0f}"
      " % of 2x armature)")

# ------------------------------------------------------------------ the knee
print(knee)
flexion = np.linspace(0.0, 1.5, 31)
q, rows = knee.q_reference, []
for k in flexion:
    q = pkm.solve_ik(knee, [k], q).q
    J = pkm.forward_jacobian(knee, q)[0, 0]  # knee rate per motor rate
    w = pkm.capability(knee, q, "wrench").along["knee"]
    v = pkm.capability(knee, q, "twist").along["knee"]
    rows.append((knee.actuated_q(q)[0], J, w[0], w[1], v[0], reflected(knee, q)[0, 0]))
rows = np.array(rows)
rotor = knee.actuators[0].armature + knee.actuators[0].rotor_inertia * knee.actuators[0].gear_ratio ** 2
print(f"  knee per motor rate {rows[:, 1].min():.2f} to {rows[:, 1].max():.2f}; largest extension torque "
      f"{rows[:, 2].min():.1f} to {rows[:, 2].max():.1f} N m, flexion {rows[:, 3].min():.1f} to {rows[:, 3].max():.1f}"
      f" N m; knee speed {rows[:, 4].min():.1f} to {rows[:, 4].max():.1f} rad/s; reflected inertia "
      f"{rows[:, 5].min():.3f} to {rows[:, 5].max():.3f} kg m^2 (the motor's own: {rotor:.3f})")

# ------------------------------------------------------------------ the ankle's maps in C
if shutil.which("cc"):
    from pkm.core.export.harness import build

    with tempfile.TemporaryDirectory() as tmp:
        lib = pkm.export_c(ankle, Path(tmp) / "ankle", name="ankle")
        h = build(lib, optimise="-O0")  # (pkm's test harness, built quickly: the numbers are -O2's; optimise yours)
        y = np.array([[0.3, 0.1], [-0.4, -0.2], [0.0, 0.3]])
        rows_in = np.hstack([y, np.tile(ankle.q_reference, (len(y), 1)), np.zeros((len(y), 1))])
        out = h.run("ik", rows_in)
        print(f"exported C ({', '.join(f.name for f in lib.files)}); its inverse kinematics from neutral:")
        for target, row in zip(y, out):
            print(f"  pitch {target[0]:+.2f}, roll {target[1]:+.2f} rad -> motors {row[4 + ankle.nq:]} rad, status "
                  f"{int(row[0])}, {int(row[1])} Newton evaluations, mode id {int(row[3])}")
        for mode in (0, 1, 2, 3):  # the closed form, each leg on either branch (bit k: actuator k's other branch)
            row = h.run("ik_actuators", np.array([[0.3, 0.1, mode]]))[0]
            print(f"  closed form, mode {mode}: motors {row[3:]} rad, status {int(row[0])} (3: outside the motors' "
                  f"travel), smallest leg margin {row[2]:.3f}")
else:
    print("no C compiler: the exported C is skipped")

# ------------------------------------------------------------------ figures
if plt is not None:
    fig, ax = plt.subplots(figsize=(5.5, 4.2))
    v = np.degrees(np.vstack([region.vertices, region.vertices[:1]]))
    ax.fill(v[:, 0], v[:, 1], alpha=0.25, label=f"feasible ({region.area:.2f} rad$^2$)")
    for why in sorted(set(region.binding)):
        pts = np.degrees(region.vertices[[b == why for b in region.binding]])
        ax.plot(pts[:, 0], pts[:, 1], "o", ms=4, label=why)
    hb = np.degrees(half)
    ax.plot([-hb[0], hb[0], hb[0], -hb[0], -hb[0]], [-hb[1], -hb[1], hb[1], hb[1], -hb[1]], "k--",
             label="largest box")
    ax.set(xlabel="pitch [deg]", ylabel="roll [deg]", title="humanoid ankle: feasible pitch-roll region")
    ax.legend(fontsize=6, loc="lower left")
    fig.tight_layout()
    fig.savefig(OUT / "ankle_region.png", dpi=150)
    for axis in AXES:
        torques.figure(str(OUT / f"ankle_{axis.split('_')[1]}_torque.png"), along=axis)
        speeds.figure(str(OUT / f"ankle_{axis.split('_')[1]}_speed.png"), along=axis)
    fig, ax = plt.subplots(figsize=(5.5, 3.6))
    ax.plot(np.degrees(sweep), inertia[:, 0], label="pitch, $J^{-T}$ diag(armature) $J^{-1}$")
    ax.plot(np.degrees(sweep), inertia[:, 1], label="roll")
    ax.axhline(2 * armature, color="k", ls="--", label="2x armature (constant)")
    ax.set(xlabel="pitch [deg] (roll 0)", ylabel="reflected inertia [kg m$^2$]")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(OUT / "ankle_reflected_inertia.png", dpi=150)
    fig, axs = plt.subplots(2, 2, figsize=(8, 5.5), sharex=True)
    deg = np.degrees(flexion)
    axs[0, 0].plot(deg, rows[:, 1])
    axs[0, 0].set(ylabel="knee rate per motor rate [-]")
    axs[0, 1].plot(deg, rows[:, 2], label="extension")
    axs[0, 1].plot(deg, rows[:, 3], label="flexion")
    axs[0, 1].set(ylabel="largest knee torque [N m]")
    axs[0, 1].legend(fontsize=7)
    axs[1, 0].plot(deg, rows[:, 4])
    axs[1, 0].set(ylabel="largest knee speed [rad/s]", xlabel="flexion [deg]")
    axs[1, 1].plot(deg, rows[:, 5])
    axs[1, 1].set(ylabel="reflected inertia [kg m$^2$]", xlabel="flexion [deg]")
    fig.suptitle("humanoid knee through a four-bar: 80 N m, 15 rad/s motor")
    fig.tight_layout()
    fig.savefig(OUT / "knee.png", dpi=150)
    print("figures in", OUT.resolve())
