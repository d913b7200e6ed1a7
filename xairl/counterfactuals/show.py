"""What the places that show counterfactuals (the CLI, the report's cards, the notebook, the review page) read of a
search's answer: :func:`summary`, a plain JSON-ready dict (it travels in a narrative's evidence into the feedback
store and back to the review page), and :func:`single_flips`, the run's view: per feature, how often a change of
that feature alone flips the decisions and how large it is.

Values are written by ``text(feature, value)`` when the caller gives one (the report and the CLI give the narratives'
own writer: '100 % full', '-85.3 dBm'), else as the narratives write numbers, with the feature's unit. It reads
:class:`xairl.Counterfactuals` without importing them (their notebook card calls :func:`summary`).

One rounding rule for what is written, here and in the words (:mod:`xairl.counterfactual_facts`): :func:`outward`, a
value rounded to the digits it is written with, *away from the line* ('below 37.6' for a line at 37.64, never 'below
37.7', which rounds back across it). Where the policy is at hand (the CLI, the report's cards) the answer shown is
the one the words say, each value as written and re-run through the policy as written
(:func:`xairl.counterfactual_facts.as_written`, ``as_written=True``); a bare answer (a notebook's card) has no policy
to re-run, so its values are rounded away from the state's value, just past the line, and said to be so.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Sequence

import numpy as np

from xairl.numbers import format_number, written_step


def outward(x: float, down: bool, extra: int = 0) -> float:
    """``x`` rounded to the digits it is written with, away from the line (down for 'below'), ``extra`` steps more."""
    s = written_step(x)
    n = math.floor(x / s + 1e-9) - extra if down else math.ceil(x / s - 1e-9) + extra
    return float(format_number(n * s))


def summary(cfs, text: Callable[[str, float], str] | None = None, n: int = 3, as_written: bool = False) -> dict:
    """A decision's answer as plain data: ``chosen``, ``target``, ``reason`` ('' when some were found) and ``found``,
    its first ``n`` counterfactuals, each with its ``changes`` (feature, before, after, their texts, unit, background
    quantiles), the ``action`` the policy then takes (a threshold's: the output's new value, ``output``), its
    ``margin`` and its ``distance`` (in quantiles). ``as_written``: the values are the ones re-run as written
    (:func:`xairl.counterfactual_facts.as_written`); else each ``after`` is rounded away from the state's value
    (:func:`outward`), past the line but not re-run so (module doc)."""

    def write(change, value: float) -> str:
        return text(change.feature, value) if text is not None else f"{format_number(value)} {change.unit}".strip()

    def shown(c) -> float:
        return float(c.after) if as_written or c.after == c.before else outward(c.after, c.after < c.before)

    found = [
        {
            "changes": [
                {
                    "feature": c.feature,
                    "before": c.before,
                    "after": shown(c),
                    "before_text": write(c, c.before),
                    "after_text": write(c, shown(c)),
                    "unit": c.unit,
                    "quantiles": [float(q) for q in c.quantiles],
                }
                for c in cf.changes
            ],
            "action": cf.action,
            "output": cf.output,
            "margin": cf.margin,
            "distance": cf.distance,
        }
        for cf in cfs.found[:n]
    ]
    threshold = bool(re.match(rf"{re.escape(cfs.chosen)} (?:above|below) ", cfs.target))  # (a Threshold's words)
    return {
        "index": cfs.index,
        "chosen": cfs.chosen,
        "target": cfs.target,
        "reason": cfs.reason,
        "found": found,
        "as_written": as_written,
        "threshold": threshold,
    }


def single_flips(results: Sequence, features: Sequence[str]) -> dict[str, dict[str, dict]]:
    """Per feature of ``features``, per chosen action: over the decisions ``results`` (searched with
    ``max_changes=1`` and ``n`` at least the number of features, so that every feature's single change is kept), how
    many a change of that feature alone flips (``flips``) and the median change needed (``median_delta`` in the
    feature's own unit, ``median_quantiles`` the signed change of its background quantile; NaN when none)."""
    out: dict[str, dict[str, dict]] = {}
    for f in features:
        seen: dict[str, list] = {}
        for r in results:
            change = next(
                (cf.changes[0] for cf in r.found if len(cf.changes) == 1 and cf.changes[0].feature == f), None
            )
            if change is not None:
                seen.setdefault(r.chosen, []).append((change.delta, change.quantiles[1] - change.quantiles[0]))
        out[f] = {
            action: {
                "flips": len(pairs),
                "median_delta": float(np.median([d for d, _ in pairs])),
                "median_quantiles": _median([q for _, q in pairs]),
            }
            for action, pairs in seen.items()
        }
    return out


def _median(values: list[float]) -> float:
    known = [v for v in values if np.isfinite(v)]
    return float(np.median(known)) if known else float("nan")
