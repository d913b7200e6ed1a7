"""Table I as an operator reads it: what each policy costs, per flight, with bootstrap 95 % intervals.

Every controller flies the same held-out flights (:func:`evaluate.run_flights`, several evaluation seeds pooled);
each figure is a statistic over flights, and its interval comes from resampling the flights with replacement
(percentile bootstrap, 1,000 resamples, seeded). With several DQN checkpoints pooled (``groups``: the training seed
of each flight's policy), each resample first draws training seeds with replacement, then flights within each, so
the interval holds the spread between seeds too. Each per-flight figure is given as mean and as median (the paper's
Table I reports medians: :func:`format_paper` sets ours beside them). Shares pooled over handovers (ping-pong share,
handovers taken with an empty or a full buffer) are ratios of sums, resampled as such. The ping-pong window is
``HandoverConfig.min_time_of_stay_s`` (the rows that say 'minimum time of stay'); the 1, 2, 5 and 10 s windows are
shown beside it, except the one equal to the minimum time of stay (given ``min_stay_s``, :func:`shown_rows`): its
rows would repeat the minimum time of stay's.
"""

from __future__ import annotations

import numpy as np

from .env import PINGPONG_WINDOWS_S
from .evaluate import PAPER, run_flights


def pingpong_share(m: dict, i, key: str = "pingpongs") -> np.ndarray:
    """Per-flight ping-pong share (%) of the flights ``i`` that handed over; ``key`` the window's count
    (default the minimum time of stay; ``pingpongs_10s``: 10 s)."""
    ho = m["handovers"][i]
    return 100 * m[key][i][ho > 0] / ho[ho > 0]


# statistics of the per-flight arrays ``m`` over the flights ``i``
def _pooled(num, den):
    return lambda m, i: 100 * m[num][i].sum() / max(m[den][i].sum(), 1)


def _mean(key, scale=1.0):
    return lambda m, i: scale * m[key][i].mean()


def _median(key, scale=1.0):
    return lambda m, i: scale * float(np.median(m[key][i]))


def _worst5(key):
    return lambda m, i: np.sort(m[key][i])[: max(1, len(i) // 20)].mean()


#: (key, label, statistic of the per-flight arrays ``m``) in the table's order
def _rows():
    rows = [
        ("handovers", "handovers per flight, mean", _mean("handovers")),
        ("handovers_median", "handovers per flight, median", _median("handovers")),
        ("pp_share_median", "ping-pong share per flight, median, minimum time of stay (%)", _share_median),
        ("pp_share", "ping-pong share, minimum time of stay (%)", _pooled("pingpongs", "handovers")),
        (
            "pp_per_min",
            "ping-pongs per flight-minute, minimum time of stay",
            lambda m, i: m["pingpongs"][i].sum() / m["minutes"][i].sum(),
        ),
    ]
    rows += [
        (f"pp_{w:g}s", f"ping-pong share, {w:g} s window (%)", _pooled(f"pingpongs_{w:g}s", "handovers"))
        for w in PINGPONG_WINDOWS_S
    ]
    rows += [
        (
            f"pp_share_median_{w:g}s",
            f"ping-pong share per flight, median, {w:g} s window (%)",
            lambda m, i, key=f"pingpongs_{w:g}s": _share_median(m, i, key),
        )
        for w in PINGPONG_WINDOWS_S
    ]
    rows += [
        (
            "pp_over_5",
            "flights with > 5 ping-pongs, minimum time of stay (%)",
            lambda m, i: 100 * (m["pingpongs"][i] > 5).mean(),
        ),
        ("lost_mbit", "lost data per flight, mean (Mbit)", _mean("lost_data_kbit", 1e-3)),
        ("lost_mbit_median", "lost data per flight, median (Mbit)", _median("lost_data_kbit", 1e-3)),
        ("availability", "service availability, mean (%)", _mean("service_availability_pct")),
        ("availability_median", "service availability, median (%)", _median("service_availability_pct")),
        ("availability_worst5", "service availability, worst 5 % of flights (%)", _worst5("service_availability_pct")),
        ("rsrq_violation", "time below the RSRQ threshold, mean (%)", _mean("rsrq_violation_pct")),
        ("rsrq_violation_median", "time below the RSRQ threshold, median (%)", _median("rsrq_violation_pct")),
        ("rsrp_violation", "time below the RSRP threshold, mean (%)", _mean("rsrp_violation_pct")),
        ("rsrp_violation_median", "time below the RSRP threshold, median (%)", _median("rsrp_violation_pct")),
        (
            "ho_empty",
            "handovers taken with an empty buffer (%)",
            lambda m, i: 100 - _pooled("handovers_buffer_nonempty", "handovers")(m, i),
        ),
        ("ho_full", "handovers taken with a full buffer (%)", _pooled("handovers_buffer_full", "handovers")),
        ("rlf", "radio link failures per flight, mean", _mean("radio_link_failures")),
        ("hof", "handover failures per flight, mean", _mean("handover_failures")),
        ("outage", "time re-establishing after a failure, mean (%)", _mean("outage_pct")),
        ("buffer_in_use", "decisions taken with a non-empty buffer, mean (%)", _mean("buffer_nonempty_pct")),
        ("buffer_in_use_median", "decisions taken with a non-empty buffer, median (%)", _median("buffer_nonempty_pct")),
    ]
    return rows


def _share_median(m: dict, i, key: str = "pingpongs") -> float:
    share = pingpong_share(m, i, key)
    return float(np.median(share)) if len(share) else 0.0


ROWS = _rows()
#: rows where more is better (everywhere else less is)
HIGHER_IS_BETTER = {"availability", "availability_median", "availability_worst5"}
#: Table I rows the paper reports (its medians per flight), in PAPER's order
PAPER_ROWS = ("handovers_median", "pp_share_median")
WINDOWS = " / ".join(f"{w:g}" for w in PINGPONG_WINDOWS_S)


def flights(controller, config, n_flights: int, seeds) -> dict[str, np.ndarray]:
    """Per-flight metrics of ``controller`` on ``n_flights`` held-out flights for each evaluation seed, pooled."""
    runs = [run_flights(controller, config, n_flights, seed) for seed in seeds]
    return {key: np.concatenate([r[key] for r in runs]) for key in runs[0]}


def pooled_seeds(runs: list[dict[str, np.ndarray]]) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """The per-flight metrics of several policies (one per training seed) pooled, and each flight's seed index
    (``groups`` of :func:`with_intervals`)."""
    groups = np.concatenate([np.full(len(r["handovers"]), k) for k, r in enumerate(runs)])
    return {key: np.concatenate([r[key] for r in runs]) for key in runs[0]}, groups


def resample(n: int, resamples: int, seed: int, groups=None) -> list[np.ndarray]:
    """``resamples`` arrays of flight indices: flights with replacement, or (``groups``: a group id per flight)
    groups with replacement, then flights with replacement within each drawn group (groups of unequal sizes give
    draws of unequal lengths)."""
    rng = np.random.default_rng(seed)
    if groups is None:
        return list(rng.integers(0, n, size=(resamples, n)))
    members = [np.flatnonzero(groups == g) for g in np.unique(groups)]
    out = []
    for _ in range(resamples):
        picked = rng.integers(0, len(members), size=len(members))
        out.append(np.concatenate([rng.choice(members[g], size=len(members[g])) for g in picked]))
    return out


def with_intervals(
    m: dict[str, np.ndarray], resamples: int = 1000, seed: int = 0, groups=None
) -> dict[str, tuple[float, float, float]]:
    """{row key: (value, low, high)}: each statistic on all flights and its percentile bootstrap 95 % interval
    (over flights; with ``groups``, over training seeds and flights: :func:`resample`)."""
    n = len(m["handovers"])
    everyone = np.arange(n)
    draws = resample(n, resamples, seed, groups)
    out = {}
    for key, _, stat in ROWS:
        boot = np.array([stat(m, d) for d in draws])
        out[key] = (float(stat(m, everyone)), float(np.percentile(boot, 2.5)), float(np.percentile(boot, 97.5)))
    return out


def format_paper(results: dict[str, dict[str, tuple[float, float, float]]]) -> str:
    """The paper's Table I medians beside ours: one line per policy it reports (a column named CHM, SA-MRO or
    DQN..., the one pooled over training seeds where there is one, else the first)."""
    lines = [
        "medians per flight, ours [95 % interval] vs the paper's (Meer et al., Table I); ping-pong share at the "
        "minimum time of stay, the other windows beside it:"
    ]
    for policy, (ho, pp) in PAPER.items():
        names = [n for n in results if n == policy or n.startswith(policy)]
        if not names:
            continue
        name = next((n for n in names if "seeds" in n), names[0])  # the pooled column, where there is one
        (h, hlo, hhi), (p, plo, phi) = (results[name][k] for k in PAPER_ROWS)
        beside = " / ".join(f"{results[name][f'pp_share_median_{w:g}s'][0]:.1f}" for w in PINGPONG_WINDOWS_S)
        lines.append(
            f"  {name:<24} handovers {h:.1f} [{hlo:.1f}, {hhi:.1f}] vs {ho}; ping-pong share "
            f"{p:.1f} [{plo:.1f}, {phi:.1f}] % (beside it at {WINDOWS} s: {beside} %) vs {pp} %"
        )
    return "\n".join(lines)


def shown_rows(min_stay_s: float | None = None) -> list[tuple[str, str]]:
    """(key, label) of the rows a table shows: every row of :data:`ROWS`; given the configured minimum time of stay,
    its value in the rows that count at it, and without the window rows at that same window (the same counts)."""
    if min_stay_s is None:
        return [(key, label) for key, label, _ in ROWS]
    same = {f"pp_{min_stay_s:g}s", f"pp_share_median_{min_stay_s:g}s"}
    stay = f"minimum time of stay of {min_stay_s:g} s"
    return [(key, label.replace("minimum time of stay", stay)) for key, label, _ in ROWS if key not in same]


def format_rows(results: dict[str, dict[str, tuple[float, float, float]]], min_stay_s: float | None = None) -> str:
    """One line per row (:func:`shown_rows`), one column per policy: 'value [low, high]'."""
    names = list(results)
    lines = [f"{'':<62}" + "".join(f"{n:>24}" for n in names)]
    for key, label in shown_rows(min_stay_s):
        cells = [results[n][key] for n in names]
        lines.append(f"{label:<62}" + "".join(f"{v:>9.2f} [{lo:.2f}, {hi:.2f}]".rjust(24) for v, lo, hi in cells))
    return "\n".join(lines)


def worse(res: dict, a: str, b: str, min_stay_s: float | None = None) -> list[str]:
    """Labels of the rows (:func:`shown_rows`) where policy ``a`` is worse than ``b`` beyond doubt: its interval
    lies wholly on the worse side of ``b``'s interval."""
    out = []
    for key, label in shown_rows(min_stay_s):
        (_, alo, ahi), (_, blo, bhi) = res[a][key], res[b][key]
        if (ahi < blo) if key in HIGHER_IS_BETTER else (alo > bhi):
            out.append(label)
    return out


def html_table(res: dict, min_stay_s: float | None = None) -> tuple[list[str], list[list[str]]]:
    """(header, rows) for an HTML table: one row per figure (:func:`shown_rows`), one column per policy,
    'value [low, high]'."""
    names = list(res)
    return (
        ["figure (per flight, or pooled over flights)", *names],
        [
            [label, *(f"{res[n][key][0]:.2f} [{res[n][key][1]:.2f}, {res[n][key][2]:.2f}]" for n in names)]
            for key, label in shown_rows(min_stay_s)
        ],
    )


def verdict(res: dict, a: str = "DQN", b: str = "CHM", min_stay_s: float | None = None) -> str:
    """In words, where policy ``a`` loses to ``b`` beyond the intervals (:func:`worse`)."""
    losses = worse(res, a, b, min_stay_s)
    return (
        f"The {a} is worse than {b} beyond the intervals on: " + "; ".join(losses) + "."
        if losses
        else f"The {a} is worse than {b} beyond the intervals on no figure."
    )
