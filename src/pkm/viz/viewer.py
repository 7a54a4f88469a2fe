"""The live meshcat viewer: :func:`show` draws a mechanism in a meshcat server, :class:`Viewer` moves it
(Pinocchio's ``display``/``play`` interface), :func:`close` stops the server."""

from __future__ import annotations

import contextlib
import io
import subprocess

from pkm.core.model.mechanism import Mechanism
from pkm.validation import as_scalar
from pkm.viz.backend import load_meshcat
from pkm.viz.encode import check_trajectory, meshcat_path, scene_commands
from pkm.viz.scene import Scene


def show(mech: Mechanism, q=None, *, trajectory=None, times=None, vis=None, collisions: bool = True):
    """Draw ``mech`` at ``q`` (and animate ``trajectory``) in a live meshcat viewer.

    Args:
        mech: The mechanism.
        q: Configuration shown (nq,); default ``mech.q_reference`` (or the first of ``trajectory``).
        trajectory: Configurations to animate, (N, nq), or None.
        times: Time of each configuration [s], (N,); default 30 configurations per second.
        vis: A ``meshcat.Visualizer``; None starts one (a meshcat server process; open ``vis.url()``).
        collisions: At one configuration, colour the bodies that interpenetrate and mark the witness points
            (:func:`~pkm.viz.encode.scene_commands`).

    Returns:
        The visualizer. The mechanism is drawn under ``<vis path>/pkm``, replacing an earlier drawing.
    """
    mc, _ = load_meshcat()
    if vis is None:
        import meshcat.visualizer

        with contextlib.redirect_stdout(io.StringIO()):  # it prints its URL
            vis = meshcat.visualizer.Visualizer()
    root = vis.path.append("pkm")
    scene = Scene.from_mechanism(mech, root=root.lower())
    cmds = scene_commands(scene, q, trajectory=trajectory, times=times, collisions=collisions)
    vis.window.send(mc.commands.Delete(root))
    for c in cmds:
        vis.window.send(c)
    return vis


class Viewer:
    """A live meshcat view of a mechanism with Pinocchio's visualizer interface: ``display(q)`` and
    ``play(q_trajectory, dt)`` (as ``pinocchio.visualize.MeshcatVisualizer``), drawn from pkm's scene.

    Args:
        mech: The mechanism.
        vis: A ``meshcat.Visualizer``; None starts one (a server process: :meth:`close` stops it).
    """

    def __init__(self, mech: Mechanism, vis=None):
        self.mech = mech
        self.vis = show(mech, vis=vis, collisions=False)  # (display() moves the bodies: marks would stay behind)
        self.scene = Scene.from_mechanism(mech, root=self.vis.path.append("pkm").lower())  # where show() drew it

    def url(self) -> str:
        """The viewer's web address."""
        return self.vis.url()

    def display(self, q=None) -> None:
        """Move every body to configuration ``q`` (default the reference); the geometry is sent once, here
        only the placements."""
        mc, _ = load_meshcat()
        q = self.mech.q_reference if q is None else q
        for body, T in zip(self.scene.bodies, self.scene.transforms(q).values()):
            self.vis.window.send(mc.commands.SetTransform(T, meshcat_path(mc, body.path)))

    def play(self, q_trajectory, dt: float) -> None:
        """Display the configurations of ``q_trajectory`` (N, nq) one after the other, ``dt`` [s] apart."""
        import time

        dt = as_scalar(dt, "dt", low=0.0, unit="s")
        Q = check_trajectory(self.mech, q_trajectory, None)[0]
        for q in Q:
            t0 = time.perf_counter()
            self.display(q)
            time.sleep(max(0.0, dt - (time.perf_counter() - t0)))

    def close(self) -> None:
        """Stop the viewer's server if this viewer started it (see :func:`close`)."""
        close(self.vis)


def close(vis, timeout: float = 5.0) -> None:
    """Stop the meshcat server process that :func:`show` started for ``vis`` and wait for it.

    meshcat starts its server in a session of its own and stops it only from an ``atexit`` hook,
    which a process ended by a signal never runs: without this call the server outlives its
    parent and keeps its ports (7000 on), and the next viewer silently moves to 7001. Safe to
    call twice, and on a visualizer connected to a server it did not start (then it does nothing).
    """
    proc = getattr(getattr(vis, "window", None), "server_proc", None)
    if proc is None or proc.poll() is not None:
        return
    proc.terminate()
    try:
        proc.wait(timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
