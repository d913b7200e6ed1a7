"""Narrative (the result), the narrator interface, and the confidence score.

Confidence, in [0, 1], is ``verification x weighted mean of the measured components``:

- ``verification``: 1 when every claim of the shown text was verified, else 0 (an unverified text has no confidence);
- ``additivity`` (weight 0.2): 1 / (1 + gap / (1e-3 * max(1, |score|))): 1 when contributions add up to the score;
- ``margin`` (0.3): 1 - exp(-q_margin / tau), tau = the mean |contribution| per feature: a Q-gap smaller than a
  typical single feature's effect is a near tie;
- ``agreement`` (0.25): (1 + Spearman rho) / 2 between the |contributions| of this method and a second one
  (integrated gradients, or deep_shap when the first is integrated gradients) on the same state;
- ``stability`` (0.25): mean of (1 + rho) / 2 between the contributions with the full background and with two
  half-size resamples of it.
``agreement`` and ``stability`` need the policy and the background; without them they are left out and the
weights of the others are renormalised. Every component is shown on the Narrative.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ..explanation import Explanation
from ..policy import Policy
from .verify import Claim

WEIGHTS = {"additivity": 0.2, "margin": 0.3, "agreement": 0.25, "stability": 0.25}


@dataclass(frozen=True)
class Narrative:
    """Words for one decision (or the global view), checked against the numbers.

    :param source: 'template', 'local_lm', or 'template (fallback: ...)' when the model's text failed verification.
    """

    text: str
    claims: tuple[Claim, ...]
    verified: bool
    confidence: float
    components: dict[str, float | None]
    source: str
    template: str
    index: int | None
    extras: dict = field(default_factory=dict)


class Narrator:
    """Turns facts rendered by a template into text. Subclasses implement :meth:`compose`."""

    name: ClassVar[str] = ""

    def compose(self, variants: list[list[str]], context: dict) -> str:
        raise NotImplementedError


def _spearman(a: np.ndarray, b: np.ndarray) -> float:
    ra, rb = np.argsort(np.argsort(a)), np.argsort(np.argsort(b))
    if ra.std() == 0 or rb.std() == 0:
        return 0.0
    return float(np.corrcoef(ra, rb)[0, 1])


def confidence(exp: Explanation, index: int | None, verified: bool, policy: Policy | None = None,
               background=None, seed: int = 0) -> tuple[float, dict[str, float | None]]:
    """The confidence of a narrative and its components (formula in the module doc)."""
    comp: dict[str, float | None] = {"verification": 1.0 if verified else 0.0}
    if index is None:  # a global summary: only verification and additivity apply
        gap = float(exp.additivity_gap.max())
        comp.update(additivity=1 / (1 + gap / (1e-3 * max(1.0, float(np.abs(exp.outputs).max())))), margin=None,
                    agreement=None, stability=None)
    else:
        c = int(exp.chosen[index])
        contrib = exp.values[index, :, c]
        score = float(exp.outputs[index, c])
        comp["additivity"] = 1 / (1 + float(exp.additivity_gap[index, c]) / (1e-3 * max(1.0, abs(score))))
        tau = float(np.abs(contrib).mean()) or 1e-12
        q_margin = float(exp.outputs[index, c] - exp.outputs[index, exp.runner_up[index]])
        comp["margin"] = float(1 - np.exp(-q_margin / tau))
        comp["agreement"] = comp["stability"] = None
        if policy is not None and background is not None:
            from ..attributors import explain

            bg = policy.check_states(background, "background")
            state = exp.states[index:index + 1]
            second = "deep_shap" if exp.method == "integrated_gradients" else "integrated_gradients"
            try:
                other = explain(policy, state, background=bg, method=second).values[0, :, c]
                comp["agreement"] = (1 + _spearman(np.abs(contrib), np.abs(other))) / 2
            except Exception:  # the second method may not support this network; then it is simply not measured
                comp["agreement"] = None
            rng = np.random.default_rng(seed)
            rhos = []
            for _ in range(2):
                half = bg[rng.choice(len(bg), size=max(1, len(bg) // 2), replace=False)]
                again = explain(policy, state, background=half, method=exp.method,
                                options=dict(exp.options)).values[0, :, c]
                rhos.append((1 + _spearman(contrib, again)) / 2)
            comp["stability"] = float(np.mean(rhos))
    measured = {k: v for k, v in comp.items() if k in WEIGHTS and v is not None}
    total = sum(WEIGHTS[k] for k in measured)
    score = comp["verification"] * sum(WEIGHTS[k] * v for k, v in measured.items()) / total
    return float(np.clip(score, 0.0, 1.0)), comp
