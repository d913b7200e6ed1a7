"""A sentence cut into parts: its tracked spans and the literal words between them, each in a segment (cut at any
clause mark) and a block (cut only at ; : | and line breaks)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from xairl.templates.tracking import Span
from xairl.verification.own.lexicon import BLOCK, SEGMENT


@dataclass(frozen=True)
class Part:
    """A piece of a sentence: a tracked span, or literal words (``span`` None)."""

    start: int
    end: int
    span: Span | None
    segment: int  # which segment of the sentence (cut at any of SEGMENT)
    block: int  # which block (cut only at ; : | and line breaks: a list item, a field)


def parts(sentence: str, spans: Sequence[Span]) -> list[Part]:
    out, pos, seg, block = [], 0, 0, 0
    for s in [*sorted(spans, key=lambda s: s.start), None]:
        end = len(sentence) if s is None else s.start
        if end > pos:
            words = sentence[pos:end]
            at = 0
            for m in SEGMENT.finditer(words):  # each cut starts a new segment (and a block at ; : | or a break)
                out.append(Part(pos + at, pos + m.start(), None, seg, block))
                seg += 1
                block += bool(BLOCK.match(words, m.start()))
                at = m.start()
            out.append(Part(pos + at, end, None, seg, block))
        if s is not None:
            out.append(Part(s.start, s.end, s, seg, block))
            pos = max(pos, s.end)
    return [p for p in out if p.end > p.start]


def is_name(p: Part) -> bool:
    return p.span is not None and p.span.fact.quantity == "name" and p.span.fact.feature is not None


def literal(sentence: str, parts: list[Part], a: int, b: int) -> str:
    """The literal words between positions a and b, tracked spans blanked."""
    return "".join(sentence[p.start : p.end] if p.span is None else " \0 " for p in parts if a <= p.start < b)
