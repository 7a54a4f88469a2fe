"""pkm.core.model.mechanism.Mechanism: per-thread data (one mechanism used from several threads) and pickling."""

from __future__ import annotations

import pickle
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import pkm
from pkm.core.model.compare import mechanism_differences
from pkm.errors import InvalidInputError, SpecError


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
    and reference (pkm.core.model.compare, 1e-12)."""
    mech = built(name)
    path = pkm.save(mech, tmp_path / "sub" / f"{name}.closures.toml")
    assert path.is_file() and (tmp_path / "sub" / f"{name}.urdf").is_file()
    assert mechanism_differences(pkm.load(path), mech) == []
    assert mechanism_differences(pkm.load(str(path)), mech) == []


def _floating_ankle():
    """The acceptance set's ankle hung on a free-flyer (a pelvis over a ground link), and the fixed one."""
    from pathlib import Path

    fixed = pkm.load(Path(__file__).resolve().parents[3] / "examples" / "ankle" / "ankle.closures.toml")
    urdf = fixed.urdf.replace('<robot name="ankle">', '<robot name="ankle">\n  <link name="ground"/>\n  <joint '
                              'name="pelvis" type="floating">\n    <parent link="ground"/>\n    <child link="shank"/>\n'
                              '  </joint>')
    import dataclasses

    spec = dataclasses.replace(fixed.spec, floating_base="pelvis", reference={})
    return pkm.from_strings(urdf, spec), fixed


def test_a_floating_base_is_an_input_the_solvers_hold():
    """With the pelvis turned and moved, FK and IK leave it where q puts it and give the fixed ankle's joints; the
    rate maps give it no velocity; the efforts equal the fixed ankle's under gravity turned into the pelvis's axes
    (1e-10); a saved spec keeps it."""
    import pinocchio as pin

    floating, fixed = _floating_ankle()
    assert floating.base.name == "pelvis" and len(floating.passive_v) == len(fixed.passive_v)
    R = pin.rpy.rpyToMatrix(0.3, -0.2, 1.1)
    base = np.concatenate([[0.4, -0.1, 0.9], pin.Quaternion(R).coeffs()])
    at = floating.base.idx_q
    q0 = floating.q_reference.copy()
    q0[at:at + 7] = base
    qa = np.array([0.2, -0.15])
    fk = pkm.close_loops(floating, qa, q0)
    assert np.array_equal(fk.q[at:at + 7], base)
    ref = pkm.close_loops(fixed, qa, fixed.q_reference)
    assert np.abs(pkm.TaskMap.of(floating).value(fk.q) - pkm.TaskMap.of(fixed).value(ref.q)).max() <= 1e-10
    ik = pkm.solve_ik(floating, pkm.TaskMap.of(floating).value(fk.q) + 0.01, fk.q)
    assert np.array_equal(ik.q[at:at + 7], base)
    qd, qdd = np.array([0.5, -0.3]), np.array([1.0, 2.0])
    v = pkm.velocities(floating, fk.q, qd)
    a = pkm.accelerations(floating, fk.q, v, qdd)
    assert np.abs(v[floating.base_v]).max() == 0.0 and np.abs(a[floating.base_v]).max() == 0.0
    tau = pkm.inverse_dynamics(floating, fk.q, v, a, base="fixed")  # (the base held: a has none)
    fixed.model.gravity = pin.Motion(np.concatenate([R.T @ floating.model.gravity.linear, np.zeros(3)]))
    try:
        vf = pkm.velocities(fixed, ref.q, qd)
        tau_fixed = pkm.inverse_dynamics(fixed, ref.q, vf, pkm.accelerations(fixed, ref.q, vf, qdd))
    finally:
        fixed.model.gravity = floating.model.gravity
    assert np.abs(tau - tau_fixed).max() <= 1e-10 * max(1.0, np.abs(tau).max())
    assert pkm.diagnose(floating, fk.q).idle_joints == ("rod_ball_left", "rod_ball_right")


def test_a_floating_base_must_be_a_free_flyer_on_the_world(tmp_path):
    import dataclasses

    floating, _ = _floating_ankle()
    for name, message in (("ankle_pitch", "must be a free-flyer"), ("nope", "nope")):
        with pytest.raises(SpecError, match=message):
            pkm.from_strings(floating.urdf, dataclasses.replace(floating.spec, floating_base=name))
    again = pkm.load(pkm.save(floating, tmp_path / "floating.closures.toml"))
    assert again.base is not None and again.base.name == "pelvis"


def test_an_mjcf_root_freejoint_is_a_floating_base(tmp_path):
    """A <freejoint> on the root body that carries the mechanism is its floating base; one on a leaf body (a
    platform) is not."""
    from pathlib import Path

    text = (Path(__file__).resolve().parents[3] / "examples" / "mjcf_fourbar" / "fourbar.xml").read_text()
    text = text.replace("<worldbody>", '<worldbody>\n    <body name="pelvis" pos="0 0 1"><freejoint name="root"/>'
                        '<geom type="sphere" size="0.05" mass="2"/>').replace("</worldbody>", "</body></worldbody>")
    (tmp_path / "floating.xml").write_text(text)
    mech = pkm.load(tmp_path / "floating.xml")
    assert mech.base is not None and mech.base.name == "root"
    q = pkm.close_loops(mech, [0.4], mech.q_reference).q
    assert np.abs(q[mech.base.idx_q:mech.base.idx_q + 7] - mech.q_reference[:7]).max() == 0.0


def test_an_unreachable_target_holds_the_floating_base_too(tmp_path):
    """The MJCF four-bar on a free pelvis, its coupler point 5 m up: unreachable (the least-squares search holds the
    base too), as on the fixed four-bar."""
    from pathlib import Path

    from pkm.errors import UnreachableError

    text = (Path(__file__).resolve().parents[3] / "examples" / "mjcf_fourbar" / "fourbar.xml").read_text()
    text = text.replace("<worldbody>", '<worldbody>\n    <body name="pelvis" pos="0 0 1"><freejoint name="root"/>'
                        '<geom type="sphere" size="0.05" mass="2"/>').replace("</worldbody>", "</body></worldbody>")
    (tmp_path / "floating.xml").write_text(text)
    (tmp_path / "floating.closures.toml").write_text('format = "pkm.closures/1"\nmechanism = "f"\nurdf = "floating.xml"\n'
                                                     'end_effector = "coupler_point"\nactuated = ["crank_joint"]\n'
                                                     '[task]\ncomponents = ["z"]\n')
    mech = pkm.load(tmp_path / "floating.closures.toml")
    assert mech.base is not None
    with pytest.raises(UnreachableError):
        pkm.solve_ik(mech, {"z": 5.0})


def test_construction_moved_to_the_builder_says_where():
    """``Mechanism.from_strings`` / ``from_files`` reached the builder from the model (a hidden import cycle): they
    moved to :func:`pkm.from_strings` and :func:`pkm.load`, and the old names say so."""
    with pytest.raises(AttributeError, match=r"moved to pkm\.from_strings"):
        pkm.Mechanism.from_strings("<robot/>", "")
    with pytest.raises(AttributeError, match=r"moved to pkm\.load"):
        pkm.Mechanism.from_files("my.closures.toml")


def test_limits_along_a_path_are_the_first_sample_outside_per_joint(built):
    """``limits_along`` (vectorised) against the plain rule ``lower - tol <= x <= upper + tol`` sample by sample on
    the Delta's configurations scattered to +-4 (its limits +-pi, the platform's +-1.18 m): per joint the first sample
    outside, its value and limits, in the order of the samples; ``limit_violations`` and ``outside_limits`` of each
    sample are its joints outside, in the model's order; a NaN is not called outside (the caller's to refuse)."""
    delta = built("delta")
    rng = np.random.default_rng(3)
    Q = np.tile(delta.q_reference, (40, 1))
    Q[:, :] += rng.uniform(-4.0, 4.0, Q.shape) * (rng.random(Q.shape) < 0.1)
    Q[5, 0] = np.nan
    expected: dict[str, tuple[int, float]] = {}
    for k, q in enumerate(Q):
        row = [n for n, (lo, hi) in delta.limits.items() if not lo - 1e-9 <= q[delta.joints[n].idx_q] <= hi + 1e-9
               and not np.isnan(q[delta.joints[n].idx_q])]
        assert delta.outside_limits(q) == tuple(row)
        assert [v.joint for v in delta.limit_violations(q)] == row
        for n in row:
            expected.setdefault(n, (k, float(q[delta.joints[n].idx_q])))
    along = delta.limits_along(Q)
    assert len(along) >= 3 and [k for k, _ in along] == sorted(k for k, _ in along)
    assert {v.joint: (k, v.value) for k, v in along} == expected
    assert all(v.limit == delta.limits[v.joint] for _, v in along)


def test_the_task_map_and_the_scales_are_built_on_the_mechanism_and_kept_with_it():
    """The mechanism imports neither (tests/test_import_graph.py): ``TaskMap.of`` and ``JacobianScales.of`` give
    one object per mechanism, the old attributes say where they went, and a new reference makes new scales with
    the characteristic length there (the legs extended: another L)."""
    from pkm.core.model.scale import JacobianScales

    loaded = pkm.load("gough_stewart")
    mech = pkm.Mechanism(loaded.model, loaded.spec)  # (its own: its reference is changed below)
    task = pkm.TaskMap.of(mech)
    assert pkm.TaskMap.of(mech) is task and task.mech is mech and pkm.TaskMap.of(loaded) is not task
    scales = JacobianScales.of(mech)
    assert JacobianScales.of(mech) is scales and scales.length == mech.characteristic_length
    with pytest.raises(AttributeError, match=r"moved to pkm\.TaskMap\.of\(mech\)"):
        mech.task_map  # noqa: B018
    with pytest.raises(AttributeError, match=r"moved to pkm\.core\.model\.scale\.JacobianScales\.of\(mech\)"):
        mech.jacobian_scales  # noqa: B018
    mech.q_reference = pkm.solve_ik(mech, {"z": task.named(mech.q_reference)["z"] + 0.05}).q
    now = JacobianScales.of(mech)
    assert now is not scales and now.length == mech.characteristic_length
    assert abs(now.length - scales.length) > 1e-3 * scales.length
