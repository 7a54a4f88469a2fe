"""Bad input to the readers and writers (issue 43): a file in one format with another's suffix, a closure naming a
missing frame, body or site, a writer asked for what its format cannot hold. Each is a PkmError (pkm.errors) naming
the file, the element and its line where the format has lines; a file pkm reads by its content though its suffix
names another format is read, and that is said (a PkmWarning and a note)."""

from __future__ import annotations

import shutil
import warnings

import pytest

import pkm
from pkm.errors import PkmError, PkmWarning, SpecError, SpecNameError
from tests.test_acceptance import EXAMPLES

FOURBAR = EXAMPLES / "mjcf_fourbar" / "fourbar.xml"
CONNECT = '<connect name="pin_c" body1="coupler" body2="rocker" anchor="0 0 0.33541019662496845"/>'


def _fourbar(tmp_path, name, old="", new=""):
    text = FOURBAR.read_text()
    assert old in text
    path = tmp_path / name
    path.write_text(text.replace(old, new))
    return path


def test_a_file_with_another_formats_suffix_is_read_by_content_and_said_or_refused_naming_it(tmp_path):
    """An MJCF saved as .urdf: read as MJCF, a PkmWarning and a note naming the file, <mujoco> and its line (after the
    file's comment: line 6). A URDF saved as .xml (any XML): read as URDF, which names no actuators: refused naming
    the file. A URDF saved as a spec (.closures.toml): refused naming the file, <robot> and the suffix to give it
    (not TOML's "line 1, column 1"). A YAML that is not Gepetto's: refused naming the file and, for each reader, why
    (its keys)."""
    path = _fourbar(tmp_path, "fourbar.urdf")
    with pytest.warns(PkmWarning, match=r"fourbar\.urdf: read as MJCF by its root element <mujoco> \(line 6\), "
                                        r"though its suffix '\.urdf' names URDF"):
        mech = pkm.load(path)
    assert any("<mujoco> (line 6)" in n for n in mech.notes)
    with warnings.catch_warnings():
        warnings.simplefilter("error", PkmWarning)
        assert pkm.load(FOURBAR).na == mech.na == 1  # (its own suffix: nothing said)
    shutil.copy(EXAMPLES / "knee" / "knee.urdf", tmp_path / "knee.xml")
    with pytest.raises(SpecError, match=r"knee\.xml: the URDF file names no actuated joint"):
        pkm.load(tmp_path / "knee.xml")
    shutil.copy(EXAMPLES / "knee" / "knee.urdf", tmp_path / "knee.closures.toml")
    with pytest.raises(SpecError, match=r"knee\.closures\.toml: XML with the root element <robot>, a URDF file, not a "
                                        r"pkm closure spec \(TOML\): name it \.urdf"):
        pkm.load(tmp_path / "knee.closures.toml")
    (tmp_path / "other.yaml").write_text("name: arm\nvalues: [1, 2]\n")
    with pytest.raises(SpecError, match=r"other\.yaml: no reader takes it:\n  Gepetto URDF \+ YAML: a YAML mapping "
                                        r"without the keys closed_loop or name_mot \(its keys: name, values\)"):
        pkm.load(tmp_path / "other.yaml")


def test_a_closure_naming_a_missing_frame_names_the_file_the_element_and_the_line(tmp_path):
    """MJCF: a connect's or weld's body (its line), a site equality's site (its line); pkm's spec and Gepetto's YAML:
    the frame, the closure and the line where the frame's name is written (YAML: PyYAML's composer's; TOML, whose
    parser gives no positions: the one line where the name stands quoted; none when it stands on several), also in an
    upload (load_texts); each a SpecNameError with the valid names."""
    cases = (("body2.xml", 'body2="rocker"', 'body2="rockr"', r"body 'rockr' does not exist in \S+body2\.xml "
              r"\(<equality><connect name='pin_c'> \(line 28\) body2\); did you mean 'rocker'"),
             ("weld.xml", CONNECT, '<weld name="w" body1="couplr" body2="rocker"/>',
              r"body 'couplr' does not exist in \S+weld\.xml \(<equality><weld name='w'> \(line 28\) body1\)"),
             ("site.xml", CONNECT, '<connect name="s" site1="coupler_point" site2="nosuch"/>',
              r"site 'nosuch' does not exist in \S+site\.xml \(<equality><connect name='s'> \(line 28\) site2\); "
              r"valid sites: 'coupler_point'"))
    for name, old, new, match in cases:
        with pytest.raises(SpecNameError, match=match):
            pkm.load(_fourbar(tmp_path, name, old, new))
    (tmp_path / "knee.urdf").write_text((EXAMPLES / "knee" / "knee.urdf").read_text())
    (tmp_path / "knee.closures.toml").write_text((EXAMPLES / "knee" / "knee.closures.toml").read_text()
                                                 .replace('frame_b = "thigh_pin"', 'frame_b = "thigh_pni"'))
    with pytest.raises(SpecNameError, match=r"frame 'thigh_pni' does not exist in \S+knee\.closures\.toml \(closure "
                                            r"'back_pin', line 17\); did you mean 'thigh_pin'"):
        pkm.load(tmp_path / "knee.closures.toml")
    from pkm.core.formats.load import load_texts

    texts = {n: (tmp_path / n).read_text() for n in ("knee.urdf", "knee.closures.toml")}
    with pytest.raises(SpecNameError, match=r"in up:knee\.closures\.toml \(closure 'back_pin', line 17\)"):
        load_texts(texts, "up")
    texts["knee.closures.toml"] += '# "thigh_pni" twice\n'
    with pytest.raises(SpecNameError, match=r"in up:knee\.closures\.toml \(closure 'back_pin'\); did you mean"):
        load_texts(texts, "up")
    (tmp_path / "g").mkdir()
    shutil.copy(EXAMPLES / "gepetto_fivebar" / "robot.urdf", tmp_path / "g" / "robot.urdf")
    (tmp_path / "g" / "robot.yaml").write_text((EXAMPLES / "gepetto_fivebar" / "robot.yaml").read_text()
                                               .replace("closedloop1_B", "closedloop1_X"))
    with pytest.raises(SpecNameError, match=r"frame 'closedloop1_X' does not exist in \S+robot\.yaml \(closure "
                                            r"'loop1', line 2\)"):
        pkm.load(tmp_path / "g" / "robot.yaml")


def test_a_writer_asked_for_what_its_format_cannot_hold_names_the_file_and_the_joint(tmp_path):
    """pkm.save to MJCF of a planar joint, to Gepetto's YAML of a floating base: a SpecError naming the file it was to
    write and the joint; nothing written."""
    from tests.core.model.test_mechanism import _floating_ankle
    from tests.core.twin.test_tree import zoo

    for mech, name, match in ((zoo(), "zoo.xml", r"zoo\.xml: MuJoCo's MJCF cannot hold mechanism '\w+', nothing "
                                                 r"written: .*joint '\w+': MJCF has no JointModelPlanar"),
                              (_floating_ankle()[0], "ankle.yaml", r"ankle\.yaml: Gepetto's URDF \+ YAML .*cannot "
                                                                   r"hold mechanism .*the floating base 'pelvis'")):
        with pytest.raises(PkmError, match=match):
            pkm.save(mech, tmp_path / name)
        assert not (tmp_path / name).exists()
