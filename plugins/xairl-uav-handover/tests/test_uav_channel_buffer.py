"""TR 36.777 oracle values (DESIGN.md) and the buffer recursion on hand-computed cases."""
import numpy as np
import pytest

from xairl_uav_handover.buffer import buffer_step, service_bits
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
    assert (los_probability("RMa-AV", 60, d) == 1).all()    # and above 40 m in RMa
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


def test_service_is_shannon_rate():
    # SINR 0 dB -> log2(2) = 1 bit/s/Hz: W_s |B| dt = 180 kHz * 6 * 0.04 s
    assert service_bits(0.0, 6, 180e3, 0.04) == pytest.approx(43_200.0)
    assert service_bits(10 * np.log10(3), 1, 1.0, 1.0) == pytest.approx(2.0)


def test_buffer_recursion_by_hand():
    q, lost = buffer_step(np.array([1000.0, 1000.0, 1.9e6]), np.array([500.0, 3000.0, 2e5]),
                          np.array([2000.0, 1500.0, 0.0]), q_max=2e6)
    np.testing.assert_allclose(q, [0.0, 2500.0, 2e6])   # clipped at 0; 1000+3000-1500; capped at q_max
    np.testing.assert_allclose(lost, [0.0, 0.0, 1e5])   # overflow is lost data
