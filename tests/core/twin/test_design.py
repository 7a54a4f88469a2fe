"""pkm.core.twin.design: kernels with design inputs equal, at each design, the kernels compiled for that design alone
and the generic core on that design's mechanism; one compiled library serves them all; bad designs are refused with
the choices named."""

from __future__ import annotations

import numpy as np
import pytest

import pkm
from pkm.core.kinematics.constraints import residual
from pkm.core.twin.design import design_mechanism, read_design, structure
from pkm.core.twin.kernels import Kernels
from pkm.errors import InvalidInputError, UnknownNameError
from tests.core.twin.test_tree import FILES

GS_NAMES = tuple(f"u{i}.{c}" for i in range(1, 7) for c in ("x", "y"))


@pytest.fixture(scope="module")
def gough_stewart():
    mech = pkm.load(FILES["gough_stewart"])
    return mech, Kernels(mech, design=GS_NAMES)


def _designs(K: Kernels, n: int, spread: float, seed: int = 0):
    rng = np.random.default_rng(seed)
    return [dict(zip(K.design.names, K.design.base + spread * rng.uniform(-1, 1, len(K.design)))) for _ in range(n)]


def moved_design(mech) -> dict[str, float]:
    """The Gough-Stewart's six base joints moved up to 2 cm (seed 3): the design whose map is checked here and whose
    capability tests/sweeps/test_objectives.py checks, so that both use one shared twin and one own twin (each
    compiled once: the cache keys on their source)."""
    base = np.array(list(read_design(mech, GS_NAMES).values()))
    return dict(zip(GS_NAMES, base + 0.02 * np.random.default_rng(3).uniform(-1, 1, len(GS_NAMES))))


def _rel(a, b) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / max(1.0, float(np.max(np.abs(b)))))


def test_six_base_joints_moved_give_the_efforts_and_jacobians_of_that_design(gough_stewart):
    """At three designs (base joints moved up to 3 cm): inverse dynamics and the forward Jacobian of the shared
    kernels equal the generic core (Pinocchio) on the design's own mechanism to 1e-12 relative, and the library is
    the same file for every design."""
    mech, K = gough_stewart
    for values in _designs(K, 3, 0.03):
        d = design_mechanism(mech, values)
        Kd = K.at(values, d)
        rng = np.random.default_rng(1)
        q, qd, qdd = d.q_reference, rng.standard_normal(6), rng.standard_normal(6)
        v = pkm.velocities(d, q, qd)
        tau = pkm.inverse_dynamics(d, q, v, pkm.accelerations(d, q, v, qdd))
        assert _rel(Kd.inverse_dynamics(q, qd, qdd), tau) <= 1e-12
        assert _rel(Kd.forward_jacobian(q), pkm.forward_jacobian(d, q)) <= 1e-12
        assert Kd.how == K.how  # (one compiled library: the views share it)


def test_a_design_s_map_equals_the_map_of_its_own_compiled_twin(gough_stewart):
    """A 12 x 12 map of one moved design through the shared kernels equals the map through that design's own
    twin (compiled for it alone): the same reachable nodes, singular values to 1e-12."""
    mech, K = gough_stewart
    values = moved_design(mech)
    d = design_mechanism(mech, values)
    axes = {"x": np.linspace(-0.15, 0.15, 12), "y": np.linspace(-0.15, 0.15, 12)}
    shared = pkm.workspace_map(d, axes, kernels=K.at(values, d), length=0.5)
    own = pkm.workspace_map(d, axes, length=0.5)
    assert shared.nodes == own.nodes > 100
    assert np.array_equal(shared.reachable, own.reachable)
    assert _rel(shared.singular_values[shared.reachable], own.singular_values[own.reachable]) <= 1e-12


def test_paths_at_a_design_close_that_design(gough_stewart):
    mech, K = gough_stewart
    values, = _designs(K, 1, 0.02, seed=5)
    d = design_mechanism(mech, values)
    Kd = K.at(values, d)
    qa = d.actuated_q(d.q_reference)
    path = Kd.close_loops_path(qa + np.linspace(0, 0.02, 5)[:, None])
    assert not path.fallback and path.residual.max() <= 1e-12
    for q, target in zip(path.q, qa + np.linspace(0, 0.02, 5)[:, None]):
        assert np.abs(residual(d, q)).max() <= 1e-11
        assert np.allclose(d.actuated_q(q), target, atol=1e-12)


def test_inertial_parameters_as_inputs_give_that_design_s_efforts():
    """The 3-PRS with its platform's mass and one inertia moment as inputs: efforts at a heavier platform equal
    the core on the mechanism with those inertias. (Its disc's Izz is Ixx + Iyy: a larger Izz would break the
    triangle inequality, a design whose dynamics pkm refuses; a smaller one is a real platform.)"""
    mech = pkm.load("prs3")
    body = read_design(mech)
    names = ("platform_link.m", "platform_link.Izz")
    K = Kernels(mech, design=names)
    values = {"platform_link.m": 1.7 * body["platform_link.m"], "platform_link.Izz": 0.9 * body["platform_link.Izz"]}
    d = design_mechanism(mech, values)
    rng = np.random.default_rng(2)
    q, qd, qdd = mech.q_reference, rng.standard_normal(3), rng.standard_normal(3)
    v = pkm.velocities(d, q, qd)
    tau = pkm.inverse_dynamics(d, q, v, pkm.accelerations(d, q, v, qdd))
    assert _rel(K.at(values, d).inverse_dynamics(q, qd, qdd), tau) <= 1e-12
    assert _rel(K.inverse_dynamics(q, qd, qdd), pkm.inverse_dynamics(mech, q, pkm.velocities(mech, q, qd),
                pkm.accelerations(mech, q, pkm.velocities(mech, q, qd), qdd))) <= 1e-12  # (the file's design)


def test_fixed_joint_origins_move_the_frames_they_carry():
    """The 3-RRR's platform vertices hang on fixed joints: with their origins as inputs, the closure residual of
    the shared kernels is that design's (checked through the closure Newton step: one step from the design's own
    closed configuration stays there)."""
    mech = pkm.load("rrr3")
    names = ("platform_B_fixed.x", "platform_C_fixed.x", "platform_C_fixed.y")
    K = Kernels(mech, design=names)
    values = dict(zip(names, np.array(list(read_design(mech, names).values())) * 1.2))
    own = design_mechanism(mech, values)
    Kd = K.at(values, own)
    q = own.q_reference
    nxt, residual, _ = Kd.kernel("closure_newton")(q[None], own.actuated_q(q)[None],
                                                   Kd.design_values[None])
    assert residual[0, 0] <= 1e-12 and np.abs(nxt[0] - q).max() <= 1e-12
    _, residual_file, _ = K.kernel("closure_newton")(q[None], own.actuated_q(q)[None], K.design_values[None])
    assert residual_file[0, 0] > 1e-3  # (at the file's vertices the design's configuration is open)


def test_bad_designs_are_refused_with_the_choices_named(gough_stewart):
    mech, K = gough_stewart
    with pytest.raises(UnknownNameError, match=r"u1\.x"):
        Kernels(mech, design=("u9.x",))
    with pytest.raises(InvalidInputError, match="named twice"):
        Kernels(mech, design=("u1.x", "u1.x"))
    with pytest.raises(UnknownNameError):
        K.at({"u1.z": 0.1})  # (not an input of these kernels)
    with pytest.raises(InvalidInputError, match="12 finite"):
        K.at([0.1, np.nan])
    with pytest.raises(InvalidInputError, match="no design inputs"):
        Kernels(mech).at({"u1.x": 0.5})
    with pytest.raises(InvalidInputError, match="regressor"):
        K.function("regressor")


def test_a_fixed_joint_carrying_mass_varies_only_with_the_body_it_merges_into(gough_stewart):
    """A 2 kg weight bolted to the platform by a fixed joint: its origin moves mass within the platform's body, so
    it is refused without the platform's ten inertial parameters (one of them is not enough: the others would stay
    the file's); with them (``with_merged_bodies``, their values the design's as Pinocchio merges them) the efforts
    at a moved weight are that design's, to 1e-12."""
    from pkm.core.twin.design import with_merged_bodies

    mech, _ = gough_stewart
    weight = ('<link name="weight"><inertial><mass value="2.0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" '
              'iyz="0" izz="0.01"/></inertial></link><joint name="weight_fixed" type="fixed"><parent link="platform"/>'
              '<child link="weight"/><origin xyz="0 0 0.1" rpy="0 0 0"/></joint></robot>')
    heavy = pkm.from_strings(mech.urdf.replace("</robot>", weight), mech.spec.to_toml(), source="heavy")
    for names in (("weight_fixed.z",), ("weight_fixed.z", "platform.mz")):
        with pytest.raises(InvalidInputError, match="carries 2 kg"):
            Kernels(heavy, design=names)
    names = with_merged_bodies(heavy, ("weight_fixed.z",))
    assert len(names) == 11 and "platform.Izz" in names
    K = Kernels(heavy, design=names)
    d = design_mechanism(heavy, {"weight_fixed.z": 0.4})
    rng = np.random.default_rng(4)
    q, qd, qdd = d.q_reference, rng.standard_normal(6), rng.standard_normal(6)
    v = pkm.velocities(d, q, qd)
    tau = pkm.inverse_dynamics(d, q, v, pkm.accelerations(d, q, v, qdd))
    assert _rel(K.at(read_design(d, names), d).inverse_dynamics(q, qd, qdd), tau) <= 1e-12


def test_the_structure_ignores_origins_inertias_and_the_reference_but_not_the_spec():
    mech = pkm.load("rrr3")
    moved = pkm.build("rrr3", a=0.5, h=0.2)
    assert structure(moved) == structure(mech)
    assert structure(pkm.build("rrr3", branch=2)) != structure(mech)


def test_views_of_two_designs_answer_from_two_threads_each_its_own(gough_stewart):
    """Two threads calling one sample at a time, each on its own design's view (the views share the compiled
    kernels): every answer is its own design's (the single-sample buffers are each thread's)."""
    import threading

    mech, K = gough_stewart
    views = []
    for values in _designs(K, 2, 0.03, seed=7):
        d = design_mechanism(mech, values)
        views.append((K.at(values, d), d.q_reference))
    qd, qdd = np.full(6, 0.3), np.full(6, -0.2)
    expected = [view.inverse_dynamics(q, qd, qdd) for view, q in views]
    wrong = [0, 0]

    def run(k: int) -> None:
        view, q = views[k]
        for _ in range(3000):
            wrong[k] += not np.array_equal(view.inverse_dynamics(q, qd, qdd), expected[k])

    threads = [threading.Thread(target=run, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert wrong == [0, 0]


def test_a_batch_reads_the_design_once_and_equals_one_sample_at_a_time(gough_stewart, monkeypatch):
    """300 states of one design (the design a single row, read in place by every sample: the vector driver's and
    the scalar driver's stride 0, on two threads) give each sample's efforts bit for bit; numpy's route (no
    compiler) broadcasts it, to 1e-12."""
    from pkm.core.twin import kernels as kmod

    mech, K = gough_stewart
    values, = _designs(K, 1, 0.02, seed=9)
    d = design_mechanism(mech, values)
    view = K.at(values, d)
    rng = np.random.default_rng(9)
    qa = d.actuated_q(d.q_reference)
    Q = view.close_loops_path(qa + 0.01 * np.sin(np.linspace(0, 3, 300))[:, None] * rng.standard_normal(6)).q
    QD, QDD = rng.standard_normal((300, 6)), rng.standard_normal((300, 6))
    monkeypatch.setattr(kmod, "THREAD_SAMPLES", 100)
    batch = view.inverse_dynamics(Q, QD, QDD)
    one = np.array([view.inverse_dynamics(q, qd, qdd) for q, qd, qdd in zip(Q, QD, QDD)])
    assert np.array_equal(batch, one)
    numpy = Kernels(mech, design=GS_NAMES, compiled=False).at(values, d).inverse_dynamics(Q[:5], QD[:5], QDD[:5])
    assert _rel(numpy, one[:5]) <= 1e-12
