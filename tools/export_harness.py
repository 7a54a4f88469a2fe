"""The exported C of every shipped mechanism, the acceptance set and the humanoid ankle and knee, proven in C (run by ``.ci/run``).

For each mechanism: :func:`pkm.core.export.export_c`, then with every compiler present (``gcc``; ``clang`` where
installed) a strict C99 build (``-std=c99 -Wall -Wextra -Werror -pedantic -O2``; a warning fails it), the object
file's undefined symbols checked (no ``malloc``, ``free``, ``printf``...), and every function compared with pkm's
generic core at four closed configurations (:func:`pkm.core.export.harness.compare`) to :data:`TOL`; then the
bad-input calls (:func:`pkm.core.export.harness.domain`) and the header's named mode ids, each on a configuration in
its mode (:func:`pkm.core.export.harness.check_modes`). Exit status 1 on any failure.

Usage: ``python tools/export_harness.py [--out DIR] [--only NAME ...]``.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: Every function matches pkm to this (relative to max(1, the largest reference value)).
TOL = 1e-12
MECHANISMS = {
    "rrr3": "rrr3", "delta": "delta", "prs3": "prs3", "hexapod": "hexapod",
    "gough_stewart": ROOT / "examples/gough_stewart/gough_stewart.closures.toml",
    "fivebar": ROOT / "examples/gepetto_fivebar", "rssr": ROOT / "examples/gepetto_rssr/robot.yaml",
    "rpr3": ROOT / "examples/rpr3/rpr3.closures.toml", "ankle": ROOT / "examples/ankle/ankle.closures.toml",
    "knee": ROOT / "examples/knee/knee.closures.toml", "mjcf_fourbar": ROOT / "examples/mjcf_fourbar/fourbar.xml",
    "slider_crank": ROOT / "examples/sdf_slider_crank/slider_crank.closures.toml",
    "humanoid_ankle": ROOT / "examples/humanoid_ankle/ankle.closures.toml",
    "humanoid_knee": ROOT / "examples/humanoid_knee/knee.closures.toml",
}


def main(argv: list[str] | None = None) -> int:
    import pkm
    from pkm.core.export import export_c
    from pkm.core.export.harness import build, check_modes, compare, compiler, domain

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=None, help="where the libraries go (default: a temporary folder)")
    ap.add_argument("--only", nargs="*", default=None, help="these mechanisms only")
    args = ap.parse_args(argv)
    compilers = [c for c in ("gcc", "clang") if compiler(c)]
    if not compilers:
        print("export harness: no C compiler (gcc, clang) on the PATH")
        return 1
    failed = []
    with tempfile.TemporaryDirectory() as tmp:
        root = args.out or Path(tmp)
        for name, source in MECHANISMS.items():
            if args.only and name not in args.only:
                continue
            t0 = time.perf_counter()
            mech = pkm.load(source)
            lib = export_c(mech, root / name)
            t1 = time.perf_counter()
            for cc in compilers:
                h = build(lib, cc)
                t2 = time.perf_counter()
                errors = compare(mech, h)
                bad_input, statuses = domain(mech, h)
                modes = check_modes(mech, h)
                worst = max(v for k, v in errors.items() if k != "status")
                ok = worst <= TOL and errors["status"] == 0 and not bad_input and not modes
                print(f"{name:14s} {cc:5s} export {t1 - t0:6.1f} s, build {t2 - t1:6.1f} s: largest difference "
                      f"{worst:.2e} ({max((k for k in errors if k != 'status'), key=errors.get)}), "
                      f"{int(errors['status'])} calls not OK; bad input {'ok' if not bad_input else bad_input}, fk beyond "
                      f"the workspace {statuses}; named modes ({sum(map(len, lib.modes.values()))}) "
                      f"{'ok' if not modes else modes}"
                      f"{'' if ok else '  FAILED'}", flush=True)
                if not ok:
                    failed.append(f"{name} ({cc})")
                t1 = time.perf_counter()
    if failed:
        print("export harness: FAILED:", ", ".join(failed))
        return 1
    print(f"export harness: {len(compilers)} compiler(s), every library warning-free and within {TOL:g} of pkm")
    return 0


if __name__ == "__main__":
    sys.exit(main())
