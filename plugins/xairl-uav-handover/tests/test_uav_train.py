"""Training from demonstrations (DQfD): the rule that demonstrates, the margin loss, and pretraining that imitates."""

from types import SimpleNamespace

import numpy as np
import pytest
import torch
from stable_baselines3.common.buffers import ReplayBuffer

from xairl_uav_handover.baselines import RSRQRule
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.env import HandoverVecEnv
from xairl_uav_handover.features import BUFFER, FEATURES, RSRQ
from xairl_uav_handover.policy import greedy
from xairl_uav_handover.train import TrainConfig, _demonstrations, margin_loss, train


def _state(serving_rsrq, candidates_rsrq, queue_bits):
    s = np.zeros(len(FEATURES), dtype=np.float32)
    s[RSRQ] = [serving_rsrq, *candidates_rsrq]
    s[BUFFER] = queue_bits
    return s


def test_rsrq_rule_hands_over_only_when_triggered_and_the_target_is_better():
    cfg = SimConfig()
    full = cfg.buffer.q_max_bits
    states = np.stack(
        [
            _state(-8, [-5, -6, -7], 0),  # good serving cell, empty buffer: stay
            _state(-16, [-12, -9, -15], 1e5),  # poor serving cell with data waiting: best RSRQ, candidate 2
            _state(-16, [-12, -9, -15], 0),  # poor serving cell, nothing to send: stay
            _state(-8, [-7, -4, -30], full),  # full buffer: candidate 2 is 4 dB better
            _state(-8, [-6, -7, -30], full),  # full buffer, but no candidate 3 dB better: stay
        ]
    )
    assert RSRQRule(-14, 3, 0.5).act(states, cfg).tolist() == [0, 2, 0, 2, 0]


def test_margin_loss_is_zero_only_when_the_demonstrated_action_leads_by_the_margin():
    q = torch.nn.Linear(1, 3, bias=True)
    with torch.no_grad():
        q.weight.zero_()
        q.bias.copy_(torch.tensor([10.0, 4.0, 20.0]))
    batch = SimpleNamespace(
        observations=torch.zeros(2, 1),
        actions=torch.tensor([[0], [0]]),
        available=np.array([[True, True, False], [True, True, True]]),
    )
    # state 1: action 2 unavailable, 10 leads 4 by more than 5 -> 0; state 2: 20 + 5 - 10 = 15
    assert margin_loss(q, batch, 5.0).item() == 7.5


@pytest.mark.slow
def test_pretraining_on_demonstrations_imitates_the_rule():
    sim = SimConfig.model_validate(
        {**SimConfig().model_dump(), "flight": {**SimConfig().flight.model_dump(), "duration_s": 20.0}}
    )
    tc = TrainConfig(
        episodes=1,
        n_flights=8,
        demonstrations=2,
        pretrain_updates=400,
        eps_start=0.0,
        eps_end=0.0,
        learning_starts=10**6,
        seed=3,
        standardise_states=256,
    )
    env = HandoverVecEnv(sim, tc.n_flights)
    rb = ReplayBuffer(
        10_000,
        env.single_observation_space,
        env.single_action_space,
        n_envs=tc.n_flights,
        handle_timeout_termination=False,
    )
    demos = _demonstrations(tc, sim, env, rb)
    assert rb.size() * tc.n_flights == len(demos.obs) and (demos.act > 0).any()
    net, _ = train(tc, sim, progress=False)
    plain, _ = train(tc.model_copy(update={"demonstrations": 0}), sim, progress=False)
    agree = (greedy(net, demos.obs, sim) == demos.act).mean()
    assert agree >= 0.95 > (greedy(plain, demos.obs, sim) == demos.act).mean()


def test_exploration_follows_demonstrations_and_old_checkpoints_read_as_plain():
    assert TrainConfig().eps_start == 1.0 and TrainConfig(demonstrations=10).eps_start == 0.2  # plain by default
    assert TrainConfig(demonstrations="0").eps_start == 1.0 and TrainConfig(eps_start=0.5).eps_start == 0.5
    assert TrainConfig.model_validate(TrainConfig().model_dump()) == TrainConfig()
    old = TrainConfig.of_checkpoint({"train_config": {"episodes": 40, "n_flights": 64, "eps_start": 1.0, "seed": 2}})
    assert old.demonstrations == 0 and old.eps_start == 1.0
