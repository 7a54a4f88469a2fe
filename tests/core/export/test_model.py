"""The exported C's singularity test is homogenised (:class:`pkm.core.export.model.Newton`'s row and column factors,
:class:`~pkm.core.model.scale.JacobianScales`'): on a slider-crank scaled by 1000 (a model in millimetres read as
metres), compiled once, ``fk_distance`` (what SINGULAR is decided on) is pkm's direct distance of the copy and of
the original, where the raw matrix's ratio is 136 times smaller."""

from __future__ import annotations

import re
import shutil

import numpy as np
import pytest

import pkm
from pkm.core.export import export_c
from pkm.core.export.harness import build
from pkm.core.export.library import mode_id
from pkm.core.export.model import ExportModel
from pkm.core.model.scale import JacobianScales, scale_configuration
from tests.test_acceptance import load

pytestmark = pytest.mark.skipif(shutil.which("cc") is None, reason="needs a C compiler (cc)")


@pytest.fixture(scope="module")
def scaled(tmp_path_factory):
    """The slider-crank and its copy scaled by 1000, the copy's library exported and built once (-O0)."""
    mech = load("slider_crank")
    big = pkm.scaled_mechanism(mech, 1000.0)
    return mech, big, build(export_c(big, tmp_path_factory.mktemp("big")), optimise="-O0")


def test_the_c_decides_singularity_on_the_homogenised_matrix_as_pkm_does(scaled):
    """At the reference and at two other closed configurations: the C's fk_distance equals pkm.diagnose's direct
    distance on the copy and on the original (1e-9 relative), and the Python twin's (mode_id); the raw matrix's
    ratio is not scale-free (the slider's column is in m: 1000 times longer steps, the ratio far smaller)."""
    mech, big, h = scaled
    model = ExportModel(big)
    qa0 = mech.actuated_q(mech.q_reference)
    for qa in (qa0, qa0 + 0.3, qa0 - 0.2):
        q0 = pkm.close_loops(mech, qa).q
        q = pkm.close_loops(big, qa, scale_configuration(mech, q0, 1000.0)).q
        want = pkm.diagnose(mech, q0).direct_distance
        assert abs(pkm.diagnose(big, q).direct_distance - want) <= 1e-9 * want
        got = h.run("modes", q[None])[0]
        assert got[0] == 0 and abs(got[4] - want) <= 1e-9 * want, (got[4], want)
        assert abs(mode_id(model.fk, q, big.actuated_q(q))[1] - want) <= 1e-9 * want
        sv = np.linalg.svd(np.array(model.fk.system(q, big.actuated_q(q))[0]), compute_uv=False)
        assert sv[-1] / sv[0] < 0.1 * want  # (the raw ratio: what the C judged before)


def test_the_factors_are_emitted_as_constants(scaled):
    """The C's row and column factors are the Newton matrices' (the copy's characteristic length on the slider's
    column), as pkm's JacobianScales gives them."""
    _, big, h = scaled
    text = h.lib.source.read_text()
    model, L = ExportModel(big), JacobianScales.of(big).length
    for kind, newton in (("fk", model.fk), ("ik", model.ik)):
        for side, values in (("row", newton.row_scale), ("col", newton.column_scale)):
            found = re.search(rf"{h.lib.name}_{kind}_{side}_scale\[\d+\] = \{{([^}}]*)\}}", text).group(1)
            assert np.allclose([float(x) for x in found.split(",")], values, rtol=1e-15), (kind, side)
    assert np.isclose(model.fk.column_scale.max(), L, rtol=1e-15) and L > 10.0  # (a length column, in a 1000x copy)
