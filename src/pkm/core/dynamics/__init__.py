"""Dynamics: Khalil's projection of Pinocchio's RNEA onto the actuated joints, the virtual-work route, the
forward dynamics through ``constraintDynamics`` (:mod:`~pkm.core.dynamics.projection`).

The names of :mod:`~pkm.core.dynamics.projection` are importable from here too (``pkm.core.dynamics.X``, as before 0.2.0, when
this package was one module), imported on first use, so that importing another module of the package stays as
cheap as that module.
"""

from pkm._lazy import delegate

__getattr__ = delegate("pkm.core.dynamics.projection")
