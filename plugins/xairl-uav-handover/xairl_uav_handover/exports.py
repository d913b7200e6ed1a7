"""Real UAV flights from drive-test exports (Nemo "Exported Measurements", like ../shared/data/ukm-uav-lte/raw),
read and checked.

Rows are events; rows with the same Time form one time step (forward-filled over two steps for the sparse neighbour
lists and SNR). The last lines are a footer and are dropped (the rows after the last one whose Time parses). The
number of detected-cell slots varies, so columns are selected by name. Altitude is the nominal height in the file
name. A measurement no UE can report (inf, 1e400, an RSRP of 0 dBm) is refused by file, line and column.

An export is machine-written (the 29 UKM ones hold no such row), so a row it cannot be read from is a broken file,
never dropped in silence: a file with any row before the footer that holds a NUL byte, more fields than the header,
a Time that does not parse, or text where a measurement belongs, is refused in one line that counts those rows and
names the first (:func:`_check_rows`). Only regular files of at most :data:`MAX_FILE_BYTES` are read
(:func:`read_plain`, the zip path's check too): a FIFO would block for ever and a link to /dev/zero never ends.
"""

from __future__ import annotations

import io
import os
import re
import stat
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from xairl import InputError

REF_LAT, REF_LON = 2.9228, 101.7715  # centre of the UKM campaign area: local metres are measured from here
PCI, RSRP, RSRQ = "Physical cell identity (LTE pcell)", "RSRP (LTE pcell)", "RSRQ (LTE pcell)"
REQUIRED = ("Time", "Latitude", "Longitude", PCI, RSRP, RSRQ, "RS SNR")
TIME_RE = r"^\d{1,2}:\d{2}:\d{2}(\.\d+)?$"
#: the most bytes one flight export may hold, on disk or unpacked from a zip (ukm.py): the UKM's largest is 1.2 MB
MAX_FILE_BYTES = 16 << 20
#: what a user can give instead, ending a refusal of a file that is no export
GIVE_FILE = "give a folder of flight exports (Nemo CSV, regular files)."


def check_plain(path: Path, limit: int, st: os.stat_result | None = None) -> os.stat_result:
    """Refuse, in one line, a ``path`` that is no regular file (a FIFO blocks a read for ever, a device such as
    /dev/zero never ends, a socket cannot be read) or holds more than ``limit`` bytes; a link is followed to what it
    names. ``st``: the stat of the file already opened (the same check, without a second look-up)."""
    try:
        st = st or path.stat()
    except OSError as exc:
        raise InputError(f"{path}: cannot read it ({exc.strerror or type(exc).__name__}); {GIVE_FILE}") from None
    link = f" (a link to {os.readlink(path)})" if path.is_symlink() else ""
    if not stat.S_ISREG(st.st_mode):
        kinds = (
            (stat.S_ISFIFO, "a named pipe (FIFO)"),
            (stat.S_ISCHR, "a character device"),
            (stat.S_ISBLK, "a block device"),
            (stat.S_ISSOCK, "a socket"),
            (stat.S_ISDIR, "a folder"),
        )
        kind = next((k for test, k in kinds if test(st.st_mode)), "not a regular file")
        raise InputError(f"{path}{link}: {kind}, not a regular file; refused unread; {GIVE_FILE}")
    if st.st_size > limit:
        raise InputError(f"{path}{link}: {st.st_size} bytes, more than the {limit} allowed here; refused unread.")
    return st


def read_plain(path: Path, limit: int = MAX_FILE_BYTES) -> bytes:
    """The bytes of regular file ``path``, at most ``limit`` (:func:`check_plain` before it is opened, and again on
    what was opened, in case the name changed in between; opened without blocking, so a FIFO put there in between
    cannot hang the read)."""
    check_plain(path, limit)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError as exc:
        raise InputError(f"{path}: cannot read it ({exc.strerror or type(exc).__name__}); {GIVE_FILE}") from None
    with os.fdopen(fd, "rb") as fh:
        check_plain(path, limit, os.fstat(fd))
        data = fh.read(limit + 1)
    if len(data) > limit:  # it grew since
        raise InputError(f"{path}: more than the {limit} bytes a flight export may have; refused.")
    return data


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

    data = read_plain(path)
    _check_fields(data, path)
    try:  # (index + 2: the row's line in the file; blank lines are kept)
        df = pd.read_csv(io.BytesIO(data), low_memory=False, dtype={"Time": str}, skip_blank_lines=False)
    except (OSError, ValueError, pd.errors.ParserError) as exc:
        raise InputError(f"{path}: cannot read it as CSV ({str(exc).splitlines()[0]}).") from None
    missing = [c for c in REQUIRED if c not in df.columns]
    if missing:
        raise InputError(
            f"{path}: missing column '{missing[0]}'"
            + (f" (and {len(missing) - 1} more)" if len(missing) > 1 else "")
            + "."
        )
    blank = df.isna().all(axis=1).to_numpy()  # a blank line is no row
    df["Time"] = df["Time"].astype(str).str.strip()
    timed = df["Time"].str.match(TIME_RE).to_numpy()
    if not timed.any():
        raise InputError(f"{path}: no rows with a parseable Time (H:MM:SS.mmm); the file looks truncated.")
    footer = int(np.flatnonzero(timed)[-1]) + 1  # the rows after the last timed one: the export's footer
    body, timed, blank = df.iloc[:footer], timed[:footer], blank[:footer]
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
    numeric = ["Latitude", "Longitude", PCI, RSRP, RSRQ, "RS SNR", *_neighbour_columns(slots, df.columns)]
    _check_rows(body, timed, blank, numeric, path)
    df = body[timed].copy()
    for c in numeric:
        df[c] = pd.to_numeric(df[c], errors="coerce")
    _check_measurements(df, path)
    return df, slots


def _check_fields(data: bytes, path: Path) -> None:
    """Refuse a file with a NUL byte, or a row with more fields than its header (pandas would shift or cut it)."""
    import csv

    if b"\0" in data:
        lines = data.split(b"\n")
        bad = [k for k, line in enumerate(lines) if b"\0" in line]
        raise InputError(
            f"{path}: {len(bad)} row(s) hold a NUL byte (binary data, not text), first on line {bad[0] + 1}; fix or "
            "delete those rows."
        )
    rows = csv.reader(io.StringIO(data.decode("utf-8", "replace"), newline=""))
    width = len(next(rows, []))
    long = [(rows.line_num, len(r)) for r in rows if len(r) > width]
    if long:
        line, n = long[0]
        raise InputError(
            f"{path}: {len(long)} row(s) hold more fields than the header's {width}, first line {line} ({n}); fix or "
            "delete those rows."
        )


def _check_rows(body, timed: np.ndarray, blank: np.ndarray, numeric: list[str], path: Path) -> None:
    """Refuse rows before the footer that cannot be read: a Time that does not parse (``timed``: it does), or text
    (not a number) where a measurement belongs; a ``blank`` line is no row. One line: how many, and the first."""
    import pandas as pd

    why = np.where(~timed & ~blank, "its Time does not parse (H:MM:SS.mmm)", "").astype(object)
    for c in numeric:
        v = body[c]
        if v.dtype.kind in "fiu":  # parsed as numbers throughout: no text in it
            continue
        text = v.notna().to_numpy() & pd.to_numeric(v, errors="coerce").isna().to_numpy()
        for k in np.flatnonzero(text & (why == "")):
            if str(v.iloc[k]).strip():
                why[k] = f"column '{c}' holds the text {str(v.iloc[k])[:40]!r}, not a number"
    bad = np.flatnonzero(why != "")
    if len(bad):
        k = int(bad[0])
        raise InputError(
            f"{path}: {len(bad)} of {int((~blank).sum())} rows cannot be read, first line {int(body.index[k]) + 2}: {why[k]}; "
            "fix or delete those rows."
        )


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
    for f in sorted(folder.rglob("*.csv")):  # (each read by read_plain: regular files of bounded size only)
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
