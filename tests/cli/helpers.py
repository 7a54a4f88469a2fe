"""Running the ``pkm`` command line, and what the tests read of it.

:func:`run` calls the command line's entry (:func:`pkm.cli.app.main`) in this process, as ``python -m pkm ARGS``
would run it: its output captured as text, its exit status read as the process's, an exception it lets through
printed as the interpreter would (a traceback on stderr, status 1), and the state a process would have dropped on
exit (the current directory, the environment, ``sys.argv``, warning filters, logging, signal handlers, open
figures) put back. A subprocess costs about a second of interpreter start and imports each; the tests that check
the process itself (the entry point, its signals, what it leaves running when it exits, a CPU bound on a hang)
call :func:`run_process`.
"""

from __future__ import annotations

import io
import logging
import os
import signal
import socket
import subprocess
import sys
import traceback
import warnings
from pathlib import Path

from tests import bounded

#: The warning filters of a Python process started without ``-W`` or ``PYTHONWARNINGS`` (CPython's defaults, in
#: their order): what the command line's warnings go through, not the test runner's.
PROCESS_WARNING_FILTERS = (("default", DeprecationWarning, "__main__"), ("ignore", DeprecationWarning, ""),
                           ("ignore", PendingDeprecationWarning, ""), ("ignore", ImportWarning, ""),
                           ("ignore", ResourceWarning, ""))


def run_process(*args: str, cwd: Path | None = None, cpu: float = 120) -> subprocess.CompletedProcess:
    """``python -m pkm ARGS`` in a subprocess (text output, no check), ended past ``cpu`` seconds of CPU time (a
    hang; :mod:`tests.bounded`: never because the machine is busy)."""
    return bounded.run([sys.executable, "-m", "pkm", *args], cwd=cwd, cpu=cpu)


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """What an interpreter's :func:`warnings.showwarning` does: the formatted warning on stderr (as it is now)."""
    (sys.stderr if file is None else file).write(warnings.formatwarning(message, category, filename, lineno, line))


def _exit_status(code: object) -> int:
    """The exit status of a process ended by ``SystemExit(code)`` (a code that is no number printed on stderr)."""
    if code is None:
        return 0
    if isinstance(code, int):
        return code % 256
    print(code, file=sys.stderr)
    return 1


def run(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """``pkm ARGS`` run in this process as ``python -m pkm ARGS`` would run it (see the module's docstring), in
    ``cwd`` when given: the exit status, stdout and stderr (text) of that process."""
    import pkm
    from pkm.cli.app import main

    out, err = io.StringIO(), io.StringIO()
    saved_streams, saved_argv, saved_cwd, saved_env = (sys.stdout, sys.stderr), sys.argv, os.getcwd(), dict(os.environ)
    saved_signals = {s: h for s in signal.valid_signals() if (h := signal.getsignal(s)) is not None}
    root = logging.getLogger()
    saved_logging = (root.level, list(root.handlers), logging.root.manager.disable)
    pyplot = sys.modules.get("matplotlib.pyplot")
    figures = set(pyplot.get_fignums()) if pyplot else set()
    with warnings.catch_warnings():  # (the filters and showwarning put back on leaving)
        warnings.resetwarnings()
        for action, category, module in PROCESS_WARNING_FILTERS:
            warnings.filterwarnings(action, category=category, module=module, append=True)
        warnings.showwarning = _show_warning
        saved_once = dict(warnings.onceregistry)
        warnings.onceregistry.clear()
        try:
            os.environ.setdefault("MPLBACKEND", "Agg")  # (headless, as a process without a display)
            sys.argv = [str(Path(pkm.__file__).with_name("__main__.py")), *args]
            sys.stdout, sys.stderr = out, err
            if cwd is not None:
                os.chdir(cwd)
            try:
                status = _exit_status(main(list(args)))
            except SystemExit as exc:
                status = _exit_status(exc.code)
            except Exception:  # (the interpreter prints what main lets through; the process exits 1)
                traceback.print_exc()
                status = 1
        finally:
            sys.stdout, sys.stderr = saved_streams
            sys.argv = saved_argv
            os.chdir(saved_cwd)
            for key in set(os.environ) - set(saved_env):
                del os.environ[key]
            for key, value in saved_env.items():
                if os.environ.get(key) != value:
                    os.environ[key] = value
            for s, handler in saved_signals.items():
                if signal.getsignal(s) != handler:
                    signal.signal(s, handler)
            root.setLevel(saved_logging[0])
            root.handlers[:] = saved_logging[1]
            logging.disable(saved_logging[2])
            warnings.onceregistry.clear()
            warnings.onceregistry.update(saved_once)
            if pyplot := sys.modules.get("matplotlib.pyplot"):
                for number in set(pyplot.get_fignums()) - figures:
                    pyplot.close(number)
    return subprocess.CompletedProcess([sys.executable, "-m", "pkm", *args], status, out.getvalue(), err.getvalue())


def one_error_line(proc: subprocess.CompletedProcess) -> str:
    """The single ``pkm: error: ...`` line a failing command prints (asserted: nothing else, no traceback)."""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("pkm: error: "), proc.stderr
    assert proc.stdout == ""
    return lines[0]


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
