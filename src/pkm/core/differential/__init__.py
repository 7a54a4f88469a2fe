"""Differential kinematics: rate and acceleration maps, singularity diagnosis and the actuation's fit
(:mod:`~pkm.core.differential.velocity`), screws (:mod:`~pkm.core.differential.screws`) and condition indices
(:mod:`~pkm.core.differential.indices`).

The names of :mod:`~pkm.core.differential.velocity` are importable from here too (``pkm.core.differential.X``, as before 0.2.0, when
this package was one module), imported on first use, so that importing another module of the package stays as
cheap as that module.
"""

from pkm._lazy import delegate

__getattr__ = delegate("pkm.core.differential.velocity")
