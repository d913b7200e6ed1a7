"""The UAV report's own figures: handover rate against altitude (simulated CHM, CHM on the real measurements, the
live network, and Baltaci et al.'s events where their folder lies beside the real flights) and the hindsight
bound's frontier from benchmarks/oracle_frontier.py's JSON (report.py adds them to the page).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import xairl
from xairl import InputError

from .evaluate import chm_rate_by_altitude


def frontier_section(path: str, out) -> tuple[str, Path]:
    """The hindsight bound's figure from benchmarks/oracle_frontier.py's JSON at ``path``, and its caption."""
    import json

    try:
        data = json.loads(Path(path).read_text())
        chm, dqn = data["policies"]["CHM"], data["policies"]["DQN"]
    except (OSError, ValueError, KeyError) as e:
        raise InputError(
            f"cannot read the frontier {path} ({e}); give the frontier.json that benchmarks/oracle_frontier.py wrote."
        ) from None
    caption = (
        f"What hindsight allows on {data['flights']} held-out flights: the least time below the RSRQ threshold for "
        f"each number of handovers, exact over decisions every {data['decision_s']:g} s among the env's candidates, "
        f"and with 0.2-5 s of foresight. At CHM's RSRQ time ({chm['rsrq_pct']:.1f} %) the bound needs "
        f"{chm['bound_handovers_at_rsrq']:.2f} handovers per flight (CHM {chm['handovers']:.2f}); at the DQN's "
        f"{dqn['handovers']:.2f} it reaches {dqn['bound_rsrq_at_handovers']:.1f} % (DQN {dqn['rsrq_pct']:.1f} %). "
        "The bound knows each flight's future: the gap to it is what prediction could win, not what physics forbids."
    )
    return caption, Path(frontier_figure(data, Path(out) / "frontier.png"))


def altitude_figure(
    out: Path, real: str, cfg, flights, chm_real: list[int], seed: int, n_flights: int = 40
) -> tuple[str, Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .real_data import baltaci_rate_by_altitude

    alts = np.arange(20, 161, 20)
    fig, ax = plt.subplots(figsize=(7.5, 4.5))
    ax.plot(
        alts,
        chm_rate_by_altitude(alts, cfg, n_flights=n_flights, seed=seed),
        "o-",
        label="simulator, CHM (A3 2 dB / 160 ms)",
    )
    long = [(f, n) for f, n in zip(flights, chm_real) if f.t[-1] > 60]
    ax.plot(
        [f.altitude_m for f, _ in long], [n / (f.t[-1] / 60) for f, n in long], "x", label="CHM on the UKM measurements"
    )
    ax.plot(
        [f.altitude_m for f, _ in long],
        [f.observed_handovers / (f.t[-1] / 60) for f, _ in long],
        "s",
        label="UKM flights, live network (nominal height)",
    )
    baltaci = next(
        (
            p / "baltaci-imc22-handovers"
            for p in Path(real).resolve().parents
            if (p / "baltaci-imc22-handovers" / "handovers.csv").is_file()
        ),
        None,
    )
    caption = "Handover rate vs altitude"
    if baltaci is not None:
        bins, rate, n = baltaci_rate_by_altitude(baltaci)
        ax.plot(bins + 5, rate, "^-", label=f"Baltaci et al. IMC'22 flights ({n} handovers, per modem)")
        caption += f" (Baltaci et al. data: the folder {baltaci.name} beside the real flights)"
    ax.set_xlabel("height (m)")
    ax.set_ylabel("handovers per minute")
    ax.legend(fontsize=8)
    fig.tight_layout()
    path = Path(out) / "handover_rate_vs_altitude.png"
    xairl.plugin.save_figure(fig, path, dpi=90)
    plt.close(fig)
    return caption, path


def frontier_figure(data: dict, path) -> str:
    """The frontier of ``data`` (benchmarks/oracle_frontier.py's frontier.json) with the receding horizons and each
    policy's place, as a PNG at ``path``; returns the path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    ax.plot(data["frontier"]["handovers"], data["frontier"]["rsrq_pct"], "k-o", ms=3, label="hindsight bound")
    for h, pts in data.get("receding", {}).items():
        ax.plot(pts["handovers"], pts["rsrq_pct"], "--.", lw=1, label=f"{h} s of foresight")
    policies = data.get("policies", {})
    for (name, p), marker in zip(policies.items(), "s^Dvp", strict=False):
        ax.plot(p["handovers"], p["rsrq_pct"], marker, ms=8, label=name)
    seen = [p["rsrq_pct"] for p in policies.values()] + data["frontier"]["rsrq_pct"]
    ax.set_ylim(0.9 * min(seen), 2.5 * max([p["rsrq_pct"] for p in policies.values()] or seen))
    ax.set_xlabel("handovers per flight (mean)")
    ax.set_ylabel("time below the RSRQ threshold (%)")
    ax.set_title(f"What hindsight allows: {data.get('flights', '?')} held-out flights")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return str(path)
