"""DQN training, CleanRL style: one short file, many flights in parallel, replay, target network, tqdm.

Experience replay; target network copied every ``target_every`` gradient steps; epsilon-greedy decaying linearly
from ``eps_start`` to ``eps_end`` over ``eps_fraction`` of training; learning rate lr0 / (1 + eta * episode).
"""
from __future__ import annotations

import time

import numpy as np
import torch
from pydantic import BaseModel, ConfigDict, Field

from .config import SimConfig
from .env import decision_step
from .features import ACTIONS, FEATURES
from .policy import background_states, build_qnet
from .simulator import Simulator


class TrainConfig(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

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
    eps_start: float = Field(1.0, ge=0, le=1)
    eps_end: float = Field(0.01, ge=0, le=1)
    eps_fraction: float = Field(0.5, gt=0, le=1)
    seed: int = 0


def train(tc: TrainConfig, sim_cfg: SimConfig | None = None, progress: bool = True):
    """Train a Q-network; returns (network, history list of per-episode dicts)."""
    from tqdm import tqdm

    sim_cfg = sim_cfg or SimConfig()
    rng = np.random.default_rng(tc.seed)
    torch.manual_seed(tc.seed)
    bg = background_states(2048, seed=tc.seed + 10_000, config=sim_cfg)
    mean, std = bg.mean(axis=0), np.maximum(bg.std(axis=0), 1e-3)
    q = build_qnet(mean, std, tc.hidden)
    target = build_qnet(mean, std, tc.hidden)
    target.load_state_dict(q.state_dict())
    opt = torch.optim.Adam([p for p in q.parameters() if p.requires_grad], lr=tc.lr0)
    f = len(FEATURES)
    obs_buf = np.zeros((tc.replay_size, f), np.float32)
    next_buf = np.zeros((tc.replay_size, f), np.float32)
    act_buf = np.zeros(tc.replay_size, np.int64)
    rew_buf = np.zeros(tc.replay_size, np.float32)
    done_buf = np.zeros(tc.replay_size, np.float32)
    size = ptr = updates = 0
    decisions_per_ep = int(np.ceil(sim_cfg.flight.n_steps / sim_cfg.decision_every))
    total = tc.episodes * decisions_per_ep
    history = []
    bar = tqdm(total=total, desc="training DQN", unit="dec", disable=not progress)
    step = 0
    for ep in range(tc.episodes):
        for g in opt.param_groups:
            g["lr"] = tc.lr0 / (1 + tc.eta * ep)
        sim = Simulator(sim_cfg, n_uavs=tc.n_flights, seed=tc.seed * 100_003 + ep)
        obs, cand = sim.observe()
        ep_ret, ep_ho, t0 = np.zeros(tc.n_flights), np.zeros(tc.n_flights), time.time()
        while not sim.done:
            eps = max(tc.eps_end, tc.eps_start - (tc.eps_start - tc.eps_end) * step / (tc.eps_fraction * total))
            with torch.no_grad():
                greedy = q(torch.as_tensor(obs)).argmax(dim=1).numpy()
            explore = rng.uniform(size=tc.n_flights) < eps
            act = np.where(explore, rng.integers(len(ACTIONS), size=tc.n_flights), greedy)
            reward, sums = decision_step(sim, act, cand)
            nxt, cand = sim.observe()
            idx = (ptr + np.arange(tc.n_flights)) % tc.replay_size
            obs_buf[idx], next_buf[idx], act_buf[idx], rew_buf[idx] = obs, nxt, act, reward
            done_buf[idx] = float(sim.done)
            ptr, size = (ptr + tc.n_flights) % tc.replay_size, min(size + tc.n_flights, tc.replay_size)
            obs = nxt
            ep_ret += reward
            ep_ho += sums["handover"]
            step += 1
            bar.update(1)
            if size < max(tc.learning_starts, tc.batch_size):
                continue
            for _ in range(tc.updates_per_decision):
                b = rng.integers(size, size=tc.batch_size)
                with torch.no_grad():
                    nq = target(torch.as_tensor(next_buf[b])).max(dim=1).values
                    y = torch.as_tensor(rew_buf[b]) + tc.gamma * nq * (1 - torch.as_tensor(done_buf[b]))
                qa = q(torch.as_tensor(obs_buf[b])).gather(1, torch.as_tensor(act_buf[b])[:, None])[:, 0]
                loss = torch.nn.functional.smooth_l1_loss(qa, y)
                opt.zero_grad()
                loss.backward()
                torch.nn.utils.clip_grad_norm_(q.parameters(), 10.0)
                opt.step()
                updates += 1
                if updates % tc.target_every == 0:
                    target.load_state_dict(q.state_dict())
        history.append({"episode": ep, "epsilon": round(eps, 4), "mean_return": float(ep_ret.mean()),
                        "median_handovers": float(np.median(ep_ho)), "seconds": round(time.time() - t0, 2)})
        bar.set_postfix(ho=history[-1]["median_handovers"], ret=round(history[-1]["mean_return"], 1))
    bar.close()
    return q.eval(), history
