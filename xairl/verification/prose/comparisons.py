"""Comparisons between features: 'A mattered more than B', 'about as much as', 'A outweighs B', 'A and B outweighed
C', ratios ('1.7 times as much as', '35 % more than') and a bracket setting their numbers side by side ('(0.88 vs
0.49)'); the phrases that state them and their checks."""

from __future__ import annotations

import re

from xairl.verification.prose.book import FactBook
from xairl.verification.prose.checks import EITHER, over_keys
from xairl.verification.result import Claim

SAME_WITHIN = 0.25  # 'about as much as': the two sizes within 25 % of the larger


def check_comparison(
    a_keys: tuple[str, ...], b_key: str, way: int, ctx: str | None, book: FactBook, text: str, at_least: float = 1.0
) -> Claim:
    """|contribution| of A against B's in the sentence's view (any view when it names none): way +1 larger (by the
    factor ``at_least``: 'more than twice that of B'), -1 smaller, 0 about the same."""

    def test(key):
        pairs = _sizes(key, b_key, ctx, book)
        if not pairs:
            return None
        ok = [
            c
            for x, y, c in pairs
            if (x > at_least * y if way > 0 else x < y if way < 0 else abs(x - y) <= SAME_WITHIN * max(x, y))
        ]
        x, y, c = pairs[0]
        return bool(ok), f"|{key}| {x:.3g} vs |{b_key}| {y:.3g} ({ok[0] if ok else c})"

    return over_keys(a_keys, test, "comparison", text, "rank")


def _sizes(a_key: str, b_key: str, ctx: str | None, book: FactBook) -> list[tuple[float, float, str]]:
    """(|A|, |B|, view) in each view the sentence allows where both contributions are known."""
    return [
        (abs(book.features[a_key].contribs[c]), abs(book.features[b_key].contribs[c]), c)
        for c in views(ctx, book)
        if c in book.features[a_key].contribs and c in book.features[b_key].contribs
    ]


#: a multiplier before a comparative: 'roughly 1.7 times', 'nearly twice', 'three times', 'half', '35 %'
_RATIO_BEFORE = re.compile(
    r"(?:(?P<num>\d+(?:\.\d+)?)\s*(?:times|x|-fold|fold)|(?P<word>twice|double|thrice|"
    r"half|one and a half times|two and a half times|(?:three|four|five|ten) times)|"
    r"(?P<pct>\d+(?:\.\d+)?)\s*(?:%|percent))\s*(?:\w+\s+){0,3}?$",
    re.IGNORECASE,
)
_RATIO_WORDS = {
    "twice": 2.0,
    "double": 2.0,
    "thrice": 3.0,
    "half": 0.5,
    "one and a half times": 1.5,
    "two and a half times": 2.5,
    "three times": 3.0,
    "four times": 4.0,
    "five times": 5.0,
    "ten times": 10.0,
}


def _ratio(before: str, way: int) -> float | None:
    """The ratio a multiplier before 'as much as' / 'more than' / 'less than' states: '1.7 times as much' 1.7,
    '35 % more' 1.35, '20 % less' 0.8, 'twice as much' 2; None without one."""
    m = _RATIO_BEFORE.search(before)
    if m is None:
        return None
    if m.group("pct"):
        share = float(m.group("pct")) / 100
        return 1 + share if way > 0 else 1 - share if way < 0 else share
    return float(m.group("num")) if m.group("num") else _RATIO_WORDS[m.group("word").lower()]


def views(ctx: str | None, book: FactBook) -> tuple[str, ...]:
    """The views a rank or magnitude claim is checked in: the one its sentence names, else any."""
    return (ctx,) if ctx and ctx != EITHER else book.contexts
