"""The reader of outside prose: a text checked against an Explanation by rules that are data.

Layers, each using only those before it (the import contract in pyproject.toml): lexicon (the word lists of
rules/lexicon.yaml) -> parse (sentences with names and numbers as single tokens) -> rules (rules/rules.yaml: spaCy
Matcher and DependencyMatcher patterns) -> resolve (one reading per number, direction or rank word: priority, then the
nearest name) -> check (each claim against the fact book). A claim is contradicted only where a rule binds it to its name by adjacency ('A +0.3',
'A (0.3)', 'A=0.3') or grammar (subject, object, 'by'); anything else verifies or stays unchecked.

"""

from __future__ import annotations

import numpy as np

from xairl.errors import InputError
from xairl.explanations.explanation import Explanation
from xairl.policies.policy import Policy
from xairl.policies.regions import in_regions
from xairl.policies.windows import window_of
from xairl.verification.prose import check, rules
from xairl.verification.prose.book import add_facts, clean_surface, fact_book
from xairl.verification.prose.parse import Sentence
from xairl.verification.prose.parse import parse as parse_sentences
from xairl.verification.prose.resolve import Decision, resolve
from xairl.verification.prose.unbound import read_tokens, unbound, unknown_regions
from xairl.verification.prose.units import unit_in_name
from xairl.verification.prose.vocabulary import vocabulary
from xairl.verification.prose.window import add_window_facts, per_signal
from xairl.verification.result import Claim, SentenceCheck, Verification
from xairl.verification.text import MAX_CHARS, bidi_claims, bidi_note, normalise, sentences

__all__ = ["read", "trace", "tokens", "inputs"]


def read(
    text: str, explanation: Explanation, index: int | None = 0, policy: Policy | None = None, facts=None
) -> Verification:
    """Check every claim of ``text`` against the explanation of decision ``index`` (``None``: the global view);
    never raises on odd text (a failure of the parse leaves the text unchecked with the reason).

    :param facts: optional :class:`xairl.facts.DomainFacts` beyond the explanation (e.g. a flight's handover counts).
    """
    try:
        sentences_, book, unit_of, note, known = _prepare(text, explanation, index, policy, facts)
    except InputError:
        raise
    except Exception as e:  # noqa: BLE001 - a reader bug must not take the narration down with it
        failed = Claim("internal", text[:200], "unchecked", f"the reader failed ({type(e).__name__}: {e})")
        return Verification((SentenceCheck(text.strip()[:200], (failed,)),), "")
    out = []
    for s in sentences_:
        out.append(SentenceCheck(s.text.strip(), (*bidi_claims(s.text), *_claims(s, book, unit_of, known)[0])))
    return Verification(tuple(out), "; ".join(filter(None, [note, bidi_note(text)])))


def trace(text: str, explanation: Explanation, index: int = 0, policy: Policy | None = None) -> list[str]:
    """Per sentence: every rule's candidate reading and the one that won, then the claims."""
    sentences_, book, unit_of, _, known = _prepare(text, explanation, index, policy)
    lines = []
    for s in sentences_:
        claims, decisions = _claims(s, book, unit_of, known)
        lines.append(f"sentence: {s.text.strip()}")
        for d in decisions:
            for c in d.candidates:
                mark = "*" if c is d.winner else " "
                lines.append(
                    f"  {mark} {c.rule.id} (priority {c.rule.priority}): {s.doc[c.name].text} <- {s.doc[c.anchor].text}"
                )
        lines += [f"  -> {c.kind} '{c.text}': {c.status} ({c.detail}) [{c.rule}]" for c in claims]
    return lines


def tokens(text: str, explanation: Explanation, index: int = 0, policy: Policy | None = None) -> list[list[tuple]]:
    """What the rules see, per sentence: (token, ENT_TYPE, dependency, head) for each token, names and numbers merged
    (the first step of adding a rule, docs/verifier.md)."""
    sentences_ = _prepare(text, explanation, index, policy)[0]
    return [[(t.text, t.ent_type_, t.dep_, t.head.text) for t in s.doc] for s in sentences_]


def _prepare(text, explanation, index, policy, facts=None):
    """The parsed sentences, the fact book, ``unit_of``, the note and the names' words (the shared preamble of the
    readers, :func:`xairl.narrators.verify.inputs` and :func:`~xairl.narrators.verify.aids`)."""
    text, explanation, index, note = inputs(text, explanation, index, caller="verify")
    text = text.encode("utf-8", "replace").decode("utf-8")  # (a lone surrogate: one '?', the length kept)
    book, vocab, unit_of = aids(explanation, index, policy, facts)
    pieces = [text[a:b] for a, b in sentences(text)]
    return parse_sentences(pieces, vocab), book, unit_of, note, vocab.name_words


def _claims(s: Sentence, book, unit_of, known) -> tuple[list[Claim], list[Decision]]:
    """A sentence's claims, and the decisions the trace shows: what the rules read, checked, then an unchecked claim
    for each claim word or name no rule read (unbound.py). A question asserts nothing. A failure of the reader leaves
    the sentence unchecked with the reason: never an exception to the caller."""
    if s.text.rstrip().endswith("?"):
        return [], []
    try:
        decisions = resolve(rules.candidates(s.doc))
        out, read = _checked(s, decisions, book, unit_of, known)
        mentions = [
            Claim("feature", t.text, "verified", " / ".join(t._.keys), "names.mention")
            for t in s.doc
            if t.ent_type_ == "FEATURE" and t.i in read
        ]
        return mentions + out + unbound(s, read, book) + unknown_regions(s.masked), decisions
    except Exception as e:  # noqa: BLE001 - a reader bug must not take the narration down with it
        return [Claim("internal", s.text.strip(), "unchecked", f"the reader failed ({type(e).__name__}: {e})")], []


def _checked(s: Sentence, decisions: list[Decision], book, unit_of, known) -> tuple[list[Claim], set[int]]:
    """The claims the resolved readings make, each number and label of the sentence checked, and the tokens read."""
    ctx = check.view(s, book)
    out, bound, made = [], set(), []
    for d in decisions:
        claim = check.claim(d.winner, s, book, unit_of, ctx, known)
        if claim is not None:
            out.append(claim)
            made.append((d.winner, claim))
        if d.winner.rule.claim in ("number", "output", "net", "skip"):
            bound.add(d.winner.anchor)
    read = read_tokens(s, made)
    named = {k for t in s.doc if t.i in read and t.ent_type_ == "FEATURE" for k in t._.keys}
    for t in s.doc:
        if t.ent_type_ == "NUM":
            read.add(t.i)
            if t.i not in bound and (score := check.action_score(s, t, book)) is not None:
                out.append(score)
            elif t.i not in bound:
                name = _nearest_name(s, t)
                out.append(check.free_number(t, book, name, unit_of, ctx, s.masked))
                if out[-1].rule == "number.nearest":
                    read.add(name.i)
        elif t.ent_type_ == "LABEL":
            c = check.label_claim(t, book, named)
            if c is not None:
                out.append(c)
                read.add(t.i)
    return out, read


def _nearest_name(s: Sentence, number):
    """The name nearest before a number in its clause (else the nearest after it): a binding by position alone,
    which may verify a number and never contradicts it."""
    before = [
        t
        for t in s.doc[: number.i]
        if t.ent_type_ == "FEATURE" and not any(x.text in ";|" for x in s.doc[t.i : number.i])
    ]
    after = [t for t in s.doc[number.i + 1 :] if t.ent_type_ == "FEATURE"]
    return before[-1] if before else (after[0] if after else None)


def inputs(text, explanation: Explanation, index: int | None, caller: str = "verify") -> tuple:
    """(text, explanation, index, note): a str checked (else a one-line error), the index checked (``None``: the
    global view), the explanation in regions or per signal (an image or a window is read as it is narrated), the
    text normalised and cut at
    :data:`MAX_CHARS` (the note says so). What every reader of prose does first."""
    if not isinstance(text, str):
        raise InputError(
            f"{caller}() reads text (a str), not {type(text).__name__}: decode it first, e.g. data.decode('utf-8')."
        )
    index = None if index is None else explanation.check_index(index)
    explanation, text, note = in_regions(explanation), normalise(text), ""
    if window_of(explanation) is not None:
        explanation = per_signal(explanation)
    if len(text) > MAX_CHARS:
        text, note = text[:MAX_CHARS], f"text cut at {MAX_CHARS} characters"
    return text, explanation, index, note


def aids(explanation: Explanation, index: int | None, policy: Policy | None = None, facts=None) -> tuple:
    """(fact book, vocabulary, unit_of): what a reader checks claims with, for state ``index`` of an explanation
    already in regions; ``unit_of(feature)`` is its unit (the policy's, else its name's ending)."""
    with np.errstate(all="ignore"):  # sums of contributions near 1e308 overflow: an infinite fact matches no number
        book = fact_book(explanation, index, policy)
    if facts is not None:
        add_facts(book, facts)
        book.closed = index is None  # a summary made from these facts: a number that is none of them is wrong
    if index is not None and "window" in (explanation.extras or {}):
        add_window_facts(book, explanation, index, policy)
    vocab = vocabulary(explanation, policy, clean_surface)

    def unit_of(f: str) -> str:
        info = policy.features.get(f) if policy else None
        return info.unit if info and info.unit else unit_in_name(f)

    return book, vocab, unit_of


def reader(explanation: Explanation, index: int | None, policy: Policy | None = None, facts=None):
    """The reader of one sentence (sentence -> its claims), its fact book and names made once."""
    book, vocab, unit_of = aids(explanation, index, policy, facts)

    def read_one(sentence: str) -> list[Claim]:
        return _claims(parse_sentences([sentence], vocab)[0], book, unit_of, vocab.name_words)[0]

    return read_one
