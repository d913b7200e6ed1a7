"""The reader of outside prose: a text checked against an Explanation by rules that are data.

Layers, each using only those before it (the import contract in pyproject.toml): lexicon (the word lists of
rules/lexicon.yaml) -> parse (sentences with names and numbers as single tokens) -> rules (rules/rules.yaml: spaCy
Matcher and DependencyMatcher patterns) -> resolve (one reading per number, direction or rank word: priority, then the
nearest name) -> check (each claim against the fact book). A claim is contradicted only where a rule binds it to its name by adjacency ('A +0.3',
'A (0.3)', 'A=0.3') or grammar (subject, object, 'by'); anything else verifies or stays unchecked.

Stage 1 of issue 54: numbers, names, the fact book and the sentence splitter are still those of
``xairl.narrators.verify``; they move here when this reader replaces that one.

``xairl.verify(text, explanation, ...)`` stays the public verifier whichever way this package was imported: the
module is callable and calls :func:`xairl.narrators.verify` (importing ``xairl.verify`` as a package would otherwise
replace the function of that name on ``xairl``).
"""

from __future__ import annotations

import sys
import types

from xairl.errors import InputError
from xairl.explanations.explanation import Explanation
from xairl.narrators.verify import SentenceCheck, Verification, aids, inputs, sentences
from xairl.narrators.verify.checks import Claim
from xairl.policies.policy import Policy
from xairl.verify import check, rules
from xairl.verify.parse import Sentence
from xairl.verify.parse import parse as parse_sentences
from xairl.verify.resolve import Decision, resolve

__all__ = ["read", "trace", "tokens"]


class _CallableModule(types.ModuleType):
    def __call__(self, *args, **kwargs) -> Verification:
        from xairl.narrators import verify

        return verify(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule


def read(text: str, explanation: Explanation, index: int = 0, policy: Policy | None = None) -> Verification:
    """Check every claim of ``text`` against the explanation of decision ``index``; never raises on odd text (a
    failure of the parse leaves the text unchecked with the reason)."""
    try:
        sentences_, book, unit_of, note, known = _prepare(text, explanation, index, policy)
    except InputError:
        raise
    except Exception as e:  # noqa: BLE001 - a reader bug must not take the narration down with it
        failed = Claim("internal", text[:200], "unchecked", f"the reader failed ({type(e).__name__}: {e})")
        return Verification((SentenceCheck(text.strip()[:200], (failed,)),), "")
    out = []
    for s in sentences_:
        out.append(SentenceCheck(s.text.strip(), tuple(_claims(s, book, unit_of, known)[0])))
    return Verification(tuple(out), note)


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


def _prepare(text, explanation, index, policy):
    """The parsed sentences, the fact book, ``unit_of``, the note and the names' words (the shared preamble of the
    readers, :func:`xairl.narrators.verify.inputs` and :func:`~xairl.narrators.verify.aids`)."""
    text, explanation, index, note = inputs(text, explanation, explanation.check_index(index), caller="read")
    text = text.encode("utf-8", "replace").decode("utf-8")  # (a lone surrogate: one '?', the length kept)
    book, vocab, unit_of = aids(explanation, index, policy)
    pieces = [text[a:b] for a, b in sentences(text)]
    return parse_sentences(pieces, vocab), book, unit_of, note, vocab.name_words


def _claims(s: Sentence, book, unit_of, known) -> tuple[list[Claim], list[Decision]]:
    """A sentence's claims (a name alone claims nothing checkable), and the decisions the trace shows. A failure of
    the reader leaves the sentence unchecked with the reason: never an exception to the caller."""
    names = [t for t in s.doc if t.ent_type_ == "FEATURE"]
    out = [Claim("feature", t.text, "verified", " / ".join(t._.keys), "names.mention") for t in names]
    if s.text.rstrip().endswith("?") or not any(t.ent_type_ for t in s.doc):
        return out, []  # a question asserts nothing; a sentence with no name nor number gives no rule a hold
    try:
        decisions = resolve(rules.candidates(s.doc))
        return out + _checked(s, decisions, names, book, unit_of, known), decisions
    except Exception as e:  # noqa: BLE001 - a reader bug must not take the narration down with it
        return out + [
            Claim("internal", s.text.strip(), "unchecked", f"the reader failed ({type(e).__name__}: {e})")
        ], []


def _checked(s: Sentence, decisions: list[Decision], names, book, unit_of, known) -> list[Claim]:
    ctx = check.view(s, book)
    out, bound = [], set()
    for d in decisions:
        made = check.claim(d.winner, s, book, unit_of, ctx, known)
        if made is not None:
            out.append(made)
        if d.winner.rule.claim in ("number", "output", "net", "skip"):
            bound.add(d.winner.anchor)
    named = {k for t in names for k in t._.keys} | {k for d in decisions for k in s.doc[d.winner.name]._.keys}
    for t in s.doc:
        if t.ent_type_ == "NUM" and t.i not in bound:
            out.append(check.free_number(t, book))
        elif t.ent_type_ == "LABEL":
            c = check.label_claim(t, book, named)
            if c is not None:
                out.append(c)
    return out
