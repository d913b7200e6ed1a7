"""TR 36.777 oracle values (DESIGN.md) and the buffer recursion on hand-computed cases."""

import numpy as np
import pytest

from xairl_uav_handover import uplink
from xairl_uav_handover.buffer import buffer_step
from xairl_uav_handover.channel import SCENARIOS, los_probability, path_loss, shadow_sigma
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.simulator import hex_layout


def test_uma_oracle_values():
    assert los_probability("UMa-AV", 50, 500) == pytest.approx(0.8887, abs=1e-4)
    assert path_loss("UMa-AV", 100, 520, 2.6, True) == pytest.approx(96.05, abs=0.01)
    assert path_loss("UMa-AV", 100, 520, 2.6, False) == pytest.approx(110.15, abs=0.01)
    # sigma_SF: LOS 4.64 exp(-0.0066 h) (the paper's 0.00066 is a typo), NLOS 6 dB
    assert shadow_sigma("UMa-AV", 100, True) == pytest.approx(4.64 * np.exp(-0.66))
    assert shadow_sigma("UMa-AV", 100, False) == 6.0


def test_los_probability_shape():
    d = np.array([10.0, 200.0, 1000.0, 5000.0])
    assert (los_probability("UMa-AV", 120, d) == 1).all()  # LoS certain above 100 m
    assert (los_probability("RMa-AV", 60, d) == 1).all()  # and above 40 m in RMa
    for sc in SCENARIOS:
        p = los_probability(sc, 30, d)
        assert p[0] == 1 and (np.diff(p) <= 1e-12).all() and (p > 0).all()


@pytest.mark.parametrize("scenario", SCENARIOS)
def test_nlos_never_below_los(scenario):
    d = np.linspace(30, 3000, 50)
    assert (path_loss(scenario, 60, d, 2.0, False) >= path_loss(scenario, 60, d, 2.0, True) - 1e-9).all()


def test_unknown_scenario():
    with pytest.raises(ValueError, match="unknown scenario 'XYZ'"):
        path_loss("XYZ", 50, 100, 2.0, True)


def test_capacity_is_shannon_rate():
    cfg = SimConfig.model_validate({"buffer": {"rb_per_uav": 6}})
    # SINR 0 dB -> log2(2) = 1 bit/s/Hz: W_s |B| = 180 kHz * 6
    assert uplink.capacity_bps(cfg, 0.0) == pytest.approx(1_080_000.0)
    assert uplink.capacity_bps(cfg, 10 * np.log10(3)) == pytest.approx(2 * 1_080_000.0)


def test_uplink_interference_rises_with_height_and_matches_the_link_budget():
    cfg = SimConfig()
    layout = hex_layout(cfg.layout.isd_m, cfg.layout.rings)
    i = uplink.interference_mw(cfg, layout, np.array([30.0, 60.0, 100.0, 150.0]))[:, 0]
    assert (np.diff(i) > 0).all()  # more cells in line of sight as the UAV climbs (TR 36.777)
    # no interference: SINR is P_ue - coupling loss (antenna gains included) - noise over the UAV's RBs
    quiet = SimConfig.model_validate({"radio": {"ul_activity": 0.0}})
    noise = -174 + 10 * np.log10(50 * 180e3) + 5.0
    assert uplink.sinr_db(quiet, 100.0, 0.0) == pytest.approx(23.0 - 100.0 - noise)
    assert uplink.sinr_db(cfg, 100.0, i[0]) < uplink.sinr_db(quiet, 100.0, 0.0)


def test_buffer_recursion_by_hand():
    q, lost = buffer_step(
        np.array([1000.0, 1000.0, 1.9e6]), np.array([500.0, 3000.0, 2e5]), np.array([2000.0, 1500.0, 0.0]), q_max=2e6
    )
    np.testing.assert_allclose(q, [0.0, 2500.0, 2e6])  # clipped at 0; 1000+3000-1500; capped at q_max
    np.testing.assert_allclose(lost, [0.0, 0.0, 1e5])  # overflow is lost data


def test_uma_av_is_terrestrial_uma_up_to_22_5_m():
    """TR 36.777 takes UMa-AV UEs at or below 22.5 m as terrestrial (TR 38.901 UMa), values worked by hand:
    P_LOS(20 m, 200 m) = (0.09 + e^(-200/63) 0.91) (1 + 0.7^1.5 * 1.25 * 8 e^(-4/3)) = 0.3257; C'(h) = 0 at 10 m."""
    assert los_probability("UMa-AV", 20, 200) == pytest.approx(0.3257, abs=1e-4)
    assert los_probability("UMa-AV", 10, 200) == pytest.approx(0.1280, abs=1e-4)
    # NLoS: 13.54 + 39.08 lg 500 + 20 lg 2 - 0.6 (20 - 1.5) = 113.94 dB; LoS before the breakpoint: UMa-AV's formula
    assert path_loss("UMa-AV", 20, 500, 2.0, False) == pytest.approx(113.94, abs=0.01)
    assert path_loss("UMa-AV", 20, 500, 2.0, True) == path_loss("UMa-AV", 30, 500, 2.0, True)
    assert shadow_sigma("UMa-AV", 20, True) == 4.0
    # above 22.5 m the aerial model again
    assert los_probability("UMa-AV", 23, 500) == pytest.approx(
        18 / 500 + np.exp(-500 / (4300 * np.log10(23) - 3800)) * (1 - 18 / 500)
    )


def test_cells_differ_in_uplink_interference():
    """Each cell's interference level is drawn per flight within +-spread dB; with no spread the cells of a flight
    share the layout's mean levels."""
    from xairl_uav_handover.simulator import Simulator

    flat = Simulator(SimConfig.model_validate({"radio": {"ul_interference_spread_db": 0}}), n_uavs=4, seed=3)
    spread = Simulator(SimConfig(), n_uavs=4, seed=3)
    ratio_db = 10 * np.log10(spread._ul_interference / flat._ul_interference)
    s = SimConfig().radio.ul_interference_spread_db
    assert s > 0 and (np.abs(ratio_db) <= s + 1e-9).all() and ratio_db.std() > s / 4
