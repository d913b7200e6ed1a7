"""Table I as an operator reads it: what each policy costs, per flight, with bootstrap 95 % intervals.

Every controller flies the same held-out flights (:func:`evaluate.run_flights`, several evaluation seeds pooled);
each figure is a statistic over flights, and its interval comes from resampling the flights with replacement
(percentile bootstrap, 1,000 resamples, seeded). Shares pooled over handovers (ping-pong share, handovers taken with
an empty or a full buffer) are ratios of sums, resampled as such.
"""

from __future__ import annotations

import numpy as np

from .env import PINGPONG_WINDOWS_S
from .evaluate import run_flights


#: (key, label, statistic of the per-flight arrays ``m``) in the table's order
def _rows():
    def pooled(num, den):
        return lambda m, i: 100 * m[num][i].sum() / max(m[den][i].sum(), 1)

    def mean(key, scale=1.0):
        return lambda m, i: scale * m[key][i].mean()

    def worst5(key):
        return lambda m, i: np.sort(m[key][i])[: max(1, len(i) // 20)].mean()

    rows = [
        ("handovers", "handovers per flight", mean("handovers")),
        (
            "pp_per_min",
            "ping-pongs per flight-minute (1 s window)",
            lambda m, i: m["pingpongs"][i].sum() / m["minutes"][i].sum(),
        ),
    ]
    rows += [
        (f"pp_{w:g}s", f"ping-pong share, {w:g} s window (%)", pooled(f"pingpongs_{w:g}s", "handovers"))
        for w in PINGPONG_WINDOWS_S
    ]
    rows += [
        ("pp_over_5", "flights with > 5 ping-pongs, 1 s window (%)", lambda m, i: 100 * (m["pingpongs"][i] > 5).mean()),
        ("lost_mbit", "lost data per flight (Mbit)", mean("lost_data_kbit", 1e-3)),
        ("availability", "service availability, mean (%)", mean("service_availability_pct")),
        ("availability_worst5", "service availability, worst 5 % of flights (%)", worst5("service_availability_pct")),
        ("rsrq_violation", "time below the RSRQ threshold (%)", mean("rsrq_violation_pct")),
        ("rsrp_violation", "time below the RSRP threshold (%)", mean("rsrp_violation_pct")),
        (
            "ho_empty",
            "handovers taken with an empty buffer (%)",
            lambda m, i: 100 - pooled("handovers_buffer_nonempty", "handovers")(m, i),
        ),
        ("ho_full", "handovers taken with a full buffer (%)", pooled("handovers_buffer_full", "handovers")),
        ("buffer_in_use", "decisions taken with a non-empty buffer (%)", mean("buffer_nonempty_pct")),
    ]
    return rows


ROWS = _rows()
#: rows where more is better (everywhere else less is)
HIGHER_IS_BETTER = {"availability", "availability_worst5"}


def flights(controller, config, n_flights: int, seeds) -> dict[str, np.ndarray]:
    """Per-flight metrics of ``controller`` on ``n_flights`` held-out flights for each evaluation seed, pooled."""
    runs = [run_flights(controller, config, n_flights, seed) for seed in seeds]
    return {key: np.concatenate([r[key] for r in runs]) for key in runs[0]}


def with_intervals(
    m: dict[str, np.ndarray], resamples: int = 1000, seed: int = 0
) -> dict[str, tuple[float, float, float]]:
    """{row key: (value, low, high)}: each statistic on all flights and its percentile bootstrap 95 % interval."""
    n = len(m["handovers"])
    everyone = np.arange(n)
    draws = np.random.default_rng(seed).integers(0, n, size=(resamples, n))
    out = {}
    for key, _, stat in ROWS:
        boot = np.array([stat(m, d) for d in draws])
        out[key] = (float(stat(m, everyone)), float(np.percentile(boot, 2.5)), float(np.percentile(boot, 97.5)))
    return out


def format_rows(results: dict[str, dict[str, tuple[float, float, float]]]) -> str:
    """One line per row, one column per policy: 'value [low, high]'."""
    names = list(results)
    lines = [f"{'':<48}" + "".join(f"{n:>24}" for n in names)]
    for key, label, _ in ROWS:
        cells = [results[n][key] for n in names]
        lines.append(f"{label:<48}" + "".join(f"{v:>9.2f} [{lo:.2f}, {hi:.2f}]".rjust(24) for v, lo, hi in cells))
    return "\n".join(lines)


def worse(res: dict, a: str, b: str) -> list[str]:
    """Labels of the rows where policy ``a`` is worse than ``b`` beyond doubt: its interval lies wholly on the worse
    side of ``b``'s interval."""
    out = []
    for key, label, _ in ROWS:
        (_, alo, ahi), (_, blo, bhi) = res[a][key], res[b][key]
        if (ahi < blo) if key in HIGHER_IS_BETTER else (alo > bhi):
            out.append(label)
    return out


def html_table(res: dict) -> tuple[list[str], list[list[str]]]:
    """(header, rows) for an HTML table: one row per figure, one column per policy, 'value [low, high]'."""
    names = list(res)
    return (
        ["", *names],
        [
            [label, *(f"{res[n][key][0]:.2f} [{res[n][key][1]:.2f}, {res[n][key][2]:.2f}]" for n in names)]
            for key, label, _ in ROWS
        ],
    )


def verdict(res: dict, a: str = "DQN", b: str = "CHM") -> str:
    """In words, where policy ``a`` loses to ``b`` beyond the intervals (:func:`worse`)."""
    losses = worse(res, a, b)
    return (
        f"The {a} is worse than {b} beyond the intervals on: " + "; ".join(losses) + "."
        if losses
        else f"The {a} is worse than {b} beyond the intervals on no figure."
    )
