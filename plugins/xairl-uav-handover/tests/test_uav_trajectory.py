"""Flights through waypoints (trajectory.py): waypoints reached, heights and speeds within their bounds, a seed
fixes the flights, and the simulator follows them."""

import numpy as np
import pytest

from xairl_uav_handover.config import FlightConfig, SimConfig
from xairl_uav_handover.trajectory import Waypoints


def _fly(seed: int, steps: int = 3000, radius: float = 300.0, n: int = 16, dt: float = 0.1):
    w = Waypoints(FlightConfig(), radius, np.random.default_rng(seed), n)
    pos, path, targets = w.start.copy(), [], []
    for _ in range(steps):
        targets.append(w.target.copy())
        pos = w.advance(pos, dt)
        path.append(pos.copy())
    return w, np.array(path), np.array(targets)


def test_waypoints_are_reached_exactly():
    w, path, targets = _fly(0)
    hit = np.any(np.all(np.isclose(path, targets), axis=2), axis=0)  # stood on the waypoint it flew to
    assert (w.reached > 0).all() and hit.all()
    changed = np.any(targets[1:] != targets[:-1], axis=2)  # a new waypoint only once the old one is reached
    assert ((w.reached - changed.sum(axis=0)) <= 1).all() and (changed.sum(axis=0) <= w.reached).all()  # last step


def test_heights_and_speeds_within_bounds():
    f, dt = FlightConfig(), 0.1
    w, path, _ = _fly(1, dt=dt)
    lo, hi = f.altitude_m
    assert (path[..., 2] >= lo).all() and (path[..., 2] <= hi).all()
    vz = np.diff(path[..., 2], axis=0) / dt
    assert vz.max() <= f.climb_mps + 1e-9 and vz.min() >= -f.descent_mps - 1e-9
    assert vz.max() > 0.9 * f.climb_mps and vz.min() < -0.9 * f.descent_mps  # it climbs and descends
    v_xy = np.hypot(*np.diff(path[..., :2], axis=0).transpose(2, 0, 1)) / dt
    assert (v_xy <= w.speed[None] + 1e-9).all()
    assert (np.hypot(path[..., 0], path[..., 1]) <= 300.0 + 1e-9).all()


def test_a_seed_fixes_the_flights():
    a, b, c = _fly(5, steps=500)[1], _fly(5, steps=500)[1], _fly(6, steps=500)[1]
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)


def test_simulator_follows_the_route():
    from xairl_uav_handover.simulator import Simulator

    sim = Simulator(SimConfig(), n_uavs=8, seed=2)
    heights = [sim.pos[:, 2].copy()]
    for _ in range(500):
        sim.step(sim.serving)
        heights.append(sim.pos[:, 2].copy())
    heights = np.array(heights)
    assert np.ptp(heights, axis=0).max() > 10  # altitude changes in flight
    again = Simulator(SimConfig(), n_uavs=8, seed=2)
    for _ in range(500):
        again.step(again.serving)
    np.testing.assert_array_equal(again.pos, sim.pos)
    with pytest.raises(ValueError):
        SimConfig.model_validate({"flight": {"climb_mps": 0}})
