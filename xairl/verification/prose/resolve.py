"""One reading per anchor: where several rules read the same number, direction word or rank word, the highest
priority wins, then the nearest name (as spaCy's span filtering prefers one span by a stated order, never by the
order rules were written in). The trace keeps every candidate beside the winner."""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass

from xairl.verification.prose.rules import Candidate

_NUMBERS = ("number", "output", "net", "skip")  # claims on a number: they compete for it


@dataclass(frozen=True)
class Decision:
    winner: Candidate
    candidates: tuple[Candidate, ...]


def resolve(candidates: list[Candidate]) -> list[Decision]:
    """Group the candidates by (claim, anchor) and pick one per group; in the order of the anchors."""
    groups: dict[tuple[str, int], list[Candidate]] = defaultdict(list)
    for c in candidates:
        groups[("number" if c.rule.claim in _NUMBERS else c.rule.claim, c.anchor)].append(c)
    out = []
    for key in sorted(groups, key=lambda k: k[1]):
        group = sorted(set(groups[key]), key=lambda c: (-c.rule.priority, abs(c.name - c.anchor), c.rule.id))
        out.append(Decision(group[0], tuple(group)))
    return out
