"""Gymnasium environment: one UAV flight; each step is one handover decision among the 4 candidates."""
from __future__ import annotations

import gymnasium as gym
import numpy as np

from .config import SimConfig
from .features import ACTIONS, FEATURES
from .simulator import Simulator


def decision_step(sim: Simulator, actions: np.ndarray, candidates: np.ndarray) -> tuple[np.ndarray, dict]:
    """Apply one decision per UAV (index into its candidates), then run ``decision_every`` simulator steps.

    Reward per UAV (the paper's four terms, weights in ``RewardConfig``):
    ``-w_handover*[handover] - mean over the steps of (w_buffer*q/q_max + w_rsrp*[RSRP<thr] + w_rsrq*[RSRQ<thr])``.
    """
    cfg = sim.cfg
    w, q_max = cfg.reward, cfg.buffer.q_max_bits
    target = candidates[np.arange(sim.K), np.asarray(actions, dtype=np.int64)]
    cost = np.zeros(sim.K)
    sums = {"handover": np.zeros(sim.K), "pingpong": np.zeros(sim.K), "available": np.zeros(sim.K)}
    n = 0
    for _ in range(cfg.decision_every):
        if sim.done:
            break
        info = sim.step(target if n == 0 else sim.serving)
        cost += w.w_buffer * info.queue_bits / q_max + w.w_rsrp * info.rsrp_violation + w.w_rsrq * info.rsrq_violation
        for key in sums:
            sums[key] += getattr(info, key)
        n += 1
    reward = -w.w_handover * sums["handover"] - cost / max(n, 1)
    return reward, sums


class UAVHandoverEnv(gym.Env):
    """Observation: the 13 features of :data:`FEATURES`; action: :data:`ACTIONS` (0 = stay)."""

    metadata = {"render_modes": []}

    def __init__(self, config: SimConfig | None = None):
        self.cfg = config or SimConfig()
        self.observation_space = gym.spaces.Box(-np.inf, np.inf, shape=(len(FEATURES),), dtype=np.float32)
        self.action_space = gym.spaces.Discrete(len(ACTIONS))
        self.sim: Simulator | None = None

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.sim = Simulator(self.cfg, n_uavs=1, seed=int(self.np_random.integers(2 ** 31)))
        obs, self._cand = self.sim.observe()
        return obs[0], {"candidates": self._cand[0]}

    def step(self, action):
        reward, sums = decision_step(self.sim, np.array([action]), self._cand)
        obs, self._cand = self.sim.observe()
        info = {k: float(v[0]) for k, v in sums.items()} | {"candidates": self._cand[0]}
        return obs[0], float(reward[0]), False, self.sim.done, info
