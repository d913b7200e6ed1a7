"""FeatureInfo: what a policy declares about one feature (unit, description, level words, kind, bounds, categories),
checked when it is made."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from xairl.errors import InputError


@dataclass(frozen=True)
class FeatureInfo:
    """What a feature means, for plots and narration.

    :param unit: e.g. "dBm", "m"; empty when unitless.
    :param description: a plain-language phrase ("the serving cell's reference signal power").
    :param low: how to describe a low value ("weak signal"); ``high`` likewise.
    :param aliases: other names a text may use for the feature (the verifier recognises them).
    :param categories: for a categorical feature given as integer codes, the label of each code (code k is
        ``categories[k]``): narratives name the label ("odor: foul") and the verifier checks it.
    :param kind: 'numeric' (a quantity: narrated as a reason with a signed push), 'categorical' (a label; its
        contribution is the effect of having that category), 'identifier' (an id such as a cell id: its code order
        means nothing, so it is never narrated as a cause, only as context, "while on BS 15") or 'group' (the entry
        describes a group of ``Policy.groups``, narrated as one reason whose contribution is its members' sum).
    :param capacity: for a quantity that fills up (a buffer, a queue), its maximum: narratives state the fill as a
        percentage of it and its level words come from it (below 25 % low, above 75 % high, unless ``thresholds``).
    :param thresholds: (low below, high above) in the feature's unit, e.g. RSRP (-100, -80) dBm: level words come
        from them instead of the background's quartiles.
    :param bounds: (low, high) the values the feature can take in the world (finite, or -inf/inf for no limit):
        a counterfactual (:func:`xairl.counterfactual`) moves it only within them, instead of within the background's
        1st to 99th percentile.
    :param immutable: a counterfactual never changes it (a position, a cell's id). Identifiers and categoricals
        never change either way.
    """

    unit: str = ""
    description: str = ""
    low: str = "low"
    high: str = "high"
    aliases: tuple[str, ...] = ()
    categories: tuple[str, ...] = ()
    kind: Literal["numeric", "categorical", "identifier", "group"] = "numeric"
    capacity: float | None = None
    thresholds: tuple[float, float] | None = None
    bounds: tuple[float, float] | None = None
    immutable: bool = False

    def __post_init__(self) -> None:
        if self.kind not in FEATURE_KINDS:
            raise InputError(f"FeatureInfo kind '{self.kind}' is unknown; use one of {', '.join(FEATURE_KINDS)}.")
        if self.categories and self.kind == "numeric":
            object.__setattr__(self, "kind", "categorical")
        if self.capacity is not None and not (np.isfinite(self.capacity) and self.capacity > 0):
            raise InputError(f"FeatureInfo capacity must be a positive number, got {self.capacity}.")
        if self.thresholds is not None and not (len(self.thresholds) == 2 and self.thresholds[0] <= self.thresholds[1]):
            raise InputError(
                f"FeatureInfo thresholds must be (low below, high above) with low <= high, got {self.thresholds}."
            )
        if self.bounds is not None:
            b = np.asarray(self.bounds, dtype=float) if _numbers(self.bounds) else np.array([np.nan])
            if b.shape != (2,) or np.isnan(b).any() or b[0] > b[1]:
                raise InputError(
                    f"FeatureInfo bounds must be (low, high) numbers (or -inf/inf) with low <= high, got "
                    f"{self.bounds!r:.60}."
                )
            if b[0] == np.inf or b[1] == -np.inf:  # (inf, inf) holds no value: it cannot bound anything
                raise InputError(
                    f"FeatureInfo bounds {self.bounds!r:.60} hold no value: the low bound must be below inf and the "
                    "high above -inf (use -inf/inf for no limit on a side)."
                )
            object.__setattr__(self, "bounds", (float(b[0]), float(b[1])))
        if not isinstance(self.immutable, (bool, np.bool_)):
            raise InputError(f"FeatureInfo immutable is True or False, got {self.immutable!r:.40}.")


def _numbers(value) -> bool:
    """Whether ``value`` is a sequence of real numbers (no bools, strings or None)."""
    return isinstance(value, (tuple, list, np.ndarray)) and all(
        isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, bool) for v in value
    )


FEATURE_KINDS = ("numeric", "categorical", "identifier", "group")
