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
    """Loss 100 dB, antenna -19 dB: coupling 119 dB; power -85 + 0.8 * 119 = 10.2 dBm per block; noise -174 +
    10 lg 180e3 + 5 = -116.447 dBm per block."""
    cfg = _cfg({"p0_pusch_dbm": -85.0, "pc_alpha": 0.8, "bs_antenna_gain_db": -19.0}, {"ul_share": 0.1})
    expected = (-85.0 + 0.8 * 119.0) - 119.0 - (-174.0 + 10 * np.log10(180e3) + 5.0)
    assert uplink.sinr_db(cfg, 100.0, 0.0) == pytest.approx(expected)
    assert uplink.sinr_db(cfg, 100.0, 1e-12) < expected


def test_truncated_shannon():
    """TR 36.942 Annex A: 0 below -10 dB, 0.4 log2(1 + SINR) between, 4.4 bit/s/Hz at most; over M blocks."""
    cfg = _cfg({"ul_attenuation": 0.4, "ul_sinr_min_db": -10.0, "ul_max_se": 4.4}, {"ul_share": 0.06})
    w = 180e3 * 6
    assert uplink.capacity_bps(cfg, 0.0) == pytest.approx(0.4 * w)
    assert uplink.capacity_bps(cfg, 10 * np.log10(3)) == pytest.approx(0.8 * w)
    assert uplink.capacity_bps(cfg, 60.0) == pytest.approx(4.4 * w)  # the ceiling
    assert uplink.capacity_bps(cfg, -10.5) == 0.0


def test_interference_is_the_brute_force_sum():
    """Two cells, two UEs each, loads 1: cell b hears the other cell's UEs' mean power times their gain to b."""
    cfg = _cfg({"ues_per_cell": 2, "aerial_ue_ratio": 0.5, "load_range": (1.0, 1.0)})
    bs = np.array([[0.0, 0.0], [500.0, 0.0]])
    got = uplink.interference_mw(cfg, bs, np.random.default_rng(4), 3)
    xy, h = uplink.drop_ues(cfg, bs, np.random.default_rng(4), 3)
    for k in range(3):
        for b in range(2):
            j = 1 - b
            total = 0.0
            for u in range(2):
                own = uplink._mean_gain(cfg, h[k, j, u], np.hypot(*(xy[k, j, u] - bs[j])))
                to_b = uplink._mean_gain(cfg, h[k, j, u], np.hypot(*(xy[k, j, u] - bs[b])))
                total += 10 ** (uplink.psd_dbm(cfg, -10 * np.log10(own)) / 10) * to_b / 2
            assert got[k, b] == pytest.approx(total, rel=1e-9)


def test_aerial_ues_raise_the_interference_and_loads_scale_it():
    cfg = SimConfig()
    layout = hex_layout(cfg.layout.isd_m, cfg.layout.rings)
    ground = uplink.interference_mw(_cfg({"aerial_ue_ratio": 0.0}), layout, np.random.default_rng(0), 20)
    aerial = uplink.interference_mw(_cfg({"aerial_ue_ratio": 0.5}), layout, np.random.default_rng(0), 20)
    assert np.median(aerial) > 10 * np.median(ground)  # line of sight to many cells (TR 36.777)
    full = uplink.interference_mw(_cfg({"load_range": (1.0, 1.0)}), layout, np.random.default_rng(1), 5)
    half = uplink.interference_mw(_cfg({"load_range": (0.5, 0.5)}), layout, np.random.default_rng(1), 5)
    np.testing.assert_allclose(half, full / 2)


def test_real_flight_cells_take_levels_of_one_drop():
    from xairl_uav_handover.real_data import UplinkBuffer

    cfg = SimConfig()
    link = UplinkBuffer(cfg, 60.0, seed=0, flight="f")
    for cell in range(30):
        link.sinr_db(-85.0, cell)
    assert set(link._interference.values()) <= set(link.site_interference.tolist())


def test_settings_retired_by_issue_53_are_dropped_from_old_checkpoints():
    from xairl_uav_handover.config import without_retired

    old = SimConfig().model_dump()
    old["radio"].update(ul_activity=0.06, ul_interference_spread_db=9.0)
    old["flight"]["turn_every_s"] = 30.0
    old["buffer"]["rb_per_uav"] = 50
    with pytest.raises(ValueError):
        SimConfig.model_validate(old)
    assert SimConfig.model_validate(without_retired(old)) == SimConfig()
