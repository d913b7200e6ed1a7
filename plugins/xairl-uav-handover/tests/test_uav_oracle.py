"""The hindsight bound (oracle.py): the simulator's draws do not depend on the actions, the shortest path equals brute
force over every schedule, its bookkeeping reproduces the simulator's own sums exactly, and a receding horizon that
sees the whole flight is the exact bound."""

import itertools

import numpy as np
import pytest

from xairl_uav_handover import oracle
from xairl_uav_handover.baselines import CHM
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.evaluate import run_flights
from xairl_uav_handover.policy import DQNController, load_checkpoint
from xairl_uav_handover.simulator import Simulator
from xairl_uav_handover.streams import flight_seeds

SHORT = {"flight": {"duration_s": 12.0}}


@pytest.fixture(scope="module")
def ckpt():
    return load_checkpoint()


@pytest.fixture(scope="module")
def cfg(ckpt):
    data = oracle.bound_config(ckpt.sim_config).model_dump()
    data["flight"].update(SHORT["flight"])
    return SimConfig.model_validate(data)


@pytest.fixture(scope="module")
def rec(cfg):
    return oracle.record(cfg, 16, seed=3)


@pytest.mark.parametrize("seed", [11, flight_seeds(11, 0, 5)], ids=["one stream", "a stream per flight"])
def test_draws_do_not_depend_on_the_actions(cfg, seed):
    """Two schedules (always stay; a different cell at every step) draw the same trajectories, channel latents and
    arrivals, with one stream for the batch (its generator in the same state after every step) and with a stream
    per flight (as oracle.record flies): every per-cell measurement is identical."""
    a, b = Simulator(cfg, n_uavs=5, seed=seed), Simulator(cfg, n_uavs=5, seed=seed)
    for _ in range(60):
        ia, ib = a.step(a.serving), b.step((b.serving + 1) % b.N)
        assert ib.handover.all() and not ia.handover.any()  # the schedules differ at every step
        if isinstance(seed, int):
            assert a.rng.bit_generator.state == b.rng.bit_generator.state
        for name in ("pos", "g_shadow", "g_los", "g_fast", "meas_rsrp", "meas_rsrq", "rsrp", "rsrq"):
            np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
        np.testing.assert_array_equal(a.route.target, b.route.target)


def _candidates(rsrp, rsrq, serving, detection):
    """The env's offer from ``serving``, written as Simulator.candidates writes it (not through oracle.ranking)."""
    masked = np.where(rsrq > detection, rsrp, -np.inf)
    masked[serving] = -np.inf
    top = np.argsort(-masked)[:3]
    return {serving} | {int(c) for c in top if np.isfinite(masked[c])}


def _tiny(n_cells, seed, decisions=4, every=2, flights=3):
    rng = np.random.default_rng(seed)
    rsrp = rng.normal(-90, 6, (decisions, flights, n_cells))
    rsrq = rng.normal(-12, 5, (decisions, flights, n_cells))
    ranked = [oracle.ranking(rsrp[d], rsrq[d], -14.0) for d in range(decisions)]
    below = rng.uniform(size=(decisions * every, flights, n_cells)) < 0.4
    short = rng.uniform(0, 0.6, below.shape).astype(np.float32) * (rng.uniform(size=below.shape) < 0.5)
    rec = oracle.Record(
        below,
        below.astype(np.float32),
        np.stack([r[0] for r in ranked]),
        np.stack([r[1] for r in ranked]),
        rng.integers(0, n_cells, flights),
        0.04,
        every,
        short,
        1.0,
        1,
    )
    return rec, rsrp, rsrq


def _brute(rec, rsrp, rsrq, k, w_ho, any_measured, w_cap):
    """The least cost over every schedule of flight k the env (or, any_measured, detection) allows."""
    t_all, _, n_cells, d_all = rec.shape
    offers = [
        [
            {prev} | set(np.flatnonzero(rsrq[d, k] > -14.0).tolist())
            if any_measured
            else _candidates(rsrp[d, k], rsrq[d, k], prev, -14.0)
            for prev in range(n_cells)
        ]
        for d in range(d_all)
    ]
    best = np.inf
    for cells in itertools.product(range(n_cells), repeat=d_all):
        prevs = (int(rec.initial[k]),) + cells[:-1]
        if all(c in offers[d][p] for d, (p, c) in enumerate(zip(prevs, cells, strict=True))):
            serving = np.repeat(cells, rec.every)[:t_all]
            handed = np.diff(np.concatenate([[rec.initial[k]], serving])) != 0  # interrupts its own step only
            short = np.where(handed, rec.offered_mbit, rec.short[np.arange(t_all), k, serving]).sum()
            rsrq_s = rec.dt * rec.below[np.arange(t_all), k, serving].sum()
            best = min(best, w_ho * handed.sum() + rsrq_s + w_cap * short)
    return best


@pytest.mark.parametrize("n_cells, any_measured, w_cap", [(3, False, 0), (5, False, 0), (5, True, 0), (5, False, 0.2)])
def test_shortest_path_equals_brute_force(n_cells, any_measured, w_cap):
    for seed, w_ho in itertools.product(range(3), (0.01, 0.05, 0.2)):
        rec, rsrp, rsrq = _tiny(n_cells, seed)
        s = oracle.solve(rec, w_ho, any_measured, w_cap)
        for k in range(rec.shape[1]):
            assert s.total[k] == pytest.approx(_brute(rec, rsrp, rsrq, k, w_ho, any_measured, w_cap))
        full = oracle.receding(rec, w_ho, horizon_s=1e3, any_measured=any_measured, w_cap=w_cap)
        np.testing.assert_allclose(full.total, s.total)


@pytest.mark.parametrize("which", ["CHM", "DQN"])
def test_cost_reproduces_the_simulator_sums(cfg, rec, ckpt, which):
    controller = oracle.Recorded(CHM() if which == "CHM" else DQNController(ckpt.net))
    metrics = run_flights(controller, cfg, 16, seed=3)
    c = oracle.cost(rec, controller.serving)
    np.testing.assert_array_equal(c.handovers, controller.handovers)
    np.testing.assert_array_equal(c.rsrq_steps, controller.rsrq_steps)
    np.testing.assert_array_equal(c.handovers, metrics["handovers"])
    np.testing.assert_allclose(100 * c.rsrq_steps / cfg.flight.n_steps, metrics["rsrq_violation_pct"])
    assert c.handovers.sum() > 0 and c.rsrq_steps.sum() > 0  # the check has something to get wrong
    # the shortfall's parts: the SINR at the serving cell, and no service exactly on the interrupted steps
    sinr = np.take_along_axis(rec.sinr, controller.serving.T[:, :, None], axis=2)[:, :, 0].T
    np.testing.assert_array_equal(sinr, controller.realised("sinr_db").astype(np.float32))
    ok = controller.realised("radio_ok")
    np.testing.assert_array_equal(controller.realised("available")[ok], ~c.interrupted[ok])
    assert c.interrupted.sum() == c.handovers.sum() * rec.interrupt > 0


@pytest.mark.slow
@pytest.mark.parametrize("w_ho", [0.04, 0.5])
def test_the_bound_replays_exactly(cfg, rec, ckpt, w_ho):
    """The bound's schedule flown through the env realises the planned cells, the planned costs and the simulator's
    own sums, and costs no more than the DQN's on every flight."""
    s = oracle.solve(rec, w_ho)
    controller = oracle.Recorded(oracle.ScheduleController(s.cells, cfg.decision_every))
    run_flights(controller, cfg, 16, seed=3)
    np.testing.assert_array_equal(controller.serving, oracle.per_step(rec, s.cells))
    np.testing.assert_array_equal(controller.handovers, s.cost.handovers)
    np.testing.assert_array_equal(controller.rsrq_steps, s.cost.rsrq_steps)
    assert s.cost.handovers.sum() > 0
    dqn = oracle.Recorded(DQNController(ckpt.net))  # the DQN decides among the same offers: within the bound's reach
    run_flights(dqn, cfg, 16, seed=3)
    c = oracle.cost(rec, dqn.serving)
    assert np.all(s.total <= w_ho * c.handovers + c.rsrq_s + 1e-9)


def test_receding_with_the_whole_flight_is_the_bound(rec):
    for w_ho in (0.04, 0.3, 2.0):
        exact = oracle.solve(rec, w_ho)
        np.testing.assert_allclose(oracle.receding(rec, w_ho, horizon_s=1e3).total, exact.total)
        short = oracle.receding(rec, w_ho, horizon_s=0.2)
        assert np.all(short.total >= exact.total - 1e-9)


def test_frontier_section_reads_the_benchmark_json(rec, tmp_path):
    """The report's figure and caption come from the JSON's figures; a missing file is one clear error."""
    import json

    from xairl import InputError
    from xairl_uav_handover.report import frontier_section

    w_hos = [0.04, 0.3, 3.0]
    data = {"flights": 16, "decision_s": 0.2, "frontier": oracle.frontier(rec, w_hos)}
    data["receding"] = {"1": oracle.frontier(rec, w_hos, horizon_s=1.0)}
    point = {"handovers": 0.9, "rsrq_pct": data["frontier"]["rsrq_pct"][1] + 0.5}
    point["bound_handovers_at_rsrq"] = oracle.handovers_at(data["frontier"], point["rsrq_pct"])
    point["bound_rsrq_at_handovers"] = oracle.rsrq_at(data["frontier"], point["handovers"])
    data["policies"] = {"CHM": point, "DQN": point}
    (tmp_path / "frontier.json").write_text(json.dumps(data))
    caption, png = frontier_section(str(tmp_path / "frontier.json"), tmp_path)
    assert png.stat().st_size > 0
    assert f"needs {point['bound_handovers_at_rsrq']:.2f} handovers" in caption
    with pytest.raises(InputError, match="frontier.json"):
        frontier_section(str(tmp_path / "missing.json"), tmp_path)
