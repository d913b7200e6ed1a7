"""What a counterfactual may change, how far, and how far a change is.

A *unit* of change is what one change moves: a flat feature (a dict observation's columns by their names, a window's
slots as flat features), or, for an image, a region of it (the patches of :meth:`xairl.Observation.regions`, named
as narration names them). A region's change shifts all its pixels by one amount, each kept within the pixel range
the background holds for that region (a pixel already outside it is not moved further out); its value is their mean.

Never changed: a feature declared ``FeatureInfo(immutable=True)``, an identifier (``kind='identifier'``: a cell's id
means nothing as a quantity) and a categorical (its codes have no order; the one-hot columns of a categorical input
as well). Searching among a categorical's codes is not supported: it is left out.

Each unit moves within a range: its declared ``FeatureInfo.bounds`` where they are finite (clamped to the largest
finite number of the network's dtype: a float32 network cannot be given 1e39), else the background's 1st to 99th
percentile of the unit's value, widened to include the state's own value (a state may lie outside its data).

A *binary* unit (one column whose background takes exactly two values, a leg's contact {0, 1}) moves only whole,
from one of its two values to the other (:meth:`Units.snap`): a fraction of a contact is no state the world has.

A window's slots (a memory policy's last k observations) change only at the newest step by default: a change of a
past slot alone is a history the present state cannot have. ``past=True`` (or naming a past slot in ``features``)
searches the past slots too.

A change's size is measured two ways: in background quantiles (the unit's empirical distribution function over the
background, interpolated between the sorted values: 0..1, comparable across units), and in the unit's own units
divided by its interquartile range (its 1st-99th percentile span where the quartiles coincide, else 1).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from xairl.errors import InputError
from xairl.policies.policy import Policy


@dataclass(frozen=True)
class Units:
    """The units a search may change, with what it needs of the background.

    :param names: one per unit; ``columns`` the flat columns each covers; ``labels`` its unit of measure.
    :param declared: (U, 2) declared bounds (-inf/inf where none).
    :param sorted_bg: (B, U) the background's value of each unit, sorted per unit.
    :param pixels: (U, 2) the lowest and highest value of any column of each unit in the background (a region's
        pixels are shifted within it).
    :param levels: (U, 2) a binary unit's two values (low, high); NaN for every other unit.
    """

    names: tuple[str, ...]
    columns: tuple[np.ndarray, ...]
    labels: tuple[str, ...]
    declared: np.ndarray
    sorted_bg: np.ndarray
    pixels: np.ndarray
    levels: np.ndarray

    @property
    def n(self) -> int:
        return len(self.names)

    @property
    def binary(self) -> np.ndarray:
        """(U,) whether each unit is binary (moves only from one of its two values to the other)."""
        return np.isfinite(self.levels[:, 0])

    @property
    def regions(self) -> bool:
        """Whether some unit is an image's region (many columns moved as one): each change costs a pass of the
        network over the whole image, so the search sizes its grids for that."""
        return any(len(c) > 1 for c in self.columns)

    def values(self, x: np.ndarray) -> np.ndarray:
        """(n, U) the value of each unit in flat states ``x`` (a region's: its pixels' mean)."""
        if not self.columns:
            return np.zeros((len(x), 0))
        return np.stack([x[:, c].astype(np.float64).mean(axis=1) for c in self.columns], axis=1).reshape(len(x), -1)

    def snap(self, values: np.ndarray, unit: np.ndarray) -> np.ndarray:
        """``values`` of units ``unit`` (same shape), a binary unit's each moved to the nearer of its two values."""
        lv = self.levels[np.asarray(unit)]
        with np.errstate(invalid="ignore"):
            whole = np.where(values >= lv.mean(axis=-1), lv[..., 1], lv[..., 0])
        return np.where(np.isfinite(lv[..., 0]), whole, values)

    def ranges(self, own: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(low, high), each (n, U): where each unit of each state may move (declared bounds, else the background's
        1st-99th percentile widened to the state's own value ``own`` (n, U))."""
        p1, p99 = np.percentile(self.sorted_bg, [1, 99], axis=0)
        # a binary unit's range is its two values, however rare one of them is in the background
        p1, p99 = np.where(self.binary, self.levels[:, 0], p1), np.where(self.binary, self.levels[:, 1], p99)
        low, high = np.minimum(p1, own), np.maximum(p99, own)
        low = np.where(np.isfinite(self.declared[:, 0]), self.declared[:, 0], low)
        high = np.where(np.isfinite(self.declared[:, 1]), self.declared[:, 1], high)
        return low, np.maximum(high, low)

    def scale(self) -> np.ndarray:
        """(U,) the interquartile range of each unit (its 1st-99th percentile span where that is 0, else 1)."""
        p1, q1, q3, p99 = np.percentile(self.sorted_bg, [1, 25, 75, 99], axis=0)
        return np.where(q3 > q1, q3 - q1, np.where(p99 > p1, p99 - p1, 1.0))

    def quantile(self, values: np.ndarray, unit: np.ndarray) -> np.ndarray:
        """Background quantile (0..1) of ``values`` of units ``unit`` (same shape)."""
        values, unit = np.broadcast_arrays(np.asarray(values, dtype=np.float64), np.asarray(unit))
        out = np.empty(values.shape)
        b = len(self.sorted_bg)
        levels = (np.arange(b) + 0.5) / b
        for u in np.unique(unit):
            at = unit == u
            out[at] = np.interp(values[at], self.sorted_bg[:, u], levels)
        return out

    def shift(self, x: np.ndarray, unit: np.ndarray, delta: np.ndarray) -> None:
        """Shift in place unit ``unit[r]`` of row ``x[r]`` by ``delta[r]`` (every column of a region alike)."""
        for u in np.unique(unit):
            rows = np.flatnonzero(unit == u)
            self.move(x, rows, u, delta[rows])

    def move(self, x: np.ndarray, rows, u: int, delta) -> None:
        """Shift in place unit ``u`` of rows ``rows`` of ``x`` by ``delta`` (one per row): a single column as it is;
        a region's pixels each kept within :attr:`pixels` (or where it already was, beyond them)."""
        at = np.ix_(np.atleast_1d(rows), self.columns[u])
        old = x[at]
        new = old + np.reshape(delta, (-1, 1))
        if len(self.columns[u]) > 1:
            lo, hi = self.pixels[u]
            new = np.clip(new, np.minimum(lo, old), np.maximum(hi, old))
        x[at] = new


def units(policy: Policy, background: np.ndarray, features: Sequence[str] | str | None, past: bool = False) -> Units:
    """The units of ``policy`` a counterfactual may change (``features``: only these, by name; a group's name stands
    for its members; ``past``: a window's past slots too, module doc), with the background's values of each."""
    every = _every_unit(policy)
    fixed = _immutable(policy, every)
    names = [name for name in every if name not in fixed]
    if not isinstance(past, (bool, np.bool_)):
        raise InputError(
            f"past is True (a window's past slots change too) or False (the newest step's); got {past!r:.40}."
        )
    history = set() if past else _past_slots(policy)
    if features is not None:
        asked = [features] if isinstance(features, str) else [str(f) for f in features]
        if not asked:
            raise InputError("features is empty: name at least one feature that may change, or leave it out (None).")
        wanted = [m for f in asked for m in (policy.groups.get(f) or (f,))]
        unknown = [f for f in wanted if f not in every]
        if unknown:
            raise InputError(
                f"features {', '.join(unknown[:3])} are not units a counterfactual changes; use names such as "
                f"{', '.join(names[:5])}."
            )
        frozen = [f for f in wanted if f in fixed]
        if frozen:
            raise InputError(
                f"feature {frozen[0]} never changes in a counterfactual (immutable, an identifier or a category); "
                "leave it out of features."
            )
        names = [n for n in names if n in set(wanted)]  # (a past slot named is asked for)
    else:
        names = [n for n in names if n not in history]
    columns = tuple(np.asarray(every[n]) for n in names)
    info = [policy.features.get(n) for n in names]
    declared = np.array([i.bounds if i is not None and i.bounds else (-np.inf, np.inf) for i in info], dtype=float)
    top = float(np.finfo(policy.dtype).max)  # (a bound past it would reach the network as inf)
    declared = np.where(np.isfinite(declared), np.clip(declared, -top, top), declared)
    background = np.asarray(background)
    if len(background) < 2:
        raise InputError(
            f"a counterfactual search needs at least 2 background states (ranges and quantiles), got {len(background)}; "
            "give more typical states."
        )
    pixels = np.array([(background[:, c].min(), background[:, c].max()) for c in columns], dtype=float).reshape(-1, 2)
    labels = tuple(i.unit if i else "" for i in info)
    levels = np.full((len(names), 2), np.nan)
    for u, c in enumerate(columns):
        two = np.unique(background[:, c]) if len(c) == 1 and len(background) >= BINARY_SEEN else ()
        if len(two) == 2:
            levels[u] = two
    out = Units(tuple(names), columns, labels, declared.reshape(-1, 2), np.empty(0), pixels, levels)
    bg = np.sort(out.values(background), axis=0).reshape(len(background), len(names))
    return Units(out.names, out.columns, out.labels, out.declared, bg, pixels, levels)


def _past_slots(policy: Policy) -> set[str]:
    """A window's slots of every step but the newest (the last ``len(signals)`` of its time-major names)."""
    if policy.observation.kind != "window":
        return set()
    window = policy.observation.parts[0].window
    return set(window.names()[: -len(window.signals)])


def _every_unit(policy: Policy) -> dict[str, np.ndarray]:
    """Every unit's name -> its flat columns: an image's regions, then each column no region covers."""
    regions = policy.observation.regions()
    covered = np.zeros(policy.n_features, dtype=bool)
    for cols in regions.values():
        covered[cols] = True
    out = {name: np.asarray(cols) for name, cols in regions.items()}
    out.update({f: np.array([j]) for j, f in enumerate(policy.feature_names) if not covered[j]})
    return out


def _immutable(policy: Policy, every: dict[str, np.ndarray]) -> set[str]:
    """Units never changed: declared immutable, identifiers, categoricals, and a categorical input's columns."""
    fixed = {n for n in every if (i := policy.features.get(n)) is not None and (i.immutable or i.kind in _FIXED_KINDS)}
    start, onehot = 0, set()
    for part in policy.observation.parts:
        if part.categories:
            onehot.update(range(start, start + part.size))
        start += part.size
    return fixed | {n for n, cols in every.items() if onehot.intersection(cols.tolist())}


_FIXED_KINDS = ("identifier", "categorical")
#: background states needed before a feature seen taking two values is taken for binary (2 draws of a quantity
#: take two values too)
BINARY_SEEN = 10
