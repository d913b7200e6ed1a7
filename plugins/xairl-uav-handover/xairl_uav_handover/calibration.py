"""The simulator and the DQN against the real flights: handover rates per altitude band (live network, CHM replayed
on the measurements, CHM simulated), real states outside the simulated distribution and their quantiles, and
open-loop agreement of each policy with the live network's decisions. The report (report.py) shows them as tables.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .baselines import CHMOnSamples, SAMROOnSamples
from .evaluate import chm_rate_by_altitude
from .features import FEATURES
from .policy import Checkpoint, greedy

BANDS = ((20.0, 60.0), (60.0, 100.0), (100.0, 160.0))


@dataclass
class BandRow:
    """Handovers per minute in one altitude band: the live network, CHM replayed on its measurements, CHM simulated."""

    band: str
    flights: int
    live_per_min: float
    chm_real_per_min: float
    chm_sim_per_min: float
    sim_over_real: float

    HEADER = [
        "altitude band",
        "real flights",
        "live network HO/min",
        "CHM on the real measurements HO/min",
        "CHM simulated HO/min",
        "simulated / real CHM",
    ]


@dataclass
class AgreementRow:
    """A policy's proposals against the live network's decisions at the same instants (open loop)."""

    policy: str
    proposals_per_min: float
    new_proposals_per_min: float
    network_per_min: float
    stay_agreement_pct: float
    handover_agreement_pct: float
    target_agreement_pct: float

    HEADER = [
        "policy",
        "instants proposing a HO, per min",
        "new HO proposals/min (a standing one counted once)",
        "network HO/min",
        "stays when the network stays %",
        "proposes a HO where the network handed over %",
        "same target cell %",
    ]


@dataclass
class QuantileRow:
    """One feature's distribution in simulation (the states training sees) and in the real flights."""

    feature: str
    sim_p5: float
    sim_p50: float
    sim_p95: float
    real_p5: float
    real_p50: float
    real_p95: float
    real_outside_pct: float

    HEADER = [
        "feature",
        "sim p5",
        "sim p50",
        "sim p95",
        "real p5",
        "real p50",
        "real p95",
        "real states outside sim 0.5-99.5 % range",
    ]


def band_rows(flights, chm_real: list[int], cfg, seed: int) -> list[BandRow]:
    """One row per altitude band with flights; ``chm_real``: CHM's closed-loop handovers on each flight. Simulated
    CHM flies at the band's real flights' own heights, weighted by their minutes, so both sides cover one mix."""
    rows = []
    for lo, hi in BANDS:
        inside = [(f, n) for f, n in zip(flights, chm_real) if lo <= f.altitude_m < hi]
        if not inside:
            continue
        minutes = np.array([f.t[-1] / 60 for f, _ in inside])
        live = sum(f.observed_handovers for f, _ in inside) / minutes.sum()
        real = sum(n for _, n in inside) / minutes.sum()
        heights, where = np.unique([f.altitude_m for f, _ in inside], return_inverse=True)
        weight = np.bincount(where, weights=minutes)
        sim = float(np.average(chm_rate_by_altitude(heights, cfg, seed=seed), weights=weight))
        rows.append(BandRow(f"{lo:g}-{hi:g} m", len(inside), live, real, sim, sim / max(real, 1e-9)))
    return rows


def outside(real: np.ndarray, sim: np.ndarray) -> np.ndarray:
    """(n, 13): where a real state's feature lies outside the simulated 0.5-99.5 percentile range."""
    lo, hi = np.percentile(sim, [0.5, 99.5], axis=0)
    return (real < lo) | (real > hi)


def quantile_rows(sim: np.ndarray, real: np.ndarray) -> list[QuantileRow]:
    ps, pr = np.percentile(sim, [5, 50, 95], axis=0), np.percentile(real, [5, 50, 95], axis=0)
    out = 100 * outside(real, sim).mean(axis=0)
    return [QuantileRow(f, *ps[:, j], *pr[:, j], out[j]) for j, f in enumerate(FEATURES)]


def agreement_rows(walks, ckpt: Checkpoint, cfg) -> list[AgreementRow]:
    from .real_data import agreement

    def dqn(walk):  # the DQN keeps no state: its action at every sample of the walk in one batch
        actions = dict(zip(walk.t.tolist(), greedy(ckpt.net, walk.states, cfg).tolist()))
        return lambda s, c, t: actions[t]

    rows = []
    for name, make in (
        ("DQN", dqn),
        ("CHM (A3 2 dB, 160 ms)", lambda w: CHMOnSamples(w.cells)),
        ("SA-MRO", lambda w: SAMROOnSamples(w.cells, cfg)),
    ):
        a = agreement(walks, make)
        rows.append(
            AgreementRow(
                name,
                a.proposals_per_min,
                a.new_proposals_per_min,
                a.network_handovers / a.minutes,
                100 * a.stay_agreement,
                100 * a.handover_agreement,
                100 * a.target_agreement,
            )
        )
    return rows
