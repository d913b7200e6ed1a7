"""Counterfactuals in a report (issue 56): each narrated decision's card gains 'What would have changed it', and the
run a table of how near its decisions lie to another action, feature by feature.

The cards: the narrated decisions are searched in one batch (:func:`xairl.counterfactual`: the smallest change of
at most two features that makes the policy choose its runner-up, every result re-run through the policy), guided by
the report's own explanation of them; each answer is given to the narrator (its template's last sentence, 'Had ...
been ..., the policy would have chosen ...', checked by re-running the policy on the values as written) and travels
in its card's evidence (``evidence['counterfactual']``, :func:`xairl.counterfactual_facts.as_written`), so the review
page shows it as the report does.

The run: for the first :data:`RUN` decisions, every feature that may change (a window's: its newest step's) is tried
alone (``max_changes=1``, ``target='any'``: any other action; one batched search keeps each feature's nearest
flipping value). Per feature and per chosen action: how many decisions a change of that feature alone flips, and the
median change needed, in the feature's unit (a feature with a capacity in % of it) and in percentiles of the
background (its quantile times 100). The rows 'some single feature' and 'no single feature' add up to the decisions
of each action.

Shown for discrete actions of flat, dict or window observations; an image's regions are not searched here (a
search per region costs hundreds of forward passes of the network per decision).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from xairl.counterfactuals import Counterfactuals
from xairl.counterfactuals.show import single_flips
from xairl.explanations.explanation import Explanation
from xairl.numbers import format_number
from xairl.policies.policy import Policy
from xairl.values import value_text

#: decisions of a run tried feature by feature (about 1 ms each for an MLP: one batched search)
RUN = 200


def shown(policy: Policy, exp: Explanation) -> bool:
    """Whether a report shows counterfactuals for ``exp``: discrete actions, states kept, no image."""
    return exp.output == "actions" and exp.states is not None and exp.image_shape is None


def writer(policy: Policy) -> Callable[[str, float], str]:
    """How the cards write a feature's value: as the narratives do ('100 % full', '-85.3 dBm')."""

    def write(feature: str, value: float) -> str:
        info = policy.features.get(feature)
        return value_text(value, info) if info is not None and info.kind != "group" else format_number(value)

    return write


def decisions(
    policy: Policy, exp: Explanation, idx: list[int], background, target=None, max_changes: int = 2
) -> dict[int, Counterfactuals]:
    """Each decision ``idx`` of ``exp``'s counterfactuals (``target``: the runner-up by default; at most
    ``max_changes`` changes), searched in one batch."""
    from xairl.counterfactuals import counterfactual

    if not idx:
        return {}
    found = counterfactual(
        policy,
        exp.states[idx],
        index=None,
        target=target,
        max_changes=max_changes,
        background=background,
        explanation=exp[idx],
        n=3,
    )  # fmt: skip  (n=3: alternatives, so that one still flips once written as the words write it)
    return {i: replace(r, index=i) for i, r in zip(idx, found)}  # numbered as the states of ``exp``


def attach(pairs: list, found: dict[int, Counterfactuals], policy: Policy) -> None:
    """Put each decision's answer into its card's evidence (``(narrative, evidence)`` pairs), written as narrated."""
    from xairl.counterfactual_facts import as_written

    write = writer(policy)
    for n, ev in pairs:
        if n.index in found and ev is not None:  # the values as the sentence writes them, re-run as written
            ev["counterfactual"] = as_written(policy, found[n.index], write)


def flip_rows(policy: Policy, exp: Explanation, background, limit: int = RUN) -> tuple[str, list[str], list[list], str]:
    """(title, header, rows, sentence) of the run's table: per feature, per chosen action, the decisions a change of
    that feature alone flips (share and count) and the median change needed; then the rows 'some single feature',
    'no single feature' and 'decisions'. ``sentence`` says the most frequent one in words."""
    from xairl.counterfactuals import counterfactual
    from xairl.counterfactuals.bounds import units

    k = min(len(exp), limit)
    names = list(units(policy, policy.check_states(background, "background"), None).names)  # any form it takes
    found = counterfactual(
        policy, exp.states[:k], index=None, target="any", max_changes=1, n=max(len(names), 1),
        background=background, explanation=exp[:k],
    )  # fmt: skip
    stats = single_flips(found, names)
    total = Counter(r.chosen for r in found)
    actions = [a for a in exp.action_names if total[a]]
    some = Counter(r.chosen for r in found if any(len(cf.changes) == 1 for cf in r.found))

    def cells(f: str | None, count: int, a: str) -> list[str]:
        one = stats[f].get(a) if f else None
        size = f"{_size(policy, f, one['median_delta'])} ({_points(one['median_quantiles'])})" if one else ""
        return [f"{100 * count / total[a]:.0f} % ({count})", size]

    def row(label: str, counts: dict, f: str | None = None) -> list:
        return [label, *[c for a in actions for c in cells(f, counts.get(a, 0), a)]]

    rows = [
        row(f, {a: s["flips"] for a, s in stats[f].items()}, f) for f in sorted(names, key=lambda f: -_flips(stats[f]))
    ]
    rows.append(row("some single feature", some))
    rows.append(row("no single feature", {a: total[a] - some[a] for a in actions}))
    rows.append(["decisions", *[c for a in actions for c in (str(total[a]), "")]])
    header = [
        "feature changed alone",
        *[h for a in actions for h in (f"{a}: flipped", f"{a}: median change (in percentiles)")],
    ]
    title = (
        f"Distance to another action: how often a change of one feature alone flips the decision ({k} decisions; "
        "each feature tried alone within its bounds, to any other action, every flip re-run through the policy; "
        "share of the decisions of each chosen action, and the median change of those it flips)"
    )
    return title, header, rows, _sentence(policy, stats, total)


def _flips(per_action: dict) -> int:
    return sum(s["flips"] for s in per_action.values())


def _size(policy: Policy, feature: str, delta: float) -> str:
    """A median change in the feature's unit: a feature with a capacity in % of it."""
    if not np.isfinite(delta):
        return ""
    info = policy.features.get(feature)
    if info is not None and info.capacity:
        return f"{format_number(100 * delta / info.capacity, signed=True)} % of capacity"
    return f"{format_number(delta, signed=True)} {info.unit if info is not None else ''}".strip()


def _points(q: float) -> str:
    return f"{format_number(100 * q, signed=True)} percentiles" if np.isfinite(q) else ""


def _sentence(policy: Policy, stats: dict, total: Counter) -> str:
    """The most frequent single flip, in words: 'A change of rsrp_0 alone would flip 53 % of the stay decisions
    (median change -9.57 dBm, -37.1 percentiles of the background).'"""
    share = {(f, a): s["flips"] / total[a] for f in stats for a, s in stats[f].items()}
    if not share:
        return "No decision is flipped by a change of one feature alone within the bounds."
    f, a = max(share, key=lambda fa: (stats[fa[0]][fa[1]]["flips"], share[fa]))  # the most decisions
    one = stats[f][a]
    return (
        f"A change of {f} alone would flip {100 * share[f, a]:.0f} % of the {a} decisions (median change "
        f"{_size(policy, f, one['median_delta'])}, {_points(one['median_quantiles'])} of the background)."
    )
