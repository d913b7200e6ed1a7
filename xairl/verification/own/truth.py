"""The facts a tracked span may name, recomputed from the explanation (never taken from the span), and the check of
one span against its fact."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace

import numpy as np

from xairl.explanations.explanation import Explanation
from xairl.facts import DomainFacts, decision_facts, global_facts
from xairl.policies.policy import Policy
from xairl.templates.tracking import Span
from xairl.verification.own.lexicon import KINDS, NUMBER, NUMERIC
from xairl.verification.result import Claim


@dataclass
class Truth:
    """The facts of one decision (or of the global view) recomputed from the explanation, by (quantity, feature,
    view, role)."""

    values: dict
    features: dict  # name -> {view: FeatureFact or ranking dict}
    actions: dict  # role -> name
    output: str
    policy: Policy | None = None  # a counterfactual sentence is checked by running it (provenance.counterfactual)
    state: np.ndarray | None = None  # the decision's state, flat, when it is the policy's input

    def get(self, span: Span):
        f = span.fact
        return self.values.get((f.quantity, f.feature, view_of(f.view), f.role), MISSING)


MISSING = object()


def view_of(view: str | None) -> str | None:
    return "score" if view == "output" else view


def truth(exp: Explanation, index: int | None, policy: Policy | None, domain: DomainFacts | None) -> Truth:
    """Every fact a tracked span may name, recomputed from ``exp``."""
    values, features = {}, {}
    if index is None:
        for view in ("margin", "score"):
            g = global_facts(exp, policy, k=len(exp.feature_names), view=view)
            v = view_of(g.view)
            values[("n_states", None, None, None)] = g.n_states
            values[("target", None, v, None)] = g.target
            for r in g.ranking:
                features.setdefault(r["name"], {})[v] = r
                for q, key in (("mean_abs", "mean_abs"), ("mean", "mean"), ("rank", "rank"), ("name", "name")):
                    values[(q, r["name"], v, None)] = r[key]
                values[("direction", r["name"], v, None)] = r["direction"]
                values[("direction_high", r["name"], v, None)] = r["high_values"]
                values[("direction_low", r["name"], v, None)] = r["low_values"]
                values[("unit", r["name"], v, None)] = r["unit"]
        values[("method", None, None, None)] = exp.method
        return Truth(values, features, {}, exp.output)
    d = decision_facts(exp, index, policy, k=len(exp.feature_names))
    domain = domain or DomainFacts(d.extras, d.comparisons)  # the policy's facts hook, called again
    actions = {"chosen": d.action, "runner_up": d.runner_up}
    values.update(
        {
            ("index", None, None, None): d.index,
            ("action", None, None, "chosen"): d.action,
            ("action", None, None, "runner_up"): d.runner_up,
            ("score", None, "score", "chosen"): d.score,
            ("score", None, "score", "runner_up"): d.runner_up_score,
            ("margin", None, "margin", None): d.q_margin,
            ("base_value", None, "score", "chosen"): d.base_value,
            ("base_margin", None, "margin", None): d.base_margin,
            ("gap", None, None, None): d.additivity_gap,
            ("method", None, None, None): d.method,
        }
    )
    for view, facts in (("score", d.top), ("margin", d.margin_top)):
        for f in facts + (d.identifiers if view == "score" else ()):
            features.setdefault(f.name, {})[view] = f
            for q in (
                *("value", "value_text", "unit", "contribution", "share", "direction", "rank", "rank_same_way"),
                *("kind", "fill"),
                *("trend", "window", "change_unit", "steps"),
            ):
                values[(q, f.name, view, None)] = getattr(f, q)
            values[("value_change", f.name, view, None)] = f.change
            values[("name", f.name, view, None)] = f.name
            values[("level", f.name, view, None)] = f.level_text or f.level
    for c in domain.comparisons if domain else ():
        values[("comparison", c.text, None, None)] = c.text
        values[("comparison_value", c.text, None, None)] = c.value
    for k, v in (domain.extras if domain else {}).items():
        values[("extra", str(k), None, None)] = v
    flat = exp.states is not None and policy is not None and exp.states.shape[1] == policy.n_features
    return Truth(values, features, actions, exp.output, policy, np.asarray(exp.states[index]) if flat else None)


def number(text: str) -> float | None:
    m = NUMBER.search(text.replace("\u2212", "-"))
    if m is None:
        return None
    try:
        return float(m.group(0).replace(",", ""))
    except ValueError:
        return None


def _transformed(x: float, transform: str, percent: bool = False) -> float:
    """``x`` as the template transformed it; a scaling counts only as a percentage (x100 with '%' written after it):
    any other multiple of a fact printed as if it were the fact is not that fact."""
    for step in filter(None, transform.split("+")):
        if step == "neg":
            x = -x
        elif step == "abs":
            x = abs(x)
        elif step.startswith("scale:") and percent and float(step[6:]) == 100:
            x *= 100
    return x


def close(printed: float, expected: float, text: str, transform: str = "") -> bool:
    """``printed`` (as ``text`` writes it) is ``expected`` rounded: within half a unit of its last digit (3
    significant digits at least), or of the digits a ``round:N`` transform kept ('|round' prints -1.0 for -1.21)."""
    if not math.isfinite(expected):
        return False
    digits = re.search(r"\.(\d+)", text)
    step = 10.0 ** -(len(digits.group(1)) if digits else 0)
    for kept in re.findall(r"round:(-?\d+)", transform):
        step = max(step, 10.0 ** -int(kept))
    return abs(printed - expected) <= 0.5 * step + 5e-4 * abs(expected) + 1e-12


def _words_similar(a: str, b: str) -> bool:
    return " ".join(str(a).lower().split()) == " ".join(str(b).lower().split())


def check_fact(span: Span, truth: Truth, after: str = "") -> Claim:
    """The span against its recomputed fact (the claim carries the span); ``after``: the words that follow it."""
    return replace(_check_fact(span, truth, bool(re.match(r"\s?(?:%|per ?cent)", after))), span=span)


def _check_fact(span: Span, truth: Truth, percent: bool = False) -> Claim:
    f = span.fact
    if f.of is not None:  # a declared claim word: its fact says which way, never the word
        return _check_claim(span, truth)
    expected = truth.get(span)
    kind = KINDS.get(f.quantity, "number" if f.quantity in NUMERIC else "feature")
    if f.quantity == "value_text":
        kind = "number" if re.search(r"\d", span.text) else "category"
    if (
        percent
        and f.quantity in NUMERIC
        and f.quantity not in ("share", "fill", "value", "value_change")  # (a fill changes in points)
        and "scale:100" not in span.transform
    ):
        return Claim(
            kind,
            span.text,
            "contradicted",
            f"the {f.quantity.replace('_', ' ')}, written as a percentage",
            "tracked.label",
        )
    if expected is MISSING:
        what = f"{f.quantity} of {f.feature}" if f.feature else f.quantity
        return Claim(
            kind, span.text, "contradicted", f"no {what} in this explanation ({f.view or ''} view)", "tracked.unknown"
        )
    if isinstance(expected, (int, float, np.floating)) and not isinstance(expected, bool):
        printed = number(span.text)
        want = _transformed(float(expected), span.transform, percent)
        ok = printed is not None and close(printed, want, span.text, span.transform)
        detail = f"{f.quantity}{' of ' + f.feature if f.feature else ''} = {float(expected):.4g}"
        detail += f" ({span.transform}: {want:.4g})" if span.transform else ""
        return Claim("number", span.text, "verified" if ok else "contradicted", detail, "tracked.fact")
    if expected is None:  # e.g. the fill of a feature without a capacity, printed as 'None'
        return Claim(kind, span.text, "unchecked", f"{f.quantity} of {f.feature}: none", "tracked.fact")
    if (
        f.quantity in CANONICAL_OF
        and span.text.strip().lower() in CANONICAL
        and not _words_similar(span.text, expected)
    ):
        return Claim(kind, span.text, "contradicted", f"{f.quantity} = {expected}", "tracked.fact")
    accepted = [expected]
    if f.quantity == "action" and truth.policy is not None:  # (an action printed as one of its declared aliases)
        accepted += list(truth.policy.action_aliases.get(str(expected), ()))
    if f.quantity == "name":  # its name or its label (description)
        accepted += [
            getattr(v, "label", None) or (v.get("label") if isinstance(v, dict) else None)
            for v in truth.features.get(f.feature, {}).values()
        ]
    ok = any(a is not None and _words_similar(span.text, a) for a in accepted)
    return Claim(kind, span.text, "verified" if ok else "contradicted", f"{f.quantity} = {expected}", "tracked.fact")


#: the facts that print a word of their own ('{{ f.direction }}': 'toward'), and those words: one printed for another
#: value of its fact ('|replace' keeps the fact) is wrong
CANONICAL_OF = frozenset({"direction", "direction_high", "direction_low", "level", "trend"})
CANONICAL = frozenset({"toward", "against", "mixed", "low", "typical", "high", "moderate", "rose", "fell", "steady"})


def _check_claim(span: Span, truth: Truth) -> Claim:
    """A claim word a claim filter printed (:mod:`xairl.templates.claim_filters`), by its fact: the word is the
    author's, so nothing reads it; a direction read from a non-push, or the same word for every case, declares
    nothing."""
    f = span.fact
    if f.quantity == "direction" and f.of not in PUSHES:
        return Claim(
            "direction",
            span.text,
            "unchecked",
            f"a direction word read from the sign of {f.of.replace('_', ' ')}, which pushes nothing: dir reads a "
            "contribution (f.contribution, q_margin, f.change)",
            "tracked.fact",
        )
    if f.alike:
        return Claim(
            f.quantity,
            span.text,
            "unchecked",
            "its filter prints this word whatever the fact: it declares nothing (give it one word for each case)",
            "tracked.fact",
        )
    want = _claimed(f, truth)
    ok = want is not MISSING and want is not None and str(f.value) == str(want)
    detail = f"{f.quantity} of {f.feature or f.value} = {want if want is not MISSING else 'unknown'}"
    return Claim(
        KINDS.get(f.quantity, f.quantity), span.text, "verified" if ok else "contradicted", detail, "tracked.fact"
    )


#: the quantities whose sign a direction word may say: pushes on a score or the margin, and a signal's change
PUSHES = frozenset(
    {"contribution", "margin", "base_margin", "mean", "value_change", "direction", "direction_high", "direction_low"}
)


def _claimed(f, truth: Truth):
    """What a claim word's fact (a claim filter's, :mod:`xairl.templates.claim_filters`) should say, recomputed:
    the sign of the quantity it read, the feature's level or rank, the larger of two contributions, the action of
    the role."""
    view = view_of(f.view)
    if f.quantity == "role":
        chosen, runner = truth.actions.get("chosen"), truth.actions.get("runner_up")
        said = {"chosen": chosen, "runner_up": runner if runner != chosen else MISSING}.get(f.role, MISSING)
        if f.role == "only":
            said = chosen if chosen == runner else MISSING
        return f.value if f.role == "counterfactual" else said  # (a counterfactual's action: its re-run checks it)
    if f.quantity == "comparison" and f.of == "contribution":
        a, b = (truth.values.get(("contribution", x, view, None)) for x in (f.feature, f.role))
        if a is None or b is None:
            return MISSING
        return "more" if abs(a) > abs(b) else "less" if abs(a) < abs(b) else "same"
    if f.quantity == "level":
        fact = truth.features.get(f.feature, {}).get(view)
        return getattr(fact, "level", MISSING) if fact is not None else MISSING
    if f.quantity in ("direction_high", "direction_low") or f.of.startswith("direction"):
        return truth.values.get((f.of, f.feature, view, None), MISSING)
    x = truth.values.get((f.of, f.feature, view, f.role), MISSING)
    if f.quantity in ("rank", "rank_same_way"):
        return x
    if f.quantity == "direction" and isinstance(x, (int, float, np.floating)) and math.isfinite(x):
        return "toward" if x >= 0 else "against"
    return MISSING
