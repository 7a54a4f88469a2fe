"""Fresh processes forked from a warm interpreter: a Python block or script run as ``python -c CODE`` or
``python SCRIPT`` runs it, without paying again for the imports every such process makes (the file loaders'
yourdfpy, trimesh and scipy: about 1 s of CPU a process, most of what a short block costs).

:class:`Zygote` is ``python`` with :data:`WARM` imported (modules only: no mechanism loaded, nothing computed or
cached), forking one child per :meth:`Zygote.run`. The child is a process of its own, as a new interpreter's would
be: its own session, working directory, environment, ``sys.argv``, ``sys.path[0]`` and a fresh ``__main__``, its
output in files; so a block still needs its own imports and leaves nothing behind for the next one. Its CPU time is
bounded as :func:`tests.bounded.run` bounds a subprocess's: ended past ``cpu`` seconds of CPU of its process tree,
or past ``idle`` seconds in which it used none (never a wall-clock timeout that a busy machine trips).
Processes the code spawns (Dask's local workers) start as they would from ``python -c``: a ``__main__`` without a
file, which they do not import. Where ``/proc`` cannot be read, the code runs in a plain subprocess
(:func:`tests.bounded.run`).
"""

from __future__ import annotations

import json
import os
import select
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from tests.bounded import POLL, tree_cpu

#: What the zygote imports before forking: what a block or an example imports first (``pkm.load``'s file
#: loaders and the numerics under them). No module that reads the environment at import (matplotlib: MPLBACKEND)
#: and none that starts threads which a fork would copy (JAX).
WARM = ("numpy", "scipy.linalg", "scipy.optimize", "scipy.spatial", "pinocchio", "pkm", "pkm.core.formats.load")

_ZYGOTE = r'''
import atexit, importlib, json, os, runpy, sys, threading, traceback, types
for name in json.loads(sys.argv[1]):
    importlib.import_module(name)
control = os.fdopen(os.dup(1), "w")
os.dup2(2, 1)  # (nothing but the control lines on the pipe)


def child(req):
    code = 1
    try:
        os.close(control.fileno())
        os.setsid()
        os.chdir(req["cwd"])
        os.environ.clear()
        os.environ.update(req["env"])
        os.dup2(os.open(os.devnull, os.O_RDONLY), 0)
        for fd, path in ((1, req["out"]), (2, req["err"])):
            f = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
            os.dup2(f, fd)
            os.close(f)
        sys.argv = list(req["argv"])
        sys.path[0] = req["path0"]
        if req["script"] is None:
            main = types.ModuleType("__main__")
            main.__dict__["__builtins__"] = __builtins__
            sys.modules["__main__"] = main
            exec(compile(req["code"], "<string>", "exec"), main.__dict__)
        else:
            runpy.run_path(req["script"], run_name="__main__")
        code = 0
    except SystemExit as exc:
        if exc.code is None or isinstance(exc.code, int):
            code = exc.code or 0
        else:
            print(exc.code, file=sys.stderr)
    except BaseException:
        traceback.print_exc()
    finally:  # (what an interpreter does at its end: other threads joined, atexit run, streams flushed)
        try:
            threading._shutdown()
            atexit._run_exitfuncs()
            sys.stdout.flush()
            sys.stderr.flush()
        finally:
            os._exit(code)


for line in sys.stdin:
    request = json.loads(line)
    pid = os.fork()
    if pid == 0:
        child(request)
    print(json.dumps({"pid": pid}), file=control, flush=True)
    _, status = os.waitpid(pid, 0)
    print(json.dumps({"rc": os.waitstatus_to_exitcode(status)}), file=control, flush=True)
'''


class Zygote:
    """A warm interpreter that forks a fresh process for each :meth:`run` (one test at a time: one process's)."""

    def __init__(self) -> None:
        self.proc: subprocess.Popen | None = None

    def _start(self) -> subprocess.Popen:
        if self.proc is None or self.proc.poll() is not None:
            self.proc = subprocess.Popen([sys.executable, "-c", _ZYGOTE, json.dumps(WARM)], stdin=subprocess.PIPE,
                                         stdout=subprocess.PIPE, text=True, bufsize=1)
        return self.proc

    def close(self) -> None:
        if self.proc is not None and self.proc.poll() is None:
            self.proc.stdin.close()
            self.proc.wait()
        self.proc = None

    def _line(self, proc: subprocess.Popen, pid: int | None, cpu: float, idle: float) -> dict:
        """The zygote's next control line; the child ``pid`` killed (its session) past its bounds meanwhile."""
        used, last_change = 0.0, time.monotonic()
        while True:
            if select.select([proc.stdout], [], [], POLL)[0]:
                line = proc.stdout.readline()
                if not line:
                    raise RuntimeError(f"the zygote ended (exit code {proc.wait()})")
                return json.loads(line)
            if pid is None:
                if time.monotonic() - last_change > idle:
                    raise RuntimeError(f"the zygote did not fork in {idle:g} s")
                continue
            try:
                now_used = tree_cpu(pid)
            except ProcessLookupError:
                continue  # (ended: its line is on its way)
            if now_used > used:
                used, last_change = now_used, time.monotonic()
            if used > cpu or time.monotonic() - last_change > idle:
                try:
                    os.killpg(pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
                self._line(proc, None, cpu, idle)  # (its exit code)
                why = f"{used:.0f} s of CPU (bound {cpu:g} s)" if used > cpu else f"no CPU used in {idle:g} s"
                raise subprocess.TimeoutExpired(pid, cpu, stderr=f"[ended: {why}]")

    def run(self, *, code: str | None = None, script: Path | None = None, cwd: Path, env: dict[str, str] | None = None,
            cpu: float, idle: float = 120.0) -> subprocess.CompletedProcess:
        """``python -c code`` or ``python script`` (no other arguments) in ``cwd`` with ``env`` (default this
        process's), as :func:`tests.bounded.run` runs it: ``returncode``, ``stdout``, ``stderr``."""
        env = dict(os.environ if env is None else env)
        args = [sys.executable, "-c", code] if script is None else [sys.executable, str(script)]
        if not Path("/proc/self/stat").exists():
            from tests import bounded

            return bounded.run(args, cwd=cwd, env=env, cpu=cpu, idle=idle)
        proc = self._start()
        with tempfile.TemporaryDirectory() as tmp:
            out, err = Path(tmp) / "out", Path(tmp) / "err"
            request = {"code": code, "script": None if script is None else str(script), "cwd": str(cwd), "env": env,
                       "argv": ["-c"] if script is None else [str(script)],
                       "path0": "" if script is None else str(Path(script).resolve().parent),
                       "out": str(out), "err": str(err)}
            proc.stdin.write(json.dumps(request) + "\n")
            proc.stdin.flush()
            pid = self._line(proc, None, cpu, idle)["pid"]
            try:
                rc = self._line(proc, pid, cpu, idle)["rc"]
            except subprocess.TimeoutExpired as exc:
                raise subprocess.TimeoutExpired(args, cpu, output=out.read_text(errors="replace"),
                                                stderr=err.read_text(errors="replace") + str(exc.stderr)) from None
            return subprocess.CompletedProcess(args, rc, out.read_text(errors="replace"),
                                               err.read_text(errors="replace"))
