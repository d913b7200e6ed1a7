"""What a narrative's features account for, and what it leaves out (:attr:`Verification.account`).

Claim coverage says how much of what a text says was checked; a verified text may still tell half the story. The
account says it in one line: of a decision between actions, the margin over the runner-up (of the chosen score, or
the output, otherwise), how much the features the text names contribute, and the features it leaves out with
their sum, split by the way they pushed::

    its 2 features account for -0.333 of the margin 2.34 (turn over forward; base +2.55); 1 more feature pushed for
    it: distance +0.12; 2 more pushed against it, together -0.354: obstacle -0.305, wind -0.049

Of a global summary (no state), the share of the mean |contribution| over the states. A left-out feature whose
contribution is (numerically) zero pushed neither way and is not listed.
"""

from __future__ import annotations

import re
from collections.abc import Iterable

import numpy as np

from xairl.explanations.explanation import Explanation
from xairl.verification.result import Claim

#: how many left-out features of each side are named (the rest are counted in the sum)
LISTED = 4


def features_named(claims: Iterable[Claim], spans: Iterable = ()) -> set[str]:
    """The features a checked text names: the fact behind each tracked value (own text), and the features the prose
    reader found (a 'feature' claim's detail holds its key, or the keys it may mean, joined by ' / ')."""
    out = {s.fact.feature for s in spans if getattr(getattr(s, "fact", None), "feature", None)}
    for c in claims:
        fact = getattr(c.span, "fact", None)
        if getattr(fact, "feature", None):
            out.add(fact.feature)
        if c.kind == "feature" and c.detail:
            out |= {c.detail, *c.detail.split(" / ")}
        elif c.rule == "name.unread" and (m := re.search(r"\(([^)]*)\)", c.detail)):  # (named, nothing read of it)
            out |= set(m.group(1).split(" / "))
    return out


def _g(x: float) -> str:
    return f"{x:+.3g}"


def _left_out(values: np.ndarray, names, shown: list[int], words: tuple[str, str], fmt=_g) -> list[str]:
    """'N more features pushed for it, together +x: a +x, b +y' per side with something left out (the largest
    ``LISTED`` named)."""
    eps = 1e-9 * max(1.0, float(np.abs(values).max(initial=0.0)))
    out = []
    for side, word in zip((1, -1), words):
        rest = [j for j in np.argsort(-np.abs(values), kind="stable") if j not in shown and side * values[j] > eps]
        if not rest:
            continue
        total = float(values[rest].sum())
        listed = ", ".join(f"{names[j]} {fmt(values[j])}" for j in rest[:LISTED])
        more = f" and {len(rest) - LISTED} more" if len(rest) > LISTED else ""
        more_ = "more " if shown else ""
        what = f"{len(rest)} {more_}feature{'s' * (len(rest) > 1)}" if not out else f"{len(rest)} {more_}".rstrip()
        out.append(f"{what} {word}{f', together {fmt(total)}' if len(rest) > 1 else ''}: {listed}{more}")
    return out


def account(explanation: Explanation, index: int | None, features_named: Iterable[str], view: str = "margin") -> str:
    """The account of a text naming ``features_named`` about state ``index`` (None: the global view), in ``view``
    'margin' (over the runner-up, where the policy decides between actions) or 'score' (module doc); '' when the
    text names nothing the explanation holds and cannot be read per signal either."""
    exp, named = explanation, set(features_named)
    if named - set(exp.feature_names) and "window" in (exp.extras or {}):
        exp = exp.by_signal()  # a window is narrated per signal
    names = list(exp.feature_names)
    shown = [j for j, f in enumerate(names) if f in named]
    if not shown and named:
        return ""
    k = f"its {len(shown)} feature{'s' * (len(shown) != 1)}"
    if index is None:
        values = np.abs(exp.contributions(view)[0]).mean(axis=0) if len(exp.values) else np.zeros(len(names))
        total = float(values.sum()) or 1.0

        def share(x: float) -> str:
            return f"{100 * abs(x) / total:.0f} %"

        head = f"{k} carr{'ies' if len(shown) == 1 else 'y'} {share(values[shown].sum())} of the mean |contribution| over {len(exp.values)} state{'s' * (len(exp.values) != 1)}"
        rest = _left_out(values, names, shown, ("are left out", ""), share)
        return "; ".join([head if shown else "it names no feature", *rest])
    c, r = int(exp.focus[index]), int(exp.runner_up[index])
    deciding = view == "margin" and exp.output == "actions" and r != c
    values = exp.values[index, :, c] - (exp.values[index, :, r] if deciding else 0.0)
    base = float(exp.base_values[index, c] - (exp.base_values[index, r] if deciding else 0.0))
    total = float(exp.outputs[index, c] - (exp.outputs[index, r] if deciding else 0.0))
    a = exp.action_names[c]
    target = (
        f"the margin {total:.3g} ({a} over {exp.action_names[r]}; base {_g(base)})"
        if deciding
        else f"{a}'s score {total:.3g} (base {_g(base)})"
        if exp.output == "actions"
        else f"the output {a} {total:.3g} (base {_g(base)})"
    )
    head = f"{k} account{'s' * (len(shown) == 1)} for {_g(float(values[shown].sum()))} of {target}"
    if not shown:
        head = f"it names no feature behind {target}"
    words = ("pushed for it", "pushed against it") if deciding else ("raised it", "lowered it")
    rest = _left_out(values, names, shown, words)
    return "; ".join([head, *rest] if rest else [head, "it leaves no feature out"])
