"""The check of a counterfactual sentence (issue 56) by running the policy on what it states.

'Had the uplink buffer been below 37.6 % full (it was 100 % full), the DQN would have chosen to hand over to
candidate 2 (margin 4.2)' is read from its tracked spans (:func:`xairl.tracking.track_counterfactual`: each span
knows which change of the fact it printed, but its *text* is what is checked): the feature each change names (its
name, description or an alias), the value it states (a fill in % of the capacity turned back into the feature's
unit, a category's label into its code), the direction word ('below', 'above': tracked, or the template's own word
right before the value) and the 'it was' value. The state of the decision with every stated feature set to its
stated value, the others as they were, is run through the policy (its action mask honoured), and:

- the stated action must be the one the policy takes there, and not the one it took (else the action and the stated
  values are contradicted: a threshold on the wrong side of the line, a wrong feature, a wrong action);
- the stated margin must be that action's score minus the best other available one's, as written;
- a direction word must point from the state's value to the stated one, and 'it was' must be the state's value.

Without the policy, or without the state as its input (an image narrated in regions), nothing of it is checked:
its claims are 'unchecked', never 'verified'. The 'nothing within the bounds' sentence states the search's answer,
which a single re-run cannot check: unchecked too.
"""

from __future__ import annotations

import re

import numpy as np

from ...counterfactual_facts import NOISE
from ...policy import FeatureInfo
from ..verify import Claim
from .parts import Part
from .truth import Truth, close, number

RULE = "tracked.counterfactual"
_BELOW = re.compile(r"\b(?:below|under|less than|lower than|smaller than|at most|beneath)\s*$", re.I)
_ABOVE = re.compile(r"\b(?:above|over|more than|higher than|greater than|larger than|at least|exceed\w*)\s*$", re.I)
_STATED = ("after_text", "after", "after_fill")  # the value it would need
_WAS = ("value_text", "value", "fill")  # the value it had


def is_counterfactual(p: Part) -> bool:
    return p.span is not None and p.span.fact.quantity.startswith("cf_")


def _claim(p: Part, kind: str, status: str, detail: str) -> Claim:
    return Claim(kind, p.span.text, status, detail, RULE, span=p.span)


def _said(text: str) -> str:
    return " ".join(text.lower().split()).strip(" .,;:'\"")


def _feature(policy, text: str, meant: str | None = None) -> int | None:
    """The feature a text names: its name, description or an alias (None when it names none); of several that share
    the words, the one the span was printed from (``meant``)."""
    said, named = _said(text), []
    for j, f in enumerate(policy.feature_names):
        info = policy.features.get(f) or FeatureInfo()
        if said in {_said(w) for w in (f, info.description, *info.aliases) if w}:
            named.append(j)
    return next((j for j in named if policy.feature_names[j] == meant), named[0] if named else None)


def _action(policy, text: str) -> int | None:
    """The action a text names: its name, or an alias no other action has."""
    said = _said(text)
    named = [k for k, a in enumerate(policy.action_names) if _said(a) == said]
    aliased = [k for k, a in enumerate(policy.action_names) if said in map(_said, policy.action_aliases.get(a, ()))]
    return named[0] if named else aliased[0] if len(aliased) == 1 else None


def _percent(text: str, quantity: str, after: str) -> bool:
    """A value written as a percentage of its capacity: a 'fill', or a number with '%' after it."""
    return quantity.endswith("fill") or "%" in text or after.lstrip().startswith("%")


def _value(text: str, info: FeatureInfo, quantity: str, after: str) -> float | None:
    """A stated value in the feature's own unit: a category's label as its code, a percentage of a capacity as its
    share of it."""
    if info.categories and _said(text) in map(_said, info.categories):
        return float([_said(c) for c in info.categories].index(_said(text)))
    x = number(text)
    if x is None or info.capacity is None or not _percent(text, quantity, after):
        return x
    return x * info.capacity / 100.0


def check_counterfactual(s, cf: list[Part], truth: Truth) -> list[Claim]:
    """The claims of the counterfactual spans ``cf`` of sentence ``s`` (a :class:`.spans.Sentence`), checked by
    running the policy on the state they state (module doc)."""
    if not cf:
        return []
    policy, state = truth.policy, truth.state
    if policy is None or state is None or truth.output != "actions":
        return [_claim(p, "number", "unchecked", "no policy and state to re-run the stated change") for p in cf]
    changes: dict[int, dict[str, list[Part]]] = {}
    rest = []
    for p in cf:
        role = p.span.fact.role or ""
        if role.startswith("change:"):
            changes.setdefault(int(role[7:]), {}).setdefault(p.span.fact.quantity[3:], []).append(p)
        else:
            rest.append(p)
    claims, stated = [], []
    for parts in changes.values():
        claims += _change(s, parts, policy, state, stated)
    return claims + _rerun(rest, policy, state, stated, truth)


def _was(s, p: Part, q: str, info: FeatureInfo, before: float) -> Claim:
    """'it was ...': the state's value, as written."""
    printed, percent = number(p.span.text), _percent(p.span.text, q, s.after(p, 3))
    if info.categories:
        ok = _value(p.span.text, info, q, "") == before
    elif printed is not None and info.capacity is not None and percent:
        ok = close(printed, 100 * before / info.capacity, p.span.text)
    else:
        ok = printed is not None and close(printed, before, p.span.text)
    return _claim(p, "number", "verified" if ok else "contradicted", f"it was {before:.4g}")


def _change(s, parts: dict[str, list[Part]], policy, state: np.ndarray, stated: list) -> list[Claim]:
    """One change's claims (its feature, direction, 'it was' value); (column, stated value, its spans) goes into
    ``stated`` (column or value None when the words do not say them)."""
    claims, names = [], parts.get("name", []) + parts.get("label", [])
    cols = [_feature(policy, p.span.text, p.span.fact.feature) for p in names]
    for p, j in zip(names, cols):
        ok = j is not None and j == cols[0]
        claims.append(_claim(p, "feature", "verified" if ok else "contradicted", "a feature of the policy"))
    j = cols[0] if names else _feature(policy, next(iter(parts.values()))[0].span.fact.feature or "")
    values = [(q, p) for q in _STATED for p in parts.get(q, [])]
    if j is None:
        stated.append((None, None, [p for _, p in values]))
        return claims
    info, before = policy.features.get(policy.feature_names[j]) or FeatureInfo(), float(state[j])
    claims += [_was(s, p, q, info, before) for q in _WAS for p in parts.get(q, [])]
    after = {_value(p.span.text, info, q, s.after(p, 3)) for q, p in values}
    value = after.pop() if len(after) == 1 else None  # (two spans stating two values: no value)
    stated.append((j, value, [p for _, p in values]))
    if values and value is not None:
        word = parts["direction"][0] if parts.get("direction") else values[0][1]
        sign = -1 if _BELOW.search(word.span.text if parts.get("direction") else s.before(word, 24)) else 0
        sign = sign or (1 if _ABOVE.search(word.span.text if parts.get("direction") else s.before(word, 24)) else 0)
        if sign:
            ok = (value - before) * sign > 0
            claims.append(_claim(word, "direction", "verified" if ok else "contradicted", f"from {before:.4g}"))
    return claims


def _rerun(rest: list[Part], policy, state: np.ndarray, stated: list, truth: Truth) -> list[Claim]:
    """The stated change run through the policy: the stated values (they change the decision), the action (the one
    taken there) and the margin (its score minus the best other available one's)."""
    acts = [p for p in rest if p.span.fact.quantity in ("cf_action", "cf_action_words")]
    margins = [p for p in rest if p.span.fact.quantity == "cf_margin"]
    others = [p for p in rest if p not in acts and p not in margins]
    claims = [_claim(p, "number", "unchecked", "the search's answer: one re-run cannot check it") for p in others]
    values = [p for _, _, spans in stated for p in spans]
    if not stated or any(j is None or v is None for j, v, _ in stated):
        why = "no change stated" if not stated else "a stated change names no feature or no value"
        status = "unchecked" if not stated else "contradicted"
        return claims + [_claim(p, "action", status, why) for p in acts + margins + values]
    x = np.array(state, dtype=float)
    x[[j for j, _, _ in stated]] = [v for _, v, _ in stated]
    scores = policy.scores(x[None])[0]
    free = np.where(policy.available(x[None])[0], scores, -np.inf)
    taken, chosen = int(free.argmax()), policy.action_names.index(truth.actions["chosen"])
    said = [_action(policy, p.span.text) for p in acts]
    target = said[0] if said and said[0] is not None else taken
    how = ", ".join(f"{policy.feature_names[j]} = {v:.6g}" for j, v, _ in stated)
    how = f"re-run with {how}: the policy takes {policy.action_names[taken]}"
    for p in values:
        ok = taken != chosen
        claims.append(_claim(p, "number", "verified" if ok else "contradicted", how + ("" if ok else ", as it did")))
    for p, a in zip(acts, said):
        claims.append(_claim(p, "action", "verified" if a == taken != chosen else "contradicted", how))
    others_best = np.delete(free, target).max() if len(free) > 1 else -np.inf
    margin = float(scores[target] - others_best)
    for p in margins:
        printed, noise = number(p.span.text), NOISE * max(1.0, float(np.abs(scores).max()))
        ok = printed is not None and np.isfinite(margin)
        ok = ok and (close(printed, margin, p.span.text) or abs(printed - margin) <= noise)  # (batch shape's bits)
        claims.append(_claim(p, "number", "verified" if ok else "contradicted", f"{how}; margin {margin:.4g}"))
    return claims
