"""The uplink (uplink.py): open-loop power control and SINR worked by hand, TR 36.942's truncated Shannon, the
interference of one drop against a brute-force sum, and the real flights on the same drop."""

import numpy as np
import pytest

from xairl_uav_handover import uplink
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.simulator import hex_layout


def _cfg(radio=None, buffer=None) -> SimConfig:
    return SimConfig.model_validate({"radio": radio or {}, "buffer": buffer or {}})


def test_power_control_by_hand():
    """TS 36.213 5.1.1.1 per resource block: min(P_CMAX - 10 lg M, P0 + alpha PL)."""
    cfg = _cfg({"p0_pusch_dbm": -85.0, "pc_alpha": 0.8, "ue_tx_power_dbm": 23.0}, {"ul_share": 0.1})
    assert cfg.buffer.rb_per_uav == 10
    assert uplink.psd_dbm(cfg, 100.0) == pytest.approx(-85.0 + 80.0)  # -5 dBm per block, 5 dBm in all
    assert uplink.psd_dbm(cfg, 130.0) == pytest.approx(23.0 - 10.0)  # 19 dBm asked, capped at 13 per block


def test_sinr_without_interference_by_hand():
    """Coupling loss 119 dB (antenna gain and link loss included); power -85 + 0.8 * 119 = 10.2 dBm per block;
    noise -174 + 10 lg 180e3 + 5 = -116.447 dBm per block."""
    cfg = _cfg({"p0_pusch_dbm": -85.0, "pc_alpha": 0.8}, {"ul_share": 0.1})
    expected = (-85.0 + 0.8 * 119.0) - 119.0 - (-174.0 + 10 * np.log10(180e3) + 5.0)
    assert uplink.sinr_db(cfg, 119.0, 0.0) == pytest.approx(expected)
    assert uplink.sinr_db(cfg, 119.0, 1e-12) < expected


def test_truncated_shannon():
    """TR 36.942 Annex A: 0 below -10 dB, 0.4 log2(1 + SINR) between, 4.4 bit/s/Hz at most; over M blocks."""
    cfg = _cfg({"ul_attenuation": 0.4, "ul_sinr_min_db": -10.0, "ul_max_se": 4.4}, {"ul_share": 0.06})
    w = 180e3 * 6
    assert uplink.capacity_bps(cfg, 0.0) == pytest.approx(0.4 * w)
    assert uplink.capacity_bps(cfg, 10 * np.log10(3)) == pytest.approx(0.8 * w)
    assert uplink.capacity_bps(cfg, 60.0) == pytest.approx(4.4 * w)  # the ceiling
    assert uplink.capacity_bps(cfg, -10.5) == 0.0


def _gain_by_hand(cfg, ue_xy, ue_h, site_xy, boresight_deg) -> float:
    """One UE's linear coupling gain to one cell, written out from the standards (not from uplink.py or antenna.py):
    P_LOS-weighted path gain (TR 36.777), TR 36.814's sector pattern, less the link loss."""
    from xairl_uav_handover.channel import los_probability, path_loss

    c, a = cfg.channel, cfg.antenna
    dx, dy = ue_xy[0] - site_xy[0], ue_xy[1] - site_xy[1]
    d2d = float(np.hypot(dx, dy))
    d3d = float(np.hypot(d2d, ue_h - c.bs_height_m))
    p = float(los_probability(c.scenario, ue_h, max(d2d, 1.0)))
    path = p * 10 ** (-float(path_loss(c.scenario, ue_h, d3d, c.carrier_ghz, True, c.bs_height_m)) / 10)
    path += (1 - p) * 10 ** (-float(path_loss(c.scenario, ue_h, d3d, c.carrier_ghz, False, c.bs_height_m)) / 10)
    phi = (np.degrees(np.arctan2(dy, dx)) - boresight_deg + 180) % 360 - 180
    theta = np.degrees(np.arctan2(c.bs_height_m - ue_h, d2d))  # below the horizon
    a_h = -min(12 * (phi / a.h_beamwidth_deg) ** 2, a.front_back_db)
    a_v = -min(12 * ((theta - a.downtilt_deg) / a.v_beamwidth_deg) ** 2, a.side_lobe_db)
    gain_db = a.max_gain_dbi - min(-(a_h + a_v), a.front_back_db) - cfg.radio.link_loss_db
    return path * 10 ** (gain_db / 10)


def test_interference_is_the_brute_force_sum():
    """Two sites (six cells), two UEs a cell, loads 1: cell b hears every other cell's UEs, each sending at its
    open-loop power towards its own cell (P0 + alpha PL, capped at P_CMAX over M blocks), through its coupling gain
    to b; every gain and power written out by hand here."""
    from xairl_uav_handover.antenna import SECTOR_AZIMUTHS_DEG

    cfg = _cfg({"ues_per_cell": 2, "aerial_ue_ratio": 0.5, "ul_load_range": (1.0, 1.0)})
    sites = np.array([[0.0, 0.0], [500.0, 0.0]])
    cells = [(sites[s], SECTOR_AZIMUTHS_DEG[j]) for s in range(2) for j in range(3)]
    got = uplink.interference_mw(cfg, sites, np.random.default_rng(4), 3)
    xy, h = uplink.drop_ues(cfg, sites, np.random.default_rng(4), 3)
    rad, m = cfg.radio, cfg.buffer.rb_per_uav
    assert got.shape == (3, 6)
    for k in range(3):
        for b in range(6):
            total = 0.0
            for j in range(6):
                for u in range(2 * (j != b)):
                    own = _gain_by_hand(cfg, xy[k, j, u], h[k, j, u], *cells[j])
                    psd = min(
                        rad.ue_tx_power_dbm - 10 * np.log10(m), rad.p0_pusch_dbm - rad.pc_alpha * 10 * np.log10(own)
                    )
                    total += 10 ** (psd / 10) * _gain_by_hand(cfg, xy[k, j, u], h[k, j, u], *cells[b]) / 2
            assert got[k, b] == pytest.approx(total, rel=1e-9)


def test_aerial_ues_raise_the_interference_and_loads_scale_it():
    cfg = SimConfig()
    layout = hex_layout(cfg.layout.isd_m, cfg.layout.rings)
    ground = uplink.interference_mw(_cfg({"aerial_ue_ratio": 0.0}), layout, np.random.default_rng(0), 20)
    aerial = uplink.interference_mw(_cfg({"aerial_ue_ratio": 0.5}), layout, np.random.default_rng(0), 20)
    # line of sight to many cells (TR 36.777), though through the side lobes of their sector antennas
    assert np.median(aerial) > 3 * np.median(ground)
    full = uplink.interference_mw(_cfg({"ul_load_range": (1.0, 1.0)}), layout, np.random.default_rng(1), 5)
    half = uplink.interference_mw(_cfg({"ul_load_range": (0.5, 0.5)}), layout, np.random.default_rng(1), 5)
    np.testing.assert_allclose(half, full / 2)


def test_real_flight_cells_take_levels_of_one_drop():
    from xairl_uav_handover.real_data import UplinkBuffer

    cfg = SimConfig()
    link = UplinkBuffer(cfg, 60.0, seed=0, flight="f")
    for cell in range(30):
        link.sinr_db(-85.0, cell)
    assert set(link._interference.values()) <= set(link.cell_interference.tolist())


def test_settings_retired_by_issue_53_are_dropped_from_old_checkpoints():
    from xairl_uav_handover.policy import without_retired

    old = SimConfig().model_dump()
    old["radio"].update(ul_activity=0.06, ul_interference_spread_db=9.0)
    old["flight"]["turn_every_s"] = 30.0
    old["buffer"]["rb_per_uav"] = 50
    with pytest.raises(ValueError):
        SimConfig.model_validate(old)
    assert SimConfig.model_validate(without_retired(old)) == SimConfig()
