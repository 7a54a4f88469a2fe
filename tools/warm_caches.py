"""Fill the caches the test run reads, on the core ``make test`` leaves idle while mypy runs: MuJoCo Warp's and pkm's
Warp kernels, compiled by a first step of the example environment (tests/learn/test_mjwarp.py: about 30 s of CPU
cold, a few seconds warm). Does nothing where the mjwarp extra is not installed; a failure here is the tests' to
report, not this script's (it exits 0)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np


def main() -> int:
    if importlib.util.find_spec("mujoco_warp") is None:
        return 0
    try:
        path = Path(__file__).resolve().parents[1] / "examples" / "mjwarp" / "ankle_env.py"
        spec = importlib.util.spec_from_file_location("pkm_example_ankle_env", path)
        assert spec is not None and spec.loader is not None
        example = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(example)
        env = example.AnkleEnv(1, seed=0)
        env.reset()
        env.step(np.zeros((1, len(env.hold))))
    except Exception as exc:  # (the test run says what is wrong)
        print(f"warm_caches: {exc!r}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
