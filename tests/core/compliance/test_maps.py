"""pkm.core.compliance.maps: a stiffness map's indices at each node are pkm.stiffness's and vibration_modes' there;
its CSV holds them by node; a map without configurations, and bad springs, are refused."""

from __future__ import annotations

import csv

import numpy as np
import pytest

import pkm
from pkm.core.compliance import stiffness, vibration_modes
from pkm.core.compliance.maps import stiffness_map
from pkm.errors import InvalidInputError, UnknownNameError


def test_each_node_holds_the_stiffness_there(tmp_path):
    delta = pkm.load("delta")
    motors = {j: 500.0 for j in delta.actuated_names}
    wmap = pkm.workspace_map(delta, {"x": np.linspace(-0.05, 0.05, 4), "y": np.linspace(-0.04, 0.04, 3)},
                             configurations=True)
    smap = stiffness_map(delta, wmap, joints=motors, frequencies=True)
    assert smap.reachable.shape == (3, 4) and smap.reachable.all() and not smap.failures
    for idx in [(0, 0), (2, 3), (1, 2)]:
        q = wmap.q[idx]
        k = stiffness(delta, q, joints=motors).principal("force")[0]
        assert (smap.force_min[idx], smap.force_max[idx]) == (k[0], k[-1])
        assert np.isinf(smap.moment_min[idx])  # (the Delta's platform cannot turn)
        assert smap.first_frequency[idx] == vibration_modes(delta, q, joints=motors).frequencies[0]
    summary = smap.summary()
    assert summary["force_min_N_per_m"]["worst"] == smap.force_min.min() and summary["anisotropy"]["best"] >= 1.0
    rows = list(csv.DictReader(smap.write_csv(tmp_path / "s.csv").open()))
    assert len(rows) == 12 and float(rows[5]["x"]) == wmap.axes[0][1][1] and float(rows[5]["y"]) == 0.0
    assert float(rows[5]["force_min_N_per_m"]) == smap.force_min[1, 1]
    with pytest.raises(InvalidInputError, match="configurations=True"):
        stiffness_map(delta, pkm.workspace_map(delta, {"x": [0.0, 0.01]}), joints=motors)
    with pytest.raises(UnknownNameError):
        stiffness_map(delta, wmap, joints={"motor_9": 1.0})
