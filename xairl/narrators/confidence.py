"""The confidence score of a narrative, in [0, 1]: ``verification x weighted mean of the measured components``.

- ``verification``: 1 when the verdict is 'verified' (every claim checked, and true), else 0: a contradicted or a
  partly checked text has no confidence;
- ``coverage`` (weight 0.2): the share of the text's checkable claims that were checked
  (:attr:`xairl.Verification.coverage`). A verified text has checked them all, so it is 1 wherever the score is not
  0; it is kept among the components to show how much of a partly checked text was checked;
- ``additivity`` (weight 0.15): 1 / (1 + gap / (1e-3 * max(1, |score|))): 1 when contributions add up to the score;
- ``margin`` (weight 0.25): 1 - exp(-q_margin / tau), tau = the mean |contribution| per feature: a Q-gap smaller than
  a typical single feature's effect is a near tie (discrete actions only: a value or a continuous action has none);
- ``agreement`` (weight 0.2): (1 + Spearman rho) / 2 between the |contributions| of this method and a second one
  (integrated gradients, or deep_shap when the first is integrated gradients) on the same state;
- ``stability`` (weight 0.2): mean of (1 + rho) / 2 between the contributions with the full background and with two
  half-size resamples of it.

Cost: ``additivity`` and ``margin`` are read off the Explanation. ``agreement`` and ``stability`` (the robustness
components) explain the one state three more times: once with the second method, twice with half the background.
They run only with ``robustness=True`` and a policy and background (:class:`NarrationOptions`); otherwise they are left
out (shown as None) and the weights of the others are renormalised.
"""

from __future__ import annotations

import numpy as np

from xairl.explanations.explanation import Explanation
from xairl.narrators.options import NarrationOptions
from xairl.policies.policy import Policy

WEIGHTS = {"coverage": 0.2, "additivity": 0.15, "margin": 0.25, "agreement": 0.2, "stability": 0.2}  # as the doc says


def _spearman(a: np.ndarray, b: np.ndarray) -> float:
    ra, rb = np.argsort(np.argsort(a)), np.argsort(np.argsort(b))
    if ra.std() == 0 or rb.std() == 0:
        return 0.0
    return float(np.corrcoef(ra, rb)[0, 1])


def _additivity(gap: float, score: float) -> float:
    return 1 / (1 + gap / (1e-3 * max(1.0, abs(score))))


def _agreement(exp: Explanation, index: int, policy: Policy, bg: np.ndarray, c: int) -> float | None:
    """Rank agreement of |contributions| to output ``c`` with a second method; None when it refuses this network."""
    from xairl.attributors import explain
    from xairl.errors import XairlError

    second = "deep_shap" if exp.method == "integrated_gradients" else "integrated_gradients"
    try:
        other = explain(policy, exp.states[index : index + 1], background=bg, method=second).values[0, :, c]
    except (XairlError, RuntimeError):  # the second method may not support this network: not measured
        return None
    return (1 + _spearman(np.abs(exp.values[index, :, c]), np.abs(other))) / 2


def _stability(exp: Explanation, index: int, policy: Policy, bg: np.ndarray, seed: int, c: int) -> float:
    """Mean rank agreement of the contributions to output ``c`` with those from two half-size resamples of the
    background."""
    from xairl.attributors import explain

    rng = np.random.default_rng(seed)
    rhos = []
    for _ in range(2):
        half = bg[rng.choice(len(bg), size=max(1, len(bg) // 2), replace=False)]
        again = explain(
            policy, exp.states[index : index + 1], background=half, method=exp.method, options=dict(exp.options)
        ).values[0, :, c]
        rhos.append((1 + _spearman(exp.values[index, :, c], again)) / 2)
    return float(np.mean(rhos))


def components(
    exp: Explanation,
    index: int | None,
    verified: bool,
    narration: NarrationOptions | None = None,
    *,
    seed: int = 0,
    output: int | None = None,
    coverage: float | None = None,
) -> dict[str, float | None]:
    """Every component of the confidence (None where not measured); see the module doc.

    :param narration: the narration's options: its ``policy``, ``background`` and ``robustness`` say whether the
        robustness components are measured (default: not, without a policy).
    :param output: the output narrated when nothing is chosen (a value, one dimension of a continuous action);
        there the margin does not apply. Default: the chosen action.
    :param coverage: the share of the text's checkable claims that were checked (:attr:`xairl.Verification.coverage`);
        None: not known."""
    comp: dict[str, float | None] = {
        "verification": 1.0 if verified else 0.0,
        "coverage": coverage,
        "additivity": None,
        "margin": None,
        "agreement": None,
        "stability": None,
    }
    if index is None:  # a global summary: only verification and additivity apply
        comp["additivity"] = _additivity(float(exp.additivity_gap.max()), float(np.abs(exp.outputs).max()))
        return comp
    c, r = int(exp.chosen[index]) if output is None else output, int(exp.runner_up[index])
    comp["additivity"] = _additivity(float(exp.additivity_gap[index, c]), float(exp.outputs[index, c]))
    if exp.output == "actions" and r != c:  # one available action: no choice, so no tie to doubt
        tau = float(np.abs(exp.values[index, :, c]).mean()) or 1e-12
        comp["margin"] = float(1 - np.exp(-float(exp.outputs[index, c] - exp.outputs[index, r]) / tau))
    o = narration or NarrationOptions()
    policy = o.policy
    if o.robustness and policy is not None and o.background is not None and exp.states is not None:
        bg = policy.check_states(o.background, "background")
        comp["agreement"] = _agreement(exp, index, policy, bg, c)
        comp["stability"] = _stability(exp, index, policy, bg, seed, c)
    return comp


def confidence(
    exp: Explanation,
    index: int | None,
    verified: bool,
    narration: NarrationOptions | None = None,
    *,
    seed: int = 0,
    output: int | None = None,
    coverage: float | None = None,
) -> tuple[float, dict[str, float | None]]:
    """The confidence of a narrative and its components (formula and cost in the module doc; the parameters are
    those of :func:`components`)."""
    comp = components(exp, index, verified, narration, seed=seed, output=output, coverage=coverage)
    measured = {k: v for k, v in comp.items() if k in WEIGHTS and v is not None}
    score = comp["verification"] * sum(WEIGHTS[k] * v for k, v in measured.items()) / sum(WEIGHTS[k] for k in measured)
    return float(np.clip(score, 0.0, 1.0)), comp
