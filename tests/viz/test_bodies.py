"""pkm.viz.bodies and pkm.viz.scene, read from the meshcat snapshot of every mechanism, decoded and checked against Pinocchio.

The snapshot's commands are read back the way the viewer reads them (base64, then msgpack)
and compared with forward kinematics computed here on a fresh ``pin.Data``: every drawn body
sits where its frame is, joint spheres sit on joint origins in their actuation's colour, links
join what they claim to join, the platform and base polygons pass through the closure frames
and anchors, and an animation's keyframes are the forward kinematics of each sample.
"""

from __future__ import annotations

import numpy as np
import pytest

import pkm
from pkm import viz
from pkm.viz.interference import interference_marks
from tests.viz.helpers import TOL, TOL_F32, by_path, decode, fk, frame_placement, matrix, point, vertices


@pytest.mark.parametrize("which", [0, 1], ids=["reference", "assembled"])
def test_every_drawn_body_sits_at_its_frame(case, which):
    """Each body's transform in the snapshot is Pinocchio's placement of its frame times its offset (1e-9)."""
    mech, scene, qs = case
    q = qs[which]
    cmds = decode(viz.snapshot_html(mech, q))
    objects, transforms = by_path(cmds, "set_object"), by_path(cmds, "set_transform")
    paths = [b.path for b in scene.bodies]
    marks = interference_marks(scene, q)  # (the witness points, where the mechanism has collision geometry)
    assert set(objects) == set(paths) | {b.path for b in (marks.bodies if marks else ())}
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
    assert [b for b in scene.bodies if b.role == "link"]
    for q in qs:
        assert _link_error(mech, scene, q) <= TOL


def _link_error(mech: pkm.Mechanism, scene: viz.Scene, q: np.ndarray) -> float:
    """The largest distance [m] at ``q`` between a link cylinder's ends and the joints or frames it names."""
    data = fk(mech, q)
    tr = scene.transforms(q)
    worst = 0.0
    for b in scene.bodies:
        if b.role != "link":
            continue
        half = np.array([[0.0, b.size[0] / 2, 0.0, 1.0], [0.0, -b.size[0] / 2, 0.0, 1.0]])
        ends = (tr[b.path] @ half.T).T[:, :3]
        a, c = point(mech, data, b.ends[0], b.joint), point(mech, data, b.ends[1], b.joint)
        worst = max(worst, min(np.linalg.norm(ends[1] - a) + np.linalg.norm(ends[0] - c),
                               np.linalg.norm(ends[0] - a) + np.linalg.norm(ends[1] - c)))
    return worst


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


def _undrawn(mech: pkm.Mechanism, scene: viz.Scene) -> list[str]:
    """The bodies of ``mech``'s tree (one per joint) that ``scene`` does not draw: a body reaching off its joint's
    origin (a child joint, a frame it carries (a task, closure or link frame), the centre of mass of a body with mass,
    farther than 1e-9 of the mechanism's size) needs a link or the platform on it; every body its joint's sphere."""
    model = mech.model
    eps = 1e-9 * scene.length
    links = {b.joint for b in scene.bodies if b.role in ("link", "platform")}
    spheres = {b.joint for b in scene.bodies if b.role == "joint"}
    missing = []
    for j in range(1, model.njoints):
        name = model.names[j]
        points = [model.jointPlacements[c].translation for c in range(1, model.njoints) if model.parents[c] == j]
        points += [f.placement.translation for f in model.frames if f.parentJoint == j]
        if model.inertias[j].mass > 0:
            points.append(model.inertias[j].lever)
        if name not in spheres or (any(np.linalg.norm(p) > eps for p in points) and name not in links):
            missing.append(name)
    return missing


def test_every_body_of_every_mechanism_is_drawn():
    """Every body of the shipped mechanisms (the test-only five-bar included), the acceptance set and Gepetto's nine
    robots that load: a link (or the platform) on each body that reaches off its joint, a sphere on each joint. The
    five-bar's distal link 1 carries the end effector on a platform of one point (no polygon): it was left out, leg 1
    drawn broken; the knee's thigh likewise; a body whose only extent is its centre of mass (the Gough-Stewart
    example's cylinders, the 3-RPR's rockers) is a link to it. Each link joins the points it names (1e-9 m)."""
    from tests.test_acceptance import ACCEPTANCE
    from tests.test_acceptance import load as acceptance
    from tests.test_gepetto_robots import ROBOTS, gepetto

    mechanisms = [pkm.load(n) for n in pkm.MECHANISMS] + [acceptance(n) for n in ACCEPTANCE]
    mechanisms += [gepetto(n) for n in ROBOTS]
    assert "fivebar" in pkm.MECHANISMS and len(mechanisms) == len(pkm.MECHANISMS) + len(ACCEPTANCE) + 9
    scenes = [(m, viz.Scene.from_mechanism(m)) for m in mechanisms]
    assert {m.name: u for m, s in scenes if (u := _undrawn(m, s))} == {}
    assert max(_link_error(m, s, m.q_reference) for m, s in scenes) <= TOL  # (the new links too)
    fivebar = next(s for m, s in scenes if m.name == "fivebar")
    distal = [b for b in fivebar.bodies if b.joint == "elbow_1" and b.role == "link"]
    assert [(b.ends, b.leg) for b in distal] == [(("elbow_1", "tip_1"), "motor_1")]  # (in leg 1's colour)
