"""Training through a parallel ankle's dynamics in JAX: the gradient of a loss passes through pkm's kernel.

The humanoid ankle (``humanoid_ankle/``: MJCF + spec, two motors, cranks and rods to the heel, the rods spinning
idle) has an actuator-space model: at a closed state, ``qdd = M_a⁻¹ (τ - h_a)`` (rotor inertias in, the idle spins
settled). pkm generates it as a kernel and ``pkm.Kernels(ankle).jax("forward_dynamics")`` translates it to a jitted
JAX function of one sample (:mod:`pkm.core.twin.jaxgen`). Here a
linear policy maps (motor angles, motor speeds, desired motor accelerations) to motor torques; the loss is the gap
between the accelerations those torques produce (the kernel, ``jax.vmap`` over a batch of closed states) and the
desired ones; ``jax.value_and_grad`` differentiates it through the kernel, plain SGD follows (no flax, no optax).
The learned torques end near the model's ``M_a qdd + h_a`` (the C kernel ``mass_and_bias``) on states not trained on,
where the loss is taken through the C kernel ``forward_dynamics`` (the same equations, compiled without XLA).
Needs JAX (``pip install "pkm-robotics[jax]"``). Run it from anywhere: python examples/ankle_jax_training.py
"""

import sys
from pathlib import Path

import numpy as np

import pkm

try:
    import jax
    import jax.numpy as jnp
except ImportError:
    sys.exit('this example needs JAX: pip install "pkm-robotics[jax]"')

ankle = pkm.load(Path(__file__).resolve().parent / "humanoid_ankle" / "ankle.closures.toml")
K = pkm.Kernels(ankle)
# the kernel in JAX (64-bit mode on: the kernel is double precision, as its C): (q, qd, tau, friction) -> (qdd, pivot)
forward = K.jax("forward_dynamics")
FRICTION = jnp.array([0.0, 0.05])  # (friction off; the Coulomb velocity scale, unused then)
print(ankle)


def states(n: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``n`` closed configurations (motors within ±0.3 rad of neutral), motor speeds and desired accelerations."""
    rng = np.random.default_rng(seed)
    qa0 = ankle.actuated_q(ankle.q_reference)
    Q = np.array([pkm.close_loops(ankle, qa0 + rng.uniform(-0.3, 0.3, ankle.na)).q for _ in range(n)])
    return Q, rng.normal(0.0, 2.0, (n, ankle.na)), rng.normal(0.0, 10.0, (n, ankle.na))


Q, QD, QDD = states(256, seed=0)
X = np.hstack([np.array([ankle.actuated_q(q) for q in Q]), QD, QDD])  # the policy's features
MEAN, STD = X.mean(axis=0), X.std(axis=0)
SCALE = float(np.mean(np.diag(K.mass_matrix(ankle.q_reference))))  # torque per unit acceleration [kg m^2]


def policy(params: dict, x: jnp.ndarray) -> jnp.ndarray:
    """Motor torques [N m]: linear in the normalised features (JAX arrays in training, numpy arrays after)."""
    return SCALE * (((x - MEAN) / STD) @ params["W"] + params["b"])


def loss(params: dict, Q, QD, X, QDD) -> jnp.ndarray:
    """Mean squared gap between the accelerations the policy's torques produce (the kernel) and the desired ones."""
    qdd, _ = jax.vmap(forward, in_axes=(0, 0, 0, None))(Q, QD, policy(params, X), FRICTION)
    return jnp.mean((qdd - QDD) ** 2)


@jax.jit
def step(params: dict, Q, QD, X, QDD, lr: float = 0.2) -> tuple[dict, jnp.ndarray]:
    value, grad = jax.value_and_grad(loss)(params, Q, QD, X, QDD)
    return jax.tree_util.tree_map(lambda p, g: p - lr * g, params, grad), value


params = {"W": jnp.zeros((X.shape[1], ankle.na)), "b": jnp.zeros(ankle.na)}
data = tuple(jnp.asarray(a) for a in (Q, QD, X, QDD))
for k in range(41):
    params, value = step(params, *data)
    if k % 5 == 0:
        print(f"step {k:3d}: loss {float(value):10.4f} (rad/s^2)^2")

# on states not trained on: the policy's torques against the model's M_a qdd + h_a (the compiled C kernel)
params = {k: np.asarray(p) for k, p in params.items()}  # (the trained policy in numpy from here: no XLA compile)
Qt, QDt, QDDt = states(64, seed=1)
Xt = np.hstack([np.array([ankle.actuated_q(q) for q in Qt]), QDt, QDDt])
M, h = K.mass_and_bias(Qt, QDt)
exact = np.einsum("nij,nj->ni", M, QDDt) + h
learned = policy(params, Xt)
held_out = np.mean((K.forward_dynamics(Qt, QDt, learned) - QDDt) ** 2)  # (the loss through the C kernel)
print(f"held-out states: loss {held_out:.4f} (rad/s^2)^2; torques within "
      f"{np.abs(learned - exact).max():.4f} N m of M_a qdd + h_a (largest {np.abs(exact).max():.2f} N m)")
print("learned torque per unit desired acceleration [kg m^2]:\n", np.round(SCALE * params["W"][4:] / STD[4:, None],
                                                                          4))
print("the model's M_a at neutral:\n", np.round(K.mass_matrix(ankle.q_reference), 4))
