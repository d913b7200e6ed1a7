"""FactBook: everything a text may claim about one decision (or, with ``index=None``, about all states), computed
from the Explanation alone."""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from xairl.explanations.explanation import Explanation
from xairl.facts import DomainFacts, decision_facts, global_facts, narration_units, unit_ranks
from xairl.policies.policy import Policy

_CLAIMY = re.compile(
    r"[+\-\u2212]\d|\d\.\d|%|\b(toward|towards|against|raises|lowers|increases|decreases|pushes|"
    r"favours|favors|opposes|mattered most)\b|\b(most important|main|largest|biggest|strongest|top|"
    r"first|second|third)\s+(feature|factor|driver|reason|contributor|influence)s?\b",
    re.IGNORECASE,
)


#: an index in square brackets ('forecast_price[+6h]', 'lag[-1]', 'obs[0,-2]'): whole numbers, signs and letters
_INDEX = re.compile(r"\[[\w+\-\u2212, ]*\]")


def clean_surface(text: str) -> bool:
    """May this name or description hide its words from the verifier? Not if it carries claims itself (a signed or
    decimal number, a percentage, a direction or rank word) outside an index in square brackets: text from data
    files or plugins cannot smuggle claims."""
    return not _CLAIMY.search(_INDEX.sub(" ", text))


@dataclass
class FeatureFacts:
    value: float | None = None
    label: str | None = None  # a categorical value's label
    contribs: dict[str, float] = field(default_factory=dict)  # context ('chosen', 'margin') -> contribution
    ranks: dict[str, int] = field(default_factory=dict)  # context -> rank by |contribution|
    signed_ranks: dict[str, int] = field(default_factory=dict)  # context -> rank among contributions of its sign
    shares: dict[str, float] = field(default_factory=dict)  # context -> % of the sum of |contributions|
    side_shares: dict[str, float] = field(default_factory=dict)  # context -> % of its own side's sum ('57 % of the
    #                                                               positive push')
    net_shares: dict[str, float] = field(default_factory=dict)  # context -> % of the net change, same sign ('43 % of
    #                                                              the net drop')
    fill: float | None = None  # % of the feature's capacity
    quartiles: tuple[float, float, float] | None = None  # the background's 25th, 50th and 75th percentiles
    legend: dict[int, str] = field(default_factory=dict)  # code -> its meaning, from the description's legend
    identifier: bool = False  # an id (kind 'identifier'): its number is its value
    change: float | None = None  # a window's signal: its newest value minus its oldest (xairl.policies.windows)


@dataclass
class FactBook:
    features: dict[str, FeatureFacts]
    output: str  # 'actions', 'continuous' or 'value'
    chosen: str | None
    runner_up: str | None
    scores: dict[str, float]  # every action's (or the output's) score
    margin: float | None
    base: float | None
    decision_numbers: list[float]  # every decision-level number a text may cite
    by_unit: dict[str, list[float]] = field(default_factory=dict)
    global_view: bool = False
    n_states: int = 1
    closed: bool = False  # every number must be one of the facts (a summary made from given facts)
    base_margin: float | None = None  # the margin with no reason either way (the background's average)
    #: sums over all features a text may cite with its cue words ('the positives add up to +0.39', 'the total
    #: absolute attribution of 1.62'): what -> number
    aggregates: dict[str, float] = field(default_factory=dict)

    @property
    def contexts(self) -> tuple[str, ...]:
        return ("chosen", "margin") if self.runner_up else ("chosen",)

    @property
    def in_percent(self) -> bool:
        """One probability-like output given in percent (base 18.4, prediction 46.9 of 'probability that ...'): a
        text may write its numbers as fractions ('p_dropout=0.469', '+0.096')."""
        if self.output == "actions" or self.base is None or self.chosen not in self.scores:
            return False
        score = self.scores[self.chosen]
        return bool(_PROBABILITY.search(self.chosen or "")) and 0 <= self.base <= 100 and 1 < score <= 100


_PROBABILITY = re.compile(r"\b(?:probab\w*|chances?|risk|likelihood|share|percent\w*)\b|%", re.IGNORECASE)
_LEGEND_ENTRY = re.compile(r"^\s*(\d+)\s*[:=]?\s+(\S.*?)\s*$")


def legend(description: str) -> dict[int, str]:
    """A data dictionary's legend of codes in a description: 'savings (1 none, 2 below 100 DM, 3 100 to 500 DM)' ->
    {1: 'none', 2: 'below 100 DM', 3: '100 to 500 DM'}; at least two entries, or one written with '=' ('sex (1 =
    male)'), else none."""
    for inside in re.findall(r"\(([^()]*)\)", description or ""):
        entries = [_LEGEND_ENTRY.match(part) for part in re.split(r"[,;]", inside)]
        if all(entries) and (len(entries) >= 2 or "=" in inside):
            return {int(m.group(1)): m.group(2) for m in entries}
    return {}


def fact_book(exp: Explanation, index: int | None, policy: Policy | None = None) -> FactBook:
    us = narration_units(exp, policy)
    feats = {f: FeatureFacts() for f in exp.feature_names} | {u.name: FeatureFacts() for u in us}
    if index is None:
        return _global_book(exp, policy, feats)
    d = decision_facts(exp, index, policy, k=len(exp.feature_names))
    chosen_i, runner_i = int(exp.chosen[index]), int(exp.runner_up[index])
    deciding = exp.output == "actions" and runner_i != chosen_i
    views = {"chosen": exp.values[index, :, chosen_i]}
    if deciding:
        views["margin"] = exp.values[index, :, chosen_i] - exp.values[index, :, runner_i]
    _add_ranks(feats, views, us, exp.feature_names)
    _add_values(feats, exp, index, policy)
    scores = {a: float(exp.outputs[index, k]) for k, a in enumerate(exp.action_names)}
    base = float(exp.base_values[index, chosen_i])
    numbers = [d.score, base, d.score - base, d.additivity_gap, *scores.values()]
    if deciding:
        numbers += [d.runner_up_score, d.q_margin, d.base_margin]
    book = FactBook(
        feats,
        exp.output,
        d.action,
        d.runner_up if deciding else None,
        scores,
        d.q_margin if deciding else None,
        base,
        numbers,
        base_margin=float(d.base_margin) if deciding else None,
    )
    for ctx, contrib in views.items():
        _add_sums(book, ctx, contrib, exp.feature_names)
    book.aggregates["the number of features"] = float(len(exp.feature_names))
    add_facts(book, DomainFacts(d.extras, d.comparisons))
    return book


def _global_book(exp: Explanation, policy: Policy | None, feats: dict) -> FactBook:
    """The book of a global summary: each feature's mean |contribution|, rank and average direction."""
    g = global_facts(exp, policy, k=len(exp.feature_names))
    for r in g.ranking:
        e = feats[r["name"]]
        e.value = r["mean_abs"]
        e.ranks["chosen"] = r["rank"]
        if r["direction"] != "mixed":  # the direction it pushed on average, in the summary's view
            e.contribs["chosen"] = 1.0 if r["direction"] == "toward" else -1.0
    return FactBook(
        feats, exp.output, None, None, {}, None, None, [float(g.n_states)], global_view=True, n_states=g.n_states
    )


def _add_ranks(feats: dict, views: dict, us, feature_names) -> None:
    """Each feature's contribution, ranks and share in each view, among the narration units (groups narrated as one
    reason, identifiers not ranked); a group's members are ranked among all features."""
    reasons = np.array([u.info.kind != "identifier" for u in us])
    for ctx, contrib in views.items():
        for names, c, ok in (
            ([u.name for u in us], np.array([contrib[list(u.columns)].sum() for u in us]), reasons),
            (feature_names, contrib, np.ones(len(contrib), bool)),
        ):
            rank, signed, share = unit_ranks(c, ok)
            for j, f in enumerate(names):
                e = feats[f]
                if ctx in e.contribs:  # a feature outside any group: its unit's ranks
                    continue
                e.contribs[ctx], e.ranks[ctx], e.signed_ranks[ctx], e.shares[ctx] = (
                    float(c[j]),
                    int(rank[j]) or None,
                    int(signed[j]) or None,
                    float(share[j]),
                )


def _add_values(feats: dict, exp: Explanation, index: int, policy: Policy | None) -> None:
    """Each feature's value at the decision, its fill of a capacity, label, background quartiles, legend and kind."""
    labels = exp.value_labels
    for j, f in enumerate(exp.feature_names):
        info = policy.features.get(f) if policy else None
        if exp.states is not None:
            feats[f].value = float(exp.states[index, j])
            if info is not None and info.capacity is not None:
                feats[f].fill = 100.0 * feats[f].value / info.capacity
        if labels is not None and labels[index, j] is not None:
            feats[f].label = str(labels[index, j])
        if exp.background_quantiles is not None:
            feats[f].quartiles = tuple(float(q) for q in exp.background_quantiles[:, j])
        if info is not None:
            feats[f].legend = legend(info.description)
            feats[f].identifier = info.kind == "identifier"


def _add_sums(book: FactBook, ctx: str, contrib: np.ndarray, names) -> None:
    """The sums over the features in view ``ctx`` ('the positives add up to +0.39') and each feature's share of its
    own side ('57 % of all the positive push') and of the net change when it has the net's sign ('43 % of the net
    drop')."""
    for j, f in enumerate(names):
        side = float(np.abs(contrib[np.sign(contrib) == np.sign(contrib[j])]).sum())
        if side and contrib[j]:
            book.features[f].side_shares[ctx] = 100.0 * abs(float(contrib[j])) / side
        net = float(contrib.sum())
        if net and contrib[j] * net > 0:
            book.features[f].net_shares[ctx] = 100.0 * float(contrib[j]) / net
    of = "" if ctx == "chosen" else " (margin)"
    book.aggregates |= {
        f"the sum of the positive contributions{of}": float(contrib[contrib > 0].sum()),
        f"the sum of the negative contributions{of}": float(contrib[contrib < 0].sum()),
        f"the sum of |contributions|{of}": float(np.abs(contrib).sum()),
        f"the sum of the contributions{of}": float(contrib.sum()),
    }


def add_facts(book: FactBook, facts: DomainFacts) -> None:
    """Domain facts a text may cite: numeric extras anywhere, each comparison's value before its unit."""
    book.decision_numbers += [
        float(v) for v in facts.extras.values() if isinstance(v, (int, float)) and not isinstance(v, bool)
    ]
    book.decision_numbers += [c.value for c in facts.comparisons]
    for c in facts.comparisons:
        if c.unit:
            book.by_unit.setdefault(c.unit.lower(), []).append(c.value)
