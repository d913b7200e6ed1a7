"""Real UAV flights from drive-test exports (Nemo "Exported Measurements", like ../shared/data/ukm-uav-lte/raw).

Rows are events; rows with the same Time form one time step (forward-filled over two steps for the sparse neighbour
lists and SNR). The last lines are a footer and are dropped (any row whose Time does not parse). The number of
detected-cell slots varies, so columns are selected by name. Altitude is the nominal height in the file name.

:func:`replay` flies a policy along a real trajectory in closed loop: the policy's serving cell is measured when it
is the network's serving cell or in the detected list (else the UAV falls back to the strongest measured cell, a
forced handover). The buffer is not in the data: the real link quality (RS SNR of the network's serving cell,
shifted by the RSRP difference when the policy serves elsewhere) drives the plugin's buffer model.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from xairl import InputError

from .buffer import buffer_step, service_bits
from .config import SimConfig
from .features import N_CANDIDATES, state_rows
from .simulator import n_sites

REF_LAT, REF_LON = 2.9228, 101.7715  # centre of the UKM campaign area: local metres are measured from here
PCI, RSRP, RSRQ = "Physical cell identity (LTE pcell)", "RSRP (LTE pcell)", "RSRQ (LTE pcell)"
REQUIRED = ("Time", "Latitude", "Longitude", PCI, RSRP, RSRQ, "RS SNR")
PAD_RSRP, PAD_RSRQ = -140.0, -30.0  # an empty candidate slot reads as a cell far below any measured one
TIME_RE = r"^\d{1,2}:\d{2}:\d{2}(\.\d+)?$"


@dataclass
class RealFlight:
    name: str
    altitude_m: float
    t: np.ndarray          # seconds since the first sample
    xy: np.ndarray         # (n, 2) local metres east/north of REF
    pci: np.ndarray        # (n,) serving PCI
    rsrp: np.ndarray
    rsrq: np.ndarray
    snr: np.ndarray
    nb_pci: np.ndarray     # (n, slots) detected cells, NaN where empty
    nb_rsrp: np.ndarray
    nb_rsrq: np.ndarray

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
        return np.stack([g[c].to_numpy(dtype=float) if c in g.columns else np.full(len(g), np.nan) for c in cols],
                        1) if cols else np.full((len(g), 0), np.nan)

    snr = g["RS SNR"].to_numpy(dtype=float)
    snr = np.where(np.isnan(snr), np.nanmedian(snr) if np.isfinite(snr).any() else 0.0, snr)
    return RealFlight(path.name, float(alt.group(1)), t, xy, g[PCI].to_numpy(dtype=float), g[RSRP].to_numpy(float),
                      g[RSRQ].to_numpy(float), snr, nb("Physical cell identity"), nb("RSRP"), nb("RSRQ"))


def _read_export(path: Path):
    """The export's event rows with a parseable Time, numeric columns as numbers, and its detected-cell slots."""
    import pandas as pd

    try:
        df = pd.read_csv(path, low_memory=False, dtype={"Time": str})
    except (OSError, ValueError, pd.errors.ParserError) as exc:
        raise InputError(f"{path}: cannot read it as CSV ({str(exc).splitlines()[0]}).") from None
    missing = [c for c in REQUIRED if c not in df.columns]
    if missing:
        raise InputError(f"{path}: missing column '{missing[0]}'" + (f" (and {len(missing) - 1} more)" if
                                                                      len(missing) > 1 else "") + ".")
    df["Time"] = df["Time"].astype(str).str.strip()
    df = df[df["Time"].str.match(TIME_RE)].copy()
    if df.empty:
        raise InputError(f"{path}: no rows with a parseable Time (H:MM:SS.mmm); the file looks truncated.")
    slots = sorted(int(m.group(1)) for c in df.columns if (m := re.match(r"Physical cell identity \(LTE detected\) - "
                                                                          r"(\d+)$", c)))
    for c in ["Latitude", "Longitude", PCI, RSRP, RSRQ, "RS SNR", *_neighbour_columns(slots, df.columns)]:
        df[c] = pd.to_numeric(df[c], errors="coerce")
    return df, slots


def _neighbour_columns(slots: list[int], present) -> list[str]:
    return [c for s in slots for k in ("Physical cell identity", "RSRP", "RSRQ")
            if (c := f"{k} (LTE detected) - {s}") in present]


def _time_steps(df, slots: list[int], path: Path):
    """One row per time stamp (sparse columns forward-filled over two steps), with a serving cell and a position,
    in plausible units."""
    hms = df["Time"].str.split(":", expand=True).astype(float)
    df["_t"] = hms[0] * 3600 + hms[1] * 60 + hms[2]
    g = df.groupby("_t", sort=True).first()
    fill = ["Latitude", "Longitude", "RS SNR", *_neighbour_columns(slots, g.columns)]
    g[fill] = g[fill].ffill(limit=2)
    g = g[g[PCI].notna() & g[RSRP].notna() & g[RSRQ].notna() & g["Latitude"].notna()]
    if len(g) < 2:
        raise InputError(f"{path}: fewer than 2 time steps with a serving cell ('{PCI}').")
    for col, lo, hi, unit in ((RSRP, -160, -20, "dBm"), (RSRQ, -40, 0, "dB"), ("Latitude", -90, 90, "deg"),
                              ("Longitude", -180, 180, "deg")):
        med = float(g[col].median())
        if not lo <= med <= hi:
            raise InputError(f"{path}: column '{col}' has median {med:g}, outside {lo}..{hi} {unit}; wrong units?")
    return g


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
        raise InputError(f"{folder}: no loadable flight export ({len(bad)} bad file(s)); first: "
                         f"{bad[0] if bad else 'no *.csv files'}")
    return flights, bad


@dataclass
class Replay:
    states: np.ndarray      # (n, 13) the policy's view at each step
    serving: np.ndarray     # (n,) PCI served by the policy after each decision
    handovers: int
    returns: np.ndarray     # for each handover back to the previous cell: the seconds spent in between
    forced: int             # the policy's cell vanished from the measurements
    mean_buffer_kbit: float
    lost_kbit: float

    @property
    def changes(self) -> int:
        """Every change of serving cell: the policy's handovers and the forced ones."""
        return self.handovers + self.forced

    def pingpongs(self, window_s: float) -> int:
        """Handovers back to the previous cell within ``window_s`` (the minimum time of stay)."""
        return int((self.returns < window_s).sum())


def _measured(f: RealFlight, i: int) -> dict[float, tuple[float, float]]:
    cells = {f.pci[i]: (f.rsrp[i], f.rsrq[i])}
    for p, r, q in zip(f.nb_pci[i], f.nb_rsrp[i], f.nb_rsrq[i]):
        if np.isfinite(p) and np.isfinite(r) and np.isfinite(q) and p not in cells:
            cells[p] = (r, q)
    return cells


class _Service:
    """The plugin's buffer model driven by the real link quality along the flight (see the module doc)."""

    def __init__(self, cfg: SimConfig, seed: int):
        self.b, self.h, self.rng = cfg.buffer, cfg.handover, np.random.default_rng(seed)
        self.q, self.queues, self.lost = 0.0, [], 0.0

    def step(self, sinr_db: float, dt: float, handed: bool) -> None:
        b = self.b
        served = service_bits(sinr_db, b.rb_per_uav, b.rb_bandwidth_hz,
                              max(dt - (self.h.interruption_s if handed else 0), 0))
        arrivals = self.rng.poisson(b.packet_rate_hz * dt) * b.data_packet_bits + handed * b.control_packet_bits
        q, lost = buffer_step(self.q, arrivals, served, b.q_max_bits)
        self.q = float(q)
        self.queues.append(self.q)
        self.lost += float(lost)


def replay(f: RealFlight, decide, config: SimConfig | None = None, seed: int = 0) -> Replay:
    """Fly ``decide(state (13,), candidates, t) -> action`` along the real flight (see the module doc);
    ``decide=None`` follows the network's own serving cell (the observed decisions). Ping-pongs are counted
    afterwards, for any window, with :meth:`Replay.pingpongs`."""
    cfg = config or SimConfig()
    ids = {p: k for k, p in enumerate(sorted(set(f.pci.tolist())))}
    max_id = n_sites(cfg.layout) - 1  # the simulator's ids: a real flight's cells are ranked into that range
    service = _Service(cfg, seed)
    serving = prev = f.pci[0]
    entered, ho, forced = 0.0, 0, 0
    states, path, returns = [], [], []

    def hand_over(target, t):
        nonlocal serving, prev, entered, ho
        ho += 1
        if target == prev:
            returns.append(t - entered)
        prev, entered, serving = serving, t, target

    for i in range(len(f.t)):
        cells = _measured(f, i)
        if decide is None and f.pci[i] != serving:  # the network handed over between the samples
            hand_over(f.pci[i], f.t[i])
        if serving not in cells:
            serving, forced = max(cells, key=lambda p: cells[p][0]), forced + 1
        cand = [serving] + sorted((p for p in cells if p != serving), key=lambda p: -cells[p][0])[:N_CANDIDATES - 1]
        pad = N_CANDIDATES - len(cand)
        state = state_rows([*f.xy[i], f.altitude_m], service.q, min(ids.get(serving, 0), max_id),
                           [cells[p][0] for p in cand] + [PAD_RSRP] * pad,
                           [cells[p][1] for p in cand] + [PAD_RSRQ] * pad)[0]
        states.append(state)
        a = 0 if decide is None else int(decide(state, cand, float(f.t[i])))
        target = cand[a] if a < len(cand) else serving  # a padded candidate slot: stay
        handed = target != serving or (decide is None and i > 0 and f.pci[i] != f.pci[i - 1])
        if target != serving:
            hand_over(target, f.t[i])
        path.append(serving)
        dt = float(np.clip(f.t[i + 1] - f.t[i], 0, 5)) if i + 1 < len(f.t) else 0.0
        rsrp_now = cells.get(serving, (f.rsrp[i], 0))[0]
        service.step(f.snr[i] + (rsrp_now - f.rsrp[i]), dt, handed)
    return Replay(np.array(states), np.array(path), ho, np.array(returns), forced,
                  float(np.mean(service.queues)) / 1e3, service.lost / 1e3)


def chm_handovers(f: RealFlight, config=None, sim_config: SimConfig | None = None) -> int:
    """Changes of serving cell (forced ones included) of CHM flown closed-loop along the real measurements by
    :func:`replay` (A3 on the samples' time stamps): the count to compare with simulated CHM."""
    from .baselines import CHMOnSamples

    return replay(f, CHMOnSamples(f.cells, config), sim_config).changes


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
