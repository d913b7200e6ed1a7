"""Facts computed by code from an Explanation: the only source of numbers, names and directions in a narrative."""
from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any, Mapping

import numpy as np

from ..errors import InputError, PluginError
from ..explanation import Explanation
from ..policy import FeatureInfo, Policy


def fmt(x: float, signed: bool = False) -> str:
    """How every number is written: 0 decimals from 100, 1 from 10, else 2 (3 significant digits below 0.01)."""
    a = abs(x)
    if float(x).is_integer() and a < 1e6:  # ids, counts
        s = f"{x:.0f}"
    elif a >= 100:
        s = f"{x:.0f}"
    elif a >= 10:
        s = f"{x:.1f}"
    elif a >= 0.01 or a == 0:
        s = f"{x:.2f}"
    else:
        s = f"{x:.3g}"
    if s.startswith("-") and float(s) == 0:
        s = s[1:]
    return ("+" + s) if signed and not s.startswith("-") else s


@dataclass(frozen=True)
class FeatureFact:
    """One feature's part in a decision.

    :param name: the feature's name; ``label`` its description (or the name); ``unit`` its unit.
    :param value: the feature's value in the state; ``contribution`` its signed contribution.
    :param share: |contribution| as a percentage of the sum of |contributions|.
    :param direction: 'toward' (raises the target score) or 'against'.
    :param level: 'low', 'typical' or 'high' against the background quartiles ('unknown' without them);
        ``level_text`` the feature's own words for it (``FeatureInfo.low`` / ``high``).
    :param rank: 1 for the largest |contribution|.
    """

    name: str
    label: str
    value: float
    unit: str
    contribution: float
    share: float
    direction: str
    level: str
    level_text: str
    rank: int


@dataclass(frozen=True)
class Comparison:
    """A domain fact from the policy's plugin, e.g. 'the strongest neighbour's RSRP was 4.2 dB above the serving
    BS's RSRP'. The verifier accepts ``value`` where a text writes it followed by ``unit``.

    :param text: the fact in words, ready for a template (``{{ comparisons[0].text }}``).
    :param value: the number the text states (rounded as written in ``text``).
    :param unit: the unit written after the number ("dB"); empty when unitless.
    """

    text: str
    value: float
    unit: str = ""


@dataclass(frozen=True)
class DomainFacts:
    """What a policy's ``facts_hook`` returns: domain facts a template may use besides the attribution.

    :param extras: named values for templates (``{{ extras.serving_bs }}``); numbers among them may be cited.
    :param comparisons: :class:`Comparison` facts, each with its value and unit.
    """

    extras: Mapping[str, Any] = field(default_factory=dict)
    comparisons: tuple[Comparison, ...] = ()


@dataclass(frozen=True)
class DecisionFacts:
    """Facts about one decision: the variables every decision template sees (``context()``), the template-variable
    contract of narrators and prompt authors.

    :param index: the state's index in the Explanation.
    :param action: the chosen action's name; ``runner_up`` the second-best action's name.
    :param score: the chosen action's score (Q-value or logit); ``runner_up_score`` the runner-up's.
    :param q_margin: ``score - runner_up_score``.
    :param base_value: the chosen action's expected score over the background.
    :param method: the attributor's name; ``additivity_gap`` |base + sum of contributions - score|.
    :param top: the ``k`` largest :class:`FeatureFact` by |contribution| to the chosen action's score.
    :param margin_top: the same for the margin over the runner-up (why this action and not that one).
    :param comparisons: the plugin's :class:`Comparison` facts; ``extras`` its named values (``DomainFacts``).
    :param output: the policy's output kind. For 'value' and 'continuous' (one dimension at a time) nothing is
        chosen: ``action`` names the output, ``score`` is its value, ``runner_up`` is ``action`` again and
        ``margin_top`` is empty.
    """

    index: int
    action: str
    runner_up: str
    score: float
    runner_up_score: float
    q_margin: float
    base_value: float
    method: str
    additivity_gap: float
    top: tuple[FeatureFact, ...]
    margin_top: tuple[FeatureFact, ...]
    comparisons: tuple[Comparison, ...] = ()
    extras: Mapping[str, Any] = field(default_factory=dict)
    output: str = "actions"

    def context(self) -> dict[str, Any]:
        """Variables a decision template sees: every field (feature facts as dicts) and ``k``."""
        return asdict(self) | {"extras": dict(self.extras), "k": len(self.top)}


@dataclass(frozen=True)
class GlobalFacts:
    """Over a set of states: the variables every global template sees (``context()``).

    :param n_states: how many states were explained; ``method`` the attributor.
    :param ranking: features by mean |contribution| to the chosen action, each a dict with ``name``, ``label``,
        ``unit``, ``rank``, ``mean_abs`` and ``high_values`` ('toward', 'against' or 'mixed': the direction in which
        high values push, from the correlation of value and contribution).
    """

    n_states: int
    method: str
    ranking: tuple[dict, ...]

    def context(self) -> dict[str, Any]:
        """Variables a global template sees: every field and ``k``."""
        return asdict(self) | {"k": len(self.ranking)}


def _info(policy: Policy | None, name: str) -> FeatureInfo:
    return (policy.features.get(name) if policy else None) or FeatureInfo()


def _level(exp: Explanation, j: int, value: float, info: FeatureInfo) -> tuple[str, str]:
    q = exp.background_quantiles
    if q is None:
        return "unknown", "unknown"
    if value < q[0, j]:
        return "low", info.low
    if value > q[2, j]:
        return "high", info.high
    return "typical", "typical"


def _feature_facts(exp, i, contrib, policy, k) -> tuple[FeatureFact, ...]:
    total = float(np.abs(contrib).sum()) or 1.0
    order = np.argsort(-np.abs(contrib), kind="stable")
    out = []
    for rank, j in enumerate(order[:k], start=1):
        name = exp.feature_names[j]
        info = _info(policy, name)
        value = float(exp.states[i, j]) if exp.states is not None else float("nan")
        level, level_text = _level(exp, j, value, info)
        c = float(contrib[j])
        out.append(FeatureFact(name, info.description or name, value, info.unit, c,
                               100.0 * abs(c) / total, "toward" if c >= 0 else "against", level, level_text, rank))
    return tuple(out)


def decision_facts(exp: Explanation, index: int = 0, policy: Policy | None = None, k: int = 3) -> DecisionFacts:
    """Facts about state ``index``: the action, runner-up, Q-gap, top-``k`` features for the chosen action and
    for the margin against the runner-up, and the policy plugin's own comparisons."""
    n = len(exp.values)
    if not 0 <= index < n:
        raise InputError(f"index {index} is out of range: the explanation has {n} state(s).")
    if exp.states is None:
        raise InputError("this explanation has no states (it was grouped); narrate the ungrouped explanation.")
    if exp.output != "actions" and exp.values.shape[2] != 1:
        raise InputError(f"this explanation has {exp.values.shape[2]} {exp.output} outputs; narrate one at a time "
                         "(Explanation.output_slice(j)).")
    c, r = int(exp.chosen[index]), int(exp.runner_up[index])
    domain = _domain_facts(policy, np.asarray(exp.states[index]), c, r)
    return DecisionFacts(
        index=index, action=exp.action_names[c], runner_up=exp.action_names[r],
        score=float(exp.outputs[index, c]), runner_up_score=float(exp.outputs[index, r]),
        q_margin=float(exp.outputs[index, c] - exp.outputs[index, r]), base_value=float(exp.base_values[index, c]),
        method=exp.method, additivity_gap=float(exp.additivity_gap[index, c]),
        top=_feature_facts(exp, index, exp.for_chosen()[index], policy, k),
        margin_top=_feature_facts(exp, index, exp.margin()[index], policy, k) if exp.output == "actions" else (),
        comparisons=tuple(domain.comparisons), extras=dict(domain.extras), output=exp.output,
    )


def _domain_facts(policy: Policy | None, state: np.ndarray, chosen: int, runner_up: int) -> DomainFacts:
    """The policy plugin's ``facts_hook`` output, checked for its type."""
    if policy is None or policy.facts_hook is None:
        return DomainFacts()
    out = policy.facts_hook(state, chosen, runner_up)
    if out is None:
        return DomainFacts()
    if not isinstance(out, DomainFacts) or not all(isinstance(c, Comparison) for c in out.comparisons):
        raise PluginError(f"policy '{policy.name}': facts_hook returned {type(out).__name__}; it must return "
                          "xairl.DomainFacts(extras={...}, comparisons=(xairl.Comparison(...), ...)) or None.")
    return out


def global_facts(exp: Explanation, policy: Policy | None = None, k: int = 5) -> GlobalFacts:
    """Ranking by mean |contribution to the chosen action| and the direction of effect of high values."""
    contrib = exp.for_chosen()
    mean_abs = np.abs(contrib).mean(axis=0)
    ranking = []
    for rank, j in enumerate(np.argsort(-mean_abs, kind="stable")[:k], start=1):
        name = exp.feature_names[j]
        info = _info(policy, name)
        effect = "mixed"
        if exp.states is not None and len(contrib) > 2 and np.std(exp.states[:, j]) > 0 and np.std(contrib[:, j]) > 0:
            rho = float(np.corrcoef(exp.states[:, j], contrib[:, j])[0, 1])
            effect = "toward" if rho > 0.3 else "against" if rho < -0.3 else "mixed"
        ranking.append({"name": name, "label": info.description or name, "unit": info.unit, "rank": rank,
                        "mean_abs": float(mean_abs[j]), "high_values": effect})
    return GlobalFacts(len(contrib), exp.method, tuple(ranking))
