"""TR 36.777 oracle values (DESIGN.md) and the buffer recursion on hand-computed cases."""

import numpy as np
import pytest

from xairl_uav_handover.buffer import buffer_step
from xairl_uav_handover.channel import SCENARIOS, los_probability, path_loss, shadow_sigma


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
