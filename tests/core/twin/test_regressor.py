"""pkm.core.twin.regressor: the compiled regressor (the exact ``∂τ_a/∂θ`` of the twin) equals the Python one on every
shipped mechanism, and ``regressor_batch`` picks its backend as documented."""

from __future__ import annotations

import numpy as np
import pytest

from pkm.core.identification.base import random_states
from pkm.core.identification.regressor import AUTO_SAMPLES, _kernels, parameters, regressor, regressor_batch
from pkm.errors import InvalidInputError
from tests.core.dynamics.test_model import mechanism


@pytest.mark.parametrize("name", ["rrr3", "delta", "prs3", "gough_stewart", "hexapod"])
def test_the_compiled_regressor_is_the_regressor(name):
    """At four random states, batched and one at a time: 1e-12 relative to the largest entry (the hexapod's mimic
    joints included: the twin treats them as joints, Python through rnea's linearity), and ``Y θ`` is the efforts."""
    mech = mechanism(name)
    states = random_states(mech, 4, seed=3)
    Q, QD, QDD = (np.array([s[i] for s in states]) for i in range(3))
    Y = regressor_batch(mech, Q, QD, QDD, backend="c")
    Yp = regressor_batch(mech, Q, QD, QDD, backend="python")
    assert Y.shape == Yp.shape == (4 * mech.na, len(parameters(mech)))
    assert np.abs(Y - Yp).max() <= 1e-12 * np.abs(Yp).max()
    kernels = _kernels(mech)
    assert kernels is not None
    one = kernels.regressor(Q[1], QD[1], QDD[1])
    assert np.abs(one - regressor(mech, *states[1])).max() <= 1e-12 * np.abs(Yp).max()


def test_backends_and_their_refusals():
    mech = mechanism("delta")
    states = random_states(mech, 2, seed=3)
    Q, QD, QDD = (np.array([s[i] for s in states]) for i in range(3))
    assert AUTO_SAMPLES > 2  # (two samples: "auto" runs the kernel only because it is built already)
    assert np.array_equal(regressor_batch(mech, Q, QD, QDD), regressor_batch(mech, Q, QD, QDD, backend="c"))
    with pytest.raises(InvalidInputError, match="backend"):
        regressor_batch(mech, Q, QD, QDD, backend="fortran")
    with pytest.raises(InvalidInputError, match="as many samples"):
        regressor_batch(mech, Q, QD[:1], QDD)
    bad = Q.copy()
    bad[1, 0] = np.nan
    with pytest.raises(InvalidInputError):
        regressor_batch(mech, bad, QD, QDD, backend="c")


def test_the_regressor_built_on_a_shared_twin_is_the_same_function():
    """regressor_function on a ParametricTwin whose Newton step was built first (the 50-digit route's one twin) holds
    the very instructions (operations, operands, constants) of one built on a twin of its own; a twin of another
    mechanism, or not parametric, is refused."""
    import casadi as cs

    import pkm
    from pkm.core.twin.regressor import ParametricTwin, regressor_function
    from pkm.core.twin.tree import Twin

    def listing(f):
        return [(f.instruction_id(k), f.instruction_input(k), f.instruction_output(k),
                 float(f.instruction_constant(k)) if f.instruction_id(k) == cs.OP_CONST else None)
                for k in range(f.n_instructions())]

    own, shared = pkm.load("rrr3"), pkm.load("rrr3")
    twin = ParametricTwin(shared)
    assert twin.closure_newton["q_next"].shape[0] == shared.model.nq
    assert listing(regressor_function(shared, twin)) == listing(regressor_function(own))
    with pytest.raises(InvalidInputError, match="twin"):
        regressor_function(own, ParametricTwin(pkm.load("rrr3")))
    with pytest.raises(InvalidInputError, match="twin"):
        regressor_function(own, Twin(own))  # type: ignore[arg-type]
