"""What the places that show counterfactuals (the CLI, the report's cards, the notebook, the review page) read of a
search's answer: :func:`summary`, a plain JSON-ready dict (it travels in a narrative's evidence into the feedback
store and back to the review page), and :func:`single_flips`, the run's view: per feature, how often a change of
that feature alone flips the decisions and how large it is.

Values are written by ``text(feature, value)`` when the caller gives one (the report and the CLI give the narratives'
own writer: '100 % full', '-85.3 dBm'), else as the narratives write numbers, with the feature's unit. It reads
:class:`xairl.Counterfactuals` without importing them (their notebook card calls :func:`summary`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np


def summary(cfs, text: Callable[[str, float], str] | None = None, n: int = 3) -> dict:
    """A decision's answer as plain data: ``chosen``, ``target``, ``reason`` ('' when some were found) and ``found``,
    its first ``n`` counterfactuals, each with its ``changes`` (feature, before, after, their texts, unit, background
    quantiles), the ``action`` the policy then takes, its ``margin`` and its ``distance`` (in quantiles)."""
    from ..prompts import format_number

    def write(change, value: float) -> str:
        return text(change.feature, value) if text is not None else f"{format_number(value)} {change.unit}".strip()

    found = [
        {
            "changes": [
                {
                    "feature": c.feature,
                    "before": c.before,
                    "after": c.after,
                    "before_text": write(c, c.before),
                    "after_text": write(c, c.after),
                    "unit": c.unit,
                    "quantiles": [float(q) for q in c.quantiles],
                }
                for c in cf.changes
            ],
            "action": cf.action,
            "margin": cf.margin,
            "distance": cf.distance,
        }
        for cf in cfs.found[:n]
    ]
    return {"index": cfs.index, "chosen": cfs.chosen, "target": cfs.target, "reason": cfs.reason, "found": found}


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
