"""Your own mechanism, from files pkm did not write: a spatial RSSR four-bar in the URDF + robot.yaml convention of
Gepetto's toolbox-parallel-robots (the YAML turns a URDF revolute into a ball joint), loaded, assembled and analysed
by the generic core, then saved as a pkm closure spec.

Run from anywhere: ``python examples/your_own_mechanism.py``.
"""

from pathlib import Path
from tempfile import TemporaryDirectory

import numpy as np

import pkm

HERE = Path(__file__).resolve().parent

mech = pkm.load(HERE / "gepetto_rssr")  # robot.urdf + robot.yaml; no reference in them: pkm assembles one
print(mech)
print("ball joint:", mech.joints["ball_b"].kind, "| limits stated:", mech.limits or "none")

d = pkm.diagnose(mech, mech.q_reference)
print(f"{d.classification}; mobility {d.mobility}, of which idle: {d.idle_motions} {d.idle_joints} "
      "(the coupler spinning about its own axis moves nothing)")

fk = pkm.close_loops(mech, [0.3])  # forward kinematics: the crank at 0.3 rad
ik = pkm.solve_ik(mech, pkm.TaskMap.of(mech).value(fk.q))  # and back
print(f"FK residual {fk.residual:.1e}, IK back to {mech.actuated_q(ik.q)[0]:.12f} rad")

v = pkm.velocities(mech, fk.q, [2.0])  # crank at 2 rad/s
a = pkm.accelerations(mech, fk.q, v, [0.0])
tau = pkm.inverse_dynamics(mech, fk.q, v, a)  # the motor torque (gravity included)
print(f"motor torque {tau[0]:.6f} N m")
assert np.isfinite(tau).all()

with TemporaryDirectory() as tmp:
    spec = pkm.save(mech, Path(tmp) / "rssr.closures.toml")  # a pkm spec (with [joint_types]) and its URDF
    again = pkm.load(spec)
    print("saved and loaded back:", again)
