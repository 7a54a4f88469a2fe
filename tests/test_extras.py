"""The extras (pkm._optional): the core works without any of them; a capability that needs one raises
:class:`~pkm.errors.MissingDependencyError` naming its ``pip install "pkm-robotics[...]"`` line where it is used,
never at ``import pkm``. Each check runs in a fresh interpreter whose extras' modules are blocked (``sys.modules[name] = None``:
``import name`` raises ImportError, as if it were not installed)."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

from pkm._optional import EXTRAS, missing, module, require
from pkm.errors import InvalidInputError, MissingDependencyError, PkmError
from tests import bounded

#: Every module of every extra, blocked.
BLOCKED = sorted({m for modules in EXTRAS.values() for m in modules} | {"dask.distributed"})


def _run(code: str, *args: str) -> subprocess.CompletedProcess:
    prelude = f"import sys\nfor _m in {BLOCKED!r}:\n    sys.modules[_m] = None\n"
    return bounded.run([sys.executable, "-c", prelude + textwrap.dedent(code), *args], cpu=120)


def test_the_core_works_and_each_extra_is_named_where_it_is_used(tmp_path):
    out = _run(f"""
        import numpy as np
        import pkm
        from pkm.errors import MissingDependencyError

        mech = pkm.load("delta")
        q = pkm.close_loops(mech, mech.actuated_q(mech.q_reference)).q
        res = pkm.solve_ik(mech, {{"x": 0.02, "y": -0.01, "z": -0.36}})
        assert res.residual < 1e-9 and pkm.forward_jacobian(mech, res.q).shape == (3, 3)
        tau = pkm.inverse_dynamics(mech, q, np.zeros(mech.nv), np.zeros(mech.nv))
        assert tau.shape == (3,) and np.isfinite(tau).all()
        from pkm import sweeps
        space = sweeps.grid(h="10cm:20cm:2")  # (the spaces and objectives need no extra)
        assert sweeps.objective("gci:step=4cm").column == "gci:step=4cm"

        def raises(extra, call):
            try:
                call()
            except MissingDependencyError as exc:
                assert exc.extra == extra and f'pip install "pkm-robotics[{{extra}}]"' in str(exc), exc
                print(extra, "|", exc)
            else:
                raise AssertionError(f"no MissingDependencyError for pkm-robotics[{{extra}}]")

        raises("sweeps", lambda: pkm.sweep("rrr3", space, ["gci:step=4cm"], scheduler="serial"))
        raises("sweeps", lambda: sweeps.read({str(tmp_path / "x.parquet")!r}))
        raises("figures", lambda: __import__("pkm._plot", fromlist=["figure"]).figure())
        raises("figures", lambda: sweeps.plot({str(tmp_path / "x.parquet")!r}, {str(tmp_path)!r}))
        from pkm import report
        raises("figures", lambda: report.run({str(tmp_path / "report")!r}, ["delta"], series=False))
        assert not __import__("pathlib").Path({str(tmp_path / "report")!r}).exists()  # (refused before any step)
        blocked = sorted(m for m in {BLOCKED!r} if sys.modules.get(m) is not None)
        assert not blocked, blocked
    """)
    assert out.returncode == 0, out.stderr[-3000:]
    lines = out.stdout.splitlines()
    assert [ln.split(" |")[0] for ln in lines] == ["sweeps", "sweeps", "figures", "figures", "figures"], lines
    assert lines[0].endswith('pkm.sweep (design sweeps on Dask, results in Parquet) needs dask, which pkm\'s '
                             '\'sweeps\' extra installs: pip install "pkm-robotics[sweeps]"'), lines[0]


def test_the_command_line_says_which_extra_in_one_line():
    out = _run("""
        from pkm.cli import main
        sys.exit(main(sys.argv[1:]))
    """, "sweep", "rrr3", "h=10cm:20cm:2", "--objective", "gci:step=4cm", "--scheduler", "serial")
    assert out.returncode == 1, (out.returncode, out.stderr[-2000:])
    assert out.stderr.count("\n") == 1 and "Traceback" not in out.stderr, out.stderr
    assert out.stderr.startswith("pkm: error: pkm.sweep"), out.stderr
    assert 'pip install "pkm-robotics[sweeps]"' in out.stderr, out.stderr


def test_require_and_module_in_this_environment(monkeypatch):
    """With every extra installed (the dev environment) nothing is missing; a blocked module is, and is named by
    its distribution (bertini by bertini2); an unknown extra is refused."""
    assert missing("sweeps") == [] and module("dask", extra="sweeps", what="x").__name__ == "dask"
    monkeypatch.setitem(sys.modules, "pyarrow", None)
    monkeypatch.setitem(sys.modules, "bertini", None)
    assert missing("sweeps") == ["pyarrow"] and missing("sweeps", ["dask"]) == []
    with pytest.raises(MissingDependencyError, match=r'^reading needs bertini2, .*pip install "pkm-robotics\[homotopy\]"$') as info:
        require("homotopy", "reading")
    assert isinstance(info.value, PkmError) and isinstance(info.value, ImportError) and info.value.package == "bertini2"
    with pytest.raises(InvalidInputError, match="sweeps, figures"):
        require("plots", "x")
