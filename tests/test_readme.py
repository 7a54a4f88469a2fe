"""Every Python block and every shell command line of the README runs, exactly as printed.

Python blocks run one by one in a fresh interpreter, in a scratch directory. Shell lines run in
bash, ``make`` lines in the checkout and ``pkm`` lines in the scratch directory, with the
installed ``pkm`` first on ``PATH``. A line whose comment says ``Ctrl-C`` starts something that
runs until stopped (the live viewer): it must print, then stop cleanly on Ctrl-C (SIGINT).
One line is not run: ``make test``, the command that runs this test (CI runs it).
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from tests.cli.helpers import default_sigint

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
BLOCKS = re.findall(r"^```(\w*)\n(.*?)^```", README, flags=re.S | re.M)
PYTHON = [code for lang, code in BLOCKS if lang == "python"]
SHELL = [line for lang, code in BLOCKS if lang in ("sh", "bash", "console") for line in code.splitlines()
         if line.split("#")[0].strip()]
SELF = "make test"


def _env() -> dict[str, str]:
    env = dict(os.environ, MPLBACKEND="Agg")
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
    return env


def test_the_readme_has_python_blocks_and_shell_lines():
    assert len(PYTHON) >= 3 and len(SHELL) >= 8 and SELF in [ln.split("#")[0].strip() for ln in SHELL]


@pytest.mark.parametrize("code", PYTHON, ids=[f"python{k + 1}" for k in range(len(PYTHON))])
def test_python_block_runs(code, tmp_path):
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=_env(), capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, f"README block failed:\n{code}\n--- stderr:\n{proc.stderr[-3000:]}"


@pytest.mark.parametrize("line", SHELL, ids=[ln.split("#")[0].strip()[:60] for ln in SHELL])
def test_shell_line_runs(line, tmp_path):
    command = line.split("#")[0].strip()
    if command == SELF:
        pytest.skip("the command that runs this test (CI runs it)")
    cwd = ROOT if command.startswith("make ") else tmp_path
    if "Ctrl-C" in line:
        proc = subprocess.Popen(["bash", "-c", f"exec {command}"], cwd=cwd, env=_env(), stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True, preexec_fn=default_sigint)
        try:
            first = proc.stdout.readline()
            assert first.strip(), f"{command!r} printed nothing: {proc.stderr.read() if proc.poll() else ''}"
            proc.send_signal(signal.SIGINT)
            assert proc.wait(timeout=30) == 0, proc.stderr.read()
        finally:
            proc.kill()
        return
    proc = subprocess.run(["bash", "-c", command], cwd=cwd, env=_env(), capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, f"{command!r} exited {proc.returncode}:\n{proc.stderr[-3000:]}"
