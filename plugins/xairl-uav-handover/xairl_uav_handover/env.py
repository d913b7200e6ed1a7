"""Gymnasium environments: the one thing that training and evaluation step through.

:class:`HandoverVecEnv` flies K flights at once (a ``gymnasium.vector.VectorEnv``); each step is one handover
decision per flight among its 4 candidates (0 = stay), held for ``decision_every`` simulator steps. All flights
of one vector end together, after the flight's duration (truncation, no autoreset: call ``reset`` again).
:class:`UAVHandoverEnv` is the single-flight ``gymnasium.Env`` for tools that want one (``check_env`` passes).

Reward per flight and decision (the paper's four terms and our two, weights in ``RewardConfig``, q in Mbit):
``-w_handover*[handover] - w_lost*lost - w_pingpong*[ping-pong]`` plus the mean over the steps of
``w_buffer/(1 + q) - w_rsrp*[RSRP<thr] - w_rsrq*[RSRQ<thr]``.
A ping-pong is a return within ``HandoverConfig.min_time_of_stay_s``, the one window of the metrics, the reward
and SA-MRO (``info["pingpong"]``); :data:`PINGPONG_WINDOWS_S` are counted beside it for Table I only.
An action naming an empty candidate slot (fewer neighbours measured) keeps the serving BS.
``info`` carries, per flight, the sums over the decision's simulator steps of :data:`METRICS`, and the candidate
BS ids (``info["candidates"]``, (K, 4)).
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode
from gymnasium.vector.utils import batch_space

from xairl import InputError

from .config import SimConfig
from .features import ACTIONS, FEATURES, checked_actions
from .simulator import Simulator

#: per-flight quantities summed over each decision's simulator steps (StepInfo fields)
METRICS = (
    "handover",
    "pingpong",
    "available",
    "queue_bits",
    "lost_bits",
    "rsrp_violation",
    "rsrq_violation",
    "hof",
    "rlf",
    "outage",
)
#: ping-pong windows counted beside the configured one (``pingpong_1s`` ...: back to the previous BS within w s)
PINGPONG_WINDOWS_S = (1.0, 2.0, 5.0, 10.0)


class HandoverVecEnv(gym.vector.VectorEnv):
    """K UAV flights stepped at once, one handover decision per flight and step.

    :param config: the simulator's settings.
    :param n_flights: flights flown in parallel (``num_envs``).
    :param decision_every: simulator steps per decision (default ``config.decision_every``; 1 for rule-based
        controllers that act at every measurement).
    """

    metadata = {"autoreset_mode": AutoresetMode.DISABLED}

    def __init__(self, config: SimConfig | None = None, n_flights: int = 1, decision_every: int | None = None):
        self.cfg = config or SimConfig()
        self.num_envs = n_flights
        self.decision_every = decision_every or self.cfg.decision_every
        self.single_observation_space = gym.spaces.Box(-np.inf, np.inf, shape=(len(FEATURES),), dtype=np.float32)
        self.single_action_space = gym.spaces.Discrete(len(ACTIONS))
        self.observation_space = batch_space(self.single_observation_space, n_flights)
        self.action_space = batch_space(self.single_action_space, n_flights)
        self.sim: Simulator | None = None
        self.obs: np.ndarray | None = None  # the latest observation (K, 13)
        self.candidates: np.ndarray | None = None  # the latest candidate BS ids (K, 4)
        self.info: dict | None = None  # the latest step's info

    def reset(self, *, seed: int | None = None, options=None):
        """New flights; every random draw of the episode comes from ``seed``."""
        self.sim = Simulator(self.cfg, n_uavs=self.num_envs, seed=0 if seed is None else seed)
        self._observe()
        return self.obs, {"candidates": self.candidates}

    def step(self, actions):
        """Hand over each flight to its candidate ``actions[k]`` (0 = stay) and fly ``decision_every`` steps."""
        sim, w = self.sim, self.cfg.reward
        if np.shape(actions) != (sim.K,):
            raise InputError(f"expected one action per flight, shape ({sim.K},), got shape {np.shape(actions)}.")
        target = self.candidates[np.arange(sim.K), checked_actions(actions)]
        target = np.where(target < 0, sim.serving, target)
        sums = {key: np.zeros(sim.K) for key in METRICS + tuple(f"pingpong_{w:g}s" for w in PINGPONG_WINDOWS_S)}
        gain = np.zeros(sim.K)
        n = 0
        while n < self.decision_every and not sim.done:
            info = sim.step(target if n == 0 else sim.serving)
            gain += (
                w.w_buffer / (1 + info.queue_bits / 1e6)
                - w.w_rsrp * info.rsrp_violation
                - w.w_rsrq * info.rsrq_violation
            )
            for key in METRICS:
                sums[key] += getattr(info, key)
            for window in PINGPONG_WINDOWS_S:
                sums[f"pingpong_{window:g}s"] += info.back_after_s < window
            n += 1
        reward = (
            -w.w_handover * sums["handover"]
            - w.w_lost * sums["lost_bits"] / 1e6
            - w.w_pingpong * sums["pingpong"]  # the one window, HandoverConfig.min_time_of_stay_s
            + gain / max(n, 1)
        )
        self._observe()
        ended = np.full(sim.K, sim.done)
        self.info = sums | {"candidates": self.candidates}  # the last step's (for controllers that keep a memory)
        return self.obs, reward, np.zeros(sim.K, dtype=bool), ended, self.info

    def _observe(self) -> None:
        """The simulator's states and candidates; a non-finite state is refused before any policy acts on it."""
        self.obs, self.candidates = self.sim.observe()
        bad = ~np.isfinite(self.obs)
        if bad.any():
            k, j = (int(i[0]) for i in np.nonzero(bad))
            raise InputError(
                f"the simulator gave flight {k} a state whose {FEATURES[j]} is {self.obs[k, j]:g}; "
                "check the simulator settings (a policy cannot act on it)."
            )


class UAVHandoverEnv(gym.Env):
    """One flight as a ``gymnasium.Env``: observation :data:`FEATURES`, action :data:`ACTIONS` (0 = stay)."""

    metadata = {"render_modes": []}

    def __init__(self, config: SimConfig | None = None):
        self.vec = HandoverVecEnv(config, n_flights=1)
        self.observation_space = self.vec.single_observation_space
        self.action_space = self.vec.single_action_space

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        obs, info = self.vec.reset(seed=int(self.np_random.integers(2**31)))
        return obs[0], {"candidates": info["candidates"][0]}

    def step(self, action):
        obs, reward, terminated, truncated, info = self.vec.step(np.reshape(np.asarray(action), -1))
        return obs[0], float(reward[0]), bool(terminated[0]), bool(truncated[0]), {k: v[0] for k, v in info.items()}
