"""Every Python block and every shell command line of the README and of the tour (``docs/tour/*.md``) runs, exactly
as printed.

Python blocks run one by one in a fresh process (``python -c`` as :mod:`tests.warm` forks it from a warm
interpreter: the imports paid once), in a scratch directory. Shell lines run in
bash, ``make`` lines in the checkout and ``pkm`` lines in the scratch directory, with the
installed ``pkm`` first on ``PATH``; a line of nothing but ``pkm`` commands (joined by ``&&``, no other shell
syntax) runs them as ``pkm`` would, in this process (:func:`tests.cli.helpers.run`; the installed script itself is
tests/cli/test_list.py's), but for :data:`PROCESS_COMMANDS`. A line whose comment says ``Ctrl-C`` starts something
that runs until stopped (the live viewer): it must print, then stop cleanly on Ctrl-C (SIGINT).
A block or command printed on several pages (the README's command lines are the tour's too) runs once.
Two lines are not run here: ``make test``, the command that runs this test, and ``make demo``: CI runs both on its
fresh clone (.ci/run; a test holds that it does).
"""

from __future__ import annotations

import itertools
import os
import re
import shlex
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests import bounded
from tests.cli.helpers import default_sigint, run

ROOT = Path(__file__).resolve().parents[1]
#: The pages whose blocks run: the README, then the tour of the documentation site.
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs" / "tour").glob("*.md"))]
FENCE = re.compile(r"^```(\w*)\n(.*?)^```", flags=re.S | re.M)
SELF = "make test"
#: ``make demo``, the README's other command: CI runs it on its fresh clone right after ``make test`` (.ci/run; a test
#: below holds that), not this suite (its report is 80 s of CPU, half the papers' figures, which tests/papers draw).
CI_RUNS = "make demo"
#: The ``pkm`` commands a line runs in bash even with nothing else of the shell's: ``pkm sweep`` starts a local
#: Dask cluster of worker processes (and Dask's logging), ``pkm serve`` a service until stopped; but for
#: :func:`_in_process`'s ``pkm sweep``.
PROCESS_COMMANDS = ("sweep", "serve")


def _in_process(words: list[str]) -> bool:
    """Whether ``pkm`` command ``words`` runs in this process: none of :data:`PROCESS_COMMANDS`, or a ``pkm sweep``
    that starts no cluster (``--scheduler serial``: the designs in its own process; ``pkm sweep plot`` and ``pkm
    sweep best``, which read a results file)."""
    if len(words) < 2 or words[0] != "pkm":
        return False
    if words[1] != "sweep":
        return words[1] not in PROCESS_COMMANDS
    serial = "--scheduler=serial" in words or ("--scheduler", "serial") in itertools.pairwise(words)
    return serial or words[2:3] in (["plot"], ["best"])


#: The characters of a line of ``pkm`` commands that it can run in this process (none of the shell's syntax but
#: quotes, which :func:`shlex.split` takes off as bash does).
PLAIN = re.compile(r"[\w\s=:,./+\"'-]*")
#: The README's size limit [bytes] (issue 42: what pkm is, the two commands, one example, links; the tour in docs/).
README_MAX_BYTES = 12 * 1024


def _collect() -> tuple[dict[str, str], dict[str, tuple[str, str]]]:
    """``{code: page}`` of the Python blocks and ``{command: (page, line)}`` of the shell lines, each the first time
    it is printed, in page order."""
    python: dict[str, str] = {}
    shell: dict[str, tuple[str, str]] = {}
    for page in PAGES:
        where = page.relative_to(ROOT).as_posix()
        for lang, code in FENCE.findall(page.read_text(encoding="utf-8")):
            if lang == "python":
                python.setdefault(code, where)
            elif lang in ("sh", "bash", "console"):
                for line in code.splitlines():
                    if line.split("#")[0].strip():
                        shell.setdefault(line.split("#")[0].strip(), (where, line))
    return python, shell


_PYTHON, _SHELL = _collect()
PYTHON = list(_PYTHON)
SHELL = [line for _, line in _SHELL.values()]


def _python_ids() -> Iterator[str]:
    """``README.md:python1``, ``docs/tour/dynamics.md:python2``: each block by its page and its rank there."""
    seen: dict[str, int] = {}
    for where in _PYTHON.values():
        seen[where] = seen.get(where, 0) + 1
        yield f"{where}:python{seen[where]}"


def _env() -> dict[str, str]:
    env = dict(os.environ, MPLBACKEND="Agg")
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
    return env


def _pkm_commands(command: str) -> list[list[str]] | None:
    """The words of each ``pkm`` command of a line that runs in this process (nothing but ``pkm`` commands joined by
    ``&&``, each :func:`_in_process`); None for a line that runs in bash."""
    parts = command.split("&&")
    if not all(PLAIN.fullmatch(part) for part in parts):
        return None
    commands = [shlex.split(part) for part in parts]
    return commands if all(_in_process(words) for words in commands) else None


def test_the_pages_have_python_blocks_and_shell_lines():
    """The README shows one example and the two commands; the tour the rest (10 Python blocks and 21 commands when
    the tour moved out of the README: none lost)."""
    readme = [where for where in _PYTHON.values() if where == "README.md"]
    readme_commands = {cmd for cmd, (where, _) in _SHELL.items() if where == "README.md"}
    assert len(readme) == 1 and {"make demo", SELF} <= readme_commands
    assert len(PYTHON) >= 10 and len(SHELL) >= 21


def test_ci_runs_the_readmes_two_commands_on_its_fresh_clone():
    """.ci/run runs ``make test`` and ``make demo`` (the line this suite skips), each a command of its own that stops
    the run when it fails (``set -e``), and checks that the demo wrote its report."""
    lines = [ln.split("#")[0].strip() for ln in (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()]
    assert "set -euo pipefail" in lines and SELF in lines and CI_RUNS in lines
    assert lines.index(CI_RUNS) > lines.index(SELF) and "test -s out/report.md" in lines


def test_the_readme_is_short_and_its_links_resolve():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    size = len(text.encode("utf-8"))
    assert size <= README_MAX_BYTES, f"README.md is {size} bytes, over {README_MAX_BYTES}: the tour lives in docs/tour/"
    targets = re.findall(r"\]\((?!https?://|#)([^)#]+)", text)
    assert targets, "the README links to the documentation"
    missing = [t for t in targets if not (ROOT / t).exists()]
    assert not missing, f"README links to files that are not in the checkout: {missing}"


@pytest.mark.parametrize("code", PYTHON, ids=list(_python_ids()))
def test_python_block_runs(code, tmp_path, zygote):
    proc = zygote.run(code=code, cwd=tmp_path, env=_env(), cpu=300)
    assert proc.returncode == 0, f"block failed ({_PYTHON[code]}):\n{code}\n--- stderr:\n{proc.stderr[-3000:]}"


@pytest.mark.parametrize("line", SHELL, ids=[ln.split("#")[0].strip()[:60] for ln in SHELL])
def test_shell_line_runs(line, tmp_path):
    command = line.split("#")[0].strip()
    if command == SELF:
        pytest.skip("the command that runs this test (CI runs it)")
    if command == CI_RUNS:
        pytest.skip("the README's other command: CI runs it on its fresh clone after make test (.ci/run)")
    cwd = ROOT if command.startswith("make ") else tmp_path
    (tmp_path / "examples").symlink_to(ROOT / "examples")  # (a reader in a clone: `examples/...` from its root)
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
    commands = _pkm_commands(command)
    if commands:
        for words in commands:  # (as bash runs A && B: B once A exited 0)
            proc = run(*words[1:], cwd=cwd)
            assert proc.returncode == 0, f"{' '.join(words)!r} ({_SHELL[command][0]}) exited {proc.returncode}:\n" \
                                         f"{proc.stderr[-3000:]}"
        return
    proc = bounded.run(["bash", "-c", command], cwd=cwd, env=_env(), cpu=600)
    assert proc.returncode == 0, f"{command!r} ({_SHELL[command][0]}) exited {proc.returncode}:\n{proc.stderr[-3000:]}"
