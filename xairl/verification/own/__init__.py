"""Verification of xairl's own words by provenance.

A narrative xairl rendered carries, for every value it printed, the fact it came from (:mod:`xairl.templates.tracking`). A
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
from dataclasses import replace

from xairl.explanations.explanation import Explanation
from xairl.facts import DomainFacts
from xairl.policies.policy import Policy
from xairl.policies.regions import in_regions
from xairl.templates.tracking import Span
from xairl.verification.counterfactual import check_counterfactual, is_counterfactual
from xairl.verification.own.lexicon import NUMERIC, SAID_OF_FEATURE, SUPERLATIVE
from xairl.verification.own.parts import Part, literal
from xairl.verification.own.spans import Sentence
from xairl.verification.own.truth import Truth, check_fact, close, number, truth
from xairl.verification.prose.checks import DIRECTION_RE
from xairl.verification.result import Claim, SentenceCheck, Verification
from xairl.verification.text import bidi_claims, bidi_note, sentences

__all__ = ["RULES", "Truth", "check_fact", "check_sentence", "truth", "verify"]

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
    "tracked.counterfactual": "a counterfactual ('had X been below v, it would have chosen B') re-run: the policy on "
    "the stated values takes another action than it did, the stated one, by the stated margin",
}


def _claimy(span: Span) -> bool:
    """A name that carries claims of its own ('speed, the most important feature, pushing toward go by +9.99' as a
    description): not trusted as a name, its words are read like any other."""
    return (
        span.fact.quantity in ("name", "action")
        and bool(re.search(r"[,;]", span.text))
        and bool(DIRECTION_RE.search(span.text) or SUPERLATIVE.search(span.text) or re.search(r"\d", span.text))
    )


def check_sentence(sentence: str, spans: Sequence[Span], truth: Truth, read, smuggled: bool = False) -> list[Claim]:
    """The claims of one sentence of an own narrative: its tracked spans by their facts, its literal words by the
    rules of this module, and its untracked numbers and identifiers by the reader (``read``: sentence -> claims;
    every claim it makes of the untracked words when ``smuggled``: a name that carried claims was left untracked)."""
    s = Sentence(sentence, spans, truth)
    claims = check_counterfactual(s, [p for p in s.spans if is_counterfactual(p)], truth)
    for p in s.spans:
        if is_counterfactual(p):
            continue
        claims.append(check_fact(p.span, truth, sentence[p.end : p.end + 9]))
        q = p.span.fact.quantity
        extra = []
        if q in SAID_OF_FEATURE and p.span.fact.feature:
            extra.append(s.binding(p))
        if q in ("value", "value_text"):
            extra.append(s.sign(p))
        if q in NUMERIC:
            extra += [s.label(p), s.trend(p)]
        if q in ("base_value", "base_margin"):
            extra.append(s.base(p))
        if q in ("action", "score") and p.span.fact.role:
            extra.append(s.role(p))
        claims += [c for c in extra if c is not None]
    claims += s.directions() + s.levels() + s.ranks() + s.comparisons()
    words = literal(sentence, s.parts, 0, len(sentence))
    if smuggled or re.search(r"\d|[A-Za-z][A-Za-z0-9]*_[A-Za-z0-9]", words):  # an untracked number or identifier
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
    printed = number(c.text)
    facts = [
        float(v)
        for (quantity, feature, _, _), v in truth.values.items()
        if isinstance(v, (int, float))
        and not isinstance(v, bool)
        and (feature is None or feature in named)
        and quantity not in ("extra",)
    ]
    whole = printed is not None and printed == int(printed) and 0 < printed <= max(len(truth.features), 3)
    if printed is None or whole or any(close(abs(printed), abs(v), c.text) for v in facts if math.isfinite(v)):
        return c
    return Claim(
        "number",
        c.text,
        "contradicted",
        f"not taken from the facts, and none of this decision's numbers ({c.detail})",
        "tracked.untracked",
    )


def _untracked(c: Claim, sentence: str, spans: list[Part], any_kind: bool = False) -> bool:
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
    index: int | None,
    policy: Policy | None,
    facts: DomainFacts | None,
    provenance: Sequence[Span],
    reader,
) -> Verification:
    """Check every claim of an own narrative ``text`` against the explanation of state ``index`` (``None``: the
    global view), each tracked span (``provenance``) by its fact and the words around it by their sentence's spans
    (module doc). ``reader(exp, index, policy, facts)`` gives the reader of one untracked sentence."""
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
        checks.append(SentenceCheck(sentence.strip(), (*bidi_claims(sentence), *claims)))
    return Verification(tuple(checks), bidi_note(text))


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
