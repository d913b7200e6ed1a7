"""Real UAV flights from drive-test exports (Nemo "Exported Measurements", like ../shared/data/ukm-uav-lte/raw).

Rows are events; rows with the same Time form one time step (forward-filled over two steps for the sparse neighbour
lists and SNR). The last lines are a footer and are dropped (any row whose Time does not parse). The number of
detected-cell slots varies, so columns are selected by name. Altitude is the nominal height in the file name.

:func:`walk` follows the network's own decisions along a real flight and gives, at each sample, the state a policy
would see (the same layout, detection limit and position frame as in simulation), its candidate cells and what the
network did next; :func:`agreement` compares a policy's proposals with those decisions (open loop: the policy never
steers, so every instant is a fair comparison). The buffer is not in the data: the simulator's uplink model
(uplink.py), driven by the measured serving RSRP at the flight's altitude, fills it, sub-stepped at the simulator's
time step between samples.
"""

from __future__ import annotations

import re
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from xairl import InputError

from .buffer import buffer_step
from .config import SimConfig
from .features import FEATURES, N_CANDIDATES, checked_actions, state_rows
from .features import RSRP as RSRP_COLUMNS
from .simulator import hex_layout, n_sites
from .uplink import capacity_bps, cell_deviation, interference_mw, rsrp_offset_db, sinr_db

REF_LAT, REF_LON = 2.9228, 101.7715  # centre of the UKM campaign area: local metres are measured from here
PCI, RSRP, RSRQ = "Physical cell identity (LTE pcell)", "RSRP (LTE pcell)", "RSRQ (LTE pcell)"
REQUIRED = ("Time", "Latitude", "Longitude", PCI, RSRP, RSRQ, "RS SNR")
TIME_RE = r"^\d{1,2}:\d{2}:\d{2}(\.\d+)?$"


@dataclass
class RealFlight:
    name: str
    altitude_m: float
    t: np.ndarray  # seconds since the first sample
    xy: np.ndarray  # (n, 2) local metres east/north of REF
    pci: np.ndarray  # (n,) serving PCI
    rsrp: np.ndarray
    rsrq: np.ndarray
    snr: np.ndarray
    nb_pci: np.ndarray  # (n, slots) detected cells, NaN where empty
    nb_rsrp: np.ndarray
    nb_rsrq: np.ndarray

    def __post_init__(self):
        """A flight built in code is checked as a loaded one: every measurement finite (a neighbour slot may be
        empty, NaN), so that no policy acts on an infinite state."""
        for field in ("t", "xy", "pci", "rsrp", "rsrq", "snr", "nb_pci", "nb_rsrp", "nb_rsrq"):
            v = np.asarray(getattr(self, field), dtype=float)
            bad = np.isinf(v) if field.startswith("nb_") else ~np.isfinite(v)
            if bad.any():
                i = int(np.nonzero(bad)[0][0])
                raise InputError(
                    f"{self.name}: the flight's {field} is {v[np.nonzero(bad)][0]:g} at sample {i}, "
                    "not a finite number; measurements must be finite."
                )

    @property
    def observed_handovers(self) -> int:
        return int((np.diff(self.pci) != 0).sum())

    @property
    def cells(self) -> list[float]:
        """Every cell measured on the flight (serving or detected), sorted."""
        return sorted(set(self.pci.tolist()) | {p for p in self.nb_pci.ravel().tolist() if np.isfinite(p)})


def load_flight(path: str | Path) -> RealFlight:
    """One export file; a malformed one raises :class:`InputError` naming the file and the column."""
    path = Path(path)
    alt = re.match(r"(\d+(?:\.\d+)?)m", path.stem)
    if not alt:
        raise InputError(f"{path}: the nominal altitude is read from the file name (e.g. 100m.csv); rename it.")
    df, slots = _read_export(path)
    g = _time_steps(df, slots, path)
    t = g.index.to_numpy(dtype=float)
    t = np.where(t < t[0], t + 86400, t) - t[0]  # a flight over midnight
    lat, lon = g["Latitude"].to_numpy(), g["Longitude"].to_numpy()
    xy = np.stack([(lon - REF_LON) * 111_320.0 * np.cos(np.radians(REF_LAT)), (lat - REF_LAT) * 110_574.0], 1)

    def nb(kind):
        cols = [f"{kind} (LTE detected) - {s}" for s in slots]
        return (
            np.stack([g[c].to_numpy(dtype=float) if c in g.columns else np.full(len(g), np.nan) for c in cols], 1)
            if cols
            else np.full((len(g), 0), np.nan)
        )

    snr = g["RS SNR"].to_numpy(dtype=float)
    snr = np.where(np.isnan(snr), np.nanmedian(snr) if np.isfinite(snr).any() else 0.0, snr)
    return RealFlight(
        path.name,
        float(alt.group(1)),
        t,
        xy,
        g[PCI].to_numpy(dtype=float),
        g[RSRP].to_numpy(float),
        g[RSRQ].to_numpy(float),
        snr,
        nb("Physical cell identity"),
        nb("RSRP"),
        nb("RSRQ"),
    )


def _read_export(path: Path):
    """The export's event rows with a parseable Time, numeric columns as numbers, and its detected-cell slots."""
    import pandas as pd

    try:
        df = pd.read_csv(path, low_memory=False, dtype={"Time": str}, skip_blank_lines=False)  # index + 2: line
    except (OSError, ValueError, pd.errors.ParserError) as exc:
        raise InputError(f"{path}: cannot read it as CSV ({str(exc).splitlines()[0]}).") from None
    missing = [c for c in REQUIRED if c not in df.columns]
    if missing:
        raise InputError(
            f"{path}: missing column '{missing[0]}'"
            + (f" (and {len(missing) - 1} more)" if len(missing) > 1 else "")
            + "."
        )
    df["Time"] = df["Time"].astype(str).str.strip()
    df = df[df["Time"].str.match(TIME_RE)].copy()
    if df.empty:
        raise InputError(f"{path}: no rows with a parseable Time (H:MM:SS.mmm); the file looks truncated.")
    slots = sorted(
        int(m.group(1))
        for c in df.columns
        if (
            m := re.match(
                r"Physical cell identity \(LTE detected\) - "
                r"(\d+)$",
                c,
            )
        )
    )
    for c in ["Latitude", "Longitude", PCI, RSRP, RSRQ, "RS SNR", *_neighbour_columns(slots, df.columns)]:
        df[c] = pd.to_numeric(df[c], errors="coerce")
    _check_measurements(df, path)
    return df, slots


#: per measurement: (lowest, highest) a UE can report, with a margin (TS 36.133: RSRP -156..-31 dBm, RSRQ -34..2.5
#: dB, SINR -23..40 dB; 504 PCIs in LTE, 1008 in NR): a value outside is a broken file, and as float32 it would
#: reach the DQN as inf; the unit; and the range of a column's median in that unit (outside: wrong units)
PLAUSIBLE = {
    "RSRP": (-200.0, 0.0, "dBm", (-160.0, -20.0)),
    "RSRQ": (-60.0, 20.0, "dB", (-40.0, 0.0)),
    "RS SNR": (-50.0, 60.0, "dB", (-50.0, 60.0)),
    "Physical cell identity": (0.0, 1007.0, "", (0.0, 1007.0)),
    "Latitude": (-90.0, 90.0, "deg", (-90.0, 90.0)),
    "Longitude": (-180.0, 180.0, "deg", (-180.0, 180.0)),
}


def _check_measurements(df, path: Path) -> None:
    """Refuse a column in other units (its median outside what a UE reports), then the first row (by its line in
    the file) with a non-finite or physically impossible measurement; an empty cell is a measurement not taken and
    stays (NaN)."""
    first = None
    for col in df.columns:
        kind = next((k for k in PLAUSIBLE if col == k or col.startswith(f"{k} (")), None)
        if kind is None:
            continue
        lo, hi, unit, (med_lo, med_hi) = PLAUSIBLE[kind]
        unit = f" {unit}" if unit else ""
        v = df[col].to_numpy(dtype=float)
        med = np.median(v[np.isfinite(v)]) if np.isfinite(v).any() else med_lo
        if not med_lo <= med <= med_hi:
            raise InputError(
                f"{path}: column '{col}' has median {med:g}, outside {med_lo:g}..{med_hi:g}{unit}; wrong units?"
            )
        bad = ~np.isnan(v) & ~((v >= lo) & (v <= hi))  # inf and -inf fail the range too
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            line = int(df.index[k]) + 2  # the header is line 1; blank lines were kept, so the index counts lines
            if first is None or line < first[0]:
                first = (line, col, float(v[k]), lo, hi, unit)
    if first is not None:
        line, col, value, lo, hi, unit = first
        what = (
            f"a non-finite number ({value:g})"
            if not np.isfinite(value)
            else f"{value:g}, outside the {lo:g}..{hi:g}{unit} a UE reports"
        )
        raise InputError(f"{path}: line {line}: column '{col}' holds {what}; fix or delete that row.")


def _neighbour_columns(slots: list[int], present) -> list[str]:
    return [
        c
        for s in slots
        for k in ("Physical cell identity", "RSRP", "RSRQ")
        if (c := f"{k} (LTE detected) - {s}") in present
    ]


def _time_steps(df, slots: list[int], path: Path):
    """One row per time stamp (sparse columns forward-filled over two steps), with a serving cell and a position."""
    hms = df["Time"].str.split(":", expand=True).astype(float)
    df["_t"] = hms[0] * 3600 + hms[1] * 60 + hms[2]
    g = df.groupby("_t", sort=True).first()
    fill = ["Latitude", "Longitude", "RS SNR", *_neighbour_columns(slots, g.columns)]
    g[fill] = g[fill].ffill(limit=2)
    g = g[g[PCI].notna() & g[RSRP].notna() & g[RSRQ].notna() & g["Latitude"].notna() & g["Longitude"].notna()]
    if len(g) < 2:
        raise InputError(f"{path}: fewer than 2 time steps with a serving cell ('{PCI}').")
    return g  # (each column's values and median were checked on the file's rows: _check_measurements)


def load_folder(folder: str | Path) -> tuple[list[RealFlight], list[str]]:
    """Every *.csv under ``folder``: (flights that loaded, one-line reasons for the files that did not)."""
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(f"{folder}: no such folder of flight exports.")
    flights, bad = [], []
    for f in sorted(folder.rglob("*.csv")):
        try:
            flights.append(load_flight(f))
        except InputError as exc:
            bad.append(str(exc))
    if not flights:
        raise InputError(
            f"{folder}: no loadable flight export ({len(bad)} bad file(s)); first: "
            f"{bad[0] if bad else 'no *.csv files'}"
        )
    return flights, bad


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
    RSRP offset - RSRP) with the aerial interference at the flight's altitude, sub-stepped at the sim's dt. Each
    real cell gets the interference level of a cell of the simulated layout drawn at random, times its own deviation
    (once per cell and flight, as the simulator draws them), so real and simulated links share one distribution.

    :param flight: the flight's name: each flight draws its own cells' levels.
    """

    def __init__(self, cfg: SimConfig, altitude_m: float, seed: int = 0, flight: str = ""):
        self.cfg, self.rng, self.q, self.lost = cfg, np.random.default_rng(seed), 0.0, 0.0
        self._cell_rng, self._interference = np.random.default_rng([seed, zlib.crc32(flight.encode())]), {}
        layout = hex_layout(cfg.layout.isd_m, cfg.layout.rings)
        self.site_interference = interference_mw(cfg, layout, np.array([altitude_m]))[0]  # (N,) mW per site

    def sinr_db(self, rsrp_dbm: float, cell) -> float:
        if cell not in self._interference:
            site = self._cell_rng.integers(len(self.site_interference))
            deviation = cell_deviation(self.cfg, self._cell_rng, ())
            self._interference[cell] = float(self.site_interference[site] * deviation)
        return float(sinr_db(self.cfg, rsrp_offset_db(self.cfg) - rsrp_dbm, self._interference[cell]))

    def advance(self, rsrp_dbm: float, cell, seconds: float, handed: bool) -> None:
        """Serve the buffer for ``seconds`` at the link of serving ``cell`` measured at ``rsrp_dbm``."""
        b, dt = self.cfg.buffer, self.cfg.flight.dt_s
        rate = float(capacity_bps(self.cfg, self.sinr_db(rsrp_dbm, cell)))
        interrupt = self.cfg.handover.interruption_s if handed else 0.0
        for k in range(int(round(seconds / dt))):
            arrivals = self.rng.poisson(b.packet_rate_hz * dt) * b.data_packet_bits
            arrivals += b.control_packet_bits if handed and k == 0 else 0.0
            served = rate * dt if k * dt >= interrupt else 0.0
            q, lost = buffer_step(self.q, arrivals, served, b.q_max_bits)
            self.q, self.lost = float(q), self.lost + float(lost)


def _candidates(cells: dict, serving, cfg: SimConfig) -> list:
    """The serving cell, then up to 3 neighbours measured above the detection limit, strongest RSRP first."""
    detected = [p for p in cells if p != serving and cells[p][1] > cfg.observation.detection_rsrq_db]
    return [serving] + sorted(detected, key=lambda p: -cells[p][0])[: N_CANDIDATES - 1]


def walk(f: RealFlight, config: SimConfig | None = None, seed: int = 0) -> Walk:
    """The network's own path along ``f`` with the state a policy would see at each sample (see the module doc)."""
    cfg = config or SimConfig()
    ids = {p: k for k, p in enumerate(sorted(set(f.pci.tolist())))}
    max_id = n_sites(cfg.layout) - 1  # the simulator's ids: a real flight's cells are ranked into that range
    link = UplinkBuffer(cfg, f.altitude_m, seed, f.name)
    states, cands, queues = [], [], []
    for i in range(len(f.t)):
        cells = _measured(f, i)
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
    return Walk(f.t, states, cands, np.append(f.pci[1:], f.pci[-1]), np.array(queues), link.lost, f.name)


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
