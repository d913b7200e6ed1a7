"""Helpers of tests/test_counterfactual_words.py: a linear policy whose lines are known, counterfactuals found by brute
force (a dense grid over each feature's range, refined on a second grid; independent of the search), the template's
counterfactual sentence rendered and verified, and its mutations, each checked false by running the policy."""

from __future__ import annotations

import collections
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import torch

from xairl import FeatureInfo, Policy
from xairl.counterfactual_facts import _outward, action_words
from xairl.counterfactuals import Change, Counterfactual, Counterfactuals
from xairl.facts import decision_facts
from xairl.narrators.base import first_phrasings
from xairl.templates import prompts
from xairl.templates.tracking import track_decision
from xairl.values import fill_and_text
from xairl.verification import verify

CAP = 200.0  # the linear policy's queue capacity (kbit): its fill is said in % of it


def linear_policy() -> Policy:
    """stay = 0.05 load, go = -0.2 signal - 16: go wins where 0.05 load < -0.2 signal - 16."""
    lin = torch.nn.Linear(2, 2)
    with torch.no_grad():
        lin.weight.copy_(torch.tensor([[0.05, 0.0], [0.0, -0.2]]))
        lin.bias.copy_(torch.tensor([0.0, -16.0]))
    info = {"load": FeatureInfo("kbit", "the queue", capacity=CAP), "signal": FeatureInfo("dBm", "the signal power")}
    return Policy(lin, ["load", "signal"], ["stay", "go"], features=info, name="lin")


def one_change(policy: Policy, states: np.ndarray, ranges: dict[int, tuple[float, float]], g: int = 801):
    """Per state, the single-feature change nearest its value (as a share of the range) that flips the decision:
    (column, last value that does not flip, first that does), or None; two batched grids per feature."""
    n, states = len(states), np.asarray(states, dtype=float)  # (a float32 grid would move the values it tried)
    chosen, best = policy.act(states), [None] * n
    for j, (lo, hi) in ranges.items():
        grid = np.linspace(lo, hi, g)
        rows = np.repeat(states, g, axis=0)
        rows[:, j] = np.tile(grid, n)
        acts = policy.act(rows).reshape(n, g)
        brackets = []
        for i in range(n):
            idx = np.flatnonzero(acts[i] != chosen[i])
            if not len(idx):
                brackets.append((states[i, j], states[i, j]))
                continue
            k = idx[np.argmin(np.abs(grid[idx] - states[i, j]))]
            near = grid[k - 1] if grid[k] > states[i, j] else grid[min(k + 1, g - 1)]
            inside = near if (near - states[i, j]) * (grid[k] - states[i, j]) > 0 else states[i, j]
            brackets.append((inside, grid[k]))
        fine = np.array([np.linspace(a, b, g) for a, b in brackets])
        rows = np.repeat(states, g, axis=0)
        rows[:, j] = fine.ravel()
        acts = policy.act(rows).reshape(n, g)
        for i in range(n):
            idx = np.flatnonzero(acts[i] != chosen[i])
            if len(idx) and idx[0] > 0:
                # a few fine steps past the line: a float32 network's batch of 801 and a batch of 1 differ by ~1e-6
                after, inside = fine[i, min(idx[0] + 8, g - 1)], fine[i, idx[0] - 1]
                size = abs(after - states[i, j]) / (hi - lo)
                if best[i] is None or size < best[i][0]:
                    best[i] = (size, j, inside, after)
    return [None if b is None else b[1:] for b in best]


def answer(policy: Policy, states: np.ndarray, i: int, changes: dict[int, float]) -> Counterfactuals:
    """The search's answer for state ``i`` with ``changes`` (column -> value), built and run here."""
    x = states[i].astype(float).copy()
    for j, v in changes.items():
        x[j] = v
    a = int(policy.act(x[None])[0])
    s = policy.scores(x[None])[0]
    cs = tuple(Change(policy.feature_names[j], float(states[i, j]), float(v)) for j, v in changes.items())
    cf = Counterfactual(cs, x, policy.action_names[a], float(s[a]), float(s[a] - np.delete(s, a).max()), 0.1, 0.1)
    chosen = policy.action_names[int(policy.act(states[i : i + 1])[0])]
    return Counterfactuals(i, chosen, "any other action", (cf,))


def template(name: str):
    if name == "handover":  # the plugin's own file (its prompt folder is found through its entry point)
        uav = pytest.importorskip("xairl_uav_handover.policy")
        return prompts.load(Path(uav.__file__).parent / "prompts" / "handover.yaml")
    return prompts.load(name)


#: the head of a sentence of one's own ('{{ c.label }}' and the rest): the fact as ``cf``, its first change as ``c``
OWN = "{% if counterfactual %}{% set cf = counterfactual %}{% set c = cf.changes[0] %}"
#: the built-in sentence of one change
HAD = "Had {{ c.label }} been {{ c.direction ~ ' ' if c.direction }}{{ c.after_text }} (it was {{ c.value_text }}), "


def said(exp, i, policy, fact, name="explain_action", check_policy="same", alone=False, sentence=None, head=OWN):
    """(text, status of its counterfactual sentence, verification) of template ``name`` rendered with ``fact``;
    ``alone``: its last sentence only (the counterfactual's), rendered and checked on its own; ``sentence``: that
    sentence replaced by this one (after ``head``), rendered and checked alone."""
    tpl = template(name)
    if alone or sentence is not None:
        own = [[head + sentence + "{% endif %}"]] if sentence is not None else tpl.spec.sentences[-1:]
        tpl = replace(tpl, spec=tpl.spec.model_copy(update={"sentences": own}), lines=tpl.lines[-1:])
    facts = replace(decision_facts(exp, i, policy, 3), counterfactual=fact)
    text = first_phrasings(tpl.render_variants(track_decision(facts.context())))
    v = verify(text, exp, i, policy if check_policy == "same" else check_policy, provenance=text.spans)
    last = v.sentences if sentence is not None else [s for s in v.sentences if s.text.startswith("Had ")]
    assert len(last) == 1, text
    return text, last[0].status, v


def at(policy: Policy, c, value: float):
    """Change fact ``c`` stating ``value`` (in the feature's unit), written as narratives write it."""
    info = policy.features.get(c.name) or FeatureInfo()
    fill, text = fill_and_text(value, info, None)
    return replace(c, after=value, after_text=text, after_fill=fill)


def flips_to(policy: Policy, state: np.ndarray, fact) -> bool:
    """The fact's claim is true: the policy, on the state with its stated changes, takes its stated action."""
    x = state.astype(float).copy()
    for c in fact.changes:
        x[policy.feature_names.index(c.name)] = c.after
    a = int(policy.act(x[None])[0])
    return policy.action_names[a] == fact.action and fact.action != fact.chosen


def mutants(policy: Policy, state: np.ndarray, fact, line: tuple[float, float] | None):
    """(kind, mutated fact) pairs whose claim is false (each checked by running the policy here)."""
    c, out = fact.changes[0], []
    info = policy.features.get(c.name) or FeatureInfo()
    if line is not None:  # the last value that does not flip, and the state's value
        inside = line[0]
        out.append(("threshold by a margin", fact, at(policy, c, inside + 0.5 * (c.value - inside))))
        down = c.direction == "above"  # rounded toward the state: one written digit across the line
        cross = _outward(100 * inside / info.capacity, down) * info.capacity / 100 if info.capacity else None
        out.append(("threshold just across", fact, at(policy, c, _outward(inside, down) if cross is None else cross)))
    for a in policy.action_names:
        if a != fact.action:
            out.append(("wrong action", replace(fact, action=a, action_words=action_words(policy, a)), None))
    numeric = [
        k for k, f in enumerate(policy.feature_names) if (policy.features.get(f) or FeatureInfo()).kind == "numeric"
    ]
    same = [
        k
        for k in numeric
        if policy.feature_names[k] != c.name
        and (policy.features.get(policy.feature_names[k]) or FeatureInfo()).unit == c.unit
    ]
    for k in (same + [k for k in numeric if k not in same and policy.feature_names[k] != c.name])[:3]:
        other = policy.feature_names[k]
        o = policy.features.get(other) or FeatureInfo()
        renamed = replace(c, name=other, label=o.description or other)
        out.append(("wrong feature", fact, renamed))
        out.append(
            ("wrong feature and its value", fact, replace(renamed, value_text=fill_and_text(state[k], o, None)[1]))
        )
    wrong = fill_and_text(c.value + 0.5 * (c.after - c.value), info, None)[1]
    out.append(("wrong 'it was'", fact, replace(c, value_text=wrong)))
    out.append(("wrong direction", fact, replace(c, direction="above" if c.direction == "below" else "below")))
    out.append(("wrong margin", replace(fact, margin=fact.margin + max(1.0, abs(fact.margin))), None))
    if len(fact.changes) > 1:
        out.append(("a change left out", replace(fact, changes=fact.changes[:1]), "keep"))
    for kind, f, change in out:
        m = f if change in (None, "keep") else replace(f, changes=(change, *f.changes[1:]))
        if kind not in ("wrong 'it was'", "wrong direction", "wrong margin", "wrong feature") and flips_to(
            policy, state, m
        ):
            continue  # a true claim, however it was made: no mutation
        yield kind, m


def text_mutants(policy: Policy, fact, line: tuple[float, float] | None):
    """(kind, sentence of one's own) that must be contradicted: the template's *words* mutated, with the fact right:
    its values swapped, a wrong threshold written as a literal number, the action taken said as the new one, the
    claim negated, the threshold said as a fact of the state."""
    c, then = fact.changes[0], "the policy would have chosen {{ cf.action }} (margin {{ cf.margin|num }})."
    word = c.direction + " " if c.direction else ""
    out = [
        (
            "swapped roles",
            f"Had {{{{ c.label }}}} been {word}{{{{ c.value_text }}}} (it was {{{{ c.after_text }}}}), {then}",
        ),
        ("the action taken as the new one", HAD + "the policy would have chosen {{ cf.chosen }}."),
        ("negated", HAD + "the policy would not have chosen {{ cf.action }}."),
        (
            "said as a fact of the state",
            "{{ c.label|cap }} was {{ c.after_text }}, so the policy chose {{ cf.action }}.",
        ),
    ]
    if line is not None and not (policy.features.get(c.name) or FeatureInfo()).categories:
        wrong = at(policy, c, line[0] + 0.5 * (c.value - line[0])).after_text
        out.append(
            (
                "literal threshold",
                f"Had {{{{ c.label }}}} been {word}{wrong} (it was {{{{ c.value_text }}}}), {then}",
            )
        )
    return out


def corpus(policy, exp, states, facts, lines, template="explain_action"):
    """Every correct rendering verified, every mutation contradicted: (correct, Counter of mutations by kind,
    Counter of those the re-run itself contradicted: the stated values or action, not a word or 'it was')."""
    counts, rerun, n_ok = collections.Counter(), collections.Counter(), 0
    for i, fact in facts.items():
        text, status, v = said(exp, i, policy, fact, template)
        assert status == "verified" and v.accurate, (text, v.problems())
        n_ok += 1
        for kind, m in mutants(policy, states[i], fact, lines.get(i)):
            text, status, v = said(exp, i, policy, m, template, alone=True)
            assert status == "contradicted", (kind, text)
            counts[kind] += 1
            rerun[kind] += any(c.status == "contradicted" and "re-run" in c.detail for c in v.claims)
        for kind, body in text_mutants(policy, fact, lines.get(i)) if len(fact.changes) == 1 else ():
            text, status, v = said(exp, i, policy, fact, template, sentence=body)
            assert status == "contradicted", (kind, text)
            counts[f"text: {kind}"] += 1
            rerun[f"text: {kind}"] += any(c.status == "contradicted" and "re-run" in c.detail for c in v.claims)
    return n_ok, counts, rerun


def caught_by_the_rerun(name: str, n_ok: int, counts, rerun) -> None:
    """A threshold on the wrong side, another action, a change left out: the re-run itself contradicts them."""
    print(f"{name}: {n_ok} verified; {sum(counts.values())} mutations contradicted, {sum(rerun.values())} of them "
          f"by the re-run; by kind (contradicted, by the re-run): {({k: (v, rerun[k]) for k, v in counts.items()})}")  # fmt: skip
    every = ("threshold by a margin", "threshold just across", "wrong action", "a change left out")
    for kind in (*every, "text: swapped roles", "text: literal threshold", "text: the action taken as the new one"):
        assert rerun[kind] == counts[kind], kind
