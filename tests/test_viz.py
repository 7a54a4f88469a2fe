"""pkm.viz: the meshcat snapshot of every mechanism, decoded and checked against Pinocchio.

The snapshot's commands are read back the way the viewer reads them (base64, then msgpack)
and compared with forward kinematics computed here on a fresh ``pin.Data``: every drawn body
sits where its frame is, joint spheres sit on joint origins in their actuation's colour, links
join what they claim to join, the platform and base polygons pass through the closure frames
and anchors, and an animation's keyframes are the forward kinematics of each sample.
"""

from __future__ import annotations

import base64
import json
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import umsgpack

import pkm
from pkm import viz
from pkm.errors import InvalidInputError, PkmError

TOL = 1e-9  # m, on placements sent as float64
TOL_F32 = 1e-6  # m, on mesh vertices (meshcat sends geometry as float32)


# ------------------------------------------------------------------------------------------ helpers
def decode(page: str) -> list[dict]:
    """The commands embedded in a snapshot page: a JSON list of base64 strings, each msgpack."""
    match = re.search(r'<script type="application/json" id="pkm-meshcat-commands">(.*?)</script>', page, re.DOTALL)
    assert match, "the page carries no pkm-meshcat-commands element"
    return [umsgpack.unpackb(base64.b64decode(s)) for s in json.loads(match.group(1))]


def by_path(cmds: list[dict], kind: str) -> dict[str, dict]:
    out = {}
    for c in cmds:
        if c["type"] == kind:
            assert c["path"] not in out, f"two {kind} commands for {c['path']}"
            out[c["path"]] = c
    return out


def matrix(cmd: dict) -> np.ndarray:
    """A set_transform's matrix (three.js sends column-major)."""
    return np.array(cmd["matrix"], dtype=float).reshape(4, 4).T


def vertices(obj: dict) -> np.ndarray:
    array = obj["object"]["geometries"][0]["data"]["attributes"]["position"]["array"]
    assert array.type == 0x17  # Float32Array
    return np.frombuffer(array.data, dtype=np.float32).reshape(-1, 3).astype(float)


def fk(mech, q) -> pin.Data:
    """Forward kinematics of ``mech`` at ``q`` on a data of its own."""
    data = mech.model.createData()
    pin.forwardKinematics(mech.model, data, q)
    pin.updateFramePlacements(mech.model, data)
    return data


def frame_placement(mech, data, name: str) -> np.ndarray:
    return data.oMf[mech.model.getFrameId(name)].homogeneous


def point(mech, data, name: str, host: str) -> np.ndarray:
    """World position of joint or frame ``name``; a joint as the point where body ``host`` carries it."""
    model = mech.model
    if model.existJointName(name) and name != host:
        j = model.getJointId(name)
        return (data.oMi[model.parents[j]] * model.jointPlacements[j]).translation
    if model.existJointName(name):
        return data.oMi[model.getJointId(name)].translation
    return data.oMf[model.getFrameId(name)].translation


def assembled(mech, step: float = 0.03) -> np.ndarray:
    """An assembled configuration: actuated coordinates moved off the reference by ``step``, loops closed."""
    qa = mech.actuated_q(mech.q_reference) + step * np.linspace(1.0, -0.5, mech.na)
    res = pkm.close_loops(mech, qa, mech.q_reference)
    assert res.converged
    return res.q


@pytest.fixture(scope="module", params=pkm.MECHANISMS)
def case(request):
    """(mechanism, its scene, the reference and a second assembled configuration)."""
    mech = pkm.load(request.param)
    return mech, viz.Scene.from_mechanism(mech), [mech.q_reference, assembled(mech)]


# ----------------------------------------------------------------------------------------- snapshot
@pytest.mark.parametrize("which", [0, 1], ids=["reference", "assembled"])
def test_every_drawn_body_sits_at_its_frame(case, which):
    """Each body's transform in the snapshot is Pinocchio's placement of its frame times its offset (1e-9)."""
    mech, scene, qs = case
    q = qs[which]
    cmds = decode(viz.snapshot_html(mech, q))
    objects, transforms = by_path(cmds, "set_object"), by_path(cmds, "set_transform")
    paths = [b.path for b in scene.bodies]
    assert set(objects) == set(paths)
    data = fk(mech, q)
    err = max(np.abs(matrix(transforms[b.path]) - frame_placement(mech, data, b.frame) @ b.offset).max()
              for b in scene.bodies)
    assert err <= TOL
    assert set(scene.transforms(q)) == set(paths)


@pytest.mark.parametrize("which", [0, 1], ids=["reference", "assembled"])
def test_every_joint_has_a_sphere_at_its_origin_coloured_by_actuation(case, which):
    """Every joint of the tree (mimic joints included) has one sphere, centred on it, in its actuation's colour."""
    mech, scene, qs = case
    cmds = decode(viz.snapshot_html(mech, qs[which]))
    objects, transforms = by_path(cmds, "set_object"), by_path(cmds, "set_transform")
    data = fk(mech, qs[which])
    model = mech.model
    spheres = {b.joint: b for b in scene.bodies if b.role == "joint"}
    assert sorted(spheres) == sorted(model.names[1:])
    for j in range(1, model.njoints):
        name = model.names[j]
        expected = ("actuated" if name in mech.actuated_names else
                    "mimic" if model.joints[j].shortname() == "JointModelMimic" else "passive")
        body = spheres[name]
        obj = objects[body.path]["object"]
        assert obj["geometries"][0]["type"] == "SphereGeometry"
        assert obj["materials"][0]["color"] == viz.JOINT_COLORS[expected]
        assert np.linalg.norm(matrix(transforms[body.path])[:3, 3] - data.oMi[j].translation) <= TOL
    kinds = {b.actuation for b in spheres.values()}
    assert {"actuated", "passive"} <= kinds
    assert ("mimic" in kinds) == (mech.name == "hexapod")  # its beta_2, beta_3 follow beta_1


def test_links_join_the_points_they_name(case):
    """Each link cylinder runs from its joint's origin to the child joint or frame it names (1e-9)."""
    mech, scene, qs = case
    for q in qs:
        data = fk(mech, q)
        tr = scene.transforms(q)
        links = [b for b in scene.bodies if b.role == "link"]
        assert links
        for b in links:
            half = np.array([[0.0, b.size[0] / 2, 0.0, 1.0], [0.0, -b.size[0] / 2, 0.0, 1.0]])
            ends = (tr[b.path] @ half.T).T[:, :3]
            a, c = point(mech, data, b.ends[0], b.joint), point(mech, data, b.ends[1], b.joint)
            assert min(np.linalg.norm(ends[1] - a) + np.linalg.norm(ends[0] - c),
                       np.linalg.norm(ends[0] - a) + np.linalg.norm(ends[1] - c)) <= TOL


@pytest.mark.parametrize("which", [0, 1], ids=["reference", "assembled"])
def test_platform_polygon_passes_through_the_closure_frames(case, which):
    """The platform mesh's vertices are the closure frames on the platform body (plus its joint for the 3-RRR)."""
    mech, scene, qs = case
    q = qs[which]
    data = fk(mech, q)
    model = mech.model
    pj = model.frames[mech.ee_frame].parentJoint
    expected = [data.oMf[f].translation for pair in mech.closure_frames for f in pair
                if model.frames[f].parentJoint == pj]
    if len(expected) < 3:  # a leg carries the platform: its joint is a corner too (3-RRR)
        expected.append(data.oMi[pj].translation)
    expected = np.unique(np.round(np.array(expected), 12), axis=0)
    if len(expected) < 3:  # a point, not a polygon (the five-bar's tip)
        assert not [b for b in scene.bodies if b.role == "platform"]
        return
    cmds = decode(viz.snapshot_html(mech, q))
    body = scene.body(f"{viz.ROOT}/platform")
    corners = vertices(by_path(cmds, "set_object")[body.path])
    world = (matrix(by_path(cmds, "set_transform")[body.path]) @ np.c_[corners, np.ones(len(corners))].T).T[:, :3]
    faces = {"hexapod": 8, "rrr3": 1, "delta": 1, "prs3": 1}  # a prism, or one triangle
    if mech.name in faces:
        assert len(body.faces) == faces[mech.name]
        assert len(expected) == {"hexapod": 6, "rrr3": 3, "delta": 3, "prs3": 3}[mech.name]
    dist = np.linalg.norm(world[:, None] - expected[None], axis=-1)
    assert dist.min(axis=1).max() <= TOL_F32  # every vertex is a closure frame
    assert dist.min(axis=0).max() <= TOL_F32  # every closure frame is a vertex


def test_base_polygons_pass_through_the_anchors(case):
    """The base mesh's vertices are anchors of the joints hung on the world: one triangle, two for the hexapod; two
    anchors get a bar between them."""
    mech, scene, _ = case
    model = mech.model
    anchors = np.array([model.jointPlacements[j].translation for j in range(1, model.njoints)
                        if model.parents[j] == 0 and model.joints[j].shortname() != "JointModelFreeFlyer"])
    if len(anchors) < 3:  # two motors (the five-bar): a bar between them
        (bar,) = [b for b in scene.bodies if b.role == "base"]
        half = bar.offset[:3, 1] * bar.size[0] / 2  # (a cylinder's axis is its local y)
        ends = np.array([bar.offset[:3, 3] - half, bar.offset[:3, 3] + half])
        dist = np.linalg.norm(ends[:, None] - anchors[None], axis=-1)
        assert bar.kind == "cylinder" and dist.min(axis=1).max() <= TOL and dist.min(axis=0).max() <= TOL
        return
    body = scene.body(f"{viz.ROOT}/base")
    dist = np.linalg.norm(body.vertices[:, None] - anchors[None], axis=-1)
    assert dist.min(axis=1).max() <= TOL
    assert len(body.faces) == {"hexapod": 2, "gough_stewart": 4}.get(mech.name, 1)  # two triangles; a hexagon


def test_closure_markers_coincide_on_an_assembled_configuration(case):
    """The two markers of each closure sit on its two frames, which coincide once the loops are closed."""
    mech, scene, qs = case
    for q in qs:
        tr = scene.transforms(q)
        data = fk(mech, q)
        for c in mech.spec.closures:
            a = tr[f"{viz.ROOT}/closures/{c.name}/a"][:3, 3]
            b = tr[f"{viz.ROOT}/closures/{c.name}/b"][:3, 3]
            assert np.linalg.norm(a - frame_placement(mech, data, c.frame_a)[:3, 3]) <= TOL
            assert np.linalg.norm(a - b) <= TOL


def test_world_and_end_effector_triads_are_drawn(case):
    """Triads on the world frame and on the end effector point along their frame's axes."""
    mech, scene, qs = case
    data = fk(mech, qs[1])
    tr = scene.transforms(qs[1])
    for label, frame in (("world", "universe"), (mech.spec.end_effector, mech.spec.end_effector)):
        placement = frame_placement(mech, data, frame)
        for k, axis in enumerate("xyz"):
            m = tr[f"{viz.ROOT}/frames/{label}/{axis}"]
            assert np.abs(m[:3, 1] - placement[:3, k]).max() <= TOL  # cylinder axis (its y) along the frame axis


def test_each_leg_has_one_colour_of_its_own_and_the_legend_lists_every_colour_drawn(case):
    """Links are coloured per leg (the tree cut at the world and the platform): the links of one leg share a colour,
    no two legs share one (up to len(LEG_COLORS) legs), a leg is named after its actuated joints; the legend lists
    every colour drawn, and the page shows it."""
    mech, scene, _ = case
    legs: dict[str, set[int]] = {}
    for b in scene.bodies:
        if b.role == "link" and b.leg is not None:
            legs.setdefault(b.leg, set()).add(b.color)
    assert len(legs) >= 2 and all(len(c) == 1 for c in legs.values())  # (the five-bar has two)
    colours = [c for cs in legs.values() for c in cs]
    assert len(set(colours)) == len(colours) and set(colours) <= set(viz.LEG_COLORS)
    named = {n for leg in legs for n in leg.split(", ")}
    assert set(mech.actuated_names) - {scene.platform_joint} <= named  # (a leg without links is not drawn)
    listed = {c for _, cs in scene.legend() for c in cs}
    assert {b.color for b in scene.bodies} <= listed
    assert [leg if leg.startswith("leg") else f"leg {leg}" for leg in legs] == \
        [label for label, (c, *_) in scene.legend() if c in viz.LEG_COLORS]
    page = viz.snapshot_html(mech)
    assert 'id="pkm-legend"' in page and all(f"#{c:06x}" in page for c in listed)
    assert 'id="pkm-legend"' not in viz.snapshot_html(mech, legend=False)


def test_the_camera_frames_every_joint_inside_the_view(case):
    """The snapshot's camera sees every joint and frame origin within the fill fraction of its field of view (75 deg
    vertical, a 4:3 window), and no nearer would: the farthest point lies near that edge."""
    _, scene, qs = case
    direction = scene.view_direction(qs[0])
    t = scene.camera_distance([qs[0]], direction)
    centre, _ = scene.bounds([qs[0]])
    pts = np.array([m[:3, 3] for m in scene.frame_placements(qs[0])]) - centre
    f = -direction
    right = np.cross(f, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, f)
    rel = pts + t * f
    depth = rel @ f
    reach = np.maximum(np.abs(rel @ right) / depth / (4 / 3), np.abs(rel @ up) / depth).max()
    edge = np.tan(np.radians(37.5)) * 0.8
    assert 0.8 * edge < reach < edge  # (the rest of the edge: the joint radius padding every point)


# ---------------------------------------------------------------------------------------- animation
@pytest.mark.parametrize("times, keys", [(None, [0.0, 1.0, 2.0]), ([0.0, 0.5, 2.0], [0.0, 15.0, 60.0])])
def test_animation_keyframes_are_forward_kinematics(case, times, keys):
    """A 3-sample trajectory gives, for every body, position and quaternion keys equal to FK at each sample."""
    mech, scene, qs = case
    traj = np.array([qs[0], qs[1], assembled(mech, -0.02)])
    cmds = decode(viz.snapshot_html(mech, trajectory=traj, times=times))
    (anim,) = [c for c in cmds if c["type"] == "set_animation"]
    clips = {a["path"]: a["clip"] for a in anim["animations"]}
    assert set(clips) == {b.path for b in scene.bodies}
    datas = [fk(mech, q) for q in traj]
    err = 0.0
    for b in scene.bodies:
        clip = clips[b.path]
        assert clip["fps"] == viz.FPS
        tracks = {t["name"]: t for t in clip["tracks"]}
        pos, quat = tracks[".position"]["keys"], tracks[".quaternion"]["keys"]
        assert [k["time"] for k in pos] == keys and [k["time"] for k in quat] == keys
        for k, data in enumerate(datas):
            x, y, z, w = quat[k]["value"]
            got = pin.SE3(pin.Quaternion(w, x, y, z).toRotationMatrix(), np.array(pos[k]["value"])).homogeneous
            err = max(err, np.abs(got - frame_placement(mech, data, b.frame) @ b.offset).max())
    assert err <= TOL
    # the still pose is the first sample
    first = by_path(cmds, "set_transform")[f"{viz.ROOT}/joints/{mech.actuated_names[0]}"]
    assert np.abs(matrix(first) - datas[0].oMi[mech.model.getJointId(mech.actuated_names[0])].homogeneous).max() <= TOL


# ------------------------------------------------------------------------------------------- errors
@pytest.mark.parametrize("bad, message", [
    (lambda m: np.zeros(m.nq + 1), "expected shape"),
    (lambda m: np.full(m.nq, np.nan), "non-finite"),
    (lambda m: "q", "expected"),
])
def test_bad_q_raises_pkm_error(case, bad, message):
    """A q of the wrong size, with NaNs or of the wrong type raises a PkmError saying so."""
    mech, _, _ = case
    with pytest.raises(PkmError, match=message):
        viz.snapshot_html(mech, bad(mech))


def test_unnormalised_quaternion_raises_pkm_error():
    """A free-flyer quaternion of norm 2 in q is refused with a PkmError naming the joint."""
    mech = pkm.load("prs3")
    q = mech.q_reference.copy()
    j = mech.joint("platform")
    q[j.idx_q + 3:j.idx_q + 7] *= 2.0
    with pytest.raises(InvalidInputError, match="quaternion of joint 'platform'"):
        viz.snapshot_html(mech, q)


@pytest.mark.parametrize("kw, message", [
    ({"trajectory": np.zeros((3, 2))}, r"expected shape \(N, 12\)"),
    ({"trajectory": np.zeros((0, 12))}, "N >= 1"),
    ({"trajectory": [[np.nan] * 12]}, r"trajectory\[0\]"),
    ({"trajectory": np.zeros((3, 12)), "times": [0.0, 0.2, 0.1]}, "strictly increasing"),
    ({"trajectory": np.zeros((3, 12)), "times": [0.0, 0.1]}, r"shape \(3,\)"),
    ({"times": [0.0]}, "without a trajectory"),
])
def test_bad_trajectory_or_times_raise_pkm_error(kw, message):
    """A malformed trajectory or times array raises an InvalidInputError saying what is wrong."""
    with pytest.raises(InvalidInputError, match=message):
        viz.snapshot_html(pkm.load("delta"), **kw)


def test_missing_meshcat_raises_pkm_error_saying_how_to_install(monkeypatch):
    """Without meshcat, pkm.viz raises a PkmError telling to pip install meshcat."""
    monkeypatch.setitem(sys.modules, "meshcat", None)
    with pytest.raises(viz.VizDependencyError, match=r"^pkm.viz needs meshcat: pip install meshcat$") as info:
        viz.snapshot_html(pkm.load("delta"))
    assert isinstance(info.value, PkmError)


def test_write_html_to_a_missing_folder_raises_pkm_error(tmp_path):
    """Writing into a folder that does not exist raises an InvalidInputError with the path."""
    with pytest.raises(InvalidInputError, match="cannot write"):
        viz.write_html(tmp_path / "nope" / "delta.html", pkm.load("delta"))


# ------------------------------------------------------------------------------------ page and show
def test_snapshot_is_self_contained_deterministic_and_starts_no_process(monkeypatch, tmp_path):
    """The page inlines meshcat's viewer, loads nothing from the network, is the same twice, and starts no process."""
    def no_process(*args, **kwargs):
        raise AssertionError("pkm.viz started a process")

    monkeypatch.setattr(subprocess, "Popen", no_process)
    mech = pkm.load("delta")
    page = viz.snapshot_html(mech)
    import meshcat

    js = (Path(meshcat.__file__).parent / "viewer" / "dist" / "main.min.js").read_text(encoding="utf-8")
    assert js in page
    assert "<script src" not in page and "http://" not in page.replace(js, "")
    assert "https://" not in page.replace(js, "")
    assert viz.snapshot_html(mech) == page
    out = viz.write_html(tmp_path / "delta.html", mech)
    assert out == tmp_path / "delta.html" and out.read_text(encoding="utf-8") == page
    assert decode(page) == viz.read_commands(page)


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


def test_a_joint_on_its_parents_origin_is_a_ring_around_its_sphere():
    """The 3-PRS knees sit on their sliders: larger back-face-only spheres (rings) around the slider spheres.

    The Delta's guide joints are prismatic, so they part as the platform moves: plain spheres.
    """
    mech = pkm.load("prs3")
    objects = by_path(decode(viz.snapshot_html(mech)), "set_object")
    prs3 = viz.Scene.from_mechanism(mech)
    for i in (1, 2, 3):
        slider, knee = prs3.body(f"{viz.ROOT}/joints/slider_{i}"), prs3.body(f"{viz.ROOT}/joints/knee_{i}")
        assert knee.size[0] > slider.size[0] and knee.halo and not slider.halo
        assert objects[knee.path]["object"]["materials"][0]["side"] == 1  # three.js BackSide
        assert objects[slider.path]["object"]["materials"][0]["side"] == 2  # DoubleSide
    delta = viz.Scene.from_mechanism(pkm.load("delta"))
    guide = [delta.body(f"{viz.ROOT}/joints/platform_{a}") for a in "xyz"]
    assert len({b.size[0] for b in guide}) == 1 and not any(b.halo for b in guide)


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
