"""The self-contained HTML page of a mechanism: meshcat's viewer inlined, the drawing commands carried in the page,
a legend of the colours; no server, no network, no process."""

from __future__ import annotations

import html
import json
from collections.abc import Iterable
from pathlib import Path

from pkm.core.model.mechanism import Mechanism
from pkm.errors import InvalidInputError
from pkm.viz.backend import VizDependencyError, load_meshcat
from pkm.viz.encode import pack_commands, scene_commands
from pkm.viz.interference import interference_marks
from pkm.viz.scene import Scene

_PAGE = """<!DOCTYPE html>
<html>
<head>
<meta charset="utf-8">
<title>{title}</title>
<link rel="icon" href="data:,">
<style>
body {{ margin: 0; }}
#meshcat-pane {{ width: 100vw; height: 100vh; overflow: hidden; }}
#pkm-legend {{ position: absolute; left: 8px; bottom: 8px; padding: 6px 8px; border-radius: 4px;
  background: rgba(255, 255, 255, 0.85); font: 11px sans-serif; color: #222; line-height: 1.45; }}
#pkm-legend b {{ display: block; margin-bottom: 2px; }}
#pkm-legend i {{ display: inline-block; width: 10px; height: 10px; margin-right: 5px; vertical-align: -1px;
  border: 1px solid #555; }}
</style>
</head>
<body>
<div id="meshcat-pane"></div>
{legend}
<script>
{viewer_js}
</script>
<script type="application/json" id="pkm-meshcat-commands">
{commands}
</script>
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
(function () {{
  // each entry: one meshcat command, msgpack-encoded then base64, applied in order
  var commands = JSON.parse(document.getElementById("pkm-meshcat-commands").textContent);
  for (var i = 0; i < commands.length; i++) {{
    var raw = atob(commands[i]);
    var bytes = new Uint8Array(raw.length);
    for (var k = 0; k < raw.length; k++) bytes[k] = raw.charCodeAt(k);
    viewer.handle_command_bytearray(bytes);
  }}
}})();
</script>
</body>
</html>
"""


def _viewer_js(mc) -> str:
    path = Path(mc.__file__).parent / "viewer" / "dist" / "main.min.js"
    try:
        return path.read_text(encoding="utf-8")
    except OSError as exc:
        raise VizDependencyError(f"meshcat viewer ({path}: {exc.strerror})") from None


def snapshot_html(mech: Mechanism, q=None, *, trajectory=None, times=None, loop: bool = True,
                  legend: bool = True, collisions: bool = True) -> str:
    """A self-contained HTML page showing ``mech`` at ``q``, and animating ``trajectory`` if given.

    The page inlines meshcat's viewer and carries the drawing commands itself; it needs no
    meshcat server and no network. No process is started.

    Args:
        mech: The mechanism.
        q: Configuration shown (nq,); default ``mech.q_reference`` (or the first of ``trajectory``).
        trajectory: Configurations to animate, (N, nq), or None.
        times: Time of each configuration [s], (N,); default 30 configurations per second.
        loop: Whether the animation repeats forever.
        legend: Whether the page shows the legend of the colours (:meth:`Scene.legend`) in its lower left corner.
        collisions: At one configuration (no trajectory), where the mechanism has collision geometry, colour the
            bodies that interpenetrate and mark the witness points, said in the legend with their distance
            (:mod:`pkm.viz.interference`); False: not.

    Returns:
        The HTML text. The commands are a JSON list of base64 strings in the element
        ``<script id="pkm-meshcat-commands">``, each a msgpack-encoded meshcat command.

    Raises:
        InvalidInputError: ``q``, ``trajectory`` or ``times`` is malformed.
        VizDependencyError: meshcat is not installed.
    """
    mc, _ = load_meshcat()
    scene = Scene.from_mechanism(mech)
    packed = pack_commands(scene_commands(scene, q, trajectory=trajectory, times=times, loop=loop,
                                          collisions=collisions))
    marks = None
    if collisions and trajectory is None:
        marks = interference_marks(scene, mech.check_q(mech.q_reference if q is None else q))
    return _PAGE.format(title=html.escape(f"pkm: {mech.name}"), viewer_js=_viewer_js(mc),
                        legend=_legend_html(scene, marks.legend if marks is not None else ()) if legend else "",
                        commands="[\n" + ",\n".join(json.dumps(p) for p in packed) + "\n]")


def _legend_html(scene: Scene, extra: Iterable[tuple[str, tuple[int, ...]]] = ()) -> str:
    """The ``<div id="pkm-legend">`` listing :meth:`Scene.legend` (then ``extra``): a swatch and a label per
    colour."""
    rows = "".join("<div>" + "".join(f'<i style="background:#{c:06x}"></i>' for c in colors)
                   + f"{html.escape(label)}</div>" for label, colors in [*scene.legend(), *extra])
    return f'<div id="pkm-legend"><b>{html.escape(scene.mechanism.name)}</b>{rows}</div>'


def write_html(path, mech: Mechanism, q=None, **kw) -> Path:
    """Write :func:`snapshot_html` of ``mech`` to ``path`` (UTF-8); keywords go to it. Returns the path."""
    page = snapshot_html(mech, q, **kw)
    out = Path(path)
    try:
        out.write_text(page, encoding="utf-8")
    except OSError as exc:
        raise InvalidInputError("path", f"cannot write {str(out)!r}: {exc.strerror}", path) from None
    return out
