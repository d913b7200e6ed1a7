"""Verification of xairl's own words by provenance.

A narrative xairl rendered carries, for every value it printed, the fact it came from (:mod:`xairl.tracking`). A
tracked span *is* its fact: it is checked against the explanation (recomputed, never trusted) and never re-bound by
its position. What is left, the template's (or the language model's) literal words, is judged against the tracked
spans of its sentence by the rules of :data:`RULES`:

- a number said of another feature than the one named before it (crossed numbers), a value written without its
  sign, an action named in the wrong role ('chose' the runner-up), a label beside a value that is not its quantity
  (``score=`` before the margin), a direction word against its feature's sign, a rank or comparison word against
  the tracked facts it joins: each is contradicted;
- words inside a tracked name never make a claim ('runner-up' is not the action 'up');
- a sentence with no tracked span, and any untracked number or identifier in the literal words, is read by the
  reader of outside prose (:mod:`xairl.narrators.verify`) as before.

How it reads a sentence: the spans are the facts; the literal words between them are cut into segments at
``; : | ( )``, line breaks, commas and clause words ('but', 'while'), and each rule looks only at the words of its
segment and the spans around them.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from ..errors import InputError
from ..explanation import Explanation
from ..facts import DomainFacts, decision_facts, global_facts
from ..policy import Policy
from ..regions import in_regions
from ..tracking import Span
from .verify import Claim, SentenceCheck, Verification, reader, sentences
from .verify.checks import DIRECTION_RE
from .verify.numbers import normalise

#: rule id -> what it checks (the ids a provenance claim names; docs/customising-prompts.md lists them)
RULES = {
    "tracked.fact": "a tracked number or word is its fact's value as printed (with the template's transformation)",
    "tracked.unknown": "a tracked span whose fact is not in the explanation (an unknown feature, action or view)",
    "tracked.binding": "a tracked number of one feature printed where the words say it is another's",
    "tracked.sign": "a feature's value printed without its sign, and no word that carries the sign",
    "tracked.label": "a label beside a tracked number ('score=', 'margin of') that is not its quantity",
    "tracked.view": "'to the margin' / 'to the score' beside a contribution of the other view",
    "tracked.role": "an action named with words of the other role ('chose' the runner-up)",
    "tracked.direction": "a direction word ('raised', 'against', 'favoured B') against its feature's sign",
    "tracked.rank": "a rank word ('most', 'biggest', 'second') against the rank of the feature it names",
    "tracked.level": "a level word ('low', 'normal', 'high') against the level of the feature it is said of",
    "tracked.untracked": "a number the template wrote itself that the reader cannot bind and that is no fact of the decision",
    "tracked.comparison": "'A mattered more than B' against the sizes of their contributions",
}

_NUMERIC = {
    "value",
    "fill",
    "contribution",
    "share",
    "rank",
    "score",
    "margin",
    "base_value",
    "base_margin",
    "gap",
    "mean_abs",
    "mean",
    "comparison_value",
    "n_states",
    "index",
}
#: the kind of claim a tracked span makes (a checked kind, :data:`xairl.narrators.verify.checks.CHECKED`, or a name)
_KINDS = {
    "action": "action",
    "level": "magnitude",
    "direction": "direction",
    "direction_high": "direction",
    "direction_low": "direction",
    "comparison": "number",
    "extra": "number",
}
_SAID_OF_FEATURE = {"value", "value_text", "fill", "contribution", "share", "rank", "level", "mean_abs", "mean"}
_NUMBER = re.compile(r"[+-]?\d[\d,]*(?:\.\d+)?(?:e[+-]?\d+)?", re.IGNORECASE)
#: literal words that cut a sentence into segments (a rule looks only within its segment)
_SEGMENT = re.compile(
    r"[;:()\[\]\n]|\s\|(?=\s)|,|\s[—–-]\s|\b(?:but|while|whereas|although|though|yet|despite)\b", re.I
)
_BLOCK = re.compile(r"[;:\n]|\s\|(?=\s)")  # (a table's cell, not 'mean |contribution|')
_SIGNED_CONTEXT = re.compile(
    r"\b(?:side|push\w*|pull\w*|weigh\w*|reasons?|help\w*|hurt\w*|held|back|for|against|toward\w*|favou?r\w*)\b",
    re.IGNORECASE,
)
#: words right before a value that carry its sign ('minus 1.46', 'a drop of 1.46'), and right after it ('1.46 below
#: zero')
_SIGN_BEFORE = re.compile(
    r"\b(?:minus|negative|a drop of|a fall of|a deficit of|fell(?: by)?|dropped(?: by)?|down(?: by)?|"
    r"decreased(?: by)?|short by)\W*$",
    re.IGNORECASE,
)
_SIGN_AFTER = re.compile(r"^\W*(?:(?:below|under|less than) (?:zero|0)|in the red|negative|short)\b", re.IGNORECASE)
_CHOSEN_BEFORE = re.compile(
    r"\b(?:chose|chosen|choose|chooses|picked|picks|selected|selects|took|takes|preferred|prefers|went with|"
    r"decided on|decision(?: was)?|winner(?: was| is)?|won with|(?<!next )best(?: action)?(?: was| is)?|"
    r"executing|executes|executed|why|action\s*[=:]|chosen\s*[=:]|decision\s*[=:])\W*$",
    re.IGNORECASE,
)
_RUNNER_BEFORE = re.compile(
    r"\b(?:runner[-_ ]?up(?: was| is)?|second(?: was| is| best| choice| place)?|rather than|instead of|beat|beats|"
    r"next best(?: was| is)?|alternative(?: was| is)?|why not|preferred to|preferred over|"
    r"(?:lead|margin|edge|advantage|ahead) over|over)\W*$",
    re.IGNORECASE,
)
_CHOSEN_AFTER = re.compile(
    r"^\W*(?:won|wins|was chosen|is chosen|was picked|was selected|was preferred|is preferred|beat|beats|"
    r"came first)\b",
    re.I,
)
_RUNNER_AFTER = re.compile(r"^\W*(?:came second|was second|lost|was the runner[- ]up|trailed)\b", re.I)
#: words that make a background average what it is ('on average', 'the background's'); a base value printed in
#: a sentence without one is the average written as if it were the decision's own number
_BASE_WORDS = re.compile(
    r"\b(?:average|averages|expected|expectation|baseline|base|background|typical|usual|mean|prior|start\w*|"
    r"reference)\b",
    re.IGNORECASE,
)
#: a score named with its action: 'turn (score 3.05)', 'turn won with a score of 3.05', 'score=... for turn'
_SCORE_OF_BEFORE = re.compile(r"^\W*(?:\w+\W+){0,8}$")
#: an action's cell, then its score's ('turn | score 3.05', '| turn | score: 3.05')
_CELL_SCORE = re.compile(r"\s*\|\s*(?:score|q[- ]?value|value)?\s*[=:]?\s*", re.IGNORECASE)
#: words after a number that make it a contribution ('+0.35 to its margin', '+0.82 (for forward)')
_AS_CONTRIBUTION = re.compile(
    r"\s*(?:\(\s*)?(?:to (?:the |its )?(?:margin|score)|(?:for|against|toward|towards|in favou?r of)\s*$)", re.I
)
_SCORE_FOR_AFTER = re.compile(r"^\s*(?:for|of|by)\s*$", re.IGNORECASE)
_SIDE_OF = re.compile(r"^['’]s\s+(?:side|favou?r|camp)\b", re.IGNORECASE)
#: a label right before a number (key=value, 'score of', '(margin '); quantity group it names
_LABELS = (
    (re.compile(r"\b(?:average|expected|baseline|base(?: value)?|background)\b[\w\s']{0,12}\W*$", re.I), "base"),
    (re.compile(r"\b(?:q[- ]?value|score|logit|prediction|estimate)s?\b(?:\s+(?:of|was|is|at))?\W*$", re.I), "score"),
    (
        re.compile(
            r"\b(?:came out at|came out as|ended (?:up )?at|came to|(?:was )?set to|landed at|reached)\W*$", re.I
        ),
        "score",
    ),
    (re.compile(r"\b(?:margin|gap|lead)\b(?:\s+(?:of|was|is))?\W*$", re.I), "margin"),
    (re.compile(r"\b(?:share)\b(?:\s+(?:of|was|is))?\W*$", re.I), "share"),
    (
        re.compile(
            r"\b(?:by|added|adds|adding|subtracted|took|cut|cutting|contributed|contributing|gave|worth)"
            r"(?:\s+(?:about|around|roughly|some|nearly|almost|just))?\W*$",
            re.I,
        ),
        "change",
    ),
    (re.compile(r"\b(?:rank(?:ed)?)\b(?:\s+(?:of|was|is))?\W*$", re.I), "rank"),
)
_LABEL_FITS = {
    "base": {"base_value", "base_margin", "mean", "mean_abs"},
    "score": {"score", "contribution"},  # ('it raised the score by +0.3': a contribution to it)
    "margin": {"margin", "contribution"},
    "change": {"margin", "base_margin", "contribution", "share", "mean", "mean_abs", "comparison_value"},
    "share": {"share"},
    "rank": {"rank"},
}
_DIFFERENCE = re.compile(
    r"\W*(?:points?\s+)?(?:higher|lower|more|less|above|below|ahead|behind|greater|smaller|better|worse)\b", re.I
)
_VIEW_AFTER = re.compile(
    r"^\W*(?:\w+\W+){0,2}?(?:to|on|of|for)\s+(?:the\s+|its\s+)?(?:(margin|gap|lead)|(score))\b", re.I
)
_SUPERLATIVE = re.compile(
    r"\b(?:most|biggest|largest|strongest|greatest|main|top|primary|chief|leading|foremost|first|1st|"
    r"number one|mattered most)\b",
    re.IGNORECASE,
)
_ORDINAL = {
    2: re.compile(r"\b(?:second|2nd|runner[- ]up feature)\b", re.I),
    3: re.compile(r"\b(?:third|3rd)\b", re.I),
}
_NOT_RANK = re.compile(r"\b(?:at most|most of|almost|mostly)\b", re.I)
_MORE = re.compile(
    r"\b(?:more than|outweighed|outweighs|bigger than|larger than|stronger than|exceeded|ahead of)\b", re.I
)
_LESS = re.compile(r"\b(?:less than|smaller than|weaker than|behind)\b", re.I)
_EXTRA_DIRECTIONS = re.compile(r"\b(?:(?P<neg>despite|in spite of)|(?P<for>for))\b", re.IGNORECASE)
#: words that say a side ('favoured B', 'toward B', 'against B'): about the options, so they need to name one
_SIDE = re.compile(
    r"favou?r\w*|in favou?r of|toward|towards|against|for|supports?|supported|supporting|help\w*|argu\w* (?:for|against)",
    re.IGNORECASE,
)
#: the side named in words: the chosen action ('favoured it', 'toward the decision')
_CHOSEN_SIDE = re.compile(r"\s+(?:it|this|the (?:chosen )?(?:action|decision|choice)|its choice)\b", re.IGNORECASE)
_LEVEL = re.compile(
    r"\b(?:low|high|typical|normal|moderate|average)\b(?!\s+(?:value|values|of|score|margin|when))", re.I
)
_NEGATED = re.compile(r"(?:\b(?:not|never|no longer|neither|nor)|n't)\b\W*(?:\w+\W+){0,2}$", re.IGNORECASE)


@dataclass
class Truth:
    """The facts of one decision (or of the global view) recomputed from the explanation, by (quantity, feature,
    view, role)."""

    values: dict
    features: dict  # name -> {view: FeatureFact or ranking dict}
    actions: dict  # role -> name
    output: str

    def get(self, span: Span):
        f = span.fact
        return self.values.get((f.quantity, f.feature, _view(f.view), f.role), _MISSING)


_MISSING = object()


def _view(view: str | None) -> str | None:
    return "score" if view == "output" else view


def truth(exp: Explanation, index: int | None, policy: Policy | None, domain: DomainFacts | None) -> Truth:
    """Every fact a tracked span may name, recomputed from ``exp``."""
    values, features = {}, {}
    if index is None:
        for view in ("margin", "score"):
            g = global_facts(exp, policy, k=len(exp.feature_names), view=view)
            v = _view(g.view)
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
            for q in ("value", "value_text", "unit", "contribution", "share", "direction", "rank", "kind", "fill"):
                values[(q, f.name, view, None)] = getattr(f, q)
            values[("name", f.name, view, None)] = f.name
            values[("level", f.name, view, None)] = f.level_text or f.level
    for c in domain.comparisons if domain else ():
        values[("comparison", c.text, None, None)] = c.text
        values[("comparison_value", c.text, None, None)] = c.value
    for k, v in (domain.extras if domain else {}).items():
        values[("extra", str(k), None, None)] = v
    return Truth(values, features, actions, exp.output)


def _number(text: str) -> float | None:
    m = _NUMBER.search(text.replace("\u2212", "-"))
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


def _close(printed: float, expected: float, text: str, transform: str = "") -> bool:
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
    expected = truth.get(span)
    kind = _KINDS.get(f.quantity, "number" if f.quantity in _NUMERIC else "feature")
    if f.quantity == "value_text":
        kind = "number" if re.search(r"\d", span.text) else "category"
    if percent and f.quantity in _NUMERIC and f.quantity not in ("share", "fill") and "scale:100" not in span.transform:
        return Claim(
            kind,
            span.text,
            "contradicted",
            f"the {f.quantity.replace('_', ' ')}, written as a percentage",
            "tracked.label",
        )
    if expected is _MISSING:
        what = f"{f.quantity} of {f.feature}" if f.feature else f.quantity
        return Claim(
            kind, span.text, "contradicted", f"no {what} in this explanation ({f.view or ''} view)", "tracked.unknown"
        )
    if isinstance(expected, (int, float, np.floating)) and not isinstance(expected, bool):
        printed = _number(span.text)
        want = _transformed(float(expected), span.transform, percent)
        ok = printed is not None and _close(printed, want, span.text, span.transform)
        detail = f"{f.quantity}{' of ' + f.feature if f.feature else ''} = {float(expected):.4g}"
        detail += f" ({span.transform}: {want:.4g})" if span.transform else ""
        return Claim("number", span.text, "verified" if ok else "contradicted", detail, "tracked.fact")
    if expected is None:  # e.g. the fill of a feature without a capacity, printed as 'None'
        return Claim(kind, span.text, "unchecked", f"{f.quantity} of {f.feature}: none", "tracked.fact")
    accepted = [expected]
    if f.quantity == "name":  # its name or its label (description)
        accepted += [
            getattr(v, "label", None) or (v.get("label") if isinstance(v, dict) else None)
            for v in truth.features.get(f.feature, {}).values()
        ]
    elif f.quantity == "level":
        accepted += [getattr(v, "level", None) for v in truth.features.get(f.feature, {}).values()]
    elif f.quantity in ("direction", "direction_high", "direction_low"):
        said = _polarity(span.text)
        if said and expected in ("toward", "against"):
            accepted.append(span.text if said == (1 if expected == "toward" else -1) else None)
    ok = any(a is not None and _words_similar(span.text, a) for a in accepted)
    return Claim(kind, span.text, "verified" if ok else "contradicted", f"{f.quantity} = {expected}", "tracked.fact")


def _polarity(word: str) -> int:
    """+1 for a word that raises ('raised', 'toward', 'up'), -1 for one that lowers, 0 for neither."""
    m = DIRECTION_RE.search(word) or _EXTRA_DIRECTIONS.search(word)
    if m is None:
        return (
            1
            if re.fullmatch(r"\W*(?:up|higher|more|for)\W*", word, re.I)
            else (-1 if re.fullmatch(r"\W*(?:down|lower|less)\W*", word, re.I) else 0)
        )
    return 1 if m.groupdict().get("pos") or m.groupdict().get("for") else -1


@dataclass(frozen=True)
class _Part:
    """A piece of a sentence: a tracked span, or literal words (``span`` None)."""

    start: int
    end: int
    span: Span | None
    segment: int  # which segment of the sentence (cut at any of _SEGMENT)
    block: int  # which block (cut only at ; : | and line breaks: a list item, a field)


def _parts(sentence: str, spans: Sequence[Span]) -> list[_Part]:
    out, pos, seg, block = [], 0, 0, 0
    for s in [*sorted(spans, key=lambda s: s.start), None]:
        end = len(sentence) if s is None else s.start
        if end > pos:
            words = sentence[pos:end]
            at = 0
            for m in _SEGMENT.finditer(words):  # each cut starts a new segment (and a block at ; : | or a break)
                out.append(_Part(pos + at, pos + m.start(), None, seg, block))
                seg += 1
                block += bool(_BLOCK.match(words, m.start()))
                at = m.start()
            out.append(_Part(pos + at, end, None, seg, block))
        if s is not None:
            out.append(_Part(s.start, s.end, s, seg, block))
            pos = max(pos, s.end)
    return [p for p in out if p.end > p.start]


def _is_name(p: _Part) -> bool:
    return p.span is not None and p.span.fact.quantity == "name" and p.span.fact.feature is not None


def _literal(sentence: str, parts: list[_Part], a: int, b: int) -> str:
    """The literal words between positions a and b, tracked spans blanked."""
    return "".join(sentence[p.start : p.end] if p.span is None else " \0 " for p in parts if a <= p.start < b)


class _Sentence:
    """One sentence's tracked spans and literal words, and the rules that judge the words."""

    def __init__(self, sentence: str, spans: Sequence[Span], truth: Truth):
        self.text, self.truth = sentence, truth
        self.parts = _parts(sentence, spans)
        self.spans = [p for p in self.parts if p.span is not None]
        self.names = [p for p in self.spans if _is_name(p)]

    def before(self, p: _Part, n: int = 40) -> str:
        """The literal words right before ``p`` in its segment (up to the previous span)."""
        prev = [q for q in self.spans if q.end <= p.start]
        a = max([prev[-1].end if prev else 0, p.start - n])
        return self.text[a : p.start]

    def after(self, p: _Part, n: int = 40) -> str:
        nxt = [q for q in self.spans if q.start >= p.end]
        return self.text[p.end : min(nxt[0].start if nxt else len(self.text), p.end + n)]

    def feature_fact(self, name: str, view: str | None):
        views = self.truth.features.get(name, {})
        return views.get(_view(view)) or next(iter(views.values()), None)

    # -- rules ------------------------------------------------------------------------------------------------
    def binding(self, p: _Part) -> Claim | None:
        """A feature's number said of another feature: the name before it in its segment, else the first after it in
        its segment, else the name before it in the sentence; a group of names followed by their numbers ('A and B:
        a against b') pairs them in order."""
        feature, quantity = p.span.fact.feature, p.span.fact.quantity
        own = [q for q in self.names if q.block == p.block]
        before = [q for q in own if q.end <= p.start] or ([] if own else [q for q in self.names if q.end <= p.start])
        if not before:
            after = [q for q in own if q.start >= p.end]
            return None if not after or after[0].span.fact.feature == feature else self._crossed(p, after[0])
        last = before[-1]
        if last.span.fact.feature == feature:
            return None
        earlier = [q for q in self.spans if q.end <= p.start]
        at = earlier.index(last)
        j = sum(q.span.fact.quantity == quantity for q in earlier[at + 1 :])  # its place among the numbers after
        group = []
        for q in reversed(earlier[: at + 1]):
            if q.span.fact.quantity == quantity:
                break
            if _is_name(q):
                group.insert(0, q)
        if len(group) > 1 and j < len(group) and group[j].span.fact.feature == feature:
            return None
        return self._crossed(p, last)

    def _crossed(self, p: _Part, other: _Part) -> Claim:
        return Claim(
            "number",
            p.span.text,
            "contradicted",
            f"{p.span.text} is {p.span.fact.feature}'s {p.span.fact.quantity}, written as {other.span.fact.feature}'s",
            "tracked.binding",
        )

    def sign(self, p: _Part) -> Claim | None:
        """A value printed with another sign than it has, and no word around it that carries the sign."""
        f = p.span.fact
        expected = self.truth.get(p.span)
        printed = _number(p.span.text)
        if not isinstance(expected, (int, float)) or printed is None or expected >= 0 or printed < 0:
            return None
        if abs(float(expected)) < 1e-9 or _SIGN_BEFORE.search(self.before(p, 30)) or _SIGN_AFTER.match(self.after(p)):
            return None
        return Claim(
            "number",
            p.span.text,
            "contradicted",
            f"{f.feature}'s value is {float(expected):.4g}: written without its sign",
            "tracked.sign",
        )

    def label(self, p: _Part) -> Claim | None:
        """'score=' / 'margin of' / 'average' right before a number of another quantity."""
        q = p.span.fact.quantity
        if q not in _NUMERIC | {"value_text"}:
            return None
        before = self.before(p, 24)
        if _DIFFERENCE.match(self.after(p, 20)):  # 'its score was 2.34 higher': a difference, not the score
            return None
        for pattern, group in _LABELS:
            if pattern.search(before):
                if q in _LABEL_FITS[group]:
                    return None
                return Claim(
                    "number",
                    p.span.text,
                    "contradicted",
                    f"written as the {group}, but it is the {q.replace('_', ' ')}",
                    "tracked.label",
                )
        if q in ("value", "value_text") and _AS_CONTRIBUTION.match(self.after(p, 30)):
            return Claim(
                "number",
                p.span.text,
                "contradicted",
                f"{p.span.fact.feature}'s value, written as its contribution",
                "tracked.label",
            )
        if q == "contribution" and (m := _VIEW_AFTER.search(self.after(p, 30))):
            said = "margin" if m.group(1) else "score"
            if said != _view(p.span.fact.view):
                return Claim(
                    "number",
                    p.span.text,
                    "contradicted",
                    f"a contribution to the {_view(p.span.fact.view)}, written as one to the {said}",
                    "tracked.view",
                )
        return None

    def role(self, p: _Part) -> Claim | None:
        """An action named with the other role's words, or a score beside the other action."""
        role = p.span.fact.role
        if self.truth.output != "actions" or self.truth.actions.get("chosen") == self.truth.actions.get("runner_up"):
            return None
        if p.span.fact.quantity == "score":
            return self._score_role(p)
        before, after = self.before(p, 30), self.after(p, 30)
        prev = next((q for q in reversed(self.spans) if q.end <= p.start), None)
        if prev is not None and prev.span.fact.quantity == "action" and re.fullmatch(r"\s+over\s+", before):
            said = "chosen" if prev.span.fact.role == "runner_up" else "runner_up"  # 'A over B': the other one
            return None if said == role else self._role_claim(p, role, said)
        said = (
            "chosen"
            if _CHOSEN_BEFORE.search(before) or _CHOSEN_AFTER.search(after)
            else "runner_up"
            if _RUNNER_BEFORE.search(before) or _RUNNER_AFTER.search(after)
            else None
        )
        return None if said is None or said == role else self._role_claim(p, role, said)

    @staticmethod
    def _role_claim(p: _Part, role: str, said: str) -> Claim:
        return Claim(
            "action",
            p.span.text,
            "contradicted",
            f"{p.span.text} is the {role.replace('_', '-')}, named as the {said.replace('_', '-')}",
            "tracked.role",
        )

    def _score_role(self, p: _Part) -> Claim | None:
        """A score is the score of the action its words give it to: a 'runner-up' label, a 'chosen' one, else the
        action right before it in its segment ('turn (score 3.05)'), else the one right after 'for' ('3.99 for B')."""
        role, before = p.span.fact.role, self.before(p, 60)
        said = "runner_up" if re.search(r"runner[-_ ]?up|second|next best", before, re.I) else None
        said = said or ("chosen" if re.search(r"\b(?:chosen|chose|picked|winner|won)\b", before, re.I) else None)
        if said is None:
            earlier = [q for q in self.spans if q.end <= p.start]
            later = [q for q in self.spans if q.start >= p.end]
            if earlier and earlier[-1].span.fact.quantity == "action":
                between = self.text[earlier[-1].end : p.start]
                if (earlier[-1].block == p.block and _SCORE_OF_BEFORE.match(between)) or _CELL_SCORE.fullmatch(between):
                    said = earlier[-1].span.fact.role
            if said is None and later and later[0].span.fact.quantity == "action":
                if _SCORE_FOR_AFTER.match(self.text[p.end : later[0].start]):
                    said = later[0].span.fact.role
            said = said or self._respective_role(p)
        if said is None or said == role:
            return None
        return Claim(
            "number",
            p.span.text,
            "contradicted",
            f"{p.span.text} is the {role.replace('_', '-')}'s score, written as the {said.replace('_', '-')}'s",
            "tracked.role",
        )

    def _respective_role(self, p: _Part) -> str | None:
        """'A rather than B: ... (x vs y)': two scores after two actions of different roles pair in order."""
        actions = [q for q in self.spans if q.span.fact.quantity == "action"]
        scores = [q for q in self.spans if q.span.fact.quantity == "score"]
        roles = [q.span.fact.role for q in actions]
        if len(scores) != 2 or len(actions) != 2 or len(set(roles)) != 2 or scores[0].start < actions[-1].end:
            return None
        return roles[scores.index(p)]

    def base(self, p: _Part) -> Claim | None:
        """A background average in a sentence with no word that says it is one."""
        if _BASE_WORDS.search(_literal(self.text, self.parts, 0, len(self.text))):
            return None
        return Claim(
            "number",
            p.span.text,
            "contradicted",
            f"{p.span.text} is the {p.span.fact.quantity.replace('_', ' ')} (the background's average), written "
            "with no word that says so",
            "tracked.label",
        )

    def directions(self) -> list[Claim]:
        """Each direction word of the literal text against the sign of the feature it is said of."""
        out = []
        for p in self.parts:
            if p.span is not None:
                out += self._tracked_direction(p)
                continue
            words = self.text[p.start : p.end]
            found = [(m, 1 if m.group("pos") else -1) for m in DIRECTION_RE.finditer(words)]
            found += [(m, -1 if m.group("neg") else 0) for m in _EXTRA_DIRECTIONS.finditer(words)]
            if self._between_numbers(p) and re.fullmatch(r"\W*\w+\W*", words):
                continue  # '-0.97 against +0.88', '3.05 vs 0.71': a comparison of two numbers
            prev = next((q for q in reversed(self.spans) if q.end <= p.start), None)
            if prev is not None and prev.end == p.start and prev.span.fact.quantity == "action":
                side = _SIDE_OF.match(words)  # 'the feature most on B's side': for B
                target = self._said_of(p) if side else None
                if target is not None:
                    polarity = -1 if prev.span.fact.role == "runner_up" else 1
                    out.append(self._judge(side.group(0), polarity, target, prev))
            for m, polarity in found:
                action = self._action_after(p, m.end())
                if action is None and _SIDE.fullmatch(m.group(0)) and not _CHOSEN_SIDE.match(words, m.end()):
                    continue  # 'favoured a handover to BS 2': a side the words name without a tracked action
                if polarity == 0:  # 'for': a direction only toward a named action
                    if action is None:
                        continue
                    polarity = 1
                if action is not None and action.span.fact.role == "runner_up":
                    polarity = -polarity  # 'favoured B', 'against B': for or against the runner-up
                if _NEGATED.search(self.text[max(0, p.start + m.start() - 30) : p.start + m.start()]):
                    polarity = -polarity
                target = self._said_of(p)
                if target is not None:
                    out.append(self._judge(m.group(0), polarity, target, action))
        return out

    def _tracked_direction(self, p: _Part) -> list[Claim]:
        f = p.span.fact
        if f.quantity not in ("direction",) or f.feature is None:
            return []
        return []  # its word is checked by check_fact (the direction it prints is the feature's)

    def _action_after(self, p: _Part, at: int) -> _Part | None:
        """The tracked action right after a word at ``at`` of literal part ``p`` ('toward B', 'favoured B')."""
        rest = self.text[p.start + at : p.end]
        if not re.fullmatch(r"\W*(?:the\s+|a\s+|an\s+)?(?:action\s+)?", rest):
            return None
        nxt = next((q for q in self.spans if q.start >= p.end), None)
        if nxt is None or nxt.span.fact.quantity != "action" or re.match(r"['’]s\b", self.text[nxt.end : nxt.end + 3]):
            return None  # ('the most important feature for A's score': a possessive, not a side)
        return nxt

    def _between_numbers(self, p: _Part) -> bool:
        before = [q for q in self.spans if q.end <= p.start]
        after = [q for q in self.spans if q.start >= p.end]
        return bool(before and after) and all(
            q.span.fact.quantity in _NUMERIC and before[-1].end == p.start and after[0].start == p.end
            for q in (before[-1], after[0])
        )

    def _said_of(self, p: _Part) -> _Part | None:
        """The feature a direction word of literal part ``p`` is said of: the only name of its segment, else the
        nearest name before it in the sentence, else the first after it in its segment."""
        own = [q for q in self.names if q.segment == p.segment]
        if len({q.span.fact.feature for q in own}) == 1:
            return own[0]
        before = [q for q in self.names if q.end <= p.start]
        if before:
            return before[-1]
        after = [q for q in self.names if q.start >= p.end and q.segment == p.segment]
        return after[0] if after else None

    def _judge(self, word: str, polarity: int, target: _Part, action: _Part | None) -> Claim:
        name = target.span.fact.feature
        view = "margin" if action is not None and action.span.fact.role == "runner_up" else target.span.fact.view
        fact = self.feature_fact(name, view)
        contribution = None
        if fact is not None:
            contribution = fact.contribution if hasattr(fact, "contribution") else fact.get("mean")
        if contribution is None or contribution == 0:
            return Claim(
                "direction", word, "unchecked", f"{name}: no contribution to judge '{word}' by", "tracked.direction"
            )
        ok = (contribution > 0) == (polarity > 0)
        return Claim(
            "direction",
            word,
            "verified" if ok else "contradicted",
            f"'{word}' is said of {name}, whose contribution is {contribution:+.4g}",
            "tracked.direction",
        )

    def levels(self) -> list[Claim]:
        """A level word the template or model wrote ('wind (normal)', 'a high load') against the level of the one
        feature its segment names (or whose value it follows)."""
        out = []
        for p in self.parts:
            if p.span is not None:
                continue
            for m in _LEVEL.finditer(self.text[p.start : p.end]):
                prev = next((q for q in reversed(self.spans) if q.end <= p.start), None)
                own = {q.span.fact.feature: q for q in self.names if q.segment == p.segment}
                right_after = prev is not None and not re.search(r"\w", self.text[prev.end : p.start + m.start()])
                if right_after and prev.span.fact.quantity in ("value", "value_text"):  # '(0.40, low)'
                    name = prev.span.fact.feature
                elif len(own) == 1:
                    name = next(iter(own))
                else:
                    continue
                fact = self.feature_fact(name, None)
                level = getattr(fact, "level", "unknown")
                said = (
                    "typical"
                    if m.group(0).lower() in ("normal", "typical", "moderate", "average")
                    else m.group(0).lower()
                )
                status = "unchecked" if level == "unknown" else "verified" if said == level else "contradicted"
                out.append(Claim("magnitude", m.group(0), status, f"{name}'s level is {level}", "tracked.level"))
        return out

    def ranks(self) -> list[Claim]:
        """A superlative or ordinal in a segment that names one feature: that feature's rank."""
        out = []
        segments = {p.segment for p in self.parts}
        for seg in segments:
            words = "".join(
                self.text[p.start : p.end] if p.span is None else "X" for p in self.parts if p.segment == seg
            )
            names = {q.span.fact.feature: q for q in self.names if q.segment == seg}
            if len(names) != 1 or _NOT_RANK.search(words) and not _SUPERLATIVE.search(_NOT_RANK.sub("", words)):
                continue
            said = (
                1
                if _SUPERLATIVE.search(_NOT_RANK.sub("", words))
                else next((r for r, pattern in _ORDINAL.items() if pattern.search(words)), None)
            )
            if said is None:
                continue
            ((name, q),) = names.items()
            fact = self.feature_fact(name, q.span.fact.view)
            if fact is None or not hasattr(fact, "rank"):
                continue
            signed = bool(DIRECTION_RE.search(words) or _SIGNED_CONTEXT.search(words))
            ok = fact.rank == said or (signed and self._signed_rank(name, q.span.fact.view) == said)
            out.append(
                Claim(
                    "rank",
                    f"{name}: {words.strip()[:60]}",
                    "verified" if ok else "contradicted",
                    f"said to rank {said}; {name} ranks {fact.rank}",
                    "tracked.rank",
                )
            )
        return out

    def _signed_rank(self, name: str, view: str | None) -> int:
        views = [v.get(_view(view)) for v in self.truth.features.values()]
        mine = self.feature_fact(name, view)
        same = sorted(
            (
                abs(f.contribution)
                for f in views
                if f is not None and f.rank and np.sign(f.contribution) == np.sign(mine.contribution)
            ),
            reverse=True,
        )
        return 1 + sum(s > abs(mine.contribution) for s in same)

    def comparisons(self) -> list[Claim]:
        """'A mattered more than B' (two names in one segment, the comparison between them)."""
        out = []
        for a, b in zip(self.names, self.names[1:]):
            if a.segment != b.segment or a.span.fact.feature == b.span.fact.feature:
                continue
            between = self.text[a.end : b.start]
            sign = 1 if _MORE.search(between) else -1 if _LESS.search(between) else 0
            fa, fb = (
                self.feature_fact(a.span.fact.feature, a.span.fact.view),
                self.feature_fact(b.span.fact.feature, b.span.fact.view),
            )
            if not sign or fa is None or fb is None or not hasattr(fa, "contribution"):
                continue
            x, y = abs(fa.contribution), abs(fb.contribution)
            ok = x >= y - 1e-12 if sign > 0 else x <= y + 1e-12
            out.append(
                Claim(
                    "magnitude",
                    f"{a.span.text}{between}{b.span.text}",
                    "verified" if ok else "contradicted",
                    f"|{a.span.fact.feature}| = {x:.4g}, |{b.span.fact.feature}| = {y:.4g}",
                    "tracked.comparison",
                )
            )
        return out


def _claimy(span: Span) -> bool:
    """A name that carries claims of its own ('speed, the most important feature, pushing toward go by +9.99' as a
    description): not trusted as a name, its words are read like any other."""
    return (
        span.fact.quantity in ("name", "action")
        and bool(re.search(r"[,;]", span.text))
        and bool(DIRECTION_RE.search(span.text) or _SUPERLATIVE.search(span.text) or re.search(r"\d", span.text))
    )


def check_sentence(sentence: str, spans: Sequence[Span], truth: Truth, read, smuggled: bool = False) -> list[Claim]:
    """The claims of one sentence of an own narrative: its tracked spans by their facts, its literal words by the
    rules of this module, and its untracked numbers and identifiers by the reader (``read``: sentence -> claims;
    every claim it makes of the untracked words when ``smuggled``: a name that carried claims was left untracked)."""
    s = _Sentence(sentence, spans, truth)
    claims = []
    for p in s.spans:
        claims.append(check_fact(p.span, truth, sentence[p.end : p.end + 9]))
        q = p.span.fact.quantity
        extra = []
        if q in _SAID_OF_FEATURE and p.span.fact.feature:
            extra.append(s.binding(p))
        if q in ("value", "value_text"):
            extra.append(s.sign(p))
        if q in _NUMERIC:
            extra.append(s.label(p))
        if q in ("base_value", "base_margin"):
            extra.append(s.base(p))
        if q in ("action", "score") and p.span.fact.role:
            extra.append(s.role(p))
        claims += [c for c in extra if c is not None]
    claims += s.directions() + s.levels() + s.ranks() + s.comparisons()
    literal = _literal(sentence, s.parts, 0, len(sentence))
    if smuggled or re.search(r"\d|[A-Za-z][A-Za-z0-9]*_[A-Za-z0-9]", literal):  # an untracked number or identifier
        named = {p.span.fact.feature for p in s.names}
        claims += [_own(c, truth, named) for c in read(sentence) if _untracked(c, sentence, s.spans, smuggled)]
    return claims


def _own(c: Claim, truth: Truth, named: set[str] = frozenset()) -> Claim:
    """A reader's claim in an own narrative: a number the template wrote itself that the reader leaves unchecked
    must at least be one of the decision's own numbers (a score, the margin, a base value), a fact of a feature
    the sentence names, or a count or rank (a whole number up to the number of features); one that is none of them
    is made up, and contradicted."""
    if c.kind != "number" or c.status != "unchecked":
        return c
    printed = _number(c.text)
    facts = [
        float(v)
        for (quantity, feature, _, _), v in truth.values.items()
        if isinstance(v, (int, float))
        and not isinstance(v, bool)
        and (feature is None or feature in named)
        and quantity not in ("extra",)
    ]
    whole = printed is not None and printed == int(printed) and 0 < printed <= max(len(truth.features), 3)
    if printed is None or whole or any(_close(abs(printed), abs(v), c.text) for v in facts if math.isfinite(v)):
        return c
    return Claim(
        "number",
        c.text,
        "contradicted",
        f"not taken from the facts, and none of this decision's numbers ({c.detail})",
        "tracked.untracked",
    )


def _untracked(c: Claim, sentence: str, spans: list[_Part], any_kind: bool = False) -> bool:
    """A reader's claim about words outside every tracked span (a number or name the template wrote itself)."""
    if (c.kind not in ("number", "feature", "action") and not any_kind) or not c.text:
        return False
    at = sentence.find(c.text)
    while at >= 0:
        if not any(p.start <= at < p.end or at <= p.start < at + len(c.text) for p in spans):
            return True
        at = sentence.find(c.text, at + 1)
    return False


def verify(
    text: str,
    explanation: Explanation,
    index: int | None = 0,
    policy: Policy | None = None,
    facts: DomainFacts | None = None,
    provenance: Sequence[Span] | None = None,
) -> Verification:
    """Check every claim of ``text`` against the explanation of state ``index`` (``None``: the global view).

    :param provenance: the tracked spans of ``text`` (:attr:`xairl.Narrative.provenance`, or a rendering's
        ``spans``): each is checked by its fact, and the words around it by their sentence's spans (module doc).
        Without it the whole text is read as outside prose (:mod:`xairl.narrators.verify`).

    The other parameters are those of the reader's :func:`xairl.narrators.verify.verify`.
    """
    from .verify import verify as read_prose

    several = explanation.output == "continuous" and explanation.values.shape[2] > 1 and index is not None
    if not provenance or several:  # (the spans of several dimensions do not say which one: narrate checks each)
        return read_prose(text, explanation, index, policy, facts=facts)
    if not isinstance(text, str):
        raise InputError(f"verify() reads text (a str), not {type(text).__name__}.")
    if normalise(text) != text:
        return read_prose(text, explanation, index, policy, facts=facts)  # offsets would not hold: read it
    index = None if index is None else explanation.check_index(index)
    claimy = [s for s in provenance if _claimy(s)]
    provenance = [s for s in provenance if not _claimy(s)]
    exp = in_regions(explanation)
    book = truth(exp, index, policy, facts)
    readers = []

    def read(sentence: str) -> list[Claim]:  # the reader of outside prose, set up only when a sentence needs it
        if not readers:
            readers.append(reader(exp, index, policy, facts))
        return readers[0](sentence)

    checks, header = [], None
    for a, b in sentences(text):
        own = [s.shifted(-a) for s in provenance if a <= s.start and s.end <= b]
        sentence = text[a:b]
        smuggled = any(a <= s.start < b for s in claimy)
        header, labelled = _table_row(sentence, own, header)
        if labelled is not None:  # a table's row, each cell read after its column's header ('chosen: turn')
            sentence_read, spans_read, back = labelled
            claims = check_sentence(sentence_read, spans_read, book, read, smuggled)
            claims = [replace(c, span=back.get(id(c.span), c.span)) for c in claims]
        else:
            claims = (
                check_sentence(sentence, own, book, read, smuggled) if own else [_own(c, book) for c in read(sentence)]
            )
        claims = [replace(c, span=c.span.shifted(a)) if c.span is not None else c for c in claims]
        checks.append(SentenceCheck(sentence.strip(), tuple(claims)))
    return Verification(tuple(checks))


_SEPARATOR_ROW = re.compile(r"\s*\|?(?:\s*:?-{3,}:?\s*\|)+\s*:?-*:?\s*")


def _table_row(sentence: str, spans: list[Span], header: list[str] | None):
    """(the table's header so far, and for a row under it: the row with each cell after its header's words, its
    spans moved there, and {id of a moved span: the span}); a line that is no table row ends the table."""
    if not sentence.strip().startswith("|"):
        return None, None
    if _SEPARATOR_ROW.fullmatch(sentence):
        return header, None
    bars = [i for i, ch in enumerate(sentence) if ch == "|"]
    cells = list(zip(bars, bars[1:]))
    if header is None or not spans:
        return header or [sentence[x + 1 : y].strip() for x, y in cells], None
    out, moved, back, pos = "", [], {}, 0
    for n, (x, y) in enumerate(cells):
        out += sentence[pos : x + 1] + (f" {header[n]}:" if n < len(header) and header[n] else "")
        shift = len(out) - (x + 1)
        for sp in spans:
            if x < sp.start and sp.end <= y:
                moved.append(sp.shifted(shift))
                back[id(moved[-1])] = sp
        pos = x + 1
    out += sentence[pos:]
    return header, (out, moved, back)
