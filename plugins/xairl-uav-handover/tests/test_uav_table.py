"""Table I with intervals: ping-pongs at every window agree with the simulator's own count, and each figure's
bootstrap interval holds its value."""

import numpy as np

from xairl_uav_handover.baselines import CHM
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.table import ROWS, flights, format_rows, with_intervals


def test_ping_pong_windows_nest_and_the_configured_one_matches_the_simulator():
    cfg = SimConfig()
    m = flights(CHM(), cfg, 12, [0])
    counts = [m[f"pingpongs_{w:g}s"] for w in (1.0, 2.0, 5.0, 10.0)]
    assert all((a <= b).all() for a, b in zip(counts, counts[1:]))  # a wider window holds every narrower one
    assert cfg.handover.min_time_of_stay_s == 1.0 and (counts[0] == m["pingpongs"]).all()
    assert (counts[-1] <= m["handovers"]).all() and counts[-1].sum() > counts[0].sum()
    assert np.allclose(m["minutes"], cfg.flight.duration_s / 60, rtol=0.01)


def test_every_row_has_an_interval_around_its_value():
    m = flights(CHM(), SimConfig(), 12, [0, 1])
    assert len(m["handovers"]) == 24
    res = with_intervals(m, resamples=200)
    assert set(res) == {key for key, _, _ in ROWS}
    for key, (value, low, high) in res.items():
        assert low <= value + 1e-9 and value <= high + 1e-9, key
    assert res["pp_10s"][0] >= res["pp_1s"][0] and 0 <= res["ho_full"][0] <= 100 - res["ho_empty"][0] + 1e-9
    text = format_rows({"CHM": res})
    assert "ping-pong share, 10 s window (%)" in text and text.count("[") == len(ROWS)
