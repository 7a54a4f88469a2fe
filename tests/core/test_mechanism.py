"""pkm.core.mechanism.Mechanism: per-thread data (one mechanism used from several threads) and pickling."""

from __future__ import annotations

import pickle
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import pkm
from pkm.core.compare import mechanism_differences
from pkm.errors import InvalidInputError


def test_each_thread_gets_its_own_pinocchio_data(built):
    mech = built("delta")
    seen = {}

    def grab(k):
        seen[k] = (mech.data, mech.constraint_datas[0])  # kept alive, so that no id is reused

    threads = [threading.Thread(target=grab, args=(k,)) for k in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len({id(v[0]) for v in seen.values()} | {id(mech.data)}) == 4  # three threads and this one
    assert len({id(v[1]) for v in seen.values()} | {id(mech.constraint_datas[0])}) == 4
    assert mech.data is mech.data  # made once per thread


@pytest.mark.parametrize("name", ["delta", "hexapod"])
def test_solvers_from_several_threads_give_the_serial_answers(name):
    """Inverse kinematics, loop closure and Jacobians run concurrently on one mechanism equal the serial results."""
    mech = pkm.load(name)
    task = pkm.TaskMap(mech)
    y0 = task.value(mech.q_reference)
    rng = np.random.default_rng(0)
    targets = [task.retract(y0, 0.01 * rng.standard_normal(task.size)) for _ in range(24)]

    def work(y):
        ik = pkm.solve_ik(mech, y)
        fk = pkm.close_loops(mech, mech.actuated_q(ik.q), mech.q_reference)
        return ik.q, fk.q, pkm.forward_jacobian(mech, ik.q)

    serial = [work(y) for y in targets]
    with ThreadPoolExecutor(max_workers=4) as pool:
        parallel = list(pool.map(work, targets))
    for a, b in zip(serial, parallel):
        for x, y in zip(a, b):
            np.testing.assert_array_equal(x, y)  # the same arithmetic, whichever thread ran it


@pytest.mark.parametrize("name", pkm.mechanisms.names())
def test_a_mechanism_pickles_to_the_same_model(name, built):
    mech = built(name)
    again = pickle.loads(pickle.dumps(mech))
    assert mechanism_differences(mech, again) == [] and again.params == mech.params
    np.testing.assert_array_equal(again.q_reference, mech.q_reference)


def test_a_mechanism_without_urdf_text_says_why_it_does_not_pickle(built):
    mech = built("delta")
    bare = pkm.Mechanism(mech.model, mech.spec)
    with pytest.raises(InvalidInputError, match="cannot be pickled"):
        pickle.dumps(bare)


@pytest.mark.parametrize("name", pkm.mechanisms.names())
def test_save_and_load_give_the_same_model(name, built, tmp_path):
    """pkm.save writes a spec and its URDF; pkm.load of that path gives the same model, closures, actuation, task
    and reference (pkm.core.compare, 1e-12)."""
    mech = built(name)
    path = pkm.save(mech, tmp_path / "sub" / f"{name}.closures.toml")
    assert path.is_file() and (tmp_path / "sub" / f"{name}.urdf").is_file()
    assert mechanism_differences(pkm.load(path), mech) == []
    assert mechanism_differences(pkm.load(str(path)), mech) == []
