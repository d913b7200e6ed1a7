"""Verification of xairl's own words by provenance: a lookup, never a reading.

A narrative xairl rendered carries, for every value it printed, the fact it came from (:mod:`xairl.templates.tracking`).
A tracked span *is* its fact: it is checked against the explanation (recomputed, never trusted) and never re-bound to
another name by its position. A claim word (a direction, level, rank, comparison or an action's role) is declared
through a template filter (``dir``, ``level``, ``rank``, ``cmp``, ``role``): its fact says which way, so the author's
own words (``dir('grew', 'shrank')``, Spanish) need no word list. What is left, the template's literal words:

- a claim word, a name of a feature or action, an identifier or a number the template wrote itself is *undeclared*
  (:func:`xairl.verification.claims.claim_words`): its sentence is unchecked, never verified nor contradicted;
- a label, a sign word, a view or a trend word right beside a tracked number is judged against it (adjacency:
  ``score=`` before the margin, '+0.46 to the score' for a contribution to the margin);
- a counterfactual sentence is re-run through the policy (:mod:`xairl.verification.own.counterfactual`).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import replace

from xairl.explanations.explanation import Explanation
from xairl.facts import DomainFacts
from xairl.policies.policy import Policy
from xairl.policies.regions import in_regions
from xairl.templates.tracking import Span
from xairl.verification.claims import claim_words
from xairl.verification.own.counterfactual import check_counterfactual, is_counterfactual
from xairl.verification.own.lexicon import NUMBER, NUMERIC, SAID_OF_FEATURE
from xairl.verification.own.parts import Part
from xairl.verification.own.spans import Sentence
from xairl.verification.own.truth import Truth, check_fact, number, truth
from xairl.verification.result import Claim, SentenceCheck, Verification
from xairl.verification.text import bidi_claims, bidi_note, sentences

__all__ = ["RULES", "Truth", "check_fact", "check_sentence", "truth", "verify"]

#: rule id -> what it checks (the ids a provenance claim names; docs/customising-prompts.md lists them)
RULES = {
    "tracked.fact": "a tracked number or word is its fact's value as printed (with the template's transformation)",
    "tracked.unknown": "a tracked span whose fact is not in the explanation (an unknown feature, action or view)",
    "tracked.binding": "a tracked number of one feature printed beside another feature's name (unchecked: binding by "
    "position never contradicts)",
    "tracked.trend": "a number after a trend word ('fell 4.1 dB') that is no change over the window, or of the other sign",
    "tracked.sign": "a feature's value printed without its sign, and no word that carries the sign",
    "tracked.label": "a label beside a tracked number ('score=', 'margin of') that is not its quantity",
    "tracked.view": "'to the margin' / 'to the score' beside a contribution of the other view",
    "tracked.role": "a score printed beside the other action ('turn (score 1.85)' with 1.85 the runner-up's)",
    "tracked.undeclared": "a claim word, name, identifier or number the template wrote itself (not through a filter): "
    "the sentence is unchecked",
    "tracked.counterfactual": "a counterfactual ('had X been below v, it would have chosen B') re-run: the policy on "
    "the stated values takes another action than it did, the stated one, by the stated margin",
}


def _claimy(span: Span) -> bool:
    """A name that carries claims of its own ('speed, the most important feature, pushing toward go by +9.99' as a
    description): not trusted as a name, its words are literal words like any other."""
    text = re.sub(r"\[[^\]]*\]", "", span.text)  # (an index is part of a name: 'obs[0,5,7]', 'patch[1,0]')
    return (
        span.fact.quantity in ("name", "action")
        and bool(re.search(r"[,;]", text))
        and bool(re.search(r"\d", text) or any(w.kind != "name" for w in claim_words(text)))
    )


def check_sentence(sentence: str, spans: Sequence[Span], truth: Truth, names: Sequence[str] = ()) -> list[Claim]:
    """The claims of one sentence of an own narrative: its tracked spans by their facts and the literal words right
    beside them; a counterfactual by re-running it; any claim word the template wrote itself is undeclared."""
    s = Sentence(sentence, spans, truth)
    counterfactual = [p for p in s.spans if is_counterfactual(p)]
    claims = check_counterfactual(s, counterfactual, truth)
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
        if q == "score" and p.span.fact.role:
            extra.append(s.role(p))
        if q == "action" and p.span.fact.role == "runner_up" and not _role_declared(s.spans, p, truth):
            extra.append(
                Claim(
                    "role",
                    p.span.text,
                    "unchecked",
                    "the runner-up named without its role: write the words "
                    "that say it with runner_up|role('chose', 'over')",
                    UNDECLARED,
                )
            )
        if counterfactual and q in DECISION_NUMBERS:
            what = q.replace("_", " ")
            extra.append(
                Claim(
                    "number",
                    p.span.text,
                    "unchecked",
                    f"the decision's {what}, in a sentence about the "
                    "counterfactual: print the counterfactual's (counterfactual.margin)",
                    UNDECLARED,
                )
            )
        claims += [c for c in extra if c is not None]
    claims += undeclared(sentence, s.spans, names, numbers_only=bool(counterfactual))
    return claims


def _role_declared(spans: Sequence[Part], p: Part, truth: Truth) -> bool:
    """Whether the sentence declares the role of the action ``p`` names (a ``role`` word of that action), or there
    is no other action it could be taken for."""
    if truth.actions.get("chosen") == truth.actions.get("runner_up"):
        return True
    name = p.span.fact.value if p.span.fact.value is not None else p.span.text
    return any(q.span.fact.quantity == "role" and q.span.fact.value in (name, p.span.text) for q in spans) or any(
        q.span.fact.quantity == "role" and q.span.fact.role == "runner_up" for q in spans
    )


def undeclared(
    sentence: str, spans: Sequence[Part], names: Sequence[str] = (), numbers_only: bool = False
) -> list[Claim]:
    """The claims a template wrote itself, outside every tracked span: claim words, names and identifiers
    (:func:`~xairl.verification.claims.claim_words`), and numbers other than a small count (up to 3). Of a
    counterfactual sentence (``numbers_only``) only the numbers: its words are its re-run's to judge."""
    blank = list(sentence)
    for p in spans:
        blank[p.start : p.end] = " " * (p.end - p.start)
    words = "".join(blank)
    out = [
        Claim(w.kind, w.word, "unchecked", f"'{w.word}' is a claim the template wrote itself: {w.use}", UNDECLARED)
        for w in ([] if numbers_only else claim_words(words, names))
    ]
    for m in NUMBER.finditer(words):
        x = number(m.group())
        if x is not None and x == int(x) and 0 < x <= 3 and "." not in m.group():
            continue  # a small count or a list's number ('the top 3'); a larger one may be an id ('BS 12')
        out.append(
            Claim(
                "number",
                m.group(),
                "unchecked",
                "a number the template wrote itself: print it from the facts",
                UNDECLARED,
            )
        )
    return out


UNDECLARED = "tracked.undeclared"
#: the decision's own numbers: in a counterfactual sentence they read as the counterfactual's
DECISION_NUMBERS = frozenset({"margin", "score", "base_value", "base_margin"})


def _names(truth: Truth, policy: Policy | None) -> tuple[str, ...]:
    """The names a literal word may be: every feature's name and label, every action's."""
    out = list(truth.features) + [a for a in truth.actions.values() if a]
    for views in truth.features.values():
        for f in views.values():
            label = getattr(f, "label", None) or (f.get("label") if isinstance(f, dict) else None)
            out += [label] if label else []
    if policy is not None:  # (its features are those of the facts: an image's regions, not its 12,288 pixels)
        out += list(policy.action_names or ())
    return tuple(dict.fromkeys(str(n) for n in out))


def verify(
    text: str,
    explanation: Explanation,
    index: int | None,
    policy: Policy | None,
    facts: DomainFacts | None,
    provenance: Sequence[Span],
) -> Verification:
    """Check every claim of an own narrative ``text`` against the explanation of state ``index`` (``None``: the
    global view): each tracked span (``provenance``) by its fact, the words around it as the module doc says."""
    index = None if index is None else explanation.check_index(index)
    claimy = [s for s in provenance if _claimy(s)]
    provenance = [s for s in provenance if not _claimy(s)]
    book = truth(in_regions(explanation), index, policy, facts)
    names = _names(book, policy)
    checks, header = [], None
    for a, b in sentences(text):
        own = [s.shifted(-a) for s in provenance if a <= s.start and s.end <= b]
        sentence = text[a:b]
        header, labelled = _table_row(sentence, own, header)
        if labelled is not None:  # a table's row, each cell read after its column's header ('chosen: turn')
            sentence_read, spans_read, back = labelled
            claims = check_sentence(sentence_read, spans_read, book, names)
            claims = [replace(c, span=back.get(id(c.span), c.span)) for c in claims]
        else:
            claims = check_sentence(sentence, own, book, names)
        claims = [replace(c, span=c.span.shifted(a)) if c.span is not None else c for c in claims]
        if any(a <= s.start < b for s in claimy):
            claims.append(
                Claim("feature", sentence.strip()[:80], "unchecked", "a name that holds claims of its own", UNDECLARED)
            )
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
