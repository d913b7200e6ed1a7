"""The claim filters of templates: ``dir``, ``level``, ``rank``, ``cmp`` and ``role``.

A claim word (which way a feature pushed, how high its value was, where it ranked, whether it weighed more than
another, which action was chosen) is the template author's word, in any language, printed by a filter from a tracked
fact: the filter picks the author's word for the fact's value and prints it as a :class:`TrackedStr` whose
:class:`Fact` says which claim it is (``of`` names the quantity it was read from). So the verifier checks a claim
word by identity, with no word list: ``dir('aumentó', 'redujo')`` verifies as well as ``dir('raised', 'lowered')``.
Given an untracked value (a plain number, a dict of plain values), a filter returns the plain word: that word is
then literal text like any other, and a claim word in it leaves its sentence unchecked.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

from jinja2 import pass_context

from xairl.templates.tracking import Fact, TrackedFloat, TrackedInt, TrackedStr

_DIRECTIONS = ("direction", "direction_high", "direction_low")


def _claim(word, fact: Fact | None, words=()) -> str:
    """``word`` printed as the claim ``fact`` (a plain word when there is no fact); ``words``: every word the filter
    could have printed (one word for every fact declares nothing, and the fact says so)."""
    if fact is not None and len({" ".join(str(w).lower().split()) for w in words}) == 1:
        fact = replace(fact, alike=True)
    return str(word) if fact is None else str(TrackedStr(str(word), fact))


def _field(x, key: str):
    """``x[key]`` of a feature dict, else ``x`` itself."""
    return x.get(key) if isinstance(x, Mapping) else x


def direction(x, toward: str = "toward", against: str = "against", mixed: str = "both ways") -> str:
    """``toward`` for a number >= 0, else ``against``. Given a feature dict, its contribution (or its direction in a
    global view); given a direction fact ('toward', 'against', 'mixed': a global view's ``f.direction``,
    ``f.high_values``, ``f.low_values``), its word, ``mixed`` for 'mixed'.

    Tracked, the word's fact is ``Fact('direction', feature, view, role, value='toward'|'against', of=quantity)``
    with the number's feature, view and role, ``of`` the number's quantity ('contribution', 'margin', 'mean',
    'value_change', ...), and the value the sign of that quantity (a negated number's word is chosen by the sign as
    printed, its fact says the quantity's own sign); a direction fact keeps its quantity ('direction_high', ...).
    An absolute value has no direction: its word is plain."""
    if isinstance(x, Mapping):
        x = x["contribution"] if x.get("contribution") is not None else x.get("direction")
    if isinstance(x, str):
        value = str.__str__(x)
        word = toward if value == "toward" else against if value == "against" else mixed
        f = x.fact if isinstance(x, TrackedStr) and x.fact.quantity in _DIRECTIONS else None
        fact = None if f is None else Fact(f.quantity, f.feature, f.view, f.role, value, of=f.quantity)
        return _claim(word, fact, (toward, against))
    word = toward if x >= 0 else against
    if not isinstance(x, (TrackedFloat, TrackedInt)) or "abs" in x.transform:
        return str(word)
    flipped = x.transform.split("+").count("neg") % 2 == 1
    value = "toward" if (x >= 0) != flipped else "against"
    f = x.fact
    return _claim(word, Fact("direction", f.feature, f.view, f.role, value, of=f.quantity), (toward, against))


def level(x, low: str = "low", typical: str = "typical", high: str = "high", unknown: str = "") -> str:
    """The word for a feature's level ('low', 'typical' or 'high' against its capacity, thresholds or background;
    ``unknown`` when none says), given the feature dict or its ``level``. Tracked, its fact is
    ``Fact('level', feature, view, value=the level, of='level')``."""
    x = _field(x, "level")
    value = str.__str__(x) if isinstance(x, str) else str(x)
    word = {"low": low, "typical": typical, "high": high}.get(value, unknown)
    f = x.fact if isinstance(x, TrackedStr) and x.fact.quantity == "level" else None
    return _claim(
        word, None if f is None else Fact("level", f.feature, f.view, value=value, of="level"), (low, typical, high)
    )


def rank(x, *words: str, other: str = "") -> str:
    """The ``n``-th of ``words`` for a feature ranked ``n`` in its view (1 for the largest |contribution|, or mean
    |contribution| in a global view), ``other`` past the last word (and for an identifier, which has no rank),
    given the feature dict or its ``rank``; given its ``rank_same_way``, by its rank among the pushes of its sign
    (1: the biggest push its way). Tracked, its fact is ``Fact('rank', feature, view, value=the rank, of='rank')``
    (``'rank_same_way'`` for both the quantity and ``of`` of the latter)."""
    x = _field(x, "rank")
    n = int(x)
    word = words[n - 1] if 1 <= n <= len(words) else other
    f = x.fact if isinstance(x, TrackedInt) and x.fact.quantity in ("rank", "rank_same_way") else None
    return _claim(
        word, None if f is None else Fact(f.quantity, f.feature, f.view, value=n, of=f.quantity), (*words, other)
    )


def compare(x, other, more: str = "more", less: str = "less", same: str | None = None) -> str:
    """``more`` when the feature ``x`` weighed more than the feature ``other`` (a larger |contribution|), ``less``
    when it weighed less, ``same`` on a tie (``more`` when not given: at least as much). Tracked, its fact is
    ``Fact('comparison', feature=x's name, view=x's view, role=other's name, value='more'|'less'|'same',
    of='contribution')`` (a domain comparison's fact has ``of`` None)."""
    a, b = _field(x, "contribution"), _field(other, "contribution")
    value = "more" if abs(a) > abs(b) else "less" if abs(a) < abs(b) else "same"
    word = {"more": more, "less": less, "same": more if same is None else same}[value]
    tracked = isinstance(a, TrackedFloat) and isinstance(b, TrackedFloat)
    fact = (
        Fact("comparison", a.fact.feature, a.fact.view, b.fact.feature, value, of="contribution") if tracked else None
    )
    return _claim(word, fact, (more, less))


@pass_context
def role(context, x, chosen: str = "", runner_up: str = "", only: str | None = None) -> str:
    """The word for an action's role: ``chosen`` for the chosen action (and for a counterfactual's action, the one
    chosen there), ``runner_up`` for the runner-up, and ``only`` (when given) for an action that was the only one
    available (the runner-up is the chosen action). Tracked, its fact is ``Fact('role', role='chosen'|'runner_up'|
    'only'|'counterfactual', value=the action's name, of='action'|'cf_action')``."""
    f = x.fact if isinstance(x, TrackedStr) and x.fact.quantity in ("action", "cf_action") else None
    alone = only is not None and context.get("action") is not None and context.get("runner_up") == context.get("action")
    if f is None:  # (an untracked rendering: its role by its name)
        plain = runner_up if x == context.get("runner_up") and x != context.get("action") else chosen
        return str(only if alone else plain)
    which = "counterfactual" if f.quantity == "cf_action" else "only" if alone else f.role
    word = {"chosen": chosen, "counterfactual": chosen, "only": only, "runner_up": runner_up}.get(which, "")
    return _claim(word, Fact("role", role=which, value=str.__str__(x), of=f.quantity))


#: the claim filters by their template names
FILTERS = {"dir": direction, "level": level, "rank": rank, "cmp": compare, "role": role}
