"""pkm.viz.viewer: ``show`` sends the snapshot's commands to a visualizer; ``Viewer`` displays and plays like
Pinocchio's visualizers."""

from __future__ import annotations

import time

import numpy as np
import pytest

import pkm
from pkm import viz
from pkm.errors import InvalidInputError
from tests.viz.helpers import assembled, decode, matrix


class _FakeWindow:
    def __init__(self):
        self.sent = []

    def send(self, cmd):
        self.sent.append(cmd.lower())


class _FakeVisualizer:
    created = 0

    def __init__(self):
        import meshcat.path

        print("You can open the visualizer by visiting the following URL:")
        type(self).created += 1
        self.window = _FakeWindow()
        self.path = meshcat.path.Path(("meshcat",))


def test_show_sends_the_snapshot_commands_to_a_visualizer():
    """show() clears <vis>/pkm, then sends the same commands as the snapshot to the visualizer it is given."""
    mech = pkm.load("rrr3")
    vis = _FakeVisualizer()
    traj = np.array([mech.q_reference, assembled(mech)])
    assert viz.show(mech, trajectory=traj, vis=vis) is vis
    assert vis.window.sent[0] == {"type": "delete", "path": "/meshcat/pkm"}
    assert vis.window.sent[1:] == decode(viz.snapshot_html(mech, trajectory=traj))


def test_show_without_visualizer_creates_one_and_prints_nothing(monkeypatch, capsys):
    """show() with no visualizer makes one (here a stand-in for meshcat's), returns it and prints nothing."""
    import meshcat.visualizer

    monkeypatch.setattr(meshcat.visualizer, "Visualizer", _FakeVisualizer)
    before = _FakeVisualizer.created
    vis = viz.show(pkm.load("delta"))
    assert isinstance(vis, _FakeVisualizer) and _FakeVisualizer.created == before + 1
    assert capsys.readouterr().out == ""
    assert any(c["type"] == "set_object" for c in vis.window.sent)


def test_viewer_displays_and_plays_like_pinocchios_visualizers():
    """Viewer(mech).display(q) sends every body's placement at q; play(Q, dt) displays each row, dt apart."""
    mech = pkm.load("delta")
    vis = _FakeVisualizer()
    viewer = viz.Viewer(mech, vis=vis)
    q = assembled(mech)
    drawn = len(vis.window.sent)
    viewer.display(q)
    sent = vis.window.sent[drawn:]
    expected = viewer.scene.transforms(q)
    assert [c["type"] for c in sent] == ["set_transform"] * len(expected)
    for c, (path, T) in zip(sent, expected.items()):
        assert c["path"] == path and np.allclose(matrix(c), T, atol=1e-15)
    before = len(vis.window.sent)
    t0 = time.perf_counter()
    viewer.play(np.array([mech.q_reference, q, mech.q_reference]), 0.05)
    assert len(vis.window.sent) - before == 3 * len(expected) and time.perf_counter() - t0 >= 0.15
    with pytest.raises(InvalidInputError):
        viewer.play(np.zeros((2, 3)), 0.05)
