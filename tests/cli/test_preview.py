"""``pkm preview``: an HTML page, a live viewer returning with --no-wait, and a killed viewer that leaves no meshcat
server behind."""

from __future__ import annotations

import signal
from pathlib import Path

import pytest

import pkm.viz  # noqa: F401  (a regression in pkm.viz fails here, it is not skipped)
from tests.bounded import children
from tests.cli.helpers import one_error_line, port_is_free, run, run_process, start_live_preview


def test_preview_writes_html_and_refuses_an_unknown_mechanism(tmp_path):
    """``pkm preview delta --pose z=-0.36 --html F`` writes an HTML scene; an unknown mechanism exits 2."""
    bad = run("preview", "scara", "--html", str(tmp_path / "x.html"))
    assert bad.returncode == 2 and "mechanism 'scara' does not exist" in one_error_line(bad)
    page = tmp_path / "delta.html"
    ok = run("preview", "delta", "--pose", "z=-0.36", "--html", str(page))
    assert ok.returncode == 0, ok.stderr
    assert page.stat().st_size > 1000 and "<html" in page.read_text()[:1000].lower()


def test_preview_marks_interference_unless_told_not_to(tmp_path, capsys):
    """``pkm preview`` of the Gough-Stewart with 9.5 cm legs turned 1.2 rad (in process): the page's legend names the
    crossing rods; with --no-collisions it does not."""
    from pkm import cli

    args = ["preview", "gough_stewart", "--param", "cylinder_radius=9.5cm", "rod_radius=9.5cm", "--pose", "yaw=1.2"]
    assert cli.main([*args, "--html", str(tmp_path / "a.html")]) == 0
    assert cli.main([*args, "--no-collisions", "--html", str(tmp_path / "b.html")]) == 0
    assert "rod_1 and rod_6 interpenetrate by" in (tmp_path / "a.html").read_text()
    assert "interpenetrate" not in (tmp_path / "b.html").read_text()


def test_preview_opens_the_viewer_at_given_joints_and_returns_with_no_wait():
    """``pkm preview delta --joints motor_1=-50deg --no-wait`` starts a meshcat viewer, prints its URL and exits 0;
    an unknown joint exits 2 before any viewer starts."""
    ok = run_process("preview", "delta", "--joints", "motor_1=-50deg", "--no-wait")  # (a process: the viewer
    # stops with it)
    assert ok.returncode == 0, ok.stderr
    assert ok.stdout.startswith("viewer: http://")
    bad = run("preview", "delta", "--joints", "elbow=1", "--no-wait")
    assert bad.returncode == 2 and "valid actuated joints" in one_error_line(bad)


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
