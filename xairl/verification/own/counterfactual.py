"""The check of a counterfactual sentence (issue 56): read its structure, then run the policy on what it states.

'Had the uplink buffer been below 37.6 % full (it was 100 % full), the DQN would have chosen to hand over to
candidate 2 (margin 4.2)' is read from its words: each value takes the slot the words before it give it, the
*hypothetical* one ('had X been [below] V', 'if X were V', 'with X at V') or the *actual* one ('it was V'), and is
the value of the feature named last before it. A sentence with no counterfactual form states facts of the state.

The state with every hypothetical value set is run through the policy (its mask honoured), after the world's
constraints (:func:`xairl.counterfactual_facts.broken`): the values are verified when the policy then decides
otherwise; the consequent, read only as 'would have chosen/taken/picked/selected (to) X', 'would have handed over
to X' or 'would choose/take X', must be the action it takes there (negated, contradicted only when it is); the
stated margin is that action's lead; a direction word points from the state's value to the hypothetical one. Any
other 'would' leaves the sentence unchecked, never verified. Without the policy or the state as its input nothing
is checked; a sentence that nothing would have changed the decision states a search's miss: unchecked.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace

import numpy as np

from xairl.counterfactual_facts import NOISE, broken, feature_words, lead
from xairl.policies.policy import FeatureInfo
from xairl.verification.own.lexicon import NUMBER
from xairl.verification.own.parts import Part
from xairl.verification.own.truth import Truth, close, number
from xairl.verification.result import COUNTERFACTUAL, Claim

RULE = COUNTERFACTUAL
_BELOW = r"below|under|less than|lower than|smaller than|at most|beneath"
_ABOVE = r"above|over|more than|higher than|greater than|larger than|at least|exceed\w*"
#: the forms that make a sentence counterfactual (any 'would': its consequent must then be one that :data:`WOULD` reads)
FORM = re.compile(r"\bhad\b.+?\bbeen\b|\bif\b.+?\bwere\b|\bwould", re.I | re.S)
#: the one grammar of a consequent (module doc): 'would have chosen X', 'would have handed over to X', 'would choose X';
#: negated ('would not have chosen X'): contradicted when X is what it takes there, else unchecked, never verified
WOULD = re.compile(
    r"\bwould(?P<neg>\s+not|\s+never|n't)?\s+(?:have\s+(?:chosen|taken|picked|selected)(?:\s+to)?|have\s+(?P<over>handed\s+over\s+to)|"
    r"(?:choose|take)(?:\s+to)?)\s+(?P<x>[^(),.;:!?]+?)\s*(?=[(),.;:!?]|$)",
    re.I,
)
_HYPO = re.compile(rf"\b(?:been|were|at|to)\s+(?:(?P<dir>{_BELOW}|{_ABOVE})\s+)?$", re.I)
_ACTUAL = re.compile(rf"\b(?:was|is|are|were|now|currently|at)\s+(?:(?P<dir>{_BELOW}|{_ABOVE})\s+)?$", re.I)
#: a clause that says the action taken: the action right after one of these verbs (and no 'would' in its clause)
_CHOSE = re.compile(r"\b(?:chose|chooses|took|takes|picked|selected|preferred)\s+(?:to\s+)?$", re.I)
_VALUES = ("after_text", "after", "after_fill", "value_text", "value", "fill")
_ACTIONS = ("action", "action_words", "chosen", "target")
_MISS = "a search's miss is no proof (it tries a grid of changes): no re-run can check that nothing would flip it"


def is_counterfactual(p: Part) -> bool:
    return p.span is not None and p.span.fact.quantity.startswith("cf_")


@dataclass
class _Value:
    """A value the sentence states: where, its text, its tracked span (None for a number the template wrote)."""

    start: int
    end: int
    text: str
    part: Part | None
    slot: str = ""  # 'hypo', 'actual' or '' (not said as either)
    sign: int = 0  # -1 'below', +1 'above', 0 none
    dir_at: int = -1  # where its direction word starts
    col: int | None = None
    x: float | None = None


def _claim(p: Part | None, kind: str, status: str, detail: str, text: str = "") -> Claim:
    return Claim(kind, p.span.text if p is not None else text, status, detail, RULE, span=p.span if p else None)


def _said(text: str) -> str:
    return " ".join(text.lower().split()).strip(" .,;:'\"")


def _forms(policy) -> dict[str, set[int]]:
    """Every feature's words (lower case) -> the columns they name: its name, and its description and aliases,
    or for a window's past slot its own words ('the speed 2 steps ago'), which the signal's words do not name."""
    out: dict[str, set[int]] = {}
    for j, f in enumerate(policy.feature_names):
        info = policy.features.get(f) or FeatureInfo()
        words = feature_words(policy, f)
        own = (f, words) if words.endswith(" ago") else (f, info.description, *info.aliases)
        for w in own:
            if w and _said(w):
                out.setdefault(_said(w), set()).add(j)
    return out


def _named(forms: dict[str, set[int]], text: str) -> tuple[int, int | None]:
    """(where, column) of the feature ``text`` names last (None for words that name several); (-1, None) if none."""
    low, best = text.lower(), (-1, 0, None)
    for form, cols in forms.items():
        for m in re.finditer(rf"(?<!\w){re.escape(form)}(?!\w)", low):
            if (m.end(), len(form)) > best[:2]:
                best = (m.end(), len(form), next(iter(cols)) if len(cols) == 1 else None)
    return best[0], best[2]


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


def _values(s, cf: list[Part], policy, counterfactual: bool) -> list[_Value]:
    """Every value the sentence states (tracked, or numbers written in its words), each with its slot, direction,
    feature and value in the feature's unit."""
    vals = [_Value(p.start, p.end, p.span.text, p) for p in cf if p.span.fact.quantity[3:] in _VALUES]
    for p in (q for q in s.parts if q.span is None):
        vals += [
            _Value(p.start + m.start(), p.start + m.end(), m.group(), None)
            for m in NUMBER.finditer(s.text[p.start : p.end])
        ]
    vals.sort(key=lambda v: v.start)
    forms, prev = _forms(policy), 0
    for v in vals:
        before = s.text[prev : v.start]
        hypo, actual = _HYPO.search(before), _ACTUAL.search(before)
        m = (hypo if hypo else actual) if counterfactual else (actual or hypo)
        # no counterfactual form: every value is said of the state (a number written there only after 'was', 'at')
        v.slot = ("hypo" if counterfactual and m is hypo else "actual") if m else ""
        v.slot = v.slot or ("actual" if not counterfactual and v.part is not None else "")
        if m and m["dir"]:
            v.sign, v.dir_at = (-1 if re.fullmatch(_BELOW, m["dir"], re.I) else 1), prev + m.start("dir")
        prev = v.end
        where, v.col = _named(forms, s.text[: v.start])
        if v.col is not None:
            info = policy.features.get(policy.feature_names[v.col]) or FeatureInfo()
            quantity = v.part.span.fact.quantity if v.part else ""
            v.x = _value(v.text, info, quantity, s.text[v.end : v.end + 3])
    return [v for v in vals if v.part is not None or v.slot]  # (a number the words give no slot: the reader's)


def check_counterfactual(s, cf: list[Part], truth: Truth) -> list[Claim]:
    """The claims of the counterfactual spans ``cf`` of sentence ``s`` (a :class:`.spans.Sentence`), and of the
    values its words state, checked by running the policy on the state it states (module doc)."""
    if not cf:
        return []
    policy, state = truth.policy, truth.state
    if policy is None or state is None or truth.output != "actions":
        return [_claim(p, "number", "unchecked", "no policy and state to re-run the stated change") for p in cf]
    counterfactual = bool(FORM.search(s.text))
    vals = _values(s, cf, policy, counterfactual)
    forms = _forms(policy)
    claims = []
    for p in cf:
        q = p.span.fact.quantity[3:]
        if q in ("label", "name"):
            ok = len(forms.get(_said(p.span.text), ())) == 1
            claims.append(_claim(p, "feature", "verified" if ok else "contradicted", "a feature of the policy"))
        elif q in ("max_changes", "reason", "reachable"):
            claims.append(_claim(p, "number", "unchecked", _MISS))
    claims += [_actual(s, v, policy, state) for v in vals if v.slot == "actual"]
    claims += [
        _claim(v.part, "number", "unchecked", "not said as the value it had nor the one it would need")
        for v in vals
        if not v.slot
    ]
    hypo, (acts, why) = [v for v in vals if v.slot == "hypo"], _said_actions(s, cf, policy)
    claims += _rerun(cf, hypo, acts, policy, state, truth, counterfactual)
    why = why or ("" if any(slot == "would" for *_, slot in acts) else "no action after 'would have chosen'")
    # its change or its consequent unread ('been storm', 'would likely have picked stay'): its other claims, true as
    # they may be, do not verify what it says
    if counterfactual and (not hypo or why):
        unread = "what it says would have been, or been done, was not read: " + (
            "no value after 'had ... been', 'if ... were', 'with ... at'" if not hypo else why
        )
        claims = [replace(c, status="unchecked", detail=unread) if c.status == "verified" else c for c in claims]
    return claims


def _actual(s, v: _Value, policy, state: np.ndarray) -> Claim:
    """A value said of the state ('it was ...', 'the queue was ...'): the state's value, as written."""
    if v.col is None or v.x is None:
        return _claim(v.part, "number", "contradicted", "a value of no feature the sentence names", v.text)
    before = float(state[v.col])
    info = policy.features.get(policy.feature_names[v.col]) or FeatureInfo()
    if v.sign:
        ok = (before - v.x) * v.sign > 0
    elif info.categories:
        ok = v.x == before
    elif info.capacity is not None and _percent(
        v.text, v.part.span.fact.quantity if v.part else "", s.text[v.end : v.end + 3]
    ):
        ok = close(100 * v.x / info.capacity, 100 * before / info.capacity, v.text)
    else:
        ok = close(v.x, before, v.text)
    what = f"{policy.feature_names[v.col]} was {before:.4g}"
    return _claim(v.part, "number", "verified" if ok else "contradicted", what, v.text)


def _lookup(policy) -> dict[str, int | None]:
    """Every action's name and alias (lower case; not a bare number, which is a value) -> the action it names (None
    for an alias several actions share)."""
    out: dict[str, int | None] = {}
    for a, name in enumerate(policy.action_names):
        for w in (name, *policy.action_aliases.get(name, ())):
            if w and not NUMBER.fullmatch(w.strip()):
                out[_said(w)] = a if out.get(_said(w), a) == a else None
    return out


def _said_actions(s, cf: list[Part], policy) -> tuple[list[tuple[Part | None, str, int | None, str]], str]:
    """(its span or None, its text, the action it names, its slot) per action the sentence names, and why its
    actions were not read ('' when they were): the action of each consequent :data:`WOULD` reads (slot 'would'),
    one right after 'chose' in a clause without 'would' ('chose'), and the others (''); every other 'would', and
    every action named outside those two places, leave it unread (module doc)."""
    text, names, out, spans, why = s.text, _lookup(policy), [], [], ""
    for m in WOULD.finditer(text):
        x, at = m["x"], m.start("x")
        a = names.get(_said(("hand over to " if m["over"] else "") + x))
        part = next((p for p in cf if p.start <= at < p.end), None)
        tracked = part is not None and part.span.fact.quantity[3:] in _ACTIONS and part.end >= m.end("x")
        if a is not None or tracked:  # (a tracked field there that names no action, 'the runner-up': wrong)
            out.append((part, x, a, "not" if m["neg"] else "would"))
            spans.append((m.start(), m.end()))
    if any(not any(a <= w.start() < b for a, b in spans) for w in re.finditer(r"\bwould", text, re.I)):
        why = "a 'would' in a form the check does not read (it reads 'would have chosen X', 'would choose X')"
    if not names:
        return out, why
    named = re.compile("|".join(rf"(?<!\w){re.escape(w)}(?!\w)" for w in sorted(names, key=len, reverse=True)), re.I)
    for m in named.finditer(text):
        if any(a <= m.start() < b for a, b in spans):
            continue
        clause, a = re.split(r"[,;()]", text[: m.start()])[-1], names[_said(m.group())]
        part = next((p for p in cf if p.start <= m.start() < p.end), None)
        taken = a is not None and _CHOSE.search(clause) and not re.search(r"\bwould", clause, re.I)
        out.append((part, m.group(), a, "chose" if taken else ""))
        if not taken:
            why = (
                why or f"'{m.group()}' is neither the action it would take ('would have chosen X') nor the one it took"
            )
    seen = {id(p) for p, *_ in out}
    out += [(p, p.span.text, None, "") for p in cf if p.span.fact.quantity[3:] in _ACTIONS and id(p) not in seen]
    return out, why


def _rerun(
    cf, hypo: list[_Value], acts: list, policy, state: np.ndarray, truth: Truth, counterfactual: bool
) -> list[Claim]:
    """The stated change run through the policy: the hypothetical values (they change the decision, within the
    world's constraints), the actions named (the one taken there) and the margin (module doc)."""
    chosen = policy.action_names.index(truth.actions["chosen"])
    margins = [p for p in cf if p.span.fact.quantity == "cf_margin"]
    claims = _taken(acts, chosen, truth.actions["chosen"])
    acts = [a for a in acts if a[3] in ("would", "not")]
    stated = {}
    for v in hypo:
        stated.setdefault(v.col, set()).add(v.x)
    if not counterfactual or not hypo or None in stated or any(None in xs or len(xs) > 1 for xs in stated.values()):
        why = "no change stated" if not hypo else "a stated change names no feature, or not one value"
        status = "unchecked" if not hypo else "contradicted"
        claims += [_claim(p, "action", status, why, t) for p, t, _, _ in acts]
        claims += [_claim(p, "number", status, why) for p in margins]
        return claims + [_claim(v.part, "number", status, why, v.text) for v in hypo]
    x = np.array(state, dtype=float)
    x[list(stated)] = [xs.pop() for xs in stated.values()]
    scores, avail = policy.scores(x[None])[0], policy.available(x[None])[0]
    taken = int(np.where(avail, scores, -np.inf).argmax())
    why = broken(policy, x[None], [list(stated)])[0]
    how = ", ".join(f"{policy.feature_names[j]} = {x[j]:.6g}" for j in stated)
    how = f"re-run with {how}: " + (why if why else f"the policy takes {policy.action_names[taken]}")
    for v in hypo:
        ok = taken != chosen and not why
        detail = how + ("" if ok or why else ", as it did")
        claims.append(_claim(v.part, "number", "verified" if ok else "contradicted", detail, v.text))
        if v.sign:
            ok = (v.x - float(state[v.col])) * v.sign > 0
            p = next((q for q in cf if q.start <= v.dir_at < q.end), v.part)
            claims.append(
                _claim(p, "direction", "verified" if ok else "contradicted", f"from {state[v.col]:.4g}", v.text)
            )
    for p, t, a, slot in acts:
        if slot == "not":
            status = "contradicted" if a == taken and not why else "unchecked"
            claims.append(_claim(p, "action", status, how + "; 'would not have' is never verified", t))
        else:
            claims.append(
                _claim(p, "action", "verified" if a == taken != chosen and not why else "contradicted", how, t)
            )
    said = next(
        (a for _, _, a, slot in acts if slot == "would" and a is not None), None
    )  # (the margin is the stated action's)
    if said is None:
        return claims + [_claim(p, "number", "unchecked", "no action stated: whose margin?") for p in margins]
    return claims + _margins(margins, scores, lead(scores, avail, said), how)


def _taken(acts: list[tuple], chosen: int, name: str) -> list[Claim]:
    """The claims of the actions said as the one taken ('it chose stay'), and of those said as neither."""
    claims = [
        _claim(p, "action", "verified" if a == chosen else "contradicted", f"it chose {name}", t)
        for p, t, a, slot in acts
        if slot == "chose"
    ]
    return claims + [
        _claim(p, "action", "unchecked", "no action it names is said as taken or as the one it would take", t)
        for p, t, a, slot in acts
        if slot == ""
    ]


def _margins(margins: list[Part], scores: np.ndarray, margin: float, how: str) -> list[Claim]:
    """The stated margins: the re-run's, as written (or within a float32 network's last bits of it)."""
    claims = []
    for p in margins:
        printed, noise = number(p.span.text), NOISE * max(1.0, float(np.abs(scores).max()))
        ok = printed is not None and np.isfinite(margin)
        ok = ok and (close(printed, margin, p.span.text) or abs(printed - margin) <= noise)  # (batch shape's bits)
        claims.append(_claim(p, "number", "verified" if ok else "contradicted", f"{how}; margin {margin:.4g}"))
    return claims
