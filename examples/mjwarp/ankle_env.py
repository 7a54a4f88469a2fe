"""A batched environment of the humanoid ankle for a plain training loop: N worlds in MuJoCo Warp, the two-motor
ankle's closed loop exact inside the step (pkm.learn.mjwarp), reset/step with batched motor commands.

The task: bring the foot to a random pitch/roll target and hold it. Action: the two motor torques, normalised to
[-1, 1] about the torques that hold the foot at its reference; observation: the outputs (pitch, roll), their rates,
the motors' positions and rates (from the transmission, exact) and the target; reward: minus the squared output
error [rad^2] and a small effort cost; a world is done when its episode ends or when its transmission's solve fails
(status not OK: the outputs left the closed loop's workspace), and is reset then.

Run from the checkout (``pip install "pkm-robotics[mjwarp]"``): ``python examples/mjwarp/ankle_env.py`` trains a
linear policy by random search (a few iterations, Warp's CPU device; ``--device cuda:0`` on a GPU). The first run
compiles MuJoCo Warp's and pkm's kernels (about 30 s; cached on disk for the next run). Not run by
tests/test_examples.py (examples/*.py only): tests/learn/test_mjwarp.py steps it with 4,096 worlds.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import pkm
from pkm.learn.mjwarp import TransmissionWorlds

ANKLE = Path(__file__).resolve().parents[1] / "humanoid_ankle" / "ankle.closures.toml"


class AnkleEnv:
    """``nworld`` humanoid ankles (module doc). ``dt`` [s]: MuJoCo's step; ``decimation``: steps per action;
    ``torque_scale`` [N m]: an action of 1; ``target_range`` [rad]: targets drawn within this of the reference,
    inside the serial model's box limits; ``episode``: steps per episode."""

    def __init__(self, nworld: int = 1024, *, device: str = "cpu", dt: float = 2e-3, decimation: int = 5,
                 torque_scale: float = 3.0, target_range: float = 0.15, episode: int = 100, seed: int = 0,
                 integrator: str = "euler"):
        robot = pkm.load(ANKLE)
        self.worlds = TransmissionWorlds(robot, nworld, dt=dt, integrator=integrator, device=device)
        t = self.worlds.units[0].t
        self.hold = pkm.gravity_efforts(t.mechanism, t.q_reference)  # (the motor torques holding the reference)
        self.reference = t.q_reference[t.out_q]
        lo = np.array([self.worlds.serial.limits[o][0] for o in t.outputs])
        hi = np.array([self.worlds.serial.limits[o][1] for o in t.outputs])
        self.low, self.high = np.maximum(lo, self.reference - target_range), np.minimum(hi, self.reference + target_range)
        self.n, self.decimation, self.scale, self.episode = nworld, decimation, torque_scale, episode
        self.rng = np.random.default_rng(seed)
        self.target = np.zeros((nworld, 2))
        self.steps = np.zeros(nworld, dtype=int)

    def _obs(self) -> np.ndarray:
        w = self.worlds
        return np.hstack([w.output_q, w.qvel, w.motor_q, w.motor_v, self.target])

    def reset(self) -> np.ndarray:
        """Every world at rest at its reference, a new target each; returns the observations ``(nworld, 10)``."""
        self.worlds.reset()
        self.target = self.rng.uniform(self.low, self.high, (self.n, 2))
        self.steps[:] = 0
        return self._obs()

    def step(self, action: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict]:
        """``action`` ``(nworld, 2)`` in [-1, 1]: ``(obs, reward, done, info)``; done worlds get a new target (their
        state carries on: the ankle from where it is, as a walking controller's next step)."""
        tau = self.hold + self.scale * np.clip(action, -1.0, 1.0)
        self.worlds.set_motor_torques(tau)
        self.worlds.step(self.decimation)
        obs = self._obs()
        error = self.worlds.output_q - self.target
        reward = -(error ** 2).sum(axis=1) - 1e-3 * (action ** 2).sum(axis=1)
        self.steps += 1
        failed = self.worlds.status[:, 0] != 0
        done = failed | (self.steps >= self.episode)
        if done.any():
            self.target[done] = self.rng.uniform(self.low, self.high, (int(done.sum()), 2))
            self.steps[done] = 0
        return obs, reward, done, {"failed": failed, "residual": self.worlds.residual[:, 0]}


def train(env: AnkleEnv, iterations: int = 5, horizon: int = 40, sigma: float = 0.3, lr: float = 0.5,
          seed: int = 1) -> list[float]:
    """Random search on a linear policy ``a = K [o - target, ȯ]`` (2 x 4): half the worlds try ``K + sigma δ``, half
    ``K - sigma δ`` with one ``δ`` per pair; ``K`` moves along the rewards' difference. Returns each iteration's mean
    return."""
    rng = np.random.default_rng(seed)
    K = np.zeros((2, 4))
    pairs = env.n // 2
    history = []
    for _ in range(iterations):
        delta = rng.standard_normal((pairs, 2, 4))
        gains = np.concatenate([K + sigma * delta, K - sigma * delta])
        obs = env.reset()
        total = np.zeros(env.n)
        for _ in range(horizon):
            x = np.hstack([obs[:, 0:2] - obs[:, 8:10], obs[:, 2:4]])
            obs, r, _, _ = env.step(np.einsum("nij,nj->ni", gains, x))
            total += r
        diff = total[:pairs] - total[pairs:]
        K += lr / (pairs * sigma * (diff.std() + 1e-12)) * np.einsum("n,nij->ij", diff, delta)
        history.append(float(total.mean()))
        print(f"mean return {history[-1]:.4f}, gains {np.round(K, 2).tolist()}")
    return history


if __name__ == "__main__":
    device = sys.argv[sys.argv.index("--device") + 1] if "--device" in sys.argv else "cpu"
    env = AnkleEnv(256, device=device)
    train(env)
