"""Table I with intervals: ping-pongs at every window agree with the simulator's own count, and each figure's
bootstrap interval holds its value."""

import numpy as np
import pytest

from xairl_uav_handover.baselines import CHM
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.table import ROWS, flights, format_paper, format_rows, pooled_seeds, with_intervals


@pytest.mark.slow
def test_ping_pong_windows_nest_and_the_configured_one_matches_the_simulator():
    cfg = SimConfig()
    m = flights(CHM(), cfg, 12, [0])
    counts = [m[f"pingpongs_{w:g}s"] for w in (1.0, 2.0, 5.0, 10.0)]
    assert all((a <= b).all() for a, b in zip(counts, counts[1:]))  # a wider window holds every narrower one
    assert cfg.handover.min_time_of_stay_s == 1.0 and (counts[0] == m["pingpongs"]).all()
    assert (counts[-1] <= m["handovers"]).all() and counts[-1].sum() > counts[0].sum()
    assert np.allclose(m["minutes"], cfg.flight.duration_s / 60, rtol=0.01)


@pytest.mark.slow
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
    for key in ("handovers_median", "pp_share_median", "lost_mbit_median", "rsrq_violation_median"):
        value, low, high = res[key]
        assert low <= value <= high, key  # a median's interval holds the median


def _known(handovers, pingpongs):
    n = len(handovers)
    zero = ("handovers_buffer_nonempty", "handovers_buffer_full", "buffer_nonempty_pct")
    base = {k: np.zeros(n) for k in (*zero, "radio_link_failures", "handover_failures", "outage_pct")}
    return base | {
        "handovers": np.array(handovers, float),
        "pingpongs": np.array(pingpongs, float),
        **{f"pingpongs_{w:g}s": np.array(pingpongs, float) for w in (1.0, 2.0, 5.0, 10.0)},
        "minutes": np.full(n, 2.0),
        "service_availability_pct": np.arange(n, dtype=float),
        "lost_data_kbit": 1000.0 * np.arange(n),
        "rsrq_violation_pct": np.zeros(n),
        "rsrp_violation_pct": np.zeros(n),
    }


def test_medians_and_means_of_a_known_array():
    m = _known([1, 2, 3, 4, 100], [0, 1, 0, 2, 10])
    res = with_intervals(m, resamples=200)
    assert res["handovers_median"][0] == 3 and res["handovers"][0] == 22
    assert res["pp_share_median"][0] == 10 == res["pp_share_median_10s"][0]  # per-flight shares 0, 50, 0, 50, 10 %
    assert res["lost_mbit_median"][0] == 2 and res["availability_median"][0] == 2
    assert res["handovers_median"][2] <= 100 and res["handovers"][1] >= 1


def test_intervals_over_training_seeds_hold_the_spread_between_seeds():
    """Two seeds whose flights all hand over 2 and 10 times: resampling seeds, a resample can hold one seed twice,
    so the interval of the median reaches both; resampling flights alone pins it near the pooled median."""
    runs = [_known([2] * 20, [0] * 20), _known([10] * 20, [0] * 20)]
    m, groups = pooled_seeds(runs)
    by_seed, by_flight = with_intervals(m, 400, groups=groups), with_intervals(m, 400)
    assert by_seed["handovers_median"][1:] == (2, 10) and by_seed["handovers"][1:] == (2, 10)
    assert by_flight["handovers"][2] - by_flight["handovers"][1] < 4
    text = format_paper({"CHM": by_seed, "DQN seed 0": by_flight})
    assert "vs 75" in text and "vs 12" in text and "SA-MRO" not in text


def test_intervals_over_training_seeds_of_unequal_sizes():
    m, groups = pooled_seeds([_known([1, 2, 3], [0, 0, 1]), _known([5, 6], [1, 0])])
    res = with_intervals(m, resamples=100, groups=groups)
    assert res["handovers"][0] == pytest.approx(17 / 5) and res["handovers"][1] <= res["handovers"][2]


def test_table_one_repeats_no_row_and_labels_every_column():
    """The 1 s window is the minimum time of stay (the simulator counts both alike): its share and its median share
    were each shown twice. Shown once, the minimum time of stay's rows say which window it is."""
    from xairl_uav_handover.table import html_table, verdict

    stay = SimConfig().handover.min_time_of_stay_s
    m = _known([1, 2, 3, 4, 100], [0, 1, 0, 2, 10])
    for k, w in enumerate((2, 5, 10), 1):  # a wider window counts more: its rows differ
        m[f"pingpongs_{w}s"] = m[f"pingpongs_{w}s"] + k
    res = with_intervals(m, resamples=50)
    header, rows = html_table({"CHM": res, "SA-MRO": res}, stay)
    assert all(header) and header[1:] == ["CHM", "SA-MRO"]
    cells = [tuple(r[1:]) for r in rows]
    labels = [r[0] for r in rows]
    assert len(set(labels)) == len(labels) and f"{stay:g} s window" not in " ".join(labels)
    assert "ping-pong share, minimum time of stay of 1 s (%)" in labels
    pingpong = [c for label, c in zip(labels, cells) if "ping-pong share" in label]
    assert len(set(pingpong)) == len(pingpong), "two ping-pong rows hold the same figures"
    assert "1 s window" not in verdict({"DQN": res, "CHM": res}, min_stay_s=stay)
