"""pkm.core.formats.writers and pkm.save: each writer followed by pkm.load gives the same mechanism (joint names,
limits, actuators, closures; the same closed configurations and joint placements at random actuator values, 1e-12);
what a format cannot hold is said (a PkmWarning, the YAML's comments) or refused by name."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.formats.writers import WRITERS, target, write
from pkm.core.kinematics import constraints
from pkm.errors import InvalidInputError, PkmWarning, SpecError, UnknownNameError
from tests.test_gepetto_robots import gepetto

MECHANISMS = ("delta", "rrr3", "fivebar", "gepetto:5bar_linkage_iso3d")
_CACHE: dict[str, pkm.Mechanism] = {}


def _mech(name: str) -> pkm.Mechanism:
    if name.startswith("gepetto:"):
        return gepetto(name.removeprefix("gepetto:"))
    if name not in _CACHE:
        _CACHE[name] = pkm.load(name)
    return _CACHE[name]


def _moved(src: pkm.Mechanism, dst: pkm.Mechanism, q: np.ndarray) -> np.ndarray:
    """``q`` of ``src`` in ``dst``'s coordinates, joint by joint name (mimic joints follow their leaders)."""
    out = pin.neutral(dst.model)
    for j in range(1, src.model.njoints):
        js, jd = src.model.joints[j], dst.model.joints[dst.model.getJointId(src.model.names[j])]
        if js.shortname() != "JointModelMimic":
            out[jd.idx_q:jd.idx_q + jd.nq] = q[js.idx_q:js.idx_q + js.nq]
    return out


def _placements(mech: pkm.Mechanism, q: np.ndarray) -> dict[str, np.ndarray]:
    data = mech.model.createData()
    pin.forwardKinematics(mech.model, data, q)
    return {mech.model.names[j]: data.oMi[j].homogeneous for j in range(1, mech.model.njoints)}


@pytest.mark.parametrize("to", list(WRITERS))
def test_every_writer_reads_back_as_the_same_mechanism(to, tmp_path):
    """pkm.save by suffix, pkm.load of the main file: same joints, limits, actuators (in order) and closure types
    (and names where the format has them: pkm, MJCF, URDF+, SDF, USD; frames where it keeps them: pkm, Gepetto); at three random
    actuator values near the reference the original's closed configuration closes the copy (1e-12) and is the copy's
    FK from it (close_loops moves it by <= 1e-12); every joint's placement agrees to 1e-12; pkm's spec keeps the task
    (the same task values). What the other formats cannot hold comes as a PkmWarning; pkm's spec loses nothing
    (SDF's limits to 1 ulp: written from the reference)."""
    suffix = WRITERS[to].suffixes[0]
    for name in MECHANISMS:
        mech = _mech(name)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            path = pkm.save(mech, tmp_path / name.replace(":", "_") / f"robot{suffix}")
        said = [w for w in caught if issubclass(w.category, PkmWarning)]
        assert (len(said) == 1 and "cannot hold" in str(said[0].message)) if to != "pkm" else not said, name
        back = pkm.load(path)
        assert sorted(back.joints) == sorted(mech.joints) and back.limits.keys() == mech.limits.keys(), name
        for joint, bounds in mech.limits.items():  # (SDF: from the reference and back, 1 ulp)
            assert np.abs(np.subtract(back.limits[joint], bounds)).max() <= (1e-15 if to == "sdf" else 0.0), name
        assert back.actuated_names == mech.actuated_names, name
        assert [c.type for c in back.spec.closures] == [c.type for c in mech.spec.closures], name
        if to != "gepetto":
            assert [c.name for c in back.spec.closures] == [c.name for c in mech.spec.closures], name
        if to not in ("mjcf", "urdfplus", "sdf", "usd"):
            assert [(c.frame_a, c.frame_b) for c in back.spec.closures] == \
                [(c.frame_a, c.frame_b) for c in mech.spec.closures], name
        rng = np.random.default_rng(7)
        for _ in range(3):
            qa = mech.actuated_q(mech.q_reference) + 0.01 * rng.standard_normal(mech.na)
            q = pkm.close_loops(mech, qa).q
            qb = _moved(mech, back, q)
            assert np.abs(constraints.residual(back, qb)).max() <= 1e-12, name
            assert np.abs(pkm.close_loops(back, qa, qb).q - qb).max() <= 1e-12, name
            a, b = _placements(mech, q), _placements(back, qb)
            assert max(np.abs(a[k] - b[k]).max() for k in a) <= 1e-12, name
            if to == "pkm":
                ta, tb = pkm.task_values(mech, q), pkm.task_values(back, qb)
                assert ta.keys() == tb.keys() and max(abs(ta[k] - tb[k]) for k in ta) <= 1e-12, name


def test_the_gepetto_yaml_says_what_it_cannot_hold(tmp_path):
    """The Delta's task, reference and closure names are comments in the YAML (which the reader skips), listed in
    Written.dropped; a floating base is refused by name."""
    from tests.core.model.test_mechanism import _floating_ankle

    written = write(_mech("delta"), tmp_path / "delta.yaml")
    assert [p.name for p in written.files] == ["delta.yaml", "delta.urdf"] and written.format == "gepetto"
    text = written.files[0].read_text()
    for line in written.dropped:
        assert f"#   {line}" in text
    assert any(d.startswith("task: end effector 'platform'") for d in written.dropped)
    assert any(d.startswith("reference configuration") for d in written.dropped)
    assert any(d.startswith("closure names ['ball_1'") for d in written.dropped)
    with pytest.raises(SpecError, match="cannot hold the floating base 'pelvis'"):
        write(_floating_ankle()[0], tmp_path / "ankle.yaml")


def test_a_path_names_its_format_or_is_refused_listing_the_known_ones(tmp_path):
    """By suffix (.closures.toml, .toml, .xml, .mjcf, .yaml, .yml, any case), or to= for a folder; an unknown suffix,
    a folder without to=, a suffix of another format than to=, an unknown to=: each refused, the message listing the
    formats and their suffixes; a file that cannot be written is a SpecError naming it."""
    for path, name in (("a.closures.toml", "pkm"), ("a.TOML", "pkm"), ("a.xml", "mjcf"), ("a.mjcf", "mjcf"),
                       ("a.yaml", "gepetto"), ("a.yml", "gepetto")):
        assert target(path)[0].name == name
    assert target(tmp_path / "out", "gepetto") == (WRITERS["gepetto"], None)
    for path, to, match in (("a.stl", None, r"suffix '\.stl' names no format.*known: pkm \(\.closures\.toml"),
                            ("out", None, "needs to= .* known: "), ("a.xml", "pkm", "is mjcf's, not pkm's")):
        with pytest.raises(InvalidInputError, match=match):
            target(path, to)
    with pytest.raises(UnknownNameError, match=r"format 'urdf' does not exist.*'gepetto'"):
        pkm.save(_mech("fivebar"), tmp_path / "a.urdf", to="urdf")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PkmWarning)
        main = pkm.save(_mech("fivebar"), tmp_path / "folder", to="gepetto")
    assert main == tmp_path / "folder" / "robot.yaml" and (tmp_path / "folder" / "robot.urdf").is_file()
    assert pkm.load(tmp_path / "folder").actuated_names == _mech("fivebar").actuated_names
    (tmp_path / "plain").write_text("")
    with pytest.raises(SpecError, match=r"plain/x\.xml: cannot write"):
        write(_mech("fivebar"), tmp_path / "plain" / "x.xml")


def test_a_mechanism_without_urdf_text_is_one_error_type_for_every_writer(tmp_path):
    """A Mechanism built from a pinocchio.Model has no URDF text: pkm's spec, Gepetto's format and URDF+ (which carry
    the URDF) refuse it with a SpecError naming the file (writers' module doc: one rule); MJCF and SDF write it from the
    model, and it reads back closed at the original's states (1e-12)."""
    mech = _mech("fivebar")
    bare = pkm.Mechanism(mech.model, mech.spec, source="bare")
    assert bare.urdf is None
    for to in ("pkm", "gepetto", "urdfplus"):
        path = tmp_path / f"bare{WRITERS[to].suffixes[0]}"
        with pytest.raises(SpecError, match=rf"{path.name}: .*no URDF"):
            write(bare, path)
    q = pkm.close_loops(mech, mech.actuated_q(mech.q_reference) + 0.01).q
    for to in ("mjcf", "sdf"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PkmWarning)
            back = pkm.load(pkm.save(bare, tmp_path / to, to=to))
        assert np.abs(constraints.residual(back, _moved(mech, back, q))).max() <= 1e-12, to
