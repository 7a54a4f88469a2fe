"""Kinematic calibration of any closed-loop mechanism: identifiable geometry, pose selection, estimate, write back.

One concept per module:

* :mod:`~pkm.core.calibration.parameters`: the unknowns (joint origins, actuator offsets and gains, the tracker's and
  the target's frames, passive encoders' offsets), by name;
* :mod:`~pkm.core.calibration.measurement`: the measurement models (pose, position, planar, passive) as residuals
  with their exact Jacobians through the loop closure (implicit function theorem on the twin's expressions);
* :mod:`~pkm.core.calibration.identifiable`: the base geometric parameters by two routes (double precision, 50
  digits), readable, with what each model cannot see;
* :mod:`~pkm.core.calibration.poses`: poses maximising the observability index O1 within the limits and a
  singularity margin;
* :mod:`~pkm.core.calibration.estimate`: weighted nonlinear least squares (LM, or TRF with bounds and a robust loss),
  standard deviations, pose errors before and after;
* :mod:`~pkm.core.calibration.writeback`: the measurement table (row and column named in every error) and the
  calibrated spec + URDF that :func:`pkm.load` reads;
* :mod:`~pkm.core.calibration.tolerance`: the pose error each 0.1 mm / 0.1 degree costs over the workspace.

``pkm calibrate`` and ``pkm calibrate plan`` are the command line's faces; ``docs/calibration.md`` the guide.
"""
