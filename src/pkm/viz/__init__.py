"""Meshcat previews of any pkm mechanism, drawn from primitives.

The URDFs carry no meshes, so a mechanism is drawn from what its Pinocchio tree and
closure spec say:

* every joint as a sphere on its origin, coloured by its actuation: actuated
  (:data:`ACTUATED_COLOR`), passive (:data:`PASSIVE_COLOR`) or mimic, i.e. driven by another
  joint (:data:`MIMIC_COLOR`); a joint whose origin never leaves its parent's (a universal
  joint's second axis, a knee on a slider) is a larger sphere around its parent's, drawn by its
  back faces only, so that it shows as a ring around it;
* every body as cylinders from its joint's origin to the origins of its child joints and to
  the frames it carries (leg tips, closure frames), or, when all of them sit on its origin,
  to its centre of mass if it has mass (a Gough-Stewart leg's cylinder under its piston);
  each leg in a colour of its own (:data:`LEG_COLORS`; a leg: the joints hung on the world,
  or on the platform, with their descendants up to the platform), named after its actuated
  joints; a body with nothing off its origin is its joint's sphere;
* the platform (the body holding the end-effector frame) as the convex hull of the closure
  frames it carries: a triangle for the 3-RRR, Delta and 3-PRS, a prism for the hexapod;
  where they make no polygon (the five-bar's tip on its distal link), that body is drawn as
  the others, in its leg's colour;
* the base, translucent, through the anchor points of the joints hung on the world
  (free-flyers excepted) and the closure frames fixed to it: their polygon when they are
  coplanar, one polygon per layer when they lie in parallel planes (the hexapod's two
  3-RUS), else their convex hull;
* the world and end-effector frames as triads (x red, y green, z blue);
* each closure as a small white sphere on ``frame_a`` inside a translucent bubble on
  ``frame_b``: the two are concentric when the loop is closed.
* where the mechanism has collision geometry (:mod:`pkm.core.collision`), at one configuration: the links of
  every pair of bodies that interpenetrate in red, with their witness points (a sphere each, a bar between), or,
  where none does, the closest pair's witness points in black, each said in the legend with its distance
  (:mod:`~pkm.viz.interference`; ``collisions=False``: not).

The page of :func:`snapshot_html` carries a legend of these colours (:meth:`Scene.legend`).

:class:`Scene` lists these bodies (meshcat path, primitive, the Pinocchio frame it rides
on, its offset in that frame) and gives their placements at any configuration;
:func:`snapshot_html` turns a scene into a self-contained HTML page (the meshcat viewer
inlined, no server process), :func:`show` sends it to a live meshcat viewer.

Example::

    import pkm
    from pkm import viz
    delta = pkm.load("delta")
    viz.write_html("delta.html", delta)                        # open it in a browser
    ik = pkm.solve_ik(delta, [0.02, -0.01, -0.36])
    viz.write_html("delta_ik.html", delta, ik.q)
    vis = viz.show(delta)                                      # live, in a meshcat server

Modules: :mod:`~pkm.viz.colors` (the palette), :mod:`~pkm.viz.body` (one drawn primitive),
:mod:`~pkm.viz.hull` (convex hulls), :mod:`~pkm.viz.bodies` (the bodies of a mechanism),
:mod:`~pkm.viz.scene` (:class:`Scene`), :mod:`~pkm.viz.encode` (meshcat commands),
:mod:`~pkm.viz.page` (the HTML page), :mod:`~pkm.viz.viewer` (the live viewer),
:mod:`~pkm.viz.interference` (the interference marks),
:mod:`~pkm.viz.backend` (meshcat, imported on first use), :mod:`~pkm.viz.simulation` (the figure of a
simulation: positions, speeds, efforts, energy).
"""

from __future__ import annotations

from pkm.viz.backend import VizDependencyError
from pkm.viz.body import Body
from pkm.viz.colors import (
    ACTUATED_COLOR,
    AXIS_COLORS,
    BACKGROUND,
    BASE_COLOR,
    CLOSURE_COLOR,
    JOINT_COLORS,
    LEG_COLORS,
    LINK_COLOR,
    MIMIC_COLOR,
    PASSIVE_COLOR,
    PLATFORM_COLOR,
)
from pkm.viz.encode import FPS, pack_commands, read_commands, scene_commands
from pkm.viz.page import snapshot_html, write_html
from pkm.viz.scene import ROOT, Scene
from pkm.viz.viewer import Viewer, close, show

__all__ = [
    "ACTUATED_COLOR", "AXIS_COLORS", "BACKGROUND", "BASE_COLOR", "CLOSURE_COLOR", "FPS", "JOINT_COLORS", "LEG_COLORS",
    "LINK_COLOR", "MIMIC_COLOR", "PASSIVE_COLOR", "PLATFORM_COLOR", "ROOT", "Body", "Scene", "Viewer",
    "VizDependencyError", "close", "pack_commands", "read_commands", "scene_commands", "show", "snapshot_html",
    "write_html",
]
