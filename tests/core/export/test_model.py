"""The exported C's singularity test is homogenised (:class:`pkm.core.export.model.Newton`'s row and column factors,
:class:`~pkm.core.model.scale.JacobianScales`'): on a slider-crank scaled by 1000 (a model in millimetres read as
metres), compiled once, ``fk_distance`` (what SINGULAR is decided on) is pkm's direct distance of the copy and of
the original, where the raw matrix's ratio is 136 times smaller; its Newton tolerance counts lengths in the
characteristic length (the same iterations at every size)."""

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


def _newton_iterations(newton, q, target):
    """The C's Newton loop (runtime.NEWTON, a warm start: one step of the path) on the step kernel: (iterations,
    residual at the last iterate), (None, residual) where it does not converge in MAX_ITER."""
    from pkm.core.export.library import MAX_ITER, TOL

    for it in range(1, MAX_ITER + 1):
        q_next, r, *_ = (np.array(x).ravel() for x in newton.step(q, target))
        if r[0] <= TOL:
            return it, float(r[0])
        q = q_next
    return None, float(r[0])


@pytest.mark.filterwarnings("ignore::pkm.errors.ImplausibleModelWarning")  # (the 0.1 copy's masses are the original's)
def test_the_newton_tolerance_counts_lengths_in_the_characteristic_length(scaled):
    """The slider-crank and its copies scaled by 0.1 and 10 (the step kernels the C is written from) and the compiled
    copy scaled by 1000, warm-started from the reference toward three actuated values and their task values: the same
    iterations, the first residual the same (1e-9 relative, lengths in L: TOL means the same at every size), and the
    C's status and iterations those of the Python kernels (issue 52: before, TOL was 1e-12 m, and the copies 10 and
    1000 times larger took 5 IK iterations where the original took 4)."""
    mech, big, h = scaled
    qa0, L = mech.actuated_q(mech.q_reference), mech.characteristic_length
    moves = [qa0 + d * np.where([j.revolute for j in mech.actuated], 1.0, L) for d in (0.05, -0.08, 0.1)]
    runs = {}
    for s in (1.0, 0.1, 10.0, 1000.0):
        m = {1.0: mech, 1000.0: big}.get(s) or pkm.scaled_mechanism(mech, s)
        model, ref = ExportModel(m), scale_configuration(mech, mech.q_reference, s)
        out = []
        for qa in moves:
            qa = qa * np.where([j.revolute for j in m.actuated], 1.0, s)
            y = pkm.TaskMap.of(m).value(pkm.close_loops(m, qa).q)
            first = [float(np.array(n.step(ref, t)[1])[0, 0]) for n, t in ((model.fk, qa), (model.ik, y))]
            out.append((_newton_iterations(model.fk, ref, qa)[0], _newton_iterations(model.ik, ref, y)[0], first,
                        qa, y))
        runs[s] = out
    assert all(fk is not None and ik is not None and fk >= 3 for fk, ik, *_ in runs[1.0])
    for s in (0.1, 10.0, 1000.0):
        for (fk1, ik1, first1, *_), (fk, ik, first, *_) in zip(runs[1.0], runs[s]):
            assert (fk, ik) == (fk1, ik1), s
            assert np.allclose(first, first1, rtol=1e-9, atol=0.0), (s, first, first1)
    ref = big.q_reference
    for fk, ik, _, qa, y in runs[1000.0]:
        row = h.run("fk", np.hstack([qa, ref, [0.0]])[None])[0]
        assert (int(row[0]), int(row[1])) == (0, fk) and row[2] <= 1e-12, row[:3]
        row = h.run("ik", np.hstack([y, ref, [0.0]])[None])[0]
        assert (int(row[0]), int(row[1])) == (0, ik) and row[2] <= 1e-12, row[:3]
    assert f"characteristic length L = {big.characteristic_length:.6g} m" in h.lib.header.read_text()
