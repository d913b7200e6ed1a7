"""What every reader does first: the text checked and normalised, cut into sentences; bidirectional controls."""

from __future__ import annotations

import re

from xairl.templates.prompts import bidi_controls
from xairl.verification.result import Claim

MAX_CHARS = 200_000  # longer texts are cut here (and the cut reported)
#: a longer sentence is read in pieces of at most this many characters, cut at a clause boundary (commas, 'and'):
#: the clause readers look back over their sentence, so a bound on its length keeps the time linear in the text
MAX_SENTENCE = 600

_SENTENCE_RE = re.compile(r"(?<=[.!?])\s+(?=\S)|\n+\s*(?:[-•*]\s*)?")
_ABBREVIATION = re.compile(r"(?:^|[\s(])(?:e\.g|i\.e|vs|approx|ca|etc|no|fig|cf)\.$", re.IGNORECASE)
_ITEM_NUMBER = re.compile(r"\s*\d{1,2}\.")  # a list item's number, read in place (no copy of the text before it)


def sentences(text: str) -> list[tuple[int, int]]:
    """Sentence spans: split after . ! ? before a capital or a sign, and at line breaks and bullets."""
    spans, start = [], 0
    for m in _SENTENCE_RE.finditer(text):
        if (
            _ABBREVIATION.search(text[max(0, m.start() - 8) : m.start()])
            or text[max(0, m.start() - 2) : m.start() - 1].isspace()
            or _ITEM_NUMBER.fullmatch(text, start, m.start())
        ):  # (the cheap tests first: '! ! !' after
            # 2,000 tabs read them 2,000 times over, issue 51's fuzz)
            continue  # 'e.g. X', '1. Living area ...', 'over ? (score 2.1)' (a name, not an end): no sentence end
        if text[start : m.start()].strip():
            spans.append((start, m.start()))
        start = m.end()
    if text[start:].strip():
        spans.append((start, len(text)))
    return [piece for span in spans for piece in _pieces(text, *span)]


def _pieces(text: str, a: int, b: int) -> list[tuple[int, int]]:
    """A sentence longer than :data:`MAX_SENTENCE` cut at its last clause boundary (';', ',', ' and ', a space) before
    the limit, again and again."""
    out = []
    while b - a > MAX_SENTENCE:
        window = text[a : a + MAX_SENTENCE]
        cut = max(window.rfind(";"), window.rfind(","), window.rfind(" and "))
        cut = cut if cut > MAX_SENTENCE // 3 else window.rfind(" ")
        cut = a + (cut if cut > 0 else MAX_SENTENCE)
        if text[a:cut].strip():
            out.append((a, cut))
        a = cut + 1 if text[cut : cut + 1] in ";, " else cut
    if text[a:b].strip():
        out.append((a, b))
    return out


def bidi_claims(sentence: str) -> tuple[Claim, ...]:
    """A contradicted claim for a sentence holding bidirectional control characters: what a reader sees is not the
    text that was read ('by U+202E 5.03 U+202C' shows as 'by 30.5'), so it is never verified."""
    found = bidi_controls(sentence)
    return (Claim("text", found, "contradicted", f"holds bidirectional control characters ({found})"),) if found else ()


def bidi_note(text: str) -> str:
    """Why a text holding bidirectional control characters is not verified ('' for a text without)."""
    found = bidi_controls(text)
    return (
        f"not verified: the text holds bidirectional control characters ({found}) that reorder what is shown"
        if found
        else ""
    )


def normalise(text: str) -> str:
    """One spelling of minus signs, spaces and apostrophes (same length, so positions stay valid)."""
    table = str.maketrans(
        {"\u2212": "-", "\u2012": "-", "\u00a0": " ", "\u202f": " ", "\u2009": " ", "\u2019": "'", "\u2018": "'"}
    )
    return text.translate(table)
