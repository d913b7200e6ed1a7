"""Turning user data (arrays, .csv/.npy/.json files) into checked float32 state matrices."""
from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Sequence

import numpy as np

from .errors import InputError
from .observation import Observation


def as_states(data, n_features: int, what: str = "states") -> np.ndarray:
    """Return `data` as a finite float32 array of shape (n, n_features); one state may be given as a 1-D vector.

    :param data: array-like or torch tensor.
    :param n_features: width the policy expects.
    :param what: name used in error messages ("states", "background").
    """
    return Observation.flat(n_features).flatten(data, what)


def read_states(path: str | Path, feature_names: Sequence[str], observation: Observation | None = None
                ) -> np.ndarray:
    """Read states from .npy (any shape the observation takes), .npz (one array per key of a dict observation, or
    ``arr_0, arr_1, ...`` for several inputs), .csv (header row naming the features, any order) or .json (list of
    rows or of objects).

    :param path: file to read.
    :param feature_names: the policy's features; CSV/JSON objects are reordered to match them.
    :param observation: the policy's observation (default: flat with these features).
    """
    observation = observation or Observation.flat(len(feature_names))
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such file; give a .csv, .npy or .json file of states.")
    suffix = path.suffix.lower()
    try:
        if suffix == ".npy":
            data = np.load(path, allow_pickle=False)
        elif suffix == ".npz":
            with np.load(path, allow_pickle=False) as z:
                data = {k: z[k] for k in z.files}
            if observation.kind == "tuple":
                data = [data.get(f"arr_{i}") for i in range(len(observation.parts))]
                if any(d is None for d in data):
                    raise InputError(f"the policy takes {len(observation.parts)} inputs; save them with "
                                     "np.savez(path, x0, x1, ...).")
        elif suffix == ".csv":
            data = _read_csv(path, feature_names)
        elif suffix == ".json":
            data = _read_json(path, feature_names)
        else:
            raise InputError(f"{path}: unknown file type '{suffix}'; use .csv, .npy, .npz or .json.")
    except InputError as exc:
        msg = str(exc)
        raise InputError(msg if msg.startswith(str(path)) else f"{path}: {msg}") from None
    except (ValueError, OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read it ({exc}).") from None
    try:
        return observation.flatten(data)
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None


def _read_csv(path: Path, feature_names: Sequence[str]) -> np.ndarray:
    with path.open(newline="") as fh:
        rows = [r for r in csv.reader(fh) if r and any(c.strip() for c in r)]
    if not rows:
        raise InputError("the CSV file is empty; it needs a header row and at least one row of states.")
    header = [h.strip() for h in rows[0]]
    missing = [f for f in feature_names if f not in header]
    if missing:
        raise InputError(
            f"missing column(s) {', '.join(missing)}; the header must name the features: {', '.join(feature_names)}."
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


def _read_json(path: Path, feature_names: Sequence[str]):
    data = json.loads(path.read_text())
    if isinstance(data, dict) and "states" in data:
        data = data["states"]
    if isinstance(data, list) and data and all(isinstance(r, dict) for r in data):
        missing = sorted({f for r in data for f in feature_names if f not in r})
        if missing:
            raise InputError(f"objects lack key(s) {', '.join(missing)}; each needs: {', '.join(feature_names)}.")
        data = [[r[f] for f in feature_names] for r in data]
    if not isinstance(data, list):
        raise InputError("expected a JSON list of states (rows of numbers or objects keyed by feature name).")
    return data
