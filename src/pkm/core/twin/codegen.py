"""The twin's functions as compiled C."""

from __future__ import annotations

import casadi as cs


def compile_function(fun: cs.Function, directory=None) -> tuple[cs.Function, str]:
    """``fun`` as generated C, compiled (``cc -O2 -shared``) and loaded, when a C compiler is present; else ``fun``
    itself, run by CasADi's virtual machine. Returns ``(function, how)``, ``how`` saying which (and why).

    Args:
        fun: A CasADi function (from :meth:`Twin.function`).
        directory: Where the C source and the shared library go (default: a new temporary folder, kept for the
            life of the process: the library stays loaded).
    """
    import shutil
    import subprocess
    import tempfile
    from pathlib import Path

    cc = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    if cc is None:
        return fun, "CasADi's virtual machine (no C compiler on the PATH: cc, gcc or clang)"
    folder = Path(directory) if directory is not None else Path(tempfile.mkdtemp(prefix="pkm-twin-"))
    folder.mkdir(parents=True, exist_ok=True)
    name = fun.name()
    source = folder / f"{name}.c"
    gen = cs.CodeGenerator(source.name)
    gen.add(fun)
    gen.generate(str(folder) + "/")
    library = folder / f"{name}.so"
    run = subprocess.run([cc, "-O2", "-shared", "-fPIC", "-o", str(library), str(source)], capture_output=True,
                         text=True, check=False, timeout=600)
    if run.returncode != 0:
        return fun, f"CasADi's virtual machine (the C compiler failed: {run.stderr.strip()[-300:]})"
    return cs.external(name, str(library)), f"C ({Path(cc).name} -O2, {library})"
