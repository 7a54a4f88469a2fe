"""pkm.core.collision.geometry: the collision geometry every format carries into the URDF text (SDF's <collision>,
MJCF's geoms and their contype, URDF meshes), attached where the files put it; Pinocchio's builder never sees it."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin

import pkm
from pkm.core.collision import CollisionModel
from pkm.core.formats.mjcf import read_mjcf
from pkm.core.formats.sdf import read_sdf
from pkm.core.model.urdf import load_model
from tests.core.formats.test_sdf import fourbar, mechanism

ANKLE = Path(__file__).resolve().parents[3] / "examples" / "humanoid_ankle"


def point_segment(p, a, b) -> float:
    t = np.clip((p - a) @ (b - a) / ((b - a) @ (b - a)), 0.0, 1.0)
    return float(np.linalg.norm(p - (a + t * (b - a))))


def test_sdf_collisions_are_placed_as_sdformat_poses_them():
    """A sphere on the crank, a capsule on the rocker turned to lie along x (its <pose> in the link frame, the
    rocker posed in degrees), a small sphere on the coupler (its neighbour and the rocker's across the cut joint):
    the crank's and the rocker's distance is the point-to-segment distance minus the radii, as the crank turns."""
    sphere = "<collision name='s'><pose>0.05 0 0.02 0 0 0</pose><geometry><sphere><radius>0.01</radius></sphere>" \
             "</geometry></collision>"
    capsule = "<collision name='c'><pose>-0.1 0 0.02 0 1.5707963267948966 0</pose><geometry><capsule><radius>0.01" \
              "</radius><length>0.1</length></capsule></geometry></collision><collision><geometry><plane/></geometry>" \
              "</collision>"
    small = "<collision><geometry><sphere><radius>0.005</radius></sphere></geometry></collision>"
    text = fourbar().replace('<link name="crank">', f'<link name="crank">{sphere}') \
        .replace("<pose relative_to=\"crank\">0 0 0.1 0 0 0</pose>", f"<pose relative_to='crank'>0 0 0.1 0 0 0</pose>{small}") \
        .replace('<link name="rocker"><pose degrees="true">0.3 0 0 0 0 0</pose>',
                 f'<link name="rocker"><pose degrees="true">0.3 0 0 0 0 0</pose>{capsule}')
    assert any("crank (plane)" in n or "rocker (plane)" in n for n in read_sdf(text, "fb.sdf").notes)
    mech = mechanism(text)
    cm = CollisionModel.of(mech)
    assert cm.pairs == (("crank", "rocker"),), cm.excluded
    assert cm.excluded[("coupler", "rocker")].startswith("closure") and cm.bodies == ("crank", "coupler", "rocker")
    for q in (mech.q_reference, pkm.close_loops(mech, [0.5], mech.q_reference).q):
        pin.framesForwardKinematics(mech.model, mech.data, q)
        crank, rocker = (mech.data.oMf[mech.frame_id(n)] for n in ("crank", "rocker"))
        centre = crank.act(np.array([0.05, 0.0, 0.02]))
        a, b = rocker.act(np.array([-0.15, 0.0, 0.02])), rocker.act(np.array([-0.05, 0.0, 0.02]))
        expected = point_segment(centre, a, b) - 0.02
        assert abs(pkm.clearance(mech, q).pairs[("crank", "rocker")] - expected) <= 1e-9


MJCF = """<mujoco model="two"><compiler angle="radian"/>
  <worldbody>
    <geom name="floor" type="plane" size="1 1 0.1"/>
    <body name="a"><joint name="ja" axis="0 0 1"/>
      <geom type="box" size="0.1 0.2 0.3" pos="0 0 0.5"/>
      <geom type="sphere" size="0.05" contype="0" conaffinity="0"/>
      <body name="b" pos="1 0 0"><joint name="jb" axis="0 0 1"/>
        <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.02"/></body>
    </body>
  </worldbody></mujoco>"""


def test_mjcf_geoms_become_collisions_honouring_contype():
    imp = read_mjcf(MJCF, "two.xml")
    assert imp.urdf.count("<collision") == 2  # (the plane and the non-colliding sphere left out)
    assert any("contype and conaffinity 0" in n for n in imp.notes) and any("1 plane" in n for n in imp.notes)
    assert '<box size="0.2 0.4 0.6"/>' in imp.urdf  # (MuJoCo's half-sizes doubled)
    assert '<capsule radius="0.02" length="0.4"/>' in imp.urdf


def test_pinocchios_builder_never_sees_the_geometry(capfd):
    """urdfdom prints errors for a <capsule>: pkm gives Pinocchio the tree without <collision> and <visual>."""
    gs = pkm.load("gough_stewart")
    capfd.readouterr()
    model = load_model(gs.urdf)
    assert model.njoints == gs.model.njoints
    assert capfd.readouterr().err == ""


def test_a_mesh_is_read_as_its_convex_hull(tmp_path):
    """A box written as an STL on the platform: its distance to the legs that of the primitive box."""
    trimesh = __import__("pytest").importorskip("trimesh")
    path = tmp_path / "box.stl"
    trimesh.creation.box((0.4, 0.4, 0.1)).export(path)
    gs = pkm.load("gough_stewart")
    disc = gs.urdf[gs.urdf.index('<link name="platform_link">'):]
    disc = disc[disc.index("<collision"):disc.index("</collision>") + len("</collision>")]
    as_box = gs.urdf.replace(disc, '<collision><geometry><box size="0.4 0.4 0.1"/></geometry></collision>')
    as_mesh = gs.urdf.replace(disc, f'<collision><geometry><mesh filename="{path}"/></geometry></collision>')
    q = gs.q_reference
    meshed = pkm.from_strings(as_mesh, gs.spec)
    box, mesh = pkm.clearance(pkm.from_strings(as_box, gs.spec), q).pairs, pkm.clearance(meshed, q).pairs
    assert box.keys() == mesh.keys()
    assert max(abs(box[k] - mesh[k]) for k in box) <= 1e-6  # (an STL's vertices are single precision)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (the MJCF writer's other omissions)
        pkm.save(meshed, tmp_path / "meshed.xml")
    back = pkm.load(tmp_path / "meshed.xml")  # (the mesh an <asset><mesh>, read back as the same hull)
    assert np.allclose(sorted(pkm.clearance(back, back.q_reference).pairs.values()), sorted(mesh.values()),
                       rtol=0, atol=1e-9)


def test_the_mjcf_and_sdf_writers_carry_the_geometry(tmp_path):
    """The Gough-Stewart written as MJCF and as SDFormat and read back: the same distances (the MJCF bodies named
    after their joints); what SDFormat cannot hold (a shape on the world: the ankle's shank) said."""
    from pkm.core.formats.to_sdf import sdf_from_mechanism

    gs = pkm.load("gough_stewart")
    expected = sorted(pkm.clearance(gs, gs.q_reference).pairs.values())
    for to, suffix in (("mjcf", ".xml"), ("sdf", ".toml")):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # (the writers' other omissions: the task, the universal joints)
            pkm.save(gs, tmp_path / to, to=to)
            back = pkm.load(next(f for f in (tmp_path / to).iterdir() if f.suffix == suffix))
        got = sorted(pkm.clearance(back, back.q_reference).pairs.values())
        assert len(got) == len(expected) and np.allclose(got, expected, rtol=0, atol=1e-10), to
    ankle = pkm.load(Path(__file__).resolve().parents[3] / "examples" / "humanoid_ankle" / "ankle.closures.toml")
    _, dropped = sdf_from_mechanism(ankle)
    assert any("collision geometry of shank (on the world)" in d for d in dropped)


def test_mujocos_contype_and_conaffinity_filter_the_pairs(tmp_path):
    """The ankle with contacts on and the right rod's bit masks apart from the others' (MuJoCo never collides them):
    its pairs are filtered out, said so; written as MJCF and read back, the same filter."""
    folder = tmp_path / "ankle"
    folder.mkdir()
    text = (ANKLE / "ankle.xml").read_text().replace('<geom contype="0" conaffinity="0"/>', "<geom/>").replace(
        '<geom type="capsule" fromto="0 0 0 0 0 -0.19" size="0.004"/>',
        '<geom type="capsule" fromto="0 0 0 0 0 -0.19" size="0.004" contype="2" conaffinity="2"/>')
    (folder / "ankle.xml").write_text(text)
    (folder / "ankle.closures.toml").write_text((ANKLE / "ankle.closures.toml").read_text())
    mech = pkm.load(folder / "ankle.closures.toml")
    cm = CollisionModel.of(mech)
    filtered = {p for p, r in cm.excluded.items() if r.startswith("filtered")}
    assert filtered and all("rod_right" in p for p in filtered) and not any("rod_right" in p for p in cm.pairs)
    assert ("rod_left", "shank") in cm.pairs
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pkm.save(mech, tmp_path / "again.xml")
    back = CollisionModel.of(pkm.load(tmp_path / "again.xml"))
    assert len(back.pairs) == len(cm.pairs) and sum(r.startswith("filtered") for r in back.excluded.values()) \
        == len(filtered)
