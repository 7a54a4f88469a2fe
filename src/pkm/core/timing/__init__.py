"""Time-optimal motion along a geometric path under actuator limits, for any mechanism pkm loads (issue 46).

* :mod:`~pkm.core.timing.path`: the path :math:`y(s)` (a C² cubic spline through waypoints, or a motion case);
* :mod:`~pkm.core.timing.coefficients`: the efforts along it, :math:`a \\ddot s + b \\dot s^2 + c + d \\dot s`, from
  the actuator-space model (payload, friction);
* :mod:`~pkm.core.timing.limits`: torque-speed curves, speed and acceleration limits;
* :mod:`~pkm.core.timing.solve`: the time-optimal law (TOPP-RA, ``toppra``): :func:`time_optimal`;
* :mod:`~pkm.core.timing.verify`: the law checked by :func:`pkm.inverse_dynamics` at 10x the resolution,
  Pontryagin's structure and a tracking simulation: :func:`verify_time_optimal`.
"""

from pkm.core.timing.coefficients import PathCoefficients, path_coefficients, with_payload
from pkm.core.timing.limits import Limits, actuator_limits, parse_limits
from pkm.core.timing.path import GeometricPath, motion_path, waypoint_path
from pkm.core.timing.solve import TimeOptimal, time_optimal
from pkm.core.timing.verify import Verification
from pkm.core.timing.verify import verify as verify_time_optimal

__all__ = ["GeometricPath", "Limits", "PathCoefficients", "TimeOptimal", "Verification", "actuator_limits",
           "motion_path", "parse_limits", "path_coefficients", "time_optimal", "verify_time_optimal",
           "waypoint_path", "with_payload"]
