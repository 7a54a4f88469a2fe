"""Position kinematics: closure residuals and Jacobians, the task coordinates, one configuration's
snapshot, Gauss-Newton, the position solvers (loop closure, inverse kinematics, assembly) and trajectories."""
