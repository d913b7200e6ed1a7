"""Sectored antennas, per-cell load in RSRQ, measurement errors, and radio link / handover failures."""

import numpy as np
import pytest

from xairl_uav_handover import antenna
from xairl_uav_handover.calibration import rsrq_spread
from xairl_uav_handover.config import AntennaConfig, HandoverConfig, SimConfig
from xairl_uav_handover.failures import LinkMonitor, downlink_sinr_db, rssi_activity
from xairl_uav_handover.simulator import Simulator, fading_std_db, n_cells

A = AntennaConfig()


def test_sector_pattern_oracle_values():
    """TR 36.814 Table A.2.1.1-2: 14 dBi on boresight at the tilt; the side-lobe and front-to-back floors."""
    tilt = np.radians(A.downtilt_deg)
    # a point on boresight (east), 15 deg below the horizon: the full gain
    assert antenna.gain_db(A, 100.0, 0.0, -100.0 * np.tan(tilt), 0.0) == pytest.approx(14.0)
    # 3 dB down at half the vertical beamwidth off the tilt, and at half the horizontal one
    below = np.radians(A.downtilt_deg + A.v_beamwidth_deg / 2)
    assert antenna.gain_db(A, 100.0, 0.0, -100.0 * np.tan(below), 0.0) == pytest.approx(11.0)
    side = np.radians(A.h_beamwidth_deg / 2)
    assert antenna.gain_db(A, np.cos(side), np.sin(side), -np.tan(tilt), 0.0) == pytest.approx(11.0)
    # a UAV high above the horizon in front: the vertical side-lobe floor (14 - 20); behind: A_m (14 - 25)
    assert antenna.gain_db(A, 100.0, 0.0, 100.0, 0.0) == pytest.approx(-6.0)
    assert antenna.gain_db(A, -100.0, 0.0, 100.0, 0.0) == pytest.approx(-11.0)


def test_three_cells_per_site_and_their_boresights():
    sites = np.array([[0.0, 0.0], [500.0, 0.0]])
    xy, site, boresight = antenna.cell_layout(sites)
    assert site.tolist() == [0, 0, 0, 1, 1, 1] and (xy[3:] == [500.0, 0.0]).all()
    assert np.degrees(boresight[:3]).tolist() == pytest.approx([30.0, 150.0, 270.0])
    cfg = SimConfig()
    assert Simulator(cfg, 2, seed=0).N == n_cells(cfg.layout) == 57


def test_cells_of_one_site_differ_by_their_antennas_only():
    sim = Simulator(SimConfig(), 4, seed=3)
    gain = antenna.gain_db(
        A,
        sim.pos[:, None, 0] - sim.bs_xy[None, :, 0],
        sim.pos[:, None, 1] - sim.bs_xy[None, :, 1],
        sim.pos[:, 2:3] - sim.cfg.channel.bs_height_m,
        sim.boresight,
    )
    path = sim.loss_db + gain  # what is left is the site's path: the same for its three cells
    np.testing.assert_allclose(path[:, 0::3], path[:, 1::3])
    np.testing.assert_allclose(path[:, 0::3], path[:, 2::3])


def test_rsrq_carries_each_cells_load():
    """RSRQ = N RSRP / RSSI per cell (TS 36.214): with one load everywhere and a lone cell the textbook values
    hold; with per-cell loads RSRQ - RSRP differs between cells, which one common RSSI cannot do."""
    assert rssi_activity(1.0) == 1.0 and rssi_activity(0.0) == pytest.approx(16 / 168)
    cfg = SimConfig.model_validate({"observation": {"rsrp_error_db": 0, "rsrq_error_db": 0}})
    sim = Simulator(cfg, 20, seed=1)
    d = sim.rsrq - sim.rsrp
    assert (d.max(axis=1) - d.min(axis=1) > 1e-3).all()
    one = SimConfig.model_validate({"radio": {"load_range": (1.0, 1.0)}})
    sim = Simulator(one, 20, seed=1)
    d = sim.rsrq - sim.rsrp  # fully loaded everywhere: one RSSI for every cell, so one offset
    np.testing.assert_allclose(d.max(axis=1) - d.min(axis=1), 0.0, atol=1e-9)


def test_rsrq_spread_of_a_state():
    states = np.zeros((2, 13), dtype=np.float32)
    states[:, 5:9] = [[-80, -85, -90, -95], [-80, -85, -90, -95]]
    states[:, 9:13] = [[-10, -15, -21, -30], [-10, -15, -20, -25]]
    measured = np.array([[True, True, True, False], [True, True, False, False]])
    assert rsrq_spread(states, measured).tolist() == [1.0, 0.0]
    assert rsrq_spread(states, np.eye(4, dtype=bool)[:2]).size == 0


def test_fading_residual_from_the_k_factor():
    """Rayleigh: the power's relative variance is 1, so one look is 10/ln10 = 4.34 dB; K = 9 dB far less."""
    assert fading_std_db(None, 1) == pytest.approx(10 / np.log(10))
    assert fading_std_db(None, 4) == pytest.approx(10 / np.log(10) / 2)
    k = 10**0.9
    assert fading_std_db(9.0, 2) == pytest.approx(10 / np.log(10) * np.sqrt((1 + 2 * k) / (1 + k) ** 2 / 2))


def test_downlink_sinr_by_hand():
    rsrp = np.array([[-80.0, -90.0, -90.0]])
    load = np.array([[0.5, 1.0, 0.0]])
    noise = 1e-12
    got = downlink_sinr_db(rsrp, load, noise)[0, 0]
    assert got == pytest.approx(10 * np.log10(1e-8 / (1e-9 * 1.0 + 1e-9 * (16 / 168) + noise)))


def test_t310_runs_out_after_one_second_and_in_sync_stops_it():
    hc = HandoverConfig()
    mon = LinkMonitor(hc, 2, dt=0.04)
    failed_at = [None, None]
    for step in range(60):
        # UAV 0 is out of sync throughout; UAV 1 recovers at step 10
        sinr = np.array([-12.0, -12.0 if step < 10 else 0.0])
        failed = mon.radio_link_fails(sinr)
        for k in np.nonzero(failed)[0]:
            failed_at[k] = failed_at[k] or step
    assert failed_at[0] == 25 and failed_at[1] is None  # T310 starts at step 0 and runs 1 s = 25 steps


def test_failures_in_the_simulator():
    """A handover to a cell whose SINR cannot carry it fails and the UAV re-establishes on the strongest cell,
    without service for the re-establishment delay; without failures the same handover succeeds."""
    for failures in (True, False):
        cfg = SimConfig.model_validate({"handover": {"failures": failures}})
        sim = Simulator(cfg, 1, seed=0)
        worst = int(sim.dl_sinr[0].argmin())
        info = sim.step(np.array([worst]))
        assert info.handover[0]
        if failures:
            assert info.hof[0] and info.outage[0] and not info.available[0]
            assert sim.serving[0] == sim.meas_rsrp[0].argmax() != worst
            steps = int(round(cfg.handover.reestablish_s / cfg.flight.dt_s))
            outages = [sim.step(sim.serving).outage[0] for _ in range(steps + 2)]
            assert sum(outages) == steps - 1  # the failing step, then the rest of the delay
        else:
            assert not info.hof[0] and sim.serving[0] == worst
