"""The ``pkm`` command line (pkm.cli), run through its real entry points: ``python -m pkm`` and the ``pkm`` script."""

from __future__ import annotations

import csv
import dataclasses
import json
import math
import re
import signal
import socket
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import pkm
from pkm import cli
from pkm.bench import NAMES as BENCHMARKS
from pkm.mechanisms import delta as D
from pkm.mechanisms import module, names
from tests.papers.figures import inspected


def run(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """``python -m pkm ARGS`` in a subprocess (text output, no check)."""
    return subprocess.run([sys.executable, "-m", "pkm", *args], check=False, capture_output=True, text=True,
                          cwd=cwd, timeout=120)


def one_error_line(proc: subprocess.CompletedProcess) -> str:
    """The single ``pkm: error: ...`` line a failing command prints (asserted: nothing else, no traceback)."""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("pkm: error: "), proc.stderr
    assert proc.stdout == ""
    return lines[0]


# ---------------------------------------------------------------------- units of the parameters
CASES = [(name, f.name) for name in pkm.MECHANISMS for f in dataclasses.fields(module(name).Params)]


@pytest.mark.parametrize("mechanism,field", CASES)
def test_every_parameter_has_a_unit_in_its_metadata_and_docstring(mechanism, field):
    """Every Params field carries units that the CLI knows in its metadata, the same as in brackets in its docstring,
    unless it is text or an integer."""
    info = cli.param_info(mechanism)[field]
    assert info.description, f"{mechanism}.{field} is not in the Attributes section"
    if info.unitless:
        return
    assert info.units, f"{mechanism}.{field}: no unit in its metadata (pkm.mechanisms._common.param)"
    known = {"m", "rad", "kg", "kg m^2", "-"}
    assert set(info.units) <= known, info.units
    documented = tuple(dict.fromkeys(re.findall(r"\[([A-Za-z][A-Za-z0-9^ /*.-]*|-)\]", info.description)))
    assert info.units == documented, f"{mechanism}.{field}: metadata {info.units} but the docstring says {documented}"


def test_attribute_parser_reads_grouped_entries_and_continuations():
    """A grouped docstring entry gives each field the same unit; a continued entry keeps its continuation."""
    prs3 = cli.param_info("prs3")
    assert prs3["Ixx3"].units == prs3["Izz3"].units == ("kg m^2",)
    assert prs3["reference"].units == ("m", "rad")
    assert "(eq. 41)" in prs3["reference"].description and prs3["reference"].length == 3
    assert cli.param_info("delta")["La"].units == ("m",) and cli.param_info("delta")["La"].default == 0.11


# ---------------------------------------------------------------------- list
def test_console_script_lists_every_mechanism_as_json():
    """The installed ``pkm`` script prints every mechanism's parameters with defaults and units, SI."""
    script = Path(sys.executable).with_name("pkm")
    proc = subprocess.run([str(script), "list", "--json"], check=False, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    data = json.loads(proc.stdout)["mechanisms"]
    assert list(data) == list(names(with_files=True))  # a subprocess: the shipped registry
    assert data["delta"]["parameters"]["R"] == {**data["delta"]["parameters"]["R"], "default": 0.15, "unit": "m"}
    assert data["delta"]["actuated"] == {"motor_1": "rad", "motor_2": "rad", "motor_3": "rad"}
    assert data["prs3"]["actuated"]["slider_1"] == "m" and data["hexapod"]["task"]["beta_1"] == "rad"


def test_list_as_text_and_a_bad_option(capsys):
    """``pkm list`` names each mechanism, its task origin, a reachable pose (which ``pkm ik`` takes back as it is
    printed) and its parameters; an unknown option exits 2 with one line."""
    ok = run("list")
    assert ok.returncode == 0
    assert all(f"{m}: " in ok.stdout for m in names(with_files=True)) and "task (--pose): x [m], y [m], z [m]" in ok.stdout
    rrr3 = ok.stdout[ok.stdout.index("rrr3: "):]
    assert "task origin: the base joint A1" in rrr3
    pose = re.search(r"reference pose \(reachable\): (.*)", rrr3).group(1).split()
    assert pose == ["x=50cm", "y=28.87cm", "yaw=5deg"]
    assert cli.main(["ik", "rrr3", "--pose", *pose]) == 0 and json.loads(capsys.readouterr().out)["converged"]
    bad = run("list", "--bad")
    assert bad.returncode == 2 and "unrecognized arguments: --bad" in one_error_line(bad)


# ---------------------------------------------------------------------- ik, fk
def test_ik_prints_si_json_matching_the_closed_form():
    """``pkm ik delta --pose x=2cm z=-360mm --param R=120mm``: converged, SI, motors equal to the paper's IK."""
    proc = run("ik", "delta", "--pose", "x=2cm", "z=-360mm", "--param", "R=120mm", "--branch", "knee_out")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["units"]["length"] == "m" and out["units"]["angle"] == "rad"
    assert out["converged"] and out["residual"] < 1e-9 and out["branch"] == "knee_out"
    assert out["target"] == {"x": 0.02, "y": 0.0, "z": -0.36}
    assert np.allclose([out["task"][k] for k in "xyz"], [0.02, 0.0, -0.36], atol=1e-9)
    expected = D.inverse_kinematics(D.DeltaParams(R=0.12), [0.02, 0.0, -0.36], "knee_out")
    assert np.allclose(list(out["actuated"].values()), expected, atol=1e-8)
    assert out["joints"]["motor_1"] == out["actuated"]["motor_1"] and "knee_1" in out["joints"]


def test_ik_of_an_unreachable_pose_names_the_leg():
    """An unreachable pose exits 1 with one line naming the leg; with --debug the traceback comes first."""
    proc = run("ik", "delta", "--pose", "z=-1")
    assert proc.returncode == 1
    assert "pose unreachable: leg 1 misses by" in one_error_line(proc)
    debug = run("--debug", "ik", "delta", "--pose", "z=-1")
    assert debug.returncode == 1 and debug.stderr.startswith("Traceback")
    assert "UnreachableError" in debug.stderr and debug.stderr.strip().splitlines()[-1].startswith("pkm: error: pose")


def test_fk_prints_the_pose_of_the_closed_form():
    """``pkm fk delta --joints motor_1=-50deg``: the platform position equals the paper's sphere intersection."""
    proc = run("fk", "delta", "--joints", "motor_1=-50deg")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    qa = list(out["actuated"].values())
    assert math.isclose(qa[0], math.radians(-50), rel_tol=1e-12) and out["converged"]
    assert np.allclose([out["task"][k] for k in "xyz"], D.forward_kinematics(D.DeltaParams(), qa), atol=1e-9)


@pytest.mark.parametrize("args,status,message", [
    (("fk", "delta", "--joints", "motor_9=1"), 2, "valid actuated joints: 'motor_1', 'motor_2', 'motor_3'"),
    (("ik", "scara", "--pose", "x=0"), 2, "mechanism 'scara' does not exist in the registry, nor is it a file"),
    (("ik", "delta", "--param", "Rb=0.1", "--pose", "z=-0.36"), 2, "parameter 'Rb' does not exist in delta"),
    (("ik", "delta", "--param", "R=3deg", "--pose", "z=-0.36"), 2, "'deg' is an angle unit but R is in [m]"),
    (("ik", "delta", "--pose", "z=-36in"), 2, "unknown unit 'in'"),
    (("ik", "delta", "--pose", "z"), 2, "'z' must read NAME=VALUE"),
    (("ik", "delta", "--param", "R=-0.1", "--pose", "z=-0.36"), 1, "R: must be"),
    (("ik", "delta", "--pose", "z=-0.36", "--branch", "up"), 2, "'knee_out', 'knee_in'"),
    (("map", "rrr3", "--axis", "x=0:1"), 2, "expected NAME=START:STOP:COUNT"),
    (("map", "rrr3", "--axis", "q=0:1:3"), 2, "valid task coordinates: 'x', 'y', 'yaw'"),
    (("map", "rrr3", "--axis", "x=20cm:80cm:5"), 1, "give the characteristic length"),
])
def test_bad_command_lines_give_one_helpful_line(args, status, message):
    """Unknown names, bad units, a missing '=' exit 2, an invalid parameter value exits 1; one line each."""
    proc = run(*args)
    assert proc.returncode == status
    assert message in one_error_line(proc)


def test_map_prints_a_summary_and_writes_the_figure_and_the_numbers(tmp_path):
    """``pkm map`` with units on the axes: the summary's GCI is the mean of the CSV's CIs; the PNG exists."""
    proc = run("map", "rrr3", "--axis", "x=30cm:70cm:41", "--axis", "y=10cm:50cm:41", "--pose", "yaw=0deg",
               "--length", "5.7735cm", "--png", str(tmp_path / "m.png"), "--csv", str(tmp_path / "m.csv"))
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["nodes"] == 41 * 41 and 0 < out["reachable"] <= out["nodes"]
    rows = list(csv.DictReader((tmp_path / "m.csv").open()))
    assert len(rows) == 41 * 41 and sum(int(r["reachable"]) for r in rows) == out["reachable"]
    ci = [float(r["ci_2"]) for r in rows if r["reachable"] == "1"]
    assert math.isclose(sum(ci) / len(ci), out["gci_2"], rel_tol=1e-12)
    assert (tmp_path / "m.png").stat().st_size > 10_000


def test_the_map_figure_passes_the_figure_check(tmp_path, capsys):
    """The PNG of ``pkm map`` (in process, coarse): a caption naming the mechanism, units on both axes, a colour bar,
    the white of unreachable nodes in a legend."""
    with inspected(paper=False) as found:
        assert cli.main(["map", "rrr3", "--axis", "x=0cm:100cm:21", "--axis", "y=-10cm:90cm:21", "--pose", "yaw=0deg",
                         "--length", "5.7735cm", "--png", str(tmp_path / "m.png")]) == 0
    assert found == {"m": []}


# ---------------------------------------------------------------------- preview, report, bench
def test_preview_writes_html_and_refuses_an_unknown_mechanism(tmp_path):
    """``pkm preview delta --pose z=-0.36 --html F`` writes an HTML scene; an unknown mechanism exits 2."""
    bad = run("preview", "scara", "--html", str(tmp_path / "x.html"))
    assert bad.returncode == 2 and "mechanism 'scara' does not exist" in one_error_line(bad)
    pytest.importorskip("pkm.viz", reason="pkm.viz is written in the same issue")
    page = tmp_path / "delta.html"
    ok = run("preview", "delta", "--pose", "z=-0.36", "--html", str(page))
    assert ok.returncode == 0, ok.stderr
    assert page.stat().st_size > 1000 and "<html" in page.read_text()[:1000].lower()


def test_preview_opens_the_viewer_at_given_joints_and_returns_with_no_wait():
    """``pkm preview delta --joints motor_1=-50deg --no-wait`` starts a meshcat viewer, prints its URL and exits 0;
    an unknown joint exits 2 before any viewer starts."""
    pytest.importorskip("pkm.viz", reason="pkm.viz is written in the same issue")
    ok = run("preview", "delta", "--joints", "motor_1=-50deg", "--no-wait")
    assert ok.returncode == 0, ok.stderr
    assert ok.stdout.startswith("viewer: http://")
    bad = run("preview", "delta", "--joints", "elbow=1", "--no-wait")
    assert bad.returncode == 2 and "valid actuated joints" in one_error_line(bad)


def children(pid: int) -> list[int]:
    """Processes whose parent is ``pid`` (from /proc)."""
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue
        if int(fields[1]) == pid:
            out.append(int(stat.parent.name))
    return out


def port_is_free(port: int) -> bool:
    with socket.socket() as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            s.bind(("127.0.0.1", port))
        except OSError:
            return False
    return True


def default_sigint() -> None:
    """In the child: Ctrl-C as in a terminal's foreground (a suite run from a background job ignores SIGINT, and
    Python keeps an ignored SIGINT ignored)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def start_live_preview(*args: str) -> tuple[subprocess.Popen, str]:
    """``python -m pkm preview ARGS`` (live viewer, waiting) started; returns it once it printed its URL."""
    proc = subprocess.Popen([sys.executable, "-m", "pkm", "preview", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, preexec_fn=default_sigint)
    line = proc.stdout.readline()
    assert line.startswith("viewer: http://"), (line, proc.stderr.read() if proc.poll() is not None else "")
    return proc, line.split()[1]


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads the process table from /proc")
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP, signal.SIGINT])
def test_a_killed_live_preview_leaves_no_meshcat_server_behind(sig):
    """``pkm preview delta`` killed with SIGTERM (or SIGHUP, Ctrl-C) stops its meshcat server, whose port is then
    free: meshcat starts the server in a session of its own and would otherwise leave it running."""
    pytest.importorskip("meshcat")
    proc, url = start_live_preview("delta")
    port = int(url.split(":")[2].split("/")[0])
    try:
        servers = children(proc.pid)
        assert servers and not port_is_free(port)
        proc.send_signal(sig)
        assert proc.wait(timeout=20) == 0
    finally:
        proc.kill()
    for pid in servers:
        assert not Path(f"/proc/{pid}").exists(), f"meshcat server {pid} outlived 'pkm preview'"
    assert port_is_free(port)


def test_report_writes_the_hexapod_rows_and_refuses_an_unknown_paper(tmp_path):
    """``pkm report --paper hexapod --no-figures`` writes summary.json and prints every row; a bad paper exits 2."""
    proc = run("report", "--out", str(tmp_path), "--paper", "hexapod", "--no-figures")
    assert proc.returncode == 0, proc.stderr
    rows = json.loads((tmp_path / "summary.json").read_text())["papers"]["hexapod"]["rows"]
    assert rows and all(r["id"] in proc.stdout for r in rows)
    assert (tmp_path / "report.md").exists() and not (tmp_path / "figures").exists()
    bad = run("report", "--out", str(tmp_path), "--paper", "hexapod", "--paper", "ufo")
    assert bad.returncode == 2 and "valid papers: 'hexapod', 'rrr3', 'delta', 'prs3'" in one_error_line(bad)


def test_bench_runs_a_benchmark_and_refuses_an_unknown_one(tmp_path):
    """``pkm bench opcount --json`` (about 2 s) prints its JSON under its name, from any directory; an unknown
    benchmark exits 2 listing them."""
    proc = run("bench", "opcount", "--json", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert list(out) == ["opcount"] and out["opcount"]
    bad = run("bench", "speed")
    line = one_error_line(bad)
    assert bad.returncode == 2 and ", ".join(repr(n) for n in BENCHMARKS) in line


def test_bench_quick_runs_every_benchmark_and_refuses_bad_arguments(tmp_path):
    """``pkm bench --quick --json`` runs every one (shipped in the package, so from any directory) with small
    sizes; arguments a benchmark does not take exit 2 with one line."""
    proc = run("bench", "--quick", "--json", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert sorted(out) == sorted(BENCHMARKS) == ["assembly", "dynamics", "hexapod", "kinematics", "opcount", "sweep", "twin",
                                                 "workspace"]
    assert all(r["equals_serial"] for k, r in out["sweep"]["runs"].items() if k != "serial")
    assert [r["samples"] for r in out["kinematics"]] == [3] * 5  # one row per shipped mechanism
    assert out["dynamics"]["max_force_difference_to_baseline_N"]["pkm"] < 1e-9
    bad = run("bench", "kinematics", "--", "--samples", "3")
    assert bad.returncode == 2 and "unrecognized arguments: --samples" in one_error_line(bad)


def test_help_exits_zero():
    """``pkm --help`` prints the commands and exits 0; no command at all is a usage error (2)."""
    ok = run("--help")
    assert ok.returncode == 0 and all(c in ok.stdout for c in ("list", "preview", "ik", "fk", "report", "bench"))
    bad = run()
    assert bad.returncode == 2 and "required" in one_error_line(bad)


# ---------------------------------------------------------------------- one's own files
def test_every_subcommand_takes_a_closure_spec_file(tmp_path):
    """The toy five-bar saved as files (pkm.save) is solved, run forward and previewed from its path; --param is
    refused for a file, an unknown name says that a path is accepted."""
    from tests import fivebar

    spec = pkm.save(fivebar.build(), tmp_path / "five.closures.toml")
    ik = run("ik", str(spec), "--pose", "x=1cm", "y=34cm")
    assert ik.returncode == 0, ik.stderr
    out = json.loads(ik.stdout)
    assert out["mechanism"] == "fivebar" and out["residual"] <= 1e-9
    fk = run("fk", str(spec), "--joints", *(f"{k}={v}" for k, v in out["actuated"].items()))
    assert fk.returncode == 0, fk.stderr
    assert abs(json.loads(fk.stdout)["task"]["x"] - 0.01) < 1e-9
    page = tmp_path / "five.html"
    assert run("preview", str(spec), "--html", str(page)).returncode == 0 and page.stat().st_size > 10_000
    refused = run("ik", str(spec), "--param", "d=1", "--pose", "x=0")
    assert refused.returncode == 2 and "states its own" in refused.stderr
    unknown = run("ik", "nosuch", "--pose", "x=0")
    assert unknown.returncode != 0 and "closure spec's path" in unknown.stderr


def test_spec_init_writes_a_spec_that_loads_once_filled_in(tmp_path):
    """From an MJCF file (loops and actuators stated) the spec loads as written; from a URDF it parses, lists the
    model's joints and frames, and loads once its TODO lines are filled in; an existing file is kept."""
    examples = Path(__file__).resolve().parents[1] / "examples"
    for src in (examples / "mjcf_fourbar" / "fourbar.xml", examples / "ankle" / "ankle.urdf"):
        (tmp_path / src.name).write_text(src.read_text())
    mj = run("spec", "init", str(tmp_path / "fourbar.xml"))
    assert mj.returncode == 0 and "TODO" not in mj.stdout, mj.stderr
    assert pkm.load(tmp_path / "fourbar.closures.toml").actuated_names == ("crank_joint",)
    ur = run("spec", "init", str(tmp_path / "ankle.urdf"))
    assert ur.returncode == 0 and "TODO" in ur.stdout, ur.stderr
    text = (tmp_path / "ankle.closures.toml").read_text()
    assert "motor_left" in text and "foot_ball_left" in text
    filled = text.replace("actuated = []", 'actuated = ["motor_left", "motor_right"]').replace(
        'frame_a = "shank"', 'frame_a = "rod_end_left"').replace('frame_b = "rod_end_right"', 'frame_b = "foot_ball_left"')
    filled += '\n[[closure]]\nname = "loop2"\ntype = "point"\nframe_a = "rod_end_right"\nframe_b = "foot_ball_right"\n'
    filled += '[joint_types]\nrod_ball_left = "spherical"\nrod_ball_right = "spherical"\n'
    (tmp_path / "ankle.closures.toml").write_text(filled.replace("# [joint_types]", "#"))
    mech = pkm.load(tmp_path / "ankle.closures.toml")
    assert pkm.diagnose(mech, mech.q_reference).idle_motions == 2
    again = run("spec", "init", str(tmp_path / "ankle.urdf"))
    assert again.returncode == 2 and "--force" in one_error_line(again)


def test_fk_and_ik_all_print_every_mode_and_the_sets_account():
    """``pkm fk --all`` / ``pkm ik --all``: every mode (homotopy continuation) with the set's account, SI."""
    pytest.importorskip("bertini")
    fk = json.loads(run("fk", "delta", "--joints", "motor_1=0.1", "--all").stdout)
    assert fk["complete"] and fk["paths"] == 8 and len(fk["modes"]) == 2 and not fk["failed"]
    assert {round(m["actuated"]["motor_1"], 12) for m in fk["modes"]} == {0.1}
    ik = json.loads(run("ik", "prs3", "--pose", "z=90cm", "pitch=3deg", "--all").stdout)
    assert ik["complete"] and len(ik["modes"]) == 8
    assert all(abs(m["task"]["z"] - 0.9) < 1e-9 for m in ik["modes"])
