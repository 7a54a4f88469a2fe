"""Optional dependencies: which pkm extra installs each, and the one check made where a capability needs them.

``pip install pkm-robotics`` (the distribution's name, :data:`~pkm.errors.DISTRIBUTION`: ``pkm`` on PyPI is another
project; it installs the ``pkm`` package and command) gives the library's core (loading, closing loops, kinematics,
Jacobians, dynamics, the twin's kernels, previews); the rest is behind extras, named in ``pyproject.toml``'s
``[project.optional-dependencies]`` (:data:`EXTRAS` mirrors it, a test keeps the two the same)::

    pip install "pkm-robotics[sweeps]"    # pkm.sweep and its Parquet results: Dask, pyarrow, cloudpickle
    pip install "pkm-robotics[figures]"   # the papers' figures, sweep plots, CiMap.figure: matplotlib
    pip install "pkm-robotics[homotopy]"  # every assembly mode (pkm.assembly_modes): Bertini 2 (GPL-3)
    pip install "pkm-robotics[bench]"     # the benchmarks' baseline: MuJoCo
    pip install "pkm-robotics[identify]"  # identification's physically consistent estimate: cvxpy with Clarabel
    pip install "pkm-robotics[serve]"     # the service (pkm serve) and its client: FastAPI, uvicorn, httpx, ...
    pip install "pkm-robotics[jax]"       # the twin's kernels as JAX functions (jit, vmap, grad; GPU): JAX
    pip install "pkm-robotics[warp]"      # transmission kernels on NVIDIA Warp (CPU, or a GPU where there is one)
    pip install "pkm-robotics[plan]"      # time-optimal motion (pkm.time_optimal, pkm plan): toppra
    pip install "pkm-robotics[usd]"       # USD in and out (UsdPhysics articulations, loop joints): usd-core
    pip install "pkm-robotics[mjwarp]"    # exact transmissions inside MuJoCo Warp's batched step: mujoco-warp
    pip install "pkm-robotics[all]"       # all of them

An extra is checked at the point of use, never at ``import pkm``: :func:`require` raises
:class:`~pkm.errors.MissingDependencyError` naming the ``pip install "pkm-robotics[...]"`` line (the command line
prints it as its one-line error), and :func:`module` imports one module of an extra after that check.
"""

from __future__ import annotations

import importlib
import importlib.util
from collections.abc import Iterable
from types import ModuleType

from pkm.errors import InvalidInputError, MissingDependencyError

#: extra -> {top-level module: the distribution that installs it}, in ``pyproject.toml``'s order.
EXTRAS: dict[str, dict[str, str]] = {
    "sweeps": {"dask": "dask", "distributed": "distributed", "pyarrow": "pyarrow", "cloudpickle": "cloudpickle"},
    "figures": {"matplotlib": "matplotlib"},
    "homotopy": {"bertini": "bertini2"},
    "bench": {"mujoco": "mujoco"},
    "identify": {"cvxpy": "cvxpy", "clarabel": "clarabel"},
    "serve": {"fastapi": "fastapi", "starlette": "starlette", "uvicorn": "uvicorn", "multipart": "python-multipart",
              "msgpack": "msgpack", "httpx": "httpx", "websockets": "websockets", "pydantic": "pydantic",
              "fastapi_offline": "fastapi-offline"},
    "jax": {"jax": "jax"},
    "warp": {"warp": "warp-lang"},
    "plan": {"toppra": "toppra"},
    "usd": {"pxr": "usd-core"},
    "mjwarp": {"mujoco_warp": "mujoco-warp"},
}


def missing(extra: str, modules: Iterable[str] | None = None) -> list[str]:
    """The distributions of ``extra`` (or of those of its ``modules``) that cannot be imported, in order (a module
    blocked in ``sys.modules`` as None counts as missing)."""
    if extra not in EXTRAS:
        raise InvalidInputError("extra", f"one of {', '.join(EXTRAS)}, got {extra!r}", extra)
    outside = [m for m in modules or () if m not in EXTRAS[extra]]
    if outside:
        raise InvalidInputError("modules", f"{outside} are not modules of the {extra!r} extra "
                                           f"({', '.join(EXTRAS[extra])})", outside)
    wanted = EXTRAS[extra] if modules is None else {m: EXTRAS[extra][m] for m in modules}
    out = []
    for top, dist in wanted.items():
        try:
            found = importlib.util.find_spec(top) is not None
        except (ImportError, ValueError):  # (ValueError: a module whose __spec__ is None)
            found = False
        if not found:
            out.append(dist)
    return out


def require(extra: str, what: str, modules: Iterable[str] | None = None) -> None:
    """Check that ``extra`` is installed (every module of it, or ``modules`` only) before ``what`` uses it.

    Raises:
        MissingDependencyError: naming the first missing distribution and ``pip install "pkm-robotics[extra]"``.
    """
    gone = missing(extra, modules)
    if gone:
        raise MissingDependencyError(gone[0], extra, what)


def module(name: str, *, extra: str, what: str) -> ModuleType:
    """``import name`` (a module of ``extra``: ``"matplotlib.pyplot"``), after :func:`require` of its top level."""
    require(extra, what, (name.split(".")[0],))
    return importlib.import_module(name)


__all__ = ["EXTRAS", "missing", "module", "require"]
