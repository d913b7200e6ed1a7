"""A feature's value in words: its level ('low', 'heavily loaded') against its thresholds, capacity or the
background's quartiles, and its text as narratives, figures and tables write it ('-85.3 dBm', '12 % full', a
category's label). Public through :mod:`xairl.facts`."""

from __future__ import annotations

import numpy as np

from xairl.explanations.explanation import Explanation
from xairl.numbers import format_number
from xairl.policies.policy import FeatureInfo, Policy


def value_level(value: float, info: FeatureInfo, quartiles: tuple[float, float] | None) -> tuple[str, str]:
    """(level, words) of a value: from the feature's thresholds or capacity (a physical range) when it has one,
    else from the background's quartiles when they are distinct (a degenerate background, e.g. a buffer empty in
    three states of four, says nothing about 'high'), else unknown."""
    if info.kind != "numeric" or not np.isfinite(value):
        return "unknown", ""
    bounds, middle = info.thresholds, "moderate"
    if bounds is None and info.capacity is not None:
        bounds = (0.25 * info.capacity, 0.75 * info.capacity)
    if bounds is None and quartiles is not None and quartiles[0] < quartiles[1]:
        bounds, middle = quartiles, "typical"
    if bounds is None:
        return "unknown", ""
    if value < bounds[0]:
        return "low", info.low
    if value > bounds[1]:
        return "high", info.high
    return "typical", middle


def fill_and_text(value: float, info: FeatureInfo, label: str | None, region: bool = False) -> tuple[float | None, str]:
    """(the fill in percent of a feature with a capacity, else None; the value's text): see :func:`value_text`."""
    if info.kind == "group":
        return None, ""
    if label is not None:
        return None, label
    if region:  # an image region's value is the mean of its pixels: said so, not a bare number in brackets
        return None, f"mean pixel value {format_number(value)}"
    if info.capacity is not None:
        fill = 100.0 * value / info.capacity
        return fill, f"{format_number(fill)} % full"
    return None, f"{format_number(value)} {info.unit}".strip()


def value_text(value: float, info: FeatureInfo | None = None, label: str | None = None) -> str:
    """A feature's value as the narratives write it: a category's ``label``, the fill of a feature with a capacity
    ('100 % full'), else the number in their format with the feature's unit ('-85.3 dBm'). The one formatter of
    values: narratives, figures and tables call it."""
    if info is None:
        return label if label is not None else format_number(value)
    return fill_and_text(float(value), info, label)[1]


def state_value_text(exp: Explanation, i: int, j: int, policy: Policy | None = None) -> str:
    """State ``i``'s value of feature ``j`` as :func:`value_text` writes it, with the unit, capacity and categories
    ``policy`` declares for it; empty when ``exp`` keeps no states."""
    if exp.states is None:
        return ""
    labels = exp.value_labels
    label = None if labels is None or labels[i, j] is None else str(labels[i, j])
    info = None if policy is None else policy.features.get(exp.feature_names[j])
    return value_text(float(exp.states[i, j]), info, label)
