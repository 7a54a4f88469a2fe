"""The exported C library (``pkm.export_c``), built strictly and run from Python: the ankle's and the knee's
functions against pkm's generic core to 1e-12 (relative to max(1, the largest value)), no allocation or I/O in the
object file, a status (never a NaN) for NaN, infinite and unreachable inputs, the mode and limit codes, the named
mode ids of the header proven in C (the 3-RRR's eight branches), the files a user builds with ``make``, and the
mechanisms it refuses. Every shipped and acceptance-set mechanism is run by
``tools/export_harness.py`` in CI (gcc, and clang where present)."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import pkm
from pkm.core.export import ExportError, export_c
from pkm.core.export.harness import FORBIDDEN, build, check_modes, compare, domain
from pkm.core.export.library import STATUS
from pkm.errors import PkmError, SpecError
from tests.test_acceptance import ACCEPTANCE

pytestmark = pytest.mark.skipif(shutil.which("cc") is None, reason="needs a C compiler (cc)")
TOL = 1e-12
MATH = {"sin", "cos", "sincos", "tan", "asin", "acos", "atan", "atan2", "sqrt", "exp", "log", "pow", "fabs", "fmin",
        "fmax", "floor", "ceil", "fmod", "copysign", "hypot", "sinh", "cosh", "tanh"}


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """The ankle's and the knee's libraries, exported and built once (-O2, strict)."""
    out = {}
    for name in ("ankle", "knee"):
        mech = pkm.load(ACCEPTANCE[name][0])
        lib = export_c(mech, tmp_path_factory.mktemp(name))
        out[name] = (mech, build(lib))
    return out


@pytest.mark.parametrize("name", ["ankle", "knee"])
def test_every_function_matches_pkm(built, name):
    mech, h = built[name]
    errors = compare(mech, h)
    assert errors.pop("status") == 0
    assert set(errors) >= {"fk", "ik", "jacobians", "maps", "jdot_qdot", "inverse_dynamics", "mass_matrix", "gravity"}
    assert max(errors.values()) <= TOL, errors


def test_the_object_file_allocates_and_prints_nothing(built):
    for _, h in built.values():
        assert h.symbols, "nm listed no undefined symbol: the check did not run"
        assert not h.symbols & FORBIDDEN
        assert h.symbols <= MATH, sorted(h.symbols - MATH)


@pytest.mark.parametrize("name", ["ankle", "knee"])
def test_outside_the_domain_a_status_never_a_nan(built, name):
    mech, h = built[name]
    problems, statuses = domain(mech, h)
    assert problems == []
    # driven 3 rad along a line, each mechanism leaves its workspace: both their joint limits, the ankle its
    # workspace through a fold, where fk, following its path in steps, stops NOT_CONVERGED as pkm.close_loops raises
    # (before the path, one Newton jump left for the other assembly mode: LEFT_MODE)
    met = set(statuses) - {"OK"}
    assert met <= {"NOT_CONVERGED", "LEFT_MODE", "OUTSIDE_LIMITS", "SINGULAR"} and "OUTSIDE_LIMITS" in met
    assert "NOT_CONVERGED" in met or name == "knee", statuses


def test_the_mode_asked_for_and_the_limits(built):
    mech, h = built["ankle"]
    ref = mech.q_reference
    qa = mech.actuated_q(ref)
    row = np.hstack([qa + 0.01, ref, [1.0]])  # the reference is mode 0: asking for mode 1 fails
    got = h.run("fk", row[None])[0]
    assert STATUS[int(got[0])] == "LEFT_MODE" and got[3] == 0
    solved = pkm.close_loops(mech, qa + 0.01, ref, tol=1e-14)
    assert np.abs(pkm.TaskMap.of(mech).error(pkm.TaskMap.of(mech).value(solved.q), got[4 + mech.nq:])).max() <= TOL
    got = h.run("fk", np.hstack([qa + 0.01, ref, [0.0]])[None])[0]
    assert STATUS[int(got[0])] == "OK" and 1 <= got[1] <= 6
    knee, hk = built["knee"]
    assert hk.lib.limits
    y = pkm.TaskMap.of(knee).value(knee.q_reference)
    far = hk.run("ik", np.hstack([y + 2.5, knee.q_reference, [-1.0]])[None])[0]
    assert STATUS[int(far[0])] in ("OUTSIDE_LIMITS", "NOT_CONVERGED", "SINGULAR") and np.isfinite(far).all()


def test_the_named_mode_ids_are_the_ids_the_c_returns_in_those_modes(built, tmp_path):
    """``<NAME>_IK_MODE_<BRANCH>`` for each branch of the spec (the 3-RRR's eight working modes: eight distinct ids),
    ``_FK_MODE_REFERENCE`` and ``_IK_MODE_REFERENCE``: compiled in C, each equal to what ``ik_mode`` returns at the
    branch's configuration pkm computes, and ``ik`` asked for it from there stays on the branch
    (:func:`check_modes`). A spec without branches (the ankle's) gets the reference's ids, and the header says why."""
    mech = pkm.load("rrr3")
    h = build(export_c(mech, tmp_path / "rrr3"), optimise="-O0")
    assert check_modes(mech, h) == []
    ik = h.lib.modes["ik"]
    assert set(ik) == {"REFERENCE"} | {f"MODE{k}" for k in range(1, 9)} and ik["MODE1"] == ik["REFERENCE"] == 0
    assert len({ik[f"MODE{k}"] for k in range(1, 9)}) == 8 and h.lib.modes["fk"] == {"REFERENCE": 0}
    header = h.lib.header.read_text()
    assert f"#define RRR3_IK_MODE_MODE8 {ik['MODE8']}\n" in header and "(on branch mode1)" in header
    ankle, ha = built["ankle"]
    assert check_modes(ankle, ha) == [] and ha.lib.modes == {"fk": {"REFERENCE": 0}, "ik": {"REFERENCE": 0}}
    text = ha.lib.header.read_text()
    assert "the spec names no branch" in text and "ANKLE_FK_MODE_REFERENCE 0" in text


def test_the_folder_builds_with_make_and_runs(built, tmp_path):
    if shutil.which("make") is None:
        pytest.skip("no make")
    lib = built["ankle"][1].lib
    folder = tmp_path / "ankle"
    shutil.copytree(lib.directory, folder, ignore=shutil.ignore_patterns("*.o", "harness*"))
    assert subprocess.run(["make", "-s", "CFLAGS=-std=c99 -O2 -Wall -Wextra -Werror -pedantic"], cwd=folder,
                          capture_output=True, check=False).returncode == 0
    run = subprocess.run(["./example"], cwd=folder, capture_output=True, text=True, check=False)
    assert run.returncode == 0 and "inverse dynamics: status 0" in run.stdout
    first = re.search(r"```text\n(first fk: [^\n]*)\n```", (folder / "README.md").read_text()).group(1)
    assert run.stdout.startswith(first + "\n")  # (the README's example prints what the README says)
    assert "ik: status 0, mode 0" in run.stdout and "working mode id 0 (the reference's)" in run.stdout
    header = (folder / "ankle.h").read_text()
    assert "ANKLE_MAX_ITER" in header and "fk_step" in header and " mul " in header and "ik bit 1" in header


def test_what_cannot_be_exported_is_refused(tmp_path, monkeypatch, all_actuated):
    """A task that does not fix the joints, a mechanism with no passive joint for the forward kinematics (every
    joint actuated: it was refused as 'structurally singular'), and a joint kind the twin does not write (the
    twin's refusal, forced here: no shipped file has a helical joint), are refused with the mechanism and the
    reason."""
    spec = Path(ACCEPTANCE["ankle"][0])
    shutil.copy(spec.parent / "ankle.urdf", tmp_path)
    (tmp_path / spec.name).write_text(spec.read_text().replace('joints = ["ankle_pitch", "ankle_roll"]',
                                                                'joints = ["ankle_pitch"]'))
    mech = pkm.load(tmp_path / spec.name)
    with pytest.raises(ExportError, match="do not fix every joint") as e:
        export_c(mech, tmp_path / "out")
    assert e.value.mechanism == mech.name and isinstance(e.value, PkmError)
    assert not (tmp_path / "out").exists()
    with pytest.raises(ExportError, match="no passive coordinate for the forward kinematics to solve for"):
        export_c(all_actuated, tmp_path / "all")

    def helical(mech):
        raise SpecError(mech.source, "joint 'screw': the symbolic twin does not handle a JointModelHelical")

    monkeypatch.setattr("pkm.core.export.model.Twin", helical)
    with pytest.raises(ExportError, match="JointModelHelical"):
        export_c(pkm.load(ACCEPTANCE["knee"][0]), tmp_path / "knee")


def test_the_files_names_reach_the_c_unchanged(tmp_path):
    """A joint whose name holds the template's own "p_" (``grip_pin``) keeps it in the library's name tables."""
    from pkm.core.formats.load import load_texts

    folder = Path(ACCEPTANCE["knee"][0]).parent
    files = {f.name: f.read_text() for f in folder.iterdir() if f.suffix in (".urdf", ".toml")}
    urdf = next(n for n in files if n.endswith(".urdf"))
    files[urdf] = files[urdf].replace('"knee_front"', '"grip_pin"')
    spec = next(n for n in files if n.endswith(".toml"))
    files[spec] = files[spec].replace('"knee_front"', '"grip_pin"')
    mech = load_texts(files)
    assert "grip_pin" in mech.limits
    source = export_c(mech, tmp_path / "knee").source.read_text()
    assert '"grip_pin"' in source


def test_a_branch_without_a_constant_is_said_so_and_names_that_clash_are_refused(tmp_path):
    """A branch pkm cannot reach at the reference task value (the Delta's platform_z > 0, the platform above the base,
    the reference's z being -0.254 m; not platform_x < 0 at the reference's x = 0, which a solve may end at -3e-17)
    gets no constant: a PkmWarning and the header's line (:func:`mode_constants`) say why. Two branches whose names make one C identifier are refused
    before anything is written."""
    from pkm.core.export.library import mode_constants
    from pkm.core.export.model import ExportModel
    from pkm.core.formats.load import load_texts
    from pkm.data import data_dir
    from pkm.errors import PkmWarning

    folder = data_dir("urdf")
    spec = (folder / "delta.closures.toml").read_text()
    extra = '\n[branch.up]\nsigns = { platform_z = 1 }\n'
    files = {"delta.urdf": (folder / "delta.urdf").read_text(), "delta.closures.toml": spec + extra}
    mech = load_texts(files)
    with pytest.warns(PkmWarning, match="branch 'up'.*no constant"):
        modes, lines = mode_constants(mech, ExportModel(mech))
    assert set(modes["ik"]) == {"REFERENCE", "KNEE_OUT", "KNEE_IN"}
    assert any(line.startswith("branch 'up' (platform_z > 0): no constant, pkm finds no configuration")
               for line in lines)
    files["delta.closures.toml"] = spec + '\n[branch.Knee-In]\nsigns = { knee_1 = 1 }\n'
    with pytest.raises(ExportError, match="'knee_in' and 'Knee-In' make the same C name KNEE_IN"):
        export_c(load_texts(files), tmp_path / "clash")
    assert not (tmp_path / "clash").exists()


def test_motors_driving_the_joints_through_a_map_are_named_with_it(tmp_path):
    """A differential on the 3-RRR's first two motors (``[motors]``): the header names each motor by its name and
    coefficients, and the built library's ``motor_names`` and ``motor_map`` (C, column-major) are the mechanism's;
    without ``[motors]``, the actuated joints and the identity."""
    import dataclasses

    from pkm.core.export.harness import STRICT

    rrr3 = pkm.load("rrr3")
    a = rrr3.actuated_names
    spec = dataclasses.replace(rrr3.spec, motors={"sum": {a[0]: 1.0, a[1]: 1.0}, "diff": {a[0]: 0.5, a[1]: -2.0}})
    geared = pkm.from_strings(rrr3.urdf, spec)
    lib = export_c(geared, tmp_path)
    header = lib.header.read_text()
    assert f"sum = 1 {a[0]} + 1 {a[1]}; diff = 0.5 {a[0]} - 2 {a[1]}; {a[2]} = 1 {a[2]}." in header
    (tmp_path / "main.c").write_text("""#include <stdio.h>
#include "rrr3.h"
int main(void) {
  int i;
  for (i = 0; i < RRR3_NA; ++i) printf("%s ", rrr3_motor_names[i]);
  printf("\\n");
  for (i = 0; i < RRR3_NA * RRR3_NA; ++i) printf("%.17g ", rrr3_motor_map[i]);
  printf("\\n");
  return 0;
}
""")
    subprocess.run(["cc", *STRICT, "-O0", "-o", "main", "main.c", str(lib.source), "-lm"], cwd=tmp_path, check=True,
                   capture_output=True)
    names, matrix = subprocess.run([str(tmp_path / "main")], capture_output=True, text=True,
                                   check=True).stdout.splitlines()
    assert tuple(names.split()) == geared.motor_map.names == ("sum", "diff", a[2])
    assert np.array(matrix.split(), dtype=float).tolist() == geared.motor_map.matrix.ravel(order="F").tolist()
    assert "Motors: one per actuated joint" in export_c(rrr3, tmp_path / "plain").header.read_text()
