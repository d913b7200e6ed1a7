"""Simulator, Gymnasium env, baselines and configs."""

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from pydantic import ValidationError

from xairl_uav_handover.baselines import A3Trigger, CHMConfig, CHMOnSamples
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.env import HandoverVecEnv, UAVHandoverEnv
from xairl_uav_handover.features import ACTIONS, FEATURES, RSRQ, available_actions
from xairl_uav_handover.simulator import Simulator, hex_layout

SHORT = {"flight": {"duration_s": 4.0}}


def test_hex_layout_sizes_and_spacing():
    for rings, n in ((1, 7), (2, 19), (3, 37)):
        xy = hex_layout(500.0, rings)
        assert len(xy) == n
        d = np.hypot(*(xy[:, None] - xy[None]).transpose(2, 0, 1))
        assert np.min(d[d > 0]) == pytest.approx(500.0)


def test_observation_layout():
    sim = Simulator(SimConfig(), n_uavs=8, seed=1)
    obs, cand = sim.observe()
    assert obs.shape == (8, len(FEATURES)) and cand.shape == (8, 4)
    assert (cand[:, 0] == sim.serving).all()
    rsrp = obs[:, 5:9]
    assert (np.diff(rsrp[:, 1:], axis=1) <= 0).all(), "neighbour candidates are sorted by RSRP"
    assert (obs[:, 4] == sim.serving).all()
    np.testing.assert_allclose(obs[:, 5], sim.rsrp[np.arange(8), sim.serving], rtol=1e-5)
    hidden = SimConfig.model_validate({"observation": {"position_hidden": True}})
    blind, _ = Simulator(hidden, n_uavs=8, seed=1).observe()  # the same flights, without their position
    assert (blind[:, :3] == 0).all() and np.array_equal(blind[:, 3:], obs[:, 3:]) and (obs[:, 2] > 0).all()


def test_empty_slots_are_masked_actions():
    """Few neighbours are measured at low height; their empty slots read at the detection limit and are exactly
    the masked handovers, in simulated states and in the masked greedy choice."""
    import torch

    from xairl_uav_handover.policy import greedy

    cfg = SimConfig(flight={"altitude_m": (23.0, 30.0)})
    obs, cand = Simulator(cfg, n_uavs=200, seed=2).observe()
    mask = available_actions(obs, cfg.observation)
    np.testing.assert_array_equal(mask, cand >= 0)
    assert (~mask).any() and mask[:, 0].all()
    assert (obs[:, RSRQ][~mask] == cfg.observation.detection_rsrq_db).all()
    net = torch.nn.Linear(len(FEATURES), len(ACTIONS))
    with torch.no_grad():
        net.weight.zero_(), net.bias.copy_(torch.tensor([0.0, 1.0, 2.0, 3.0]))  # prefers the highest slot
    expected = np.where(mask, np.arange(4), -1).argmax(axis=1)
    np.testing.assert_array_equal(greedy(net, obs, cfg), expected)


def test_same_seed_same_flight():
    a, b = Simulator(SimConfig(**SHORT), 3, seed=5), Simulator(SimConfig(**SHORT), 3, seed=5)
    while not a.done:
        a.step(a.serving), b.step(b.serving)
    np.testing.assert_array_equal(a.observe()[0], b.observe()[0])


def test_handover_bookkeeping_and_pingpong():
    # handovers to an arbitrary cell would often fail (test_uav_failures.py): bookkeeping alone here
    cfg = SimConfig(**{"handover": {"min_time_of_stay_s": 0.2, "interruption_s": 0.08, "failures": False}})
    sim = Simulator(cfg, n_uavs=1, seed=0)
    a, b = sim.serving[0], (sim.serving[0] + 1) % sim.N
    assert sim.step(np.array([b])).handover[0]
    info = sim.step(np.array([a]))  # back to A after 1 step (0.04 s < 0.2 s): ping-pong
    assert info.handover[0] and info.pingpong[0] and not info.available[0]
    for _ in range(10):
        sim.step(np.array([a]))
    info = sim.step(np.array([b]))  # to B after a long stay in A: a handover, not a ping-pong
    assert info.handover[0] and not info.pingpong[0]


def test_env_passes_gymnasium_checker():
    env = UAVHandoverEnv(SimConfig(**SHORT))
    check_env(env, skip_render_check=True)
    obs, info = env.reset(seed=3)
    assert env.action_space.n == len(ACTIONS) and obs.shape == (len(FEATURES),)
    rewards, lost, handovers, done = [], [], 0, False
    while not done:
        obs, r, term, trunc, info = env.step(0)
        rewards.append(r)
        lost.append(info["lost_bits"] / 1e6)
        handovers += info["handover"]
        done = term or trunc
    w = SimConfig().reward
    assert handovers == 0  # staying never hands over
    # without handovers each reward is w_buffer / (1 + q) minus violations and lost data: at most w_buffer, above
    # -w_rsrp - w_rsrq - w_lost * the Mbit lost
    assert all(-w.w_rsrp - w.w_rsrq < r + w.w_lost * m <= w.w_buffer + 1e-9 for r, m in zip(rewards, lost))


def test_chm_triggers_exactly_after_ttt():
    """Neighbour 1 is 3 dB above the serving BS from step 2 on; 160 ms TTT at 40 ms steps -> handover at step 6."""
    a3 = A3Trigger(1, 3, dt=0.04)
    serving = np.array([0])
    fired_at = None
    for t in range(12):
        rsrp = np.array([[-80.0, -80.0 + (3.0 if t >= 2 else 0.0), -90.0]])
        target = a3.targets(rsrp, serving, 2.0, 0.16)
        if target[0] != serving[0]:
            fired_at = t
            break
    assert fired_at == 6


def test_chm_timer_restarts_when_condition_breaks():
    a3 = A3Trigger(1, 2, dt=0.04)
    gains = [3, 3, 3, 0, 3, 3, 3, 3, 3]  # broken at step 3: condition holds again from step 4, fires at 4 + 4
    out = [a3.targets(np.array([[-80.0, -80.0 + g]]), np.array([0]), 2.0, 0.16)[0] for g in gains]
    assert out.index(1) == 8


def test_a3_on_time_stamps_fires_at_the_first_sample_after_ttt():
    """Irregular samples (a real flight): the condition starts at 1.0 s; 160 ms later has passed at 2.3 s."""
    a3 = A3Trigger(1, 2)
    times = [0.0, 1.0, 2.3, 3.6]
    gains = [0.0, 3.0, 3.0, 3.0]
    out = [a3.targets(np.array([[-80.0, -80.0 + g]]), np.array([0]), 2.0, 0.16, now=t)[0] for t, g in zip(times, gains)]
    assert out == [0, 0, 1, 0]  # fired at 2.3 s; then the timers start again


def test_chm_on_samples_uses_the_same_trigger():
    state = np.zeros(len(FEATURES), dtype=np.float32)
    chm = CHMOnSamples(cells=[101.0, 202.0, 303.0])
    state[5:9] = [-80, -76, -90, -140]  # candidate 1 (cell 202) 4 dB above the serving cell 101
    assert chm(state, [101.0, 202.0, 303.0], 0.0) == 0  # the condition just started
    assert chm(state, [101.0, 202.0, 303.0], 1.3) == 1  # held for 1.3 s >= 160 ms


def test_vector_env_steps_flights_together():
    env = HandoverVecEnv(SimConfig(**SHORT), n_flights=4)
    obs, info = env.reset(seed=3)
    assert obs.shape == (4, len(FEATURES)) and info["candidates"].shape == (4, 4) and env.action_space.shape == (4,)
    steps, truncated = 0, np.zeros(4, bool)
    while not truncated.all():
        obs, reward, terminated, truncated, info = env.step(np.zeros(4, int))
        steps += 1
        assert reward.shape == (4,) and not terminated.any() and (info["handover"] == 0).all()
    assert steps == int(np.ceil(env.sim.n_steps / env.decision_every))
    again, _ = env.reset(seed=3)
    np.testing.assert_array_equal(again, HandoverVecEnv(SimConfig(**SHORT), n_flights=4).reset(seed=3)[0])


@pytest.mark.parametrize(
    "data, field",
    [
        ({"radio": {"bs_tx_power_dbm": -5}}, "radio.bs_tx_power_dbm"),
        ({"flight": {"altitude_m": (1, 150)}}, "altitude_m"),
        ({"channel": {"scenario": "Mars-AV"}}, "channel.scenario"),
        ({"channel": {"scenarios": "UMa-AV"}}, "channel.scenarios"),
        ({"flight": {"dt_s": 0}}, "flight.dt_s"),
    ],
)
def test_invalid_config_names_the_field(data, field):
    with pytest.raises(ValidationError) as info:
        SimConfig.model_validate(data)
    assert field.split(".")[-1] in str(info.value)


def test_chm_config_defaults_follow_tr_36_777():
    assert CHMConfig().offset_db == 2.0 and CHMConfig().ttt_s == 0.16
