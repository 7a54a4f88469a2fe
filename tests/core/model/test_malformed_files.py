"""Malformed and hostile URDFs, closure specs and motion files: a PkmError in bounded time, nothing read outside.

Every case must end in a :class:`~pkm.errors.SpecError` (or another PkmError for a wrong argument type)
within :data:`LIMIT` seconds, run in a daemon thread so that a hang fails the test instead of the
session. Files opened by Python during a load are recorded by an audit hook, and external entities
point at a FIFO: a parser that followed one would block on it (and the test would see a reader on it).
"""

from __future__ import annotations

import errno
import os
import re
import sys
import threading
import time
from pathlib import Path

import pytest

import pkm
from pkm.core import ClosureSpec, Mechanism
from pkm.core.model.builder import from_files, from_strings
from pkm.core.model.spec import MAX_FILE_BYTES
from pkm.core.model.urdf import check_urdf, load_model
from pkm.data import spec_path, urdf_path
from pkm.errors import InvalidInputError, PkmError, SpecError, SpecNameError, UnknownNameError
from pkm.motion import load_motions

LIMIT = 10.0  # seconds allowed per malformed input

_OPENED: list[str] | None = None


_PACKAGE = Path(pkm.__file__).resolve().parent


def _audit(event: str, args) -> None:
    """Records the files opened, but pkm's own modules (a lazy import's source and bytecode: the test checks what a
    load reads of the user's files, and it must not depend on which modules an earlier test imported)."""
    if _OPENED is not None and event == "open" and args and isinstance(args[0], (str, bytes, os.PathLike)):
        path = os.fsdecode(args[0])
        if not Path(path).resolve().is_relative_to(_PACKAGE):
            _OPENED.append(path)


sys.addaudithook(_audit)


def outcome(fn, *args, limit: float = LIMIT, **kwargs):
    """Run ``fn`` in a daemon thread; return (exception or result, seconds, files opened). Fails on a hang."""
    global _OPENED
    box: dict = {}

    def target():
        try:
            box["value"] = fn(*args, **kwargs)
        except BaseException as exc:
            box["value"] = exc

    _OPENED = []
    t0 = time.perf_counter()
    th = threading.Thread(target=target, daemon=True)
    th.start()
    th.join(limit)
    opened, _OPENED = _OPENED, None
    assert not th.is_alive(), f"{fn.__name__} still running after {limit} s"
    return box["value"], time.perf_counter() - t0, opened


def refused(fn, *args, error=SpecError, match: str | None = None, **kwargs) -> PkmError:
    """``fn(*args)`` raises ``error`` (a PkmError) in bounded time; the exception is returned."""
    exc, _seconds, _ = outcome(fn, *args, **kwargs)
    assert isinstance(exc, error), f"expected {error.__name__}, got {exc!r}"
    assert isinstance(exc, PkmError)
    if match is not None:
        assert re.search(match, str(exc)), str(exc)
    assert "\n" not in str(exc)
    return exc


@pytest.fixture(scope="module")
def delta_urdf() -> str:
    return urdf_path("delta").read_text()


@pytest.fixture(scope="module")
def delta_spec() -> str:
    return spec_path("delta").read_text()


GOOD = """<robot name="r"><link name="base"/>
<link name="a"><inertial><origin xyz="0 0 0" rpy="0 0 0"/><mass value="1"/>
<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
<joint name="j" type="revolute"><parent link="base"/><child link="a"/><origin xyz="0.1 0 0" rpy="0 0 0"/>
<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"""


# ---------------------------------------------------------------------- URDF
def test_good_minimal_urdf_loads():
    """The reference document of the edits below is accepted (so each refusal is due to its edit)."""
    exc, _, _ = outcome(load_model, GOOD)
    assert not isinstance(exc, BaseException) and exc.nq == 1


@pytest.mark.parametrize("fraction", [0.0, 0.05, 0.3, 0.5, 0.77, 0.99])
def test_truncated_urdf_is_a_spec_error(delta_urdf, fraction):
    """A URDF cut anywhere is refused as not well-formed XML (or an empty document)."""
    refused(load_model, delta_urdf[:int(len(delta_urdf) * fraction)])


@pytest.mark.parametrize("edit, match", [
    (('<child link="a"/>', '<child link="ghost"/>'), "child link 'ghost' does not exist"),
    (('<parent link="base"/>', '<parent link="nowhere"/>'), "parent link 'nowhere' does not exist"),
    (('<limit lower="-1" upper="1" effort="1" velocity="1"/>', ""), r"needs a <limit> element"),
    (('<limit lower="-1" upper="1"', '<limit upper="1"'), r"states only its upper limit"),
    (('<origin xyz="0.1 0 0"', '<origin xyz="1e308 0 0"'), "absurdly large"),
    (('<origin xyz="0.1 0 0"', '<origin xyz="nan 0 0"'), "not finite"),
    (('rpy="0 0 0"/>\n<axis', 'rpy="0 inf 0"/>\n<axis'), "not finite"),
    (('<origin xyz="0.1 0 0"', '<origin xyz="0.1 0"'), "expected 3 numbers"),
    (('<origin xyz="0.1 0 0"', '<origin xyz="0.1 zero 0"'), "not a list of numbers"),
    (('<mass value="1"/>', '<mass value="-2"/>'), "negative mass"),
    (('<mass value="1"/>', '<mass value="1e300"/>'), "absurdly large"),
    (('ixx="1"', 'ixx="nan"'), "not finite"),
    (('izz="1"', 'izz="-inf"'), "not finite"),
    (('<origin xyz="0 0 0" rpy="0 0 0"/><mass', '<origin xyz="0 nan 0"/><mass'), "inertial origin"),
    (('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>'), "zero axis"),
    (('effort="1"', 'effort="nan"'), "effort"),
    (('velocity="1"', 'velocity="1e999"'), "velocity"),  # (1e99 is an exporter's "unlimited": read as none)
    (('type="revolute"', 'type="ball"'), "unknown type"),
    (("</robot>", '<link name="a"/></robot>'), "two links share a name"),
])
def test_malformed_urdf_elements_are_spec_errors(edit, match):
    """Missing links, missing limits, absurd, non-finite or unphysical numbers and zero axes are refused by name."""
    old, new = edit
    assert old in GOOD
    refused(load_model, GOOD.replace(old, new, 1), match=match)


def test_billion_laughs_is_refused_before_expansion():
    """Nested internal entities (10^9 expansions) are refused at the DOCTYPE, quickly."""
    ents = '<!ENTITY l0 "lol">' + "".join(f'<!ENTITY l{i} "{f"&l{i - 1};" * 10}">' for i in range(1, 10))
    bomb = f'<?xml version="1.0"?><!DOCTYPE robot [{ents}]><robot name="&l9;"><link name="base"/></robot>'
    exc = refused(load_model, bomb, match="DOCTYPE")
    assert "lollol" not in str(exc)
    _, seconds, _ = outcome(check_urdf, bomb)
    assert seconds < 1.0


@pytest.fixture
def fifo(tmp_path):
    """A named pipe: opening it for reading blocks until a writer comes, so a parser that follows it hangs."""
    path = tmp_path / "secret.fifo"
    os.mkfifo(path)
    return path


def _nobody_reads(path: Path) -> bool:
    """No process has ``path`` (a FIFO) open for reading (opening it to write without blocking fails)."""
    try:
        fd = os.open(path, os.O_WRONLY | os.O_NONBLOCK)
    except OSError as exc:
        return exc.errno == errno.ENXIO
    os.close(fd)
    return False


@pytest.mark.parametrize("template", [
    '<?xml version="1.0"?><!DOCTYPE r [<!ENTITY x SYSTEM "file://{p}">]><robot name="&x;"><link name="base"/></robot>',
    '<?xml version="1.0"?><!DOCTYPE r SYSTEM "file://{p}"><robot name="r"><link name="base"/></robot>',
    '<?xml version="1.0"?><!DOCTYPE r [<!ENTITY % x SYSTEM "file://{p}"> %x;]><robot name="r"/>',
    ('<robot name="r" xmlns:xi="http://www.w3.org/2001/XInclude"><xi:include href="{p}" parse="text"/>'
    '<link name="base"/></robot>'),
])
def test_external_entities_and_includes_never_open_the_file(fifo, template):
    """External entities, external DTDs and XInclude pointing at a local file are refused without opening it."""
    doc = template.format(p=fifo)
    exc, _, opened = outcome(load_model, doc)
    assert isinstance(exc, SpecError), repr(exc)
    assert str(fifo) not in opened
    assert _nobody_reads(fifo)


def test_external_entity_content_never_appears(tmp_path):
    """The content of a file named by an external entity appears neither in the error nor in any model."""
    secret = tmp_path / "secret.txt"
    secret.write_text("TOP-SECRET-CONTENT")
    doc = (f'<?xml version="1.0"?><!DOCTYPE r [<!ENTITY x SYSTEM "file://{secret}">]>'
           '<robot name="&x;"><link name="base"/></robot>')
    exc, _, opened = outcome(load_model, doc)
    assert isinstance(exc, SpecError) and "TOP-SECRET" not in str(exc)
    assert str(secret) not in opened


def test_huge_urdf_text_is_refused_without_parsing():
    """A URDF text larger than 16 MiB is refused at once."""
    huge = GOOD.replace("</robot>", "<!--" + "x" * (MAX_FILE_BYTES + 10) + "--></robot>")
    exc = refused(load_model, huge, match="larger than")
    assert outcome(check_urdf, huge)[1] < 2.0
    del exc


def test_too_many_links_is_refused():
    """More than 10,000 links or joints is refused before building anything."""
    many = '<robot name="r">' + "".join(f'<link name="l{k}"/>' for k in range(10_001)) + "</robot>"
    refused(load_model, many, match="more than 10000")


@pytest.mark.parametrize("text", [None, 42, ["<robot/>"], b"\xff\xfe<robot/>"])
def test_urdf_of_the_wrong_type_or_encoding_is_refused(text):
    """Non-text URDFs raise InvalidInputError; undecodable bytes a SpecError; never a TypeError."""
    exc, _, _ = outcome(load_model, text)
    assert isinstance(exc, (InvalidInputError, SpecError)), repr(exc)


def test_unencodable_urdf_text_is_a_spec_error():
    """A lone surrogate in the text (not encodable as UTF-8) is a SpecError, not a UnicodeEncodeError."""
    refused(load_model, GOOD.replace('name="r"', 'name="\ud800"'), match="UTF-8")


# ---------------------------------------------------------------------- closure spec (TOML)
@pytest.mark.parametrize("edit, match", [
    (lambda t: t[: len(t) // 2] + "[[clo", "not valid TOML"),
    (lambda t: t.replace('format = "pkm.closures/1"', 'format = "pkm.closures/2"'), "unsupported format"),
    (lambda t: t.replace('format = "pkm.closures/1"', "format = 1"), "must be a string"),
    (lambda t: t.replace('mechanism = "delta"\n', ""), "missing key 'mechanism'"),
    (lambda t: re.sub(r"platform_z = \[[^\]]*\]", 'platform_z = ["-0.375"]', t), "list of numbers"),
    (lambda t: re.sub(r"platform_z = \[[^\]]*\]", "platform_z = [true]", t), "list of numbers"),
    (lambda t: re.sub(r"platform_z = \[[^\]]*\]", "platform_z = [1e308]", t), "beyond"),
    (lambda t: re.sub(r"platform_z = \[[^\]]*\]", "platform_z = -0.375", t), "list of numbers"),
    (lambda t: t.replace("signs = { knee_1 = -1,", "signs = { knee_1 = true,", 1), r"\+1 or -1"),
    (lambda t: t.replace('default_branch = "knee_out"', 'default_branch = ["knee_out"]'), "must be a string"),
    (lambda t: t.replace('actuated = ["motor_1", "motor_2", "motor_3"]', 'actuated = "motor_1"'), "must be a list"),
    (lambda t: t.replace('urdf = "delta.urdf"', 'urdf = "../../etc/passwd"'), "stay inside"),
    (lambda t: t.replace('urdf = "delta.urdf"', 'urdf = "/etc/passwd"'), "stay inside"),
    (lambda t: t.replace('urdf = "delta.urdf"', 'urdf = ""'), "must not be empty"),
    (lambda t: t.replace('frame_b = "platform_ball_1"', 'frame_b = "forearm_1_tip"'), "two different frames"),
    (lambda t: t.replace("R = 0.15", "R = nan"), "finite numbers or strings"),
    (lambda t: "x = " + "[" * 5000 + "]" * 5000 + "\n" + t, "nested too deeply|not valid TOML"),
])
def test_malformed_spec_is_a_spec_error(delta_spec, edit, match):
    """Truncation, type confusion, wrong format version, missing keys and escaping paths are SpecErrors."""
    text = edit(delta_spec)
    assert text != delta_spec
    refused(ClosureSpec.from_toml, text, match=match)


def test_spec_naming_missing_frames_and_joints_is_a_spec_error(delta_urdf, delta_spec):
    """A spec that references a frame or joint the URDF lacks is a SpecError that lists the valid names."""
    for old, new in (('end_effector = "platform"', 'end_effector = "platfrom"'),
                     ('frame_a = "forearm_2_tip"', 'frame_a = "forearm_9_tip"'),
                     ('"motor_3"]', '"motor_33"]'),
                     ("knee_1 = [", "knee_99 = [")):
        exc = refused(from_strings, delta_urdf, delta_spec.replace(old, new, 1), error=SpecNameError)
        assert isinstance(exc, UnknownNameError) and exc.valid and exc.source == "<string>"


def test_spec_reference_of_the_wrong_length_is_a_spec_error(delta_urdf, delta_spec):
    """A [reference] entry with the wrong number of coordinates is reported as a defect of the spec."""
    refused(from_strings, delta_urdf, re.sub(r"platform_z = \[[^\]]*\]", "platform_z = [1, 2]", delta_spec),
            match=r"\[reference\]")


def _write(folder: Path, spec: str, urdf: str | None) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "m.closures.toml").write_text(spec)
    if urdf is not None:
        (folder / "delta.urdf").write_text(urdf)
    return folder / "m.closures.toml"


def test_files_load_and_only_the_two_files_are_opened(tmp_path, delta_urdf, delta_spec):
    """A valid spec and URDF in one folder load; the only files opened are those two."""
    path = _write(tmp_path / "ok", delta_spec, delta_urdf)
    mech, _, opened = outcome(from_files, path)
    assert isinstance(mech, Mechanism)
    assert {Path(p).resolve() for p in opened} == {path.resolve(), (tmp_path / "ok" / "delta.urdf").resolve()}


def test_urdf_path_escaping_the_folder_is_refused_without_opening(tmp_path, delta_urdf, delta_spec):
    """A URDF reached through a symbolic link that leaves the spec's folder is refused, never opened."""
    outside = tmp_path / "outside.urdf"
    outside.write_text(delta_urdf)
    folder = tmp_path / "spec"
    folder.mkdir()
    os.symlink(outside, folder / "link.urdf")
    path = _write(folder, delta_spec.replace('urdf = "delta.urdf"', 'urdf = "link.urdf"'), None)
    exc, _, opened = outcome(from_files, path)
    assert isinstance(exc, SpecError) and "outside the spec's folder" in str(exc)
    assert str(outside) not in opened and all(Path(p).resolve() != outside.resolve() for p in opened)


def test_spec_pointing_at_etc_passwd_never_opens_it(tmp_path, delta_spec):
    """urdf = "../../etc/passwd" (relative escape) and "/etc/passwd" (absolute) are refused before any read."""
    for target in ("../../../../../../etc/passwd", "/etc/passwd"):
        path = _write(tmp_path / "p", delta_spec.replace('urdf = "delta.urdf"', f'urdf = "{target}"'), None)
        exc, _, opened = outcome(from_files, path)
        assert isinstance(exc, SpecError) and "root:" not in str(exc)
        assert not any("passwd" in p for p in opened)


@pytest.mark.parametrize("kind", ["fifo", "dev_zero", "directory", "missing", "sparse_huge", "not_utf8"])
def test_spec_files_that_are_not_small_regular_text_files_are_refused(tmp_path, kind):
    """FIFOs and devices are not read (no hang), directories and missing files are errors, huge files are refused
    from their size, non-UTF-8 bytes are refused: each a SpecError in bounded time."""
    path = tmp_path / "x.closures.toml"
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "dev_zero":
        path = Path("/dev/zero")
    elif kind == "directory":
        path = tmp_path
    elif kind == "sparse_huge":
        with open(path, "wb") as f:
            f.truncate(MAX_FILE_BYTES + 1)
    elif kind == "not_utf8":
        path.write_bytes(b'format = "\xff\xfe"\n')
    exc, seconds, _ = outcome(ClosureSpec.load, path)
    assert isinstance(exc, SpecError), repr(exc)
    assert seconds < 2.0
    if kind == "fifo":
        assert _nobody_reads(path)


def test_fifo_urdf_next_to_the_spec_is_not_read(tmp_path, delta_spec):
    """A URDF that is a FIFO inside the folder is refused as not a regular file (the load does not block)."""
    folder = tmp_path / "f"
    folder.mkdir()
    os.mkfifo(folder / "delta.urdf")
    exc, _, _ = outcome(from_files, _write(folder, delta_spec, None))
    assert isinstance(exc, SpecError) and "not a regular file" in str(exc)
    assert _nobody_reads(folder / "delta.urdf")


@pytest.mark.parametrize("path", [None, 3, b"/tmp/x", "", "a\0b"])
def test_spec_paths_of_the_wrong_type_are_invalid_input(path):
    """None, numbers, bytes, empty strings and NUL characters are refused as InvalidInputError."""
    exc, _, _ = outcome(from_files, path)
    assert isinstance(exc, InvalidInputError), repr(exc)


# ---------------------------------------------------------------------- motion files
MOTION = '''format = "pkm.motion/1"
mechanism = "prs3"
coordinates = ["z"]
[case.a]
duration = 1.0
dt = 0.5
z = { law = "cosine", offset = 0.8, amplitude = 0.01, omega = 1.0 }
'''


@pytest.mark.parametrize("edit, match", [
    (("omega = 1.0", "omega = 1e308"), "magnitude"),
    (("amplitude = 0.01", "amplitude = true"), "finite number"),
    (("amplitude = 0.01", 'amplitude = "0.01"'), "finite number"),
    (("dt = 0.5", "dt = 1e-300"), "samples"),
    (('law = "cosine"', 'law = ["cosine"]'), "needs a law"),
    (('"pkm.motion/1"', '"pkm.motion/7"'), "format"),
    (("[case.a]", "[case.a"), "not valid TOML"),
])
def test_malformed_motion_files_are_spec_errors(tmp_path, edit, match):
    """Absurd coefficients, type confusion, a sampling of 10^300 points, bad laws and formats are refused."""
    path = tmp_path / "m.toml"
    path.write_text(MOTION.replace(*edit))
    refused(load_motions, path, match=match)


def test_motion_file_that_is_a_device_is_not_read():
    """/dev/zero as a motion file is refused at once (not read forever)."""
    refused(load_motions, "/dev/zero", match="not a regular file")


def test_shipped_files_still_load():
    """The shipped mechanisms and motions pass every check above."""
    for name in pkm.MECHANISMS:
        assert pkm.load(name).nq > 0
    assert load_motions("prs3_motions.toml")


def test_spec_text_with_a_lone_surrogate_is_a_spec_error(delta_urdf, delta_spec):
    """A spec whose names cannot be encoded as UTF-8 (they go to Pinocchio) is refused as a SpecError."""
    refused(from_strings, delta_urdf, delta_spec.replace('end_effector = "platform"',
                                                                    'end_effector = "\ud800"'), match="UTF-8")
