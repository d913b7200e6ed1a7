"""Real UAV flights (read and checked by :mod:`.exports`) replayed. :func:`walk` follows the network's own decisions
along a real flight and gives, at each sample, the state a policy would see (the same layout, detection limit and position frame as in simulation), its candidate cells and what the
network did next; :func:`agreement` compares a policy's proposals with those decisions (open loop: the policy never
steers, so every instant is a fair comparison). The buffer is not in the data: the simulator's uplink model
(uplink.py), driven by the measured serving RSRP, fills it, sub-stepped at the simulator's
time step between samples.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from xairl import InputError

from .buffer import buffer_steps
from .config import SimConfig
from .exports import RealFlight
from .features import FEATURES, N_CANDIDATES, checked_actions, state_rows
from .features import RSRP as RSRP_COLUMNS
from .simulator import hex_layout, n_cells
from .uplink import capacity_bps, interference_mw, rsrp_offset_db, sinr_db


@dataclass
class Walk:
    """A real flight as the network flew it, seen as a policy would see it at each sample."""

    t: np.ndarray  # (n,) seconds
    states: np.ndarray  # (n, 13)
    candidates: list[list]  # per sample: the serving PCI, then up to 3 measured neighbours by RSRP
    next_serving: np.ndarray  # (n,) the network's serving PCI at the next sample (its decision); last: itself
    queue_bits: np.ndarray  # (n,) the modelled uplink buffer
    lost_bits: float
    name: str = ""  # the flight's
    measured: list | None = None  # per sample: every measured cell's (RSRP, RSRQ), by PCI (the memory's past)
    windows: dict = field(default_factory=dict, repr=False)  # memory.walk_states, built once per setting

    @property
    def serving(self) -> np.ndarray:
        return np.array([c[0] for c in self.candidates])

    @property
    def cells(self) -> list:
        """Every cell the walk's candidates name (the columns of an A3 trigger on it)."""
        return sorted({c for cand in self.candidates for c in cand})


def _measured(f: RealFlight, i: int) -> dict[float, tuple[float, float]]:
    cells = {f.pci[i]: (f.rsrp[i], f.rsrq[i])}
    for p, r, q in zip(f.nb_pci[i], f.nb_rsrp[i], f.nb_rsrq[i]):
        if np.isfinite(p) and np.isfinite(r) and np.isfinite(q) and p not in cells:
            cells[p] = (r, q)
    return cells


class UplinkBuffer:
    """The simulator's buffer and uplink model on a real flight: SINR from the measured serving RSRP (path loss =
    RSRP offset - RSRP, power control on it) with the interference of one uplink drop of the simulated layout
    (uplink.py), sub-stepped at the sim's dt. Each real cell gets the interference of a cell of that drop drawn at
    random (once per cell and flight), so real and simulated links share one distribution.

    :param altitude_m: the flight's height; unused since issue 53 (the interference at a cell comes from the other
        cells' UEs, not from the UAV's height), kept so callers need not change.
    :param flight: the flight's name: each flight draws its own cells' levels.
    """

    def __init__(self, cfg: SimConfig, altitude_m: float, seed: int = 0, flight: str = ""):
        self.cfg, self.rng, self.q, self.lost = cfg, np.random.default_rng(seed), 0.0, 0.0
        self._cell_rng, self._interference = np.random.default_rng([seed, zlib.crc32(flight.encode())]), {}
        layout = hex_layout(cfg.layout.isd_m, cfg.layout.rings)
        self.cell_interference = interference_mw(cfg, layout, self._cell_rng, 1)[
            0
        ]  # (N,) mW per resource block, per cell

    def sinr_db(self, rsrp_dbm: float, cell) -> float:
        if cell not in self._interference:
            drawn = self._cell_rng.integers(len(self.cell_interference))
            self._interference[cell] = float(self.cell_interference[drawn])
        return float(sinr_db(self.cfg, rsrp_offset_db(self.cfg) - rsrp_dbm, self._interference[cell]))

    def advance(self, rsrp_dbm: float, cell, seconds: float, handed: bool) -> None:
        """Serve the buffer for ``seconds`` at the link of serving ``cell`` measured at ``rsrp_dbm``."""
        b, dt = self.cfg.buffer, self.cfg.flight.dt_s
        rate = float(capacity_bps(self.cfg, self.sinr_db(rsrp_dbm, cell)))
        interrupt = self.cfg.handover.interruption_s if handed else 0.0
        steps = int(round(seconds / dt))
        arrivals = (self.rng.poisson(b.packet_rate_hz * dt, size=steps) * b.data_packet_bits).tolist()
        if handed and steps:
            arrivals[0] += b.control_packet_bits
        served = [rate * dt if k * dt >= interrupt else 0.0 for k in range(steps)]
        self.q, self.lost = buffer_steps(self.q, self.lost, arrivals, served, b.q_max_bits)


def _candidates(cells: dict, serving, cfg: SimConfig) -> list:
    """The serving cell, then up to 3 neighbours measured above the detection limit, strongest RSRP first."""
    detected = [p for p in cells if p != serving and cells[p][1] > cfg.observation.detection_rsrq_db]
    return [serving] + sorted(detected, key=lambda p: -cells[p][0])[: N_CANDIDATES - 1]


def walk(f: RealFlight, config: SimConfig | None = None, seed: int = 0) -> Walk:
    """The network's own path along ``f`` with the state a policy would see at each sample (see the module doc)."""
    cfg = config or SimConfig()
    ids = {p: k for k, p in enumerate(sorted(set(f.pci.tolist())))}
    max_id = n_cells(cfg.layout) - 1  # the simulator's ids: a real flight's cells are ranked into that range
    link = UplinkBuffer(cfg, f.altitude_m, seed, f.name)
    states, cands, queues, measured = [], [], [], []
    for i in range(len(f.t)):
        cells = _measured(f, i)
        measured.append(cells)
        serving = f.pci[i]
        cand = _candidates(cells, serving, cfg)
        pad = [np.nan] * (N_CANDIDATES - len(cand))
        states.append(
            state_rows(
                [*f.xy[i], f.altitude_m],
                link.q,
                min(ids[serving], max_id),
                [cells[p][0] for p in cand] + pad,
                [cells[p][1] for p in cand] + pad,
                cfg.observation,
            )[0]
        )
        cands.append(cand)
        queues.append(link.q)
        if i + 1 < len(f.t):
            link.advance(f.rsrp[i], serving, float(np.clip(f.t[i + 1] - f.t[i], 0, 5)), f.pci[i + 1] != serving)
    states = np.array(states)
    bad = ~np.isfinite(states)
    if bad.any():  # finite measurements beyond float32 (the states' type)
        i, j = (int(k[0]) for k in np.nonzero(bad))
        raise InputError(
            f"{f.name}: the state at sample {i} has {FEATURES[j]} = {states[i, j]:g} (float32), not a "
            "finite number; fix that measurement."
        )
    next_serving = np.append(f.pci[1:], f.pci[-1])
    return Walk(f.t, states, cands, next_serving, np.array(queues), link.lost, f.name, measured)


def chm_handovers(f: RealFlight, config=None, sim_config: SimConfig | None = None) -> int:
    """Changes of serving cell of CHM flown closed-loop along the real measurements: A3 (:class:`CHMOnSamples`) on
    the samples' time stamps over CHM's own serving cell and its measured neighbours; a serving cell that is no
    longer measured is left for the strongest one measured (counted too). The count to compare with simulated CHM."""
    from .baselines import CHMOnSamples

    cfg = sim_config or SimConfig()
    chm = CHMOnSamples(f.cells, config)
    serving, changes = f.pci[0], 0
    for i in range(len(f.t)):
        cells = _measured(f, i)
        if serving not in cells:
            serving, changes = max(cells, key=lambda p: cells[p][0]), changes + 1
        cand = _candidates(cells, serving, cfg)
        state = np.full(len(FEATURES), np.nan)
        state[RSRP_COLUMNS.start : RSRP_COLUMNS.start + len(cand)] = [cells[p][0] for p in cand]
        target = cand[chm(state, cand, float(f.t[i]))]
        if target != serving:
            serving, changes = target, changes + 1
    return changes


@dataclass
class Agreement:
    """A policy's proposals against the network's decisions at the same instants (open loop)."""

    instants: int
    network_handovers: int
    proposals: int  # instants at which the policy proposed a handover
    new_proposals: int  # of those, the ones that start a proposal (not the one of the instant before)
    stay_agreement: float  # share of the network's stays where the policy also stayed
    handover_agreement: float  # share of the network's handovers where the policy proposed one
    target_agreement: float  # share of the network's handovers where the policy proposed the same cell
    minutes: float

    @property
    def proposals_per_min(self) -> float:
        return self.proposals / max(self.minutes, 1e-9)

    @property
    def new_proposals_per_min(self) -> float:
        """Open loop, a proposal the network does not carry out stands at every later instant until the policy
        changes its mind; counted once, as A3 counts one trigger, it is comparable with the network's handovers."""
        return self.new_proposals / max(self.minutes, 1e-9)


def agreement(walks: list[Walk], make_decider) -> Agreement:
    """Open-loop agreement over flights: ``make_decider(walk)`` returns ``decide(state, candidates, t) -> action``
    (a fresh one per flight, for rules with timers)."""
    n = ho = prop = new = stay_ok = ho_ok = target_ok = 0
    minutes = 0.0
    for w in walks:
        decide = make_decider(w)
        minutes += (w.t[-1] - w.t[0]) / 60
        standing = None  # (serving, proposed target) of the instant before
        for i in range(len(w.t) - 1):
            cand = w.candidates[i]
            a = decide(w.states[i], cand, float(w.t[i]))
            if type(a) is not int or not 0 <= a < N_CANDIDATES:  # a NaN must not be cast to some action
                a = int(
                    checked_actions([a], lambda _, i=i, w=w: f"sample {i} (t = {w.t[i]:g} s) of {w.name or 'a walk'}")[
                        0
                    ]
                )
            target = cand[a] if a < len(cand) else cand[0]
            net_ho = w.next_serving[i] != cand[0]
            proposes = target != cand[0]
            n, ho, prop = n + 1, ho + net_ho, prop + proposes
            new += proposes and standing != (cand[0], target)
            standing = (cand[0], target) if proposes else None
            stay_ok += (not net_ho) and not proposes
            ho_ok += net_ho and proposes
            target_ok += net_ho and target == w.next_serving[i]
    return Agreement(n, ho, prop, new, stay_ok / max(n - ho, 1), ho_ok / max(ho, 1), target_ok / max(ho, 1), minutes)


def baltaci_rate_by_altitude(folder: str | Path) -> tuple[np.ndarray, np.ndarray, int]:
    """Handovers per minute per modem in 10 m height bins from the Baltaci et al. IMC'22 handover events.

    Returns (bin lower edges, rate, events used). Time per bin comes from ``altitude-bin-durations.csv`` (seconds
    per campaign day, most likely), counted once per operator that flew that day.
    """
    import pandas as pd

    folder = Path(folder)
    try:
        ev = pd.read_csv(folder / "handovers.csv")
        dur = pd.read_csv(folder / "altitude-bin-durations.csv")
    except (OSError, ValueError) as exc:
        raise InputError(f"{folder}: cannot read the handover events ({str(exc).splitlines()[0]}).") from None
    for col in ("flight_ts", "relative_height"):
        if col not in ev.columns:
            raise InputError(f"{folder / 'handovers.csv'}: missing column '{col}'.")
    ev = ev.dropna(subset=["relative_height"])
    ev["day"] = ev["flight_ts"].str.rsplit("-", n=1).str[0]
    ev["bin"] = (ev["relative_height"] // 10 * 10).clip(upper=120)
    operators = ev.groupby("day")["flight_ts"].nunique()
    bins = dur["Altitude"].to_numpy(dtype=float)
    modem_s = np.zeros(len(bins))
    for day in operators.index:
        if day in dur.columns:
            modem_s += dur[day].to_numpy(dtype=float) * operators[day]
    counts = ev[ev["day"].isin(dur.columns)].groupby("bin").size().reindex(bins, fill_value=0).to_numpy()
    return bins, counts / np.maximum(modem_s / 60.0, 1e-9), int(counts.sum())
