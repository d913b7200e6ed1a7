"""DQN training, CleanRL style: one short file; the vectorised env, SB3's replay buffer, a named schedule, an update.

Many flights fly in parallel through :class:`env.HandoverVecEnv`; transitions go into Stable-Baselines3's
``ReplayBuffer`` (one row per flight and decision); epsilon-greedy exploration decays linearly
(:func:`linear_schedule`) from ``eps_start`` to ``eps_end`` over ``eps_fraction`` of training; the learning rate is
lr0 / (1 + eta * episode) (:func:`learning_rate`); the target network is copied every ``target_every`` updates
(:func:`dqn_update` is one gradient step). Actions are masked to the measured candidates when acting, exploring and
bootstrapping (a handover to an empty slot is no action at all). The end of a flight is terminal (no bootstrap), as
in the paper's episodic set-up. With ``demonstrations`` > 0 it learns from :class:`baselines.RSRQRule`'s flights as DQfD does
(Hester et al. 2018): :func:`margin_loss` on the rule's actions beside the TD loss, after ``pretrain_updates`` steps on
the demonstrations alone.
"""

from __future__ import annotations

import time
from contextlib import contextmanager
from types import SimpleNamespace

import gymnasium as gym
import numpy as np
import torch
from pydantic import Field, model_validator

import xairl

from .baselines import RSRQRule
from .config import SimConfig
from .env import HandoverVecEnv
from .features import available_actions
from .memory import N_FEATURES, Memory
from .policy import background_states, build_qnet, greedy, random_available


class TrainConfig(xairl.plugin.Options, frozen=True):
    """Every setting of a training run (stored in the checkpoint's metadata)."""

    episodes: int = Field(40, ge=1, description="training episodes; each flies n_flights flights at once")
    n_flights: int = Field(64, ge=1)
    hidden: tuple[int, ...] = (64, 64)
    gamma: float = Field(0.98, gt=0, lt=1)
    lr0: float = Field(1e-3, gt=0)
    eta: float = Field(0.05, ge=0, description="learning-rate decay per episode")
    batch_size: int = Field(256, ge=1)
    replay_size: int = Field(200_000, ge=1)
    learning_starts: int = Field(5_000, ge=0, description="transitions collected before the first update")
    updates_per_decision: int = Field(1, ge=1)
    target_every: int = Field(500, ge=1, description="gradient steps between target-network copies (M)")
    eps_start: float | None = Field(
        None,
        ge=0,
        le=1,
        description="unset: 0.2 with demonstrations (the pretrained "
        "network already acts like the demonstrator), 1 without (a plain DQN)",
    )
    eps_end: float = Field(0.01, ge=0, le=1)
    eps_fraction: float = Field(0.5, gt=0, le=1)
    demonstrations: int = Field(
        0,
        ge=0,
        description="episodes of the demonstrator's flights (baselines.RSRQRule) "
        "kept in a replay buffer of their own (DQfD, Hester et al. 2018); 0: a plain DQN, the paper's (default)",
    )
    pretrain_updates: int = Field(
        3000, ge=0, description="gradient steps on the demonstrations alone before the DQN flies"
    )
    standardise_states: int = Field(
        2048,
        ge=16,
        description="flights simulated (10 s each, under CHM) for the mean and spread that standardise the "
        "network's inputs; simulating them is most of a tiny run's time",
    )
    expert_margin: float = Field(
        5.0,
        ge=0,
        description="DQfD's large margin: how much higher the demonstrator's "
        "action must score than any other (reward units)",
    )
    expert_weight: float = Field(
        10.0,
        ge=0,
        description="weight of the margin loss against the TD loss (training "
        "seed 2, 600 held-out flights and the real ones: 1 met 8 of 12 targets, 3 and 10 "
        "met 9)",
    )
    demonstrator_margin_db: float = Field(
        3.5,
        ge=0,
        description="how much better (RSRQ, dB) the demonstrator's "
        "target must be than the serving cell (3 dB: RSRQ time 7.7-7.9 % but "
        "0.53-0.55x CHM's handovers; 3.5 dB: 8.1-8.4 % at 0.48x)",
    )
    memory: bool = Field(
        False,
        description="the DQN with memory (memory.py, issue 55): its state is the last 1 s (5 decisions) of "
        "the snapshot's 13 features plus the times on the cell and since the last handover; False: the snapshot DQN",
    )
    seed: int = 0

    @model_validator(mode="after")
    def _exploration(self):
        if self.memory and self.demonstrations:
            raise ValueError("demonstrations are for the snapshot DQN; train the DQN with memory without them")
        if self.eps_start is None:
            object.__setattr__(self, "eps_start", 0.2 if self.demonstrations else 1.0)  # (frozen: set once, here)
        return self

    @classmethod
    def of_checkpoint(cls, meta: dict) -> TrainConfig:
        """The settings a checkpoint was trained with; one written before demonstrations existed was a plain DQN."""
        return cls.model_validate({"demonstrations": 0, **meta["train_config"]})


def linear_schedule(start: float, end: float, duration: float, t: float) -> float:
    """``start`` moving linearly to ``end`` over ``duration`` steps, then ``end`` (CleanRL's schedule)."""
    return start + (end - start) * min(t / duration, 1.0)


def learning_rate(tc: TrainConfig, episode: int) -> float:
    """lr0 / (1 + eta * episode), the paper's decaying learning rate."""
    return tc.lr0 / (1 + tc.eta * episode)


def dqn_update(
    q: torch.nn.Module,
    target: torch.nn.Module,
    opt: torch.optim.Optimizer,
    batch,
    gamma: float,
    next_available: torch.Tensor | None = None,
    expert=None,
    expert_margin: float = 0.0,
    expert_weight: float = 0.0,
) -> float:
    """One gradient step on the Huber TD error of a replay batch; returns the loss. ``next_available`` (batch,
    actions) bool restricts the bootstrap max to the actions available in the next state. ``expert``: a batch of
    demonstrations whose :func:`margin_loss` is added with ``expert_weight``."""
    with torch.no_grad():
        next_q = target(batch.next_observations)
        if next_available is not None:
            next_q = next_q.masked_fill(~next_available, -torch.inf)
        next_q = next_q.max(dim=1).values
        y = batch.rewards.flatten() + gamma * next_q * (1 - batch.dones.flatten())
    qa = q(batch.observations).gather(1, batch.actions.long()).flatten()
    loss = torch.nn.functional.smooth_l1_loss(qa, y)
    if expert is not None:
        loss = loss + expert_weight * margin_loss(q, expert, expert_margin)
    opt.zero_grad()
    loss.backward()
    torch.nn.utils.clip_grad_norm_(q.parameters(), 10.0)
    opt.step()
    return float(loss.detach())


def margin_loss(q: torch.nn.Module, batch, margin: float) -> torch.Tensor:
    """DQfD's supervised loss on a batch of demonstrations: max_a [Q(s, a) + margin * (a != a_E)] - Q(s, a_E), over
    the actions available in s (a_E: the demonstrator's action)."""
    ok = torch.as_tensor(batch.available)
    scores = q(batch.observations)
    a_e = batch.actions.long()
    bonus = torch.full_like(scores, margin).scatter(1, a_e, 0.0)
    best = (scores + bonus).masked_fill(~ok, -torch.inf).max(dim=1).values
    return (best - scores.gather(1, a_e).flatten()).mean()


def _networks(tc: TrainConfig, sim_cfg: SimConfig):
    """Q-network and target network, standardising inputs with statistics of states met in flight."""
    if tc.memory:
        from .memory import background

        bg = background(tc.standardise_states, seed=tc.seed + 10_000, config=sim_cfg)
    else:
        bg = background_states(tc.standardise_states, seed=tc.seed + 10_000, config=sim_cfg)
    mean, std = bg.mean(axis=0), np.maximum(bg.std(axis=0), 1e-3)
    q, target = build_qnet(mean, std, tc.hidden), build_qnet(mean, std, tc.hidden)
    target.load_state_dict(q.state_dict())
    return q, target


@contextmanager
def _one_thread():
    """Torch on one thread, then as before: a 64x64 network on batches of 256 loses more to thread hand-offs than it
    gains (training ran 2x faster on this 2-core machine, and 4x when two trainings shared it)."""
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        yield
    finally:
        torch.set_num_threads(threads)


def train(tc: TrainConfig, sim_cfg: SimConfig | None = None, progress: bool = True):
    """Train a Q-network; returns (network, history: one dict per episode)."""
    with _one_thread():
        return _train(tc, sim_cfg, progress)


def _train(tc: TrainConfig, sim_cfg: SimConfig | None, progress: bool):
    from stable_baselines3.common.utils import set_random_seed

    sim_cfg = sim_cfg or SimConfig()
    set_random_seed(tc.seed)  # python, numpy (the replay buffer samples with it) and torch
    rng = np.random.default_rng(tc.seed)
    q, target = _networks(tc, sim_cfg)
    opt = torch.optim.Adam([p for p in q.parameters() if p.requires_grad], lr=tc.lr0)
    env = HandoverVecEnv(sim_cfg, tc.n_flights)
    memory = Memory() if tc.memory else None
    rb = _replay_buffer(tc, env)
    total = tc.episodes * int(np.ceil(sim_cfg.flight.n_steps / env.decision_every))
    demos = _demonstrations(tc, sim_cfg, env, rb)
    step = updates = 0

    def update():
        nonlocal updates
        batch = rb.sample(tc.batch_size)
        nxt_ok = torch.as_tensor(available_actions(batch.next_observations.numpy(), sim_cfg.observation))
        expert = None if demos is None else demos.sample(rng, tc.batch_size)
        dqn_update(q, target, opt, batch, tc.gamma, nxt_ok, expert, tc.expert_margin, tc.expert_weight)
        updates += 1
        if updates % tc.target_every == 0:
            target.load_state_dict(q.state_dict())

    for _ in range(tc.pretrain_updates if demos is not None else 0):
        update()
    history = []
    bar = xairl.plugin.progress(total=total, desc="training DQN", unit="dec", disable=not progress)
    for ep in range(tc.episodes):
        for g in opt.param_groups:
            g["lr"] = learning_rate(tc, ep)
        obs, _ = env.reset(seed=tc.seed * 100_003 + ep)
        obs = obs if memory is None else memory.start(env)
        ep_ret, ep_ho, t0, ended = np.zeros(tc.n_flights), np.zeros(tc.n_flights), time.time(), False
        while not ended:
            eps = linear_schedule(tc.eps_start, tc.eps_end, tc.eps_fraction * total, step)
            explore = rng.uniform(size=tc.n_flights) < eps
            act = np.where(explore, random_available(rng, obs, sim_cfg), greedy(q, obs, sim_cfg))
            nxt, reward, _, truncated, info = env.step(act)
            nxt = nxt if memory is None else memory.step(env, info["handover"])
            ended = bool(truncated.all())
            rb.add(obs, nxt, act, reward, truncated, [{}] * tc.n_flights)
            obs, ep_ret, ep_ho, step = nxt, ep_ret + reward, ep_ho + info["handover"], step + 1
            bar.update(1)
            if rb.size() * tc.n_flights < max(tc.learning_starts, tc.batch_size):
                continue
            for _ in range(tc.updates_per_decision):
                update()
        history.append(_record(ep, eps, ep_ret, ep_ho, t0))
        bar.set_postfix(ho=history[-1]["median_handovers"], ret=round(history[-1]["mean_return"], 1))
    bar.close()
    return q.eval(), history


def _record(ep: int, eps: float, ep_ret: np.ndarray, ep_ho: np.ndarray, t0: float) -> dict:
    """One episode's line of the training history."""
    return {
        "episode": ep,
        "epsilon": round(eps, 4),
        "mean_return": float(ep_ret.mean()),
        "median_handovers": float(np.median(ep_ho)),
        "seconds": round(time.time() - t0, 2),
    }


def _replay_buffer(tc: TrainConfig, env: HandoverVecEnv):
    """SB3's replay buffer, one row per flight and decision, of the snapshot's states or the memory's windows."""
    from stable_baselines3.common.buffers import ReplayBuffer

    space = gym.spaces.Box(-np.inf, np.inf, (N_FEATURES,)) if tc.memory else env.single_observation_space
    return ReplayBuffer(
        max(tc.replay_size // tc.n_flights, 1) * tc.n_flights,
        space,
        env.single_action_space,
        device="cpu",
        n_envs=tc.n_flights,
        handle_timeout_termination=False,
    )


class Demonstrations:
    """The demonstrator's states and actions, sampled in batches for :func:`margin_loss`."""

    def __init__(self, observations: np.ndarray, actions: np.ndarray, available: np.ndarray):
        self.obs, self.act, self.ok = observations, actions, available

    def sample(self, rng: np.random.Generator, n: int) -> SimpleNamespace:
        i = rng.integers(len(self.obs), size=n)
        return SimpleNamespace(
            observations=torch.as_tensor(self.obs[i]), actions=torch.as_tensor(self.act[i, None]), available=self.ok[i]
        )


def _demonstrations(tc: TrainConfig, sim_cfg: SimConfig, env: HandoverVecEnv, rb) -> Demonstrations | None:
    """Fly ``tc.demonstrations`` episodes under :class:`baselines.RSRQRule`; their transitions go into the replay
    buffer ``rb`` (for the TD loss) and their states and actions into the returned :class:`Demonstrations`."""
    if not tc.demonstrations:
        return None

    rule, obs_seen, act_seen = RSRQRule(margin_db=tc.demonstrator_margin_db), [], []
    for k in range(tc.demonstrations):
        obs, _ = env.reset(seed=tc.seed * 100_003 + tc.episodes + k)
        ended = False
        while not ended:
            act = rule.act(obs, sim_cfg)
            nxt, reward, _, truncated, _ = env.step(act)
            ended = bool(truncated.all())
            rb.add(obs, nxt, act, reward, truncated, [{}] * tc.n_flights)
            obs_seen.append(obs)
            act_seen.append(act)
            obs = nxt
    obs = np.concatenate(obs_seen).astype(np.float32)
    return Demonstrations(obs, np.concatenate(act_seen), available_actions(obs, sim_cfg.observation))


def reward_name(sim_cfg: SimConfig) -> str:
    """'paper' or 'priced' when the reward is one of the two named ones, else 'custom'."""
    from .config import PRICED_REWARD, RewardConfig

    for name, weights in (("paper", {}), ("priced", PRICED_REWARD)):
        if sim_cfg.reward == RewardConfig(**weights):
            return name
    return "custom"


def train_checkpoint(tc: TrainConfig, sim_cfg: SimConfig, out, progress: bool = True) -> float:
    """Train and write a checkpoint whose metadata holds both configs, the history, the seed, the wall time and the
    command that re-runs it; returns the seconds spent training."""
    from .policy import save_checkpoint

    t0 = time.time()
    net, history = train(tc, sim_cfg, progress=progress)
    seconds = round(time.time() - t0, 1)
    save_checkpoint(
        net,
        out,
        {
            "hidden": list(tc.hidden),
            "train_config": tc.model_dump(),
            "sim_config": sim_cfg.model_dump(),
            "seed": tc.seed,
            "train_seconds": seconds,
            "history": history,
            "command": f"xairl uav train --episodes {tc.episodes} --flights "
            f"{tc.n_flights} --demonstrations {tc.demonstrations} "
            f"--pretrain-updates {tc.pretrain_updates} --eps-start "
            f"{tc.eps_start:g} --reward {reward_name(sim_cfg)} --seed {tc.seed}"
            + (f" --standardise-states {tc.standardise_states}" if tc.standardise_states != 2048 else "")
            + (
                " (a custom reward: the sim_config above holds its weights)" if reward_name(sim_cfg) == "custom" else ""
            ),
        },
    )
    return seconds
