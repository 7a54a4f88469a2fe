"""The colours of a pkm drawing: joints by actuation, legs, platform, base, closures, triads, background.

:meth:`pkm.viz.Scene.legend` lists the ones a drawing uses; the page of :func:`pkm.viz.snapshot_html` shows them.
"""

from __future__ import annotations

ACTUATED_COLOR = 0xE7298A
"""Colour of actuated joints (pink)."""
PASSIVE_COLOR = 0xE6AB02
"""Colour of passive joints (mustard)."""
MIMIC_COLOR = 0xF4A6CF
"""Colour of mimic joints, driven by another joint (light pink)."""
LINK_COLOR = 0xBDBDBD
"""Colour of links that belong to no leg (those of the platform's own body)."""
LEG_COLORS = (0x1F77B4, 0x9467BD, 0x8C564B, 0x17BECF, 0x393B79, 0x637939, 0x843C39, 0x7B4173)
"""Colours of the legs' links, in the order of the legs' first joints (then again from the first): hues apart from
the joints', the platform's, the triads' and the grey background's."""
PLATFORM_COLOR = 0x1B9E77
BASE_COLOR = 0x525252
CLOSURE_COLOR = 0xFFFFFF
AXIS_COLORS = (0xFF0000, 0x00C000, 0x0000FF)

BACKGROUND = ((0.97, 0.97, 0.97), (0.78, 0.78, 0.80))
"""The page's background, top and bottom colours (RGB in [0, 1])."""

JOINT_COLORS = {"actuated": ACTUATED_COLOR, "passive": PASSIVE_COLOR, "mimic": MIMIC_COLOR}
