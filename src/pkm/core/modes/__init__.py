"""Every assembly and working mode of a mechanism, by polynomial homotopy continuation (Bertini 2).

* :mod:`~pkm.core.modes.polynomial`: sparse polynomials, compiled for evaluation;
* :mod:`~pkm.core.modes.reduce`: the mechanism reduced to its platform and the sphere or circle each leg imposes;
* :mod:`~pkm.core.modes.equations`: the reduced equations (Study parameters, planar, translational);
* :mod:`~pkm.core.modes.continuation`: Bertini 2's homotopy and the account of every path;
* :mod:`~pkm.core.modes.certify`: Smale's alpha test;
* :mod:`~pkm.core.modes.assembly`: :func:`assembly_modes` (forward kinematics);
* :mod:`~pkm.core.modes.working`: :func:`working_modes` (inverse kinematics);
* :mod:`~pkm.core.modes.tracking`: following one mode along a path, stopping where it meets another.
"""

from pkm.core.modes.assembly import Mode, ModeSet, assembly_modes
from pkm.core.modes.tracking import Meeting, ModeTrack, track_assembly_mode, track_working_mode
from pkm.core.modes.working import working_modes

__all__ = ["Meeting", "Mode", "ModeSet", "ModeTrack", "assembly_modes", "track_assembly_mode", "track_working_mode",
           "working_modes"]
