"""Facts computed by code from an Explanation: the only source of numbers, names and directions in a narrative."""

from __future__ import annotations

import inspect
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from xairl.counterfactual_facts import CounterfactualFact
from xairl.errors import InputError, PluginError
from xairl.explanations.explanation import Explanation
from xairl.numbers import format_number
from xairl.policies.policy import FeatureInfo, Policy
from xairl.policies.windows import Window, real_start, signal_facts, window_of
from xairl.values import fill_and_text, state_value_text, value_level, value_text

__all__ = [
    "Comparison",
    "DecisionFacts",
    "DomainFacts",
    "FeatureFact",
    "GlobalFacts",
    "decision_facts",
    "domain_facts",
    "format_number",
    "global_facts",
    "narration_units",
    "state_value_text",
    "value_level",
    "value_text",
]


@dataclass(frozen=True)
class FeatureFact:
    """One reason's part in a decision: a feature, or a group narrated as one reason (``FeatureInfo(kind='group')``).

    :param name: the feature's (or group's) name; ``label`` its description (or the name); ``unit`` its unit.
    :param value: the feature's value in the state (NaN for a group); ``contribution`` its signed contribution (a
        group's: the sum of its members').
    :param share: |contribution| as a percentage of the sum of |contributions| (features and groups alike).
    :param direction: 'toward' (raises the target: the chosen score, or the margin over the runner-up) or 'against'.
    :param level: 'low', 'typical' or 'high': from the feature's capacity or thresholds when it has them, else from
        the background's quartiles when they are distinct, else 'unknown'; ``level_text`` the feature's own words for
        it (``FeatureInfo.low`` / ``high``, 'typical' or 'moderate'; empty when unknown).
    :param rank: 1 for the largest |contribution| among the reasons (not identifiers); ``rank_same_way`` of its sign.
    :param kind: the feature's ``FeatureInfo.kind``; ``fill`` for one with a capacity its value in % of it, else None.
    :param value_text: the value as a narrative writes it: '-85.3 dBm', '12.0 % full', a category's label, 'mean
        pixel value 33.1' for an image region (:func:`xairl.in_regions`), or empty for a group.
    :param change: for a signal of a window (:mod:`xairl.policies.windows`): its newest value minus its oldest (``value`` is
        its newest); None for other features.
    :param trend: for such a signal: 'rose' or 'fell' when it is said as a trend (its earlier steps carry at least a
        third of its push, and it changed), else ''; ``window`` the span in words ('the last 0.8 s').
    :param change_unit: the unit of ``change``: the feature's, a dBm level's change in dB, and a quantity with a
        capacity changes in 'percentage points' of it (``change`` is then in them too: its level is said in % full).
    :param steps: for such a signal, 'pulled both ways' when its steps' pushes nearly cancel though they weigh as
        much as the largest reason (:func:`xairl.policies.windows.pulled_both_ways`), else ''.
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
    kind: str = "numeric"
    fill: float | None = None
    value_text: str = ""
    change: float | None = None
    trend: str = ""
    window: str = ""
    change_unit: str = ""
    steps: str = ""
    rank_same_way: int = 0


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
    :param top: the ``k`` largest :class:`FeatureFact` by |contribution| to the chosen action's score (the
        chosen-score view: what raised or lowered its Q-value or logit).
    :param margin_top: the same for the margin over the runner-up, ``q_margin``.
    :param reasons: the decision view, why this action and not the runner-up: up to ``k`` reasons whose
        contributions to the margin favour the chosen action, largest first (empty when none does, or when
        nothing was chosen); ``concession`` the reason that favoured the runner-up most (None when none did).
    :param base_margin: the margin expected over the background (chosen minus runner-up base value): what the
        margin is when no reason pushes either way.
    :param identifiers: the identifiers (``FeatureInfo(kind='identifier')``) with their values: context for the words
        ("while on BS 15"), never a reason.
    :param trends: the signals of a window said as trends (:attr:`FeatureFact.trend`), in the decision view (the
        margin; the score when nothing is chosen), largest first, at most ``k``; ``both_ways`` those whose steps
        pulled both ways (:attr:`FeatureFact.steps`), any rank.
    :param comparisons: the plugin's :class:`Comparison` facts; ``extras`` its named values (``DomainFacts``).
    :param output: the policy's output kind. For 'value' and 'continuous' (one dimension at a time) nothing is
        chosen: ``action`` names the output, ``score`` is its value, ``runner_up`` is ``action`` again and
        ``margin_top`` is empty.
    :param counterfactual: what would have changed the decision (:mod:`xairl.counterfactual_facts`), when asked.
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
    reasons: tuple[FeatureFact, ...] = ()
    concession: FeatureFact | None = None
    base_margin: float = 0.0
    identifiers: tuple[FeatureFact, ...] = ()
    trends: tuple[FeatureFact, ...] = ()
    counterfactual: CounterfactualFact | None = None
    both_ways: tuple[FeatureFact, ...] = ()

    def context(self) -> dict[str, Any]:
        """Variables a decision template sees: every field (feature facts as dicts) and ``k``."""
        return asdict(self) | {"extras": dict(self.extras), "k": len(self.top)}


@dataclass(frozen=True)
class GlobalFacts:
    """Over a set of states: the variables every global template sees (``context()``).

    :param n_states: how many states were explained; ``method`` the attributor.
    :param ranking: features by mean |contribution| in ``view`` (the order of the beeswarm and importance plots of
        that view), each a dict with ``name``, ``label``, ``unit``, ``rank``, ``mean_abs``, ``mean`` (the signed mean
        contribution), ``direction`` (the sign of ``mean``: 'toward' raises the target, 'against' lowers it, 'mixed'
        when the mean is under a fifth of ``mean_abs``: it pushed both ways), and ``high_values`` / ``low_values``
        (the same, over the states where the feature's value is above / at most its median; 'mixed' also when its
        values do not vary).
    :param view: what the contributions add up to: 'margin' (the chosen action's score minus the runner-up's, the
        default for discrete actions), 'score' (the chosen action's own score), or 'output' (a value or the first
        dimension of a continuous action: nothing is chosen); ``target`` the same in words ('the margin over the
        runner-up', "the chosen action's score", the output's name).
    """

    n_states: int
    method: str
    ranking: tuple[dict, ...]
    view: str = "margin"
    target: str = "the margin over the runner-up"

    def context(self) -> dict[str, Any]:
        """Variables a global template sees: every field and ``k``."""
        return asdict(self) | {"k": len(self.ranking)}


def _info(policy: Policy | None, name: str) -> FeatureInfo:
    return (policy.features.get(name) if policy else None) or FeatureInfo()


@dataclass(frozen=True)
class Unit:
    """What a narrative names as one reason: a feature, or a group narrated as one (its members' columns)."""

    name: str
    columns: tuple[int, ...]
    info: FeatureInfo
    window: Window | None = None  # a window's signal: its columns are its steps, oldest first


def narration_units(exp: Explanation, policy: Policy | None) -> list[Unit]:
    """The narration units of an explanation: each group narrated as one reason, each signal of a window (over its
    steps), then every feature outside them."""
    index = {f: j for j, f in enumerate(exp.feature_names)}
    out, taken = [], set()
    window = window_of(exp)
    for s, cols in (window.signal_columns() if window else {}).items():
        out.append(Unit(s, tuple(int(j) for j in cols), _info(policy, s), window))
        taken.update(out[-1].columns)
    for g, members in (policy.reason_groups if policy else {}).items():
        cols = tuple(index[f] for f in members if f in index)
        if cols and len(cols) == len(members) and not taken.intersection(cols):
            out.append(Unit(g, cols, policy.features.get(g) or FeatureInfo(kind="group")))  # declared alone too
            taken.update(cols)
    out += [Unit(f, (j,), _info(policy, f)) for j, f in enumerate(exp.feature_names) if j not in taken]
    return out


def unit_ranks(contrib: np.ndarray, reasons: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(rank by |contribution|, rank among contributions of the same sign, % of the sum of |contributions|) per
    unit; ranks count ``reasons`` only (identifiers are context, not reasons) and are 0 for the others."""
    order = [j for j in np.argsort(-np.abs(contrib), kind="stable") if reasons[j]]
    rank = np.zeros(len(contrib), int)
    rank[order] = np.arange(1, len(order) + 1)
    signed = np.zeros(len(contrib), int)
    for sgn in (1, -1):
        for r, j in enumerate([j for j in order if np.sign(contrib[j]) == sgn], 1):
            signed[j] = r
    size = np.abs(contrib)
    size = size / (size.max() or 1.0)  # scaled first: a sum of contributions near 1e308 would overflow
    return rank, signed, 100 * size / (float(size.sum()) or 1.0)


def _feature_facts(exp: Explanation, i: int, contrib: np.ndarray, policy: Policy | None) -> list[FeatureFact]:
    """A :class:`FeatureFact` per narration unit of state ``i`` for ``contrib`` (one value per feature)."""
    us = narration_units(exp, policy)
    c = np.array([float(contrib[list(u.columns)].sum()) for u in us])
    rank, same, share = unit_ranks(c, np.array([u.info.kind != "identifier" for u in us]))
    q = exp.background_quantiles
    labels = exp.value_labels
    regions = (exp.extras or {}).get("regions") or {}  # an image's regions (xairl.in_regions)
    start = int(real_start(exp.states[i : i + 1], w)[0]) if (w := window_of(exp)) else 0  # steps before: padding
    out = []
    for n, u in enumerate(us):
        single = len(u.columns) == 1 or u.window is not None  # a signal's value is its newest
        j = u.columns[-1]
        value = float(exp.states[i, j]) if single else float("nan")
        label = None if not single or labels is None or labels[i, j] is None else str(labels[i, j])
        lvl, words = value_level(value, u.info, None if q is None or not single else (float(q[0, j]), float(q[2, j])))
        fill, text = fill_and_text(value, u.info, label, u.name in regions)
        moved = signal_facts(u, exp.states[i], contrib, start, float(np.abs(c).max()))  # a window's signal: its change
        out.append(
            FeatureFact(
                u.name,
                u.info.description or u.name,
                value,
                u.info.unit,
                float(c[n]),
                float(share[n]),
                "toward" if c[n] >= 0 else "against",
                lvl,
                words,
                int(rank[n]),
                u.info.kind,
                fill,
                text,
                *moved,
                rank_same_way=int(same[n]),
            )
        )
    return out


def _top(facts: list[FeatureFact], k: int) -> tuple[FeatureFact, ...]:
    return tuple(sorted((f for f in facts if f.rank), key=lambda f: f.rank)[:k])


def decision_facts(
    exp: Explanation, index: int = 0, policy: Policy | None = None, k: int = 3, history: np.ndarray | None = None
) -> DecisionFacts:
    """Facts about state ``index``: action, runner-up, Q-gap, top-``k`` reasons for the chosen score and the margin,
    the reasons for the decision, its concession, identifiers as context, the plugin's facts (``history``: the past)."""
    index = exp.check_index(index)
    if exp.states is None:
        raise InputError("this explanation has no states (it was grouped); narrate the ungrouped explanation.")
    if exp.output != "actions" and exp.values.shape[2] != 1:
        raise InputError(
            f"this explanation has {exp.values.shape[2]} {exp.output} outputs; narrate one at a time "
            "(Explanation.output_slice(j))."
        )
    c, r = int(exp.chosen[index]), int(exp.runner_up[index])
    domain = domain_facts(policy, np.asarray(exp.states[index]), c, r, history)
    chosen = _feature_facts(exp, index, exp.for_chosen()[index], policy)
    deciding = exp.output == "actions" and r != c
    margin = _feature_facts(exp, index, exp.margin()[index], policy) if deciding else []
    ranked = _top(margin, len(margin))
    return DecisionFacts(
        index=index,
        action=exp.action_names[c],
        runner_up=exp.action_names[r],
        score=float(exp.outputs[index, c]),
        runner_up_score=float(exp.outputs[index, r]),
        q_margin=float(exp.outputs[index, c] - exp.outputs[index, r]),
        base_value=float(exp.base_values[index, c]),
        method=exp.method,
        additivity_gap=float(exp.additivity_gap[index, c]),
        top=_top(chosen, k),
        margin_top=_top(margin, k),
        comparisons=tuple(domain.comparisons),
        extras=dict(domain.extras),
        output=exp.output,
        reasons=tuple(f for f in ranked if f.contribution > 0)[:k],
        concession=next((f for f in ranked if f.contribution < 0), None),
        base_margin=float(exp.base_values[index, c] - exp.base_values[index, r]) if deciding else 0.0,
        identifiers=tuple(f for f in chosen if f.kind == "identifier"),
        trends=tuple(f for f in (ranked if deciding else _top(chosen, len(chosen)))[:k] if f.trend),
        both_ways=tuple(f for f in (ranked if deciding else _top(chosen, len(chosen))) if f.steps),
    )


def _takes_history(hook) -> bool:
    try:
        params = inspect.signature(hook).parameters
    except (TypeError, ValueError):
        return False
    return "history" in params or any(p.kind is p.VAR_KEYWORD for p in params.values())


def domain_facts(
    policy: Policy | None, state: np.ndarray, chosen: int, runner_up: int, history: np.ndarray | None = None
) -> DomainFacts:
    """The policy plugin's ``facts_hook`` output, checked for its type; ``history`` goes to hooks that take it. An
    image narrated in regions (:mod:`xairl.policies.regions`) has no pixel state to give the hook: it is not called there."""
    if policy is None or policy.facts_hook is None or len(state) != policy.n_features:
        return DomainFacts()
    if history is not None and len(history) and _takes_history(policy.facts_hook):
        out = policy.facts_hook(state, chosen, runner_up, history=policy.check_states(history, "history"))
    else:
        out = policy.facts_hook(state, chosen, runner_up)
    if out is None:
        return DomainFacts()
    if not isinstance(out, DomainFacts) or not all(isinstance(c, Comparison) for c in out.comparisons):
        raise PluginError(
            f"policy '{policy.name}': facts_hook returned {type(out).__name__}; it must return "
            "xairl.facts.DomainFacts(extras={...}, comparisons=(xairl.facts.Comparison(...), ...)) or None."
        )
    return out


def _direction(contrib: np.ndarray) -> str:
    """'toward', 'against' or 'mixed' (empty, or a mean under a fifth of the mean size: both ways) of contributions."""
    if not len(contrib):
        return "mixed"
    mean, size = float(contrib.mean()), float(np.abs(contrib).mean())
    return "mixed" if abs(mean) < 0.2 * size or not size else "toward" if mean > 0 else "against"


def global_facts(exp: Explanation, policy: Policy | None = None, k: int = 5, view: str = "margin") -> GlobalFacts:
    """Features ranked by mean |contribution| in ``view`` ('margin' over the runner-up by default, as the plots rank
    them; 'score': the chosen action's), each with the direction it pushed on average and for high and low values."""
    if window_of(exp) is not None:  # a window is summarised per signal, never slot by slot
        exp = exp.by_signal()
    contrib = exp.contributions(view)[0]
    shown = view if exp.decides else "score" if exp.output == "actions" else "output"
    output = exp.action_names[0] if exp.action_names[0].lower().startswith("the ") else f"the {exp.action_names[0]}"
    target = {"margin": "the margin over the runner-up", "score": "the chosen action's score"}.get(shown, output)
    mean_abs = np.abs(contrib).mean(axis=0)
    ranking = []
    for rank, j in enumerate(np.argsort(-mean_abs, kind="stable")[:k], start=1):
        name = exp.feature_names[j]
        info = _info(policy, name)
        high = low = "mixed"
        if exp.states is not None and np.ptp(exp.states[:, j]) > 0:
            above = exp.states[:, j] > np.median(exp.states[:, j])
            high, low = _direction(contrib[above, j]), _direction(contrib[~above, j])
        ranking.append(
            {
                "name": name,
                "label": info.description or name,
                "unit": info.unit,
                "rank": rank,
                "mean_abs": float(mean_abs[j]),
                "mean": float(contrib[:, j].mean()),
                "direction": _direction(contrib[:, j]),
                "high_values": high,
                "low_values": low,
            }
        )
    return GlobalFacts(len(contrib), exp.method, tuple(ranking), shown, target)
