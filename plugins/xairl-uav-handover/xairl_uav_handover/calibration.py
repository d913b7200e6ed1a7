"""The simulator and the DQN against the real flights: handover rates per altitude band (live network, CHM replayed
on the measurements, CHM simulated), real states outside the simulated distribution and their quantiles, and
open-loop agreement of each policy with the live network's decisions. The report (report.py) shows them as tables.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .baselines import CHMOnSamples, SAMROOnSamples
from .evaluate import chm_rate_by_altitude, held_at
from .features import FEATURES, RSRP, RSRQ
from .memory import walk_states
from .policy import Checkpoint, greedy, memory_of

BANDS = ((20.0, 60.0), (60.0, 100.0), (100.0, 160.0))
#: median interval between the real UKM logs' samples (s): CHM replayed on them sees the measurements this often
LOG_INTERVAL_S = 1.28


@dataclass
class BandRow:
    """Handovers per minute in one altitude band: the live network, CHM replayed on its measurements, CHM simulated."""

    band: str
    flights: int
    live_per_min: float
    chm_real_per_min: float
    chm_sim_per_min: float
    chm_sim_sampled_per_min: float  # CHM on the simulated measurements sampled as the real logs are
    sim_over_real: float  # the sampled one over the real one: like for like

    HEADER = [
        "altitude band",
        "real flights",
        "live network HO/min",
        "CHM on the real measurements HO/min",
        "CHM simulated HO/min (every 40 ms)",
        "CHM simulated HO/min (every 1.28 s, as the logs)",
        "simulated (1.28 s) / real CHM",
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


def band_rows(
    flights, chm_real: list[int], cfg, seed: int, n_flights: int = 40, duration_s: float = 60.0
) -> list[BandRow]:
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
        sim = chm_rate_by_altitude(heights, cfg, n_flights, duration_s, seed=seed)
        sim = float(np.average(sim, weights=weight))
        sampled = chm_rate_by_altitude(heights, cfg, n_flights, duration_s, seed=seed, sample_s=LOG_INTERVAL_S)
        sampled = float(np.average(sampled, weights=weight))
        rows.append(BandRow(f"{lo:g}-{hi:g} m", len(inside), live, real, sim, sampled, sampled / max(real, 1e-9)))
    return rows


def outside(real: np.ndarray, sim: np.ndarray) -> np.ndarray:
    """(n, features): where a real state's feature lies outside the simulated 0.5-99.5 percentile range."""
    lo, hi = np.percentile(sim, [0.5, 99.5], axis=0)
    return (real < lo) | (real > hi)


def quantile_rows(sim: np.ndarray, real: np.ndarray, names=FEATURES) -> list[QuantileRow]:
    """One row per feature (``names``, the columns of ``sim`` and ``real``)."""
    ps, pr = np.percentile(sim, [5, 50, 95], axis=0), np.percentile(real, [5, 50, 95], axis=0)
    out = 100 * outside(real, sim).mean(axis=0)
    return [QuantileRow(f, *ps[:, j], *pr[:, j], out[j]) for j, f in enumerate(names)]


def agreement_rows(walks, ckpt: Checkpoint, cfg, mro: dict | None = None) -> list[AgreementRow]:
    """One row per policy (the DQN, CHM, SA-MRO) proposing at every real sample (open loop). ``mro``: a dict that
    receives what SA-MRO's network did on the walks: the events it counted (too early, too late, wrong cell,
    ping-pong), its offsets' updates and largest offset (dB), which say why its row may equal CHM's."""
    from .real_data import agreement

    networks = []

    def samro(walk):
        networks.append(SAMROOnSamples(walk.cells, cfg))
        return networks[-1]

    def dqn(walk):  # the DQN's action at every sample of the walk in one batch (with memory: its windows)
        states = walk_states(walk, cfg) if memory_of(ckpt.meta) else walk.states
        actions = dict(zip(walk.t.tolist(), greedy(ckpt.net, states, cfg).tolist()))
        return lambda s, c, t: actions[t]

    rows = []
    for name, make in (
        ("DQN", dqn),
        ("CHM (A3 2 dB, 160 ms)", lambda w: CHMOnSamples(w.cells)),
        ("SA-MRO", samro),
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
    if mro is not None:
        mro.update(mro_record(networks))
    return rows


def mro_record(networks) -> dict:
    """What SA-MRO networks did (:class:`baselines.SAMROOnSamples` after their walks): the events counted over all,
    their offsets' updates, and the largest offset any pair reached (dB beyond CHM's)."""
    counted = {k: sum(n.mro.counted[k] for n in networks) for k in ("too_early", "too_late", "wrong_cell", "pingpong")}
    updates = sum(n.updates for n in networks)
    largest = max((float(np.abs(n.mro.cio).max()) for n in networks if n.mro.cio.size), default=0.0)
    return {"counted": counted, "updates": updates, "largest_offset_db": largest}


def rsrq_spread(states: np.ndarray, measured: np.ndarray, resolution_db: float = 1.0) -> np.ndarray:
    """Per state with at least two measured candidates (``measured`` (n, 4) bool): the spread (max - min) over
    them of RSRQ - RSRP, after rounding both to ``resolution_db`` as the real flights' logs report them. A spread
    of 0 means RSRQ is RSRP plus one offset common to every cell, so the two carry the same information."""
    rsrp, rsrq = states[:, RSRP].astype(float), states[:, RSRQ].astype(float)
    if resolution_db > 0:
        rsrp, rsrq = np.round(rsrp / resolution_db) * resolution_db, np.round(rsrq / resolution_db) * resolution_db
    d = np.where(measured, rsrq - rsrp, np.nan)
    keep = np.isfinite(d).sum(axis=1) >= 2
    return (np.nanmax(d[keep], axis=1) - np.nanmin(d[keep], axis=1)) if keep.any() else np.zeros(0)


def split_flights(flights) -> tuple[list, list]:
    """The real flights in two halves by name (every other one in sorted order): one to fit on, one held out."""
    ordered = sorted(flights, key=lambda f: f.name)
    return ordered[0::2], ordered[1::2]


def serving_rsrp_median(cfg, altitudes, n_flights: int = 40, seconds: float = 60.0, seed: int = 0) -> float:
    """Median serving RSRP (dBm, as reported) of simulated CHM flights held at each of ``altitudes`` (the real
    flights' heights, one batch each), sampled once a second."""
    from .baselines import CHM
    from .env import HandoverVecEnv

    values = []
    for h in altitudes:
        env = HandoverVecEnv(held_at(cfg, h, seconds), n_flights, decision_every=1)
        env.reset(seed=seed)
        chm = CHM()
        chm.reset(env)
        k = np.arange(n_flights)
        for i in range(int(seconds / cfg.flight.dt_s)):
            env.step(chm(env))
            if i % 25 == 24:
                values.append(env.sim.meas_rsrp[k, env.sim.serving].copy())
    return float(np.median(np.concatenate(values)))


def link_loss_fit(flights, cfg, seed: int = 0) -> dict[str, float]:
    """``RadioConfig.link_loss_db`` fitted on half of the real flights (:func:`split_flights`): the loss that puts
    the simulated serving RSRP's median at theirs (RSRP moves one for one with it); and the other half's median
    against the simulator's at the fitted loss, the held-out check."""
    fit, held = split_flights(flights)
    real_fit = float(np.median(np.concatenate([f.rsrp for f in fit])))
    sim_fit = serving_rsrp_median(cfg, sorted({f.altitude_m for f in fit}), seed=seed)
    loss = cfg.radio.link_loss_db + sim_fit - real_fit
    data = cfg.model_dump()
    data["radio"]["link_loss_db"] = loss
    fitted = type(cfg).model_validate(data)
    return {
        "link_loss_db": loss,
        "real_fit_median": real_fit,
        "real_held_out_median": float(np.median(np.concatenate([f.rsrp for f in held]))),
        "sim_held_out_median": serving_rsrp_median(fitted, sorted({f.altitude_m for f in held}), seed=seed + 1),
    }
