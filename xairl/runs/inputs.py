"""Turning user data (arrays, .csv/.npy/.npz/.json/.parquet files) into checked state matrices."""

from __future__ import annotations

import csv
import json
import os
import zipfile
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from xairl.errors import InputError
from xairl.policies.observation import Observation


def as_states(data, n_features: int, what: str = "states") -> np.ndarray:
    """Return `data` as a finite float32 array of shape (n, n_features); one state may be given as a 1-D vector.

    :param data: array-like or torch tensor.
    :param n_features: width the policy expects.
    :param what: name used in error messages ("states", "background").
    """
    return Observation.flat(n_features).flatten(data, what)


#: the most memory a states file may take once read (as float64), unless $XAIRL_MAX_STATES_BYTES says otherwise:
#: checked from the file's header before anything is loaded, so a small file that expands enormously is refused
MAX_STATES_BYTES = 2 * 1024**3
#: CSV and JSON files are parsed into Python objects first (~10x their size): larger ones should be .npy
MAX_TEXT_BYTES = 256 * 1024**2
LIMIT_ENV = "XAIRL_MAX_STATES_BYTES"


def read_states(
    path: str | Path, feature_names: Sequence[str], observation: Observation | None = None, what: str = "states"
) -> np.ndarray:
    """Read states from .npy (any shape the observation takes), .npz (one array per key of a dict observation, or
    ``arr_0, arr_1, ...`` for several inputs), .csv (header row naming the features, any order), .json (list of
    rows or of objects) or .parquet (one numeric column per feature, named as the features; other columns ignored).

    :param path: file to read.
    :param feature_names: the policy's features; CSV/JSON objects are reordered to match them.
    :param observation: the policy's observation (default: flat with these features).
    :param what: what the file holds, in messages ("states", "background").
    """
    observation = observation or Observation.flat(len(feature_names))
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such file; give a .csv, .npy or .json file of {what}.")
    suffix = path.suffix.lower()
    try:
        if suffix == ".npy":
            data = _load_npy(path)
        elif suffix == ".npz":
            data = _load_npz(path)
            if observation.kind == "tuple":
                data = [data.get(f"arr_{i}") for i in range(len(observation.parts))]
                if any(d is None for d in data):
                    raise InputError(
                        f"the policy takes {len(observation.parts)} inputs; save them with np.savez(path, x0, x1, ...)."
                    )
        elif suffix == ".parquet":
            data = _read_parquet(path, feature_names)
        elif suffix in (".csv", ".json"):
            if path.stat().st_size > MAX_TEXT_BYTES:
                raise InputError(
                    f"a {suffix} file of {path.stat().st_size / 1024**2:.0f} MB is too large to parse "
                    f"(limit {MAX_TEXT_BYTES // 1024**2} MB); save the {what} as .npy instead."
                )
            data = (_read_csv if suffix == ".csv" else _read_json)(path, feature_names, what)
        else:
            raise InputError(f"{path}: unknown file type '{suffix}'; use .csv, .npy, .npz, .json or .parquet.")
    except InputError as exc:
        msg = str(exc)
        raise InputError(msg if msg.startswith(str(path)) else f"{path}: {msg}") from None
    except RecursionError:
        raise InputError(f"{path}: nested too deeply to hold {what}; give rows of numbers.") from None
    except (ValueError, OSError, UnicodeDecodeError, EOFError, zipfile.BadZipFile) as exc:
        raise InputError(f"{path}: cannot read it ({' '.join(str(exc).split())[:160]}).") from None
    try:  # float64: the network's own dtype is cast to (and checked) when it is explained
        return observation.flatten(data, what, np.float64)
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None


def _limit() -> int:
    raw = os.environ.get(LIMIT_ENV, "")
    return int(raw) if raw.isdigit() else MAX_STATES_BYTES


def _check_size(shape: tuple[int, ...], name: str = "") -> None:
    """Refuse an array whose header promises more than the memory limit, before it is loaded."""
    need = 8 * int(np.prod(shape, dtype=object))  # as float64, which every state becomes
    if need > _limit():
        where = f" '{name}'" if name else ""
        raise InputError(
            f"the array{where} has shape {shape} and would take {need / 1024**3:.3g} GiB in memory, "
            f"more than the {_limit() / 1024**3:.3g} GiB limit; stream it (--format parquet --out DIR), or "
            f"raise the limit with ${LIMIT_ENV}=BYTES."
        )


def npy_header(fh) -> tuple[tuple[int, ...], bool, np.dtype]:
    """(shape, Fortran order, dtype) from the header of a .npy file open at its start; the file is left at the data."""
    version = np.lib.format.read_magic(fh)
    return np.lib.format.read_array_header_1_0(fh) if version == (1, 0) else np.lib.format.read_array_header_2_0(fh)


def _header(fh, name: str = "") -> tuple[tuple[int, ...], np.dtype]:
    """Shape and dtype from a .npy header, refused when the array would exceed the memory limit."""
    shape, _, dtype = npy_header(fh)
    _check_size(shape, name)
    return shape, dtype


def _load_npy(path: Path) -> np.ndarray:
    with path.open("rb") as fh:
        shape, dtype = _header(fh)
        start = fh.tell()
    promised = int(np.prod(shape, dtype=object)) * dtype.itemsize
    if not dtype.hasobject and path.stat().st_size - start < promised:
        raise InputError(
            f"its header promises an array of shape {shape} ({promised} bytes) but the file holds "
            f"{path.stat().st_size - start}; it is truncated: save it again."
        )
    return np.load(path, allow_pickle=False)


def _load_npz(path: Path) -> dict[str, np.ndarray]:
    """Each array's header is read from the zip before any array is expanded (a small file may hold gigabytes)."""
    with zipfile.ZipFile(path) as z:
        for info in z.infolist():
            with z.open(info) as fh:
                _header(fh, info.filename.removesuffix(".npy"))
    with np.load(path, allow_pickle=False) as z:
        return {k: z[k] for k in z.files}


def _read_csv(path: Path, feature_names: Sequence[str], what: str) -> np.ndarray:
    with path.open(newline="", encoding="utf-8-sig") as fh:  # -sig: a byte-order mark is not part of the header
        rows = [r for r in csv.reader(fh) if r and any(c.strip() for c in r)]
    if not rows:
        raise InputError(f"the CSV file is empty; it needs a header row and at least one row of {what}.")
    header = [h.strip() for h in rows[0]]
    twice = sorted({h for h in header if h in feature_names and header.count(h) > 1})
    if twice:
        raise InputError(f"column(s) {', '.join(twice)} appear more than once in the header; keep one of each.")
    missing = [f for f in feature_names if f not in header]
    if missing:
        raise InputError(
            f"the {what} lack column(s) {', '.join(missing)}; the header must name the features: "
            f"{', '.join(feature_names)}."
        )
    idx = [header.index(f) for f in feature_names]
    out = np.empty((len(rows) - 1, len(idx)), dtype=np.float64)
    for i, row in enumerate(rows[1:], start=2):
        for j, k in enumerate(idx):
            cell = row[k].strip() if k < len(row) else ""
            try:
                out[i - 2, j] = float(cell)
            except ValueError:
                raise InputError(
                    f"line {i}, column '{feature_names[j]}': '{cell}' is not a number; fix or drop the row."
                ) from None
    return out


def check_columns(schema, feature_names: Sequence[str]) -> None:
    """Refuse an Arrow schema (a Parquet file's) whose feature columns are missing, duplicated or not numbers,
    naming the column: numpy would raise a DTypePromotionError on a timestamp, pyarrow a KeyError on a duplicate."""
    import pyarrow.types as pat

    names = list(schema.names)
    twice = sorted({f for f in feature_names if names.count(f) > 1})
    if twice:
        raise InputError(f"column(s) {', '.join(twice[:5])} appear more than once; keep one of each.")
    missing = [f for f in feature_names if f not in names]
    if missing:
        raise InputError(f"lacks column(s) {', '.join(missing[:5])}; one column per feature, named as the features.")
    for f in feature_names:
        kind = schema.field(f).type
        if not (pat.is_integer(kind) or pat.is_floating(kind) or pat.is_boolean(kind) or pat.is_decimal(kind)):
            raise InputError(
                f"column '{f}' holds {kind} values, not numbers; convert it to numbers (a time to "
                "seconds, a category to its code) or rename it."
            )


def _read_parquet(path: Path, feature_names: Sequence[str]) -> np.ndarray:
    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        pf = pq.ParquetFile(path)
        check_columns(pf.schema_arrow, feature_names)
        _check_size((pf.metadata.num_rows, len(feature_names)))
        table = pf.read(columns=list(feature_names))
    except pa.ArrowException as exc:
        raise InputError(f"cannot read it as Parquet ({' '.join(str(exc).split())[:160]}).") from None
    if not table.num_rows:
        return np.empty((0, len(feature_names)))
    return np.column_stack([table.column(f).to_numpy(zero_copy_only=False).astype(np.float64) for f in feature_names])


def _read_json(path: Path, feature_names: Sequence[str], what: str):
    data = json.loads(path.read_text(encoding="utf-8-sig"))
    if isinstance(data, dict) and "states" in data:
        data = data["states"]
    if isinstance(data, list) and data and all(isinstance(r, dict) for r in data):
        missing = sorted({f for r in data for f in feature_names if f not in r})
        if missing:
            raise InputError(f"objects lack key(s) {', '.join(missing)}; each needs: {', '.join(feature_names)}.")
        data = [[r[f] for f in feature_names] for r in data]
    if not isinstance(data, list):
        raise InputError(f"expected a JSON list of {what} (rows of numbers or objects keyed by feature name).")
    return data
