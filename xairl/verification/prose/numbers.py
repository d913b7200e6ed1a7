"""Numbers as people write them: thousands separators (comma or space), decimal commas ("22,5", "0,098"), currency,
a leading dot, k/M suffixes and scale words ("40 thousand"), signs in words ("minus 1.37"), percentages ("pts") and
points, fractions, scientific notation, Unicode minus, number words, and the hedge words before them.

A :class:`Number` knows what it may stand for (``value`` and ``alternatives``) and how precisely it was written
(``unit``, one step of its last written digit). :func:`matches` compares it with a fact:

- written plainly: equal after rounding to the written digits, or truncated to them with at least three significant
  digits ("6,157" for 6157.86, not "0.42" for 0.4252);
- with a symmetric hedge ("about", "around", "roughly", "approximately", "~", "some", "close to", "something like",
  "in the ballpark of", "give or take", "a good"): within 20 % of the fact, or equal after rounding;
- "nearly", "almost", "just under", "a bit under", "a hair under", "the better part of": the fact is at most the
  number and within 20 % of it; "just over", "a little over", "a touch above": at least the number and within 20 %;
- bounds ("less than", "under", "at most", "more than", "over", "at least", "north of", "well under", "between x
  and y"): the fact's magnitude is on that side.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace

HEDGE_TOLERANCE = 0.2  # how far a hedged number may be from the fact, relative to the fact

_APPROX = (
    "about",
    "around",
    "roughly",
    "approximately",
    "approx.",
    "approx",
    "~",
    "≈",
    "some",
    "close to",
    "circa",
    "ca.",
    "an estimated",
    "on the order of",
    "something like",
    "in the ballpark of",
    "somewhere near",
    "somewhere around",
    "give or take",
    "maybe",
    "a good",
    "in the region of",
    "the order of",
)
_BELOW = (
    "nearly",
    "almost",
    "just under",
    "a bit under",
    "a little under",
    "slightly under",
    "just shy of",
    "a bit less than",
    "slightly less than",
    "a little less than",
    "a hair under",
    "a touch under",
    "the better part of",
    "not quite",
)
_ABOVE = (
    "just over",
    "a little over",
    "a bit over",
    "slightly over",
    "slightly more than",
    "a bit more than",
    "a little more than",
    "just above",
    "a touch above",
    "a touch over",
    "a hair over",
    "a bit above",
)
_AT_MOST = ("less than", "under", "at most", "up to", "no more than", "below", "well under", "well below", "south of")
_AT_LEAST = ("more than", "over", "at least", "no less than", "upwards of", "well over", "well above", "north of")
HEDGES = {
    **{h: "approx" for h in _APPROX},
    **{h: "below" for h in _BELOW},
    **{h: "above" for h in _ABOVE},
    **{h: "at_most" for h in _AT_MOST},
    **{h: "at_least" for h in _AT_LEAST},
}
_HEDGE_RE = re.compile(
    r"(?:^|[\s(])(" + "|".join(sorted(map(re.escape, HEDGES), key=len, reverse=True)) + r")\s*[+\-]?[$€£]?\s*$",
    re.IGNORECASE,
)

_NUM_RE = re.compile(
    r"(?<![\w.,])(?:(?P<sign>[+\-])|(?P<wsign>(?i:minus|negative|plus))\s)?\s?(?P<cur>[$€£])?\s?"
    r"(?P<num>(?P<dc>0,\d+|\d+,\d{1,2}(?!\d))|\d{1,3}(?:,\d{3})+(?:\.\d+)?|\d{1,3}(?: \d{3})+(?!\d|[.,]\d)|"
    r"\d+(?:\.\d+)?|\.\d+)(?!\.\d)(?![\d,]\d)"
    r"(?P<exp>[eE][+\-]?\d+)?(?!st\b|nd\b|rd\b|th\b)"
    r"(?:\s?(?P<suffix>k|K|M|bn)\b|\s(?P<scale>thousand|million|billion)\b)?"
    r"(?P<den>/\d+(?:\.\d+)?)?"
    r"(?P<pct>\s?(?:%|percent\b|per cent\b|percentage points?\b|pp\b|-?points?\b|pts?\b|(?:in|out of) 100\b))?"
)

_WORDS = {
    "zero": 0,
    "one": 1,
    "two": 2,
    "three": 3,
    "four": 4,
    "five": 5,
    "six": 6,
    "seven": 7,
    "eight": 8,
    "nine": 9,
    "ten": 10,
    "eleven": 11,
    "twelve": 12,
    "thirteen": 13,
    "fourteen": 14,
    "fifteen": 15,
    "sixteen": 16,
    "seventeen": 17,
    "eighteen": 18,
    "nineteen": 19,
    "twenty": 20,
    "thirty": 30,
    "forty": 40,
    "fifty": 50,
    "sixty": 60,
    "seventy": 70,
    "eighty": 80,
    "ninety": 90,
}
_SCALES = {"hundred": 100, "thousand": 1000, "million": 1_000_000}
_WORD_RE = re.compile(
    r"\b(" + "|".join(_WORDS) + r")(?:[\s-](" + "|".join(_WORDS) + r"))?"
    r"(?:\s(" + "|".join(_SCALES) + r"))?\b(?P<pct>\s(?:percent\b|percentage points?\b|points?\b))?",
    re.IGNORECASE,
)

#: what the old single regex found; kept for :mod:`xairl.testing`, which mutates template numbers
NUMBER_RE = re.compile(r"(?<![\w.])([+\-\u2212]?\d+(?:\.\d+)?)(\s*%)?")


@dataclass(frozen=True)
class Number:
    """One number in a text.

    :param value: what it says (a percentage as written: 43 for "43%"); ``alternatives`` other readings ("3/10"
        is 3 or 0.3). ``unit``: one step of its last written digit (0.01 for "0.07", 1000 for "12,000" and "12k").
    :param sign: '+', '-' or '' as written; ``hedge`` the kind of hedge before it (approx/below/above/at_most/
        at_least) or ''; ``percent`` whether it is a percentage or percentage points.
    """

    start: int
    end: int
    text: str
    value: float
    unit: float
    sign: str = ""
    hedge: str = ""
    percent: bool = False
    points: bool = False  # percentage points ('12 pts', 'pp'): of a probability, never a share
    currency: str = ""
    alternatives: tuple[float, ...] = ()

    @property
    def readings(self) -> tuple[float, ...]:
        return (self.value, *self.alternatives)


def _step(digits: str, decimals: int) -> float:
    if decimals:
        return 10.0**-decimals
    stripped = digits.rstrip("0")
    return 10.0 ** (len(digits) - len(stripped)) if stripped else 1.0


#: dates and clock times: no fact of an explanation ('2026-12-02T10:02:11Z', '5 p.m.', '14:30')
_MONTH = r"(?:jan|feb|mar|apr|may|jun|jul|aug|sep|sept|oct|nov|dec)[a-z]*\.?"
_WHEN_RE = re.compile(
    r"\b\d{4}-\d{2}-\d{2}(?:[T ]\d{1,2}:\d{2}(?::\d{2}(?:\.\d+)?)?Z?)?|\b\d{1,2}:\d{2}(?::\d{2})?\b|"
    r"\b\d{1,2}(?:[:.]\d{2})?\s?(?:a\.m\.|p\.m\.|am\b|pm\b)|\b\d{1,2}/\d{1,2}/\d{2,4}\b|"
    rf"\b\d{{1,2}}(?:st|nd|rd|th)?\s+(?:of\s+)?{_MONTH}(?:\s+\d{{4}})?\b|\b{_MONTH}\s+\d{{1,2}}(?:st|nd|rd|th)?"
    rf"(?:,?\s+\d{{4}})?\b",
    re.IGNORECASE,
)
#: a code: letters joined to digits by a hyphen ('QX-20931', '4471-B', 'Y-19-553'), a long number-number ('2024-0387'),
#: an index in square brackets right after a word ('lag[-1]', 'forecast[+6h]': a name shortened around its index)
_CODE_RE = re.compile(
    r"\b[A-Za-z]+(?:-\d+)+[A-Za-z]?\b|\b\d+-[A-Z]{1,3}\b|\b\d{3,}-\d{3,}\b|"
    r"(?<=[A-Za-z_\0])\[[+\-]?\d+[a-z]{0,3}\]"
)


def find_numbers(text: str) -> list[Number]:
    """Every number in ``text`` (already :func:`normalise`\\ d), digits and number words, left to right; none inside
    a date, a clock time or a code ('QX-20931')."""
    out = []
    when = [(m.start(), m.end()) for r in (_WHEN_RE, _CODE_RE) for m in r.finditer(text)]
    for m in _NUM_RE.finditer(text):
        if any(a <= m.start("num") < b for a, b in when):
            continue
        raw = m.group("num")  # a decimal comma ('22,5', '0,098'); thousands by comma or space ('12,757', '39 960')
        digits = raw.replace(",", ".") if m.group("dc") else raw.replace(",", "").replace(" ", "")
        decimals = len(digits.split(".")[1]) if "." in digits else 0
        try:
            value = float(digits + (m.group("exp") or ""))
            unit = _step(digits.split(".")[0] if not decimals else digits, decimals)
            if m.group("exp"):
                unit *= 10.0 ** int(m.group("exp")[1:])
        except (OverflowError, ValueError):
            continue  # '1e999', a 320-digit number: no float states it, so it states no fact
        scale = {"k": 1e3, "K": 1e3, "M": 1e6, "bn": 1e9, "thousand": 1e3, "million": 1e6, "billion": 1e9}.get(
            m.group("suffix") or (m.group("scale") or "").lower(), 1.0
        )
        value, unit = value * scale, unit * scale
        if not (math.isfinite(value) and math.isfinite(unit) and unit > 0):
            continue  # too large or too small for a float ('1e-400' has no step): left unread, never a claim
        alts = ()
        if m.group("den"):
            den = float(m.group("den")[1:])
            if den:
                alts = (value / den,)
        sign = m.group("sign") or {"minus": "-", "negative": "-", "plus": "+"}.get((m.group("wsign") or "").lower(), "")
        if (
            m.group("sign")
            and text[m.start("sign") + 1 : m.start("sign") + 2] == " "
            and not text[: m.start("sign")].rsplit("\n", 1)[-1].strip()
        ):
            sign = ""  # '- 58 months of tenure ...': a list's bullet, not a minus
        out.append(
            Number(
                m.start(),
                m.end(),
                m.group(0).strip(),
                -value if sign == "-" else value,
                unit,
                sign,
                _hedge(text[: m.start()]),
                bool(m.group("pct")),
                _points(m.group("pct")),
                m.group("cur") or "",
                alts,
            )
        )
    for k in range(len(out) - 1):  # '2-3 points', '10–12 minutes': a range, not a minus
        first, second = out[k], out[k + 1]
        if second.start == first.end + 1 and text[first.end] in "-–" and not second.sign and first.text[-1].isdigit():
            out[k] = replace(first, hedge=first.hedge or "at_least", percent=second.percent, points=second.points)
            out[k + 1] = replace(second, hedge="at_most")
    for m in _WORD_RE.finditer(text):
        value = _WORDS[m.group(1).lower()] + (_WORDS[m.group(2).lower()] if m.group(2) else 0)
        scale = _SCALES[m.group(3).lower()] if m.group(3) else 1
        out.append(
            Number(
                m.start(),
                m.end(),
                m.group(0),
                float(value * scale),
                float(scale),
                hedge=_hedge(text[: m.start()]),
                percent=bool(m.group("pct")),
                points=_points(m.group("pct")),
            )
        )
    return sorted(out, key=lambda n: n.start)


def _points(pct: str | None) -> bool:
    """'percentage points', 'points', 'pp', 'pts': points of a probability, not a share of a whole."""
    return bool(pct and re.search(r"point|pp|pt", pct, re.IGNORECASE))


_RANGE_LOW = re.compile(r"\bbetween\s+[+\-]?[$€£]?\s*$", re.IGNORECASE)
_RANGE_HIGH = re.compile(
    r"\bbetween\s+[+\-]?[$€£]?\s*[\d.,]+\s*[A-Za-z%]{0,3}\s+(?:and|to)\s+[+\-]?[$€£]?\s*$", re.IGNORECASE
)


def _hedge(before: str) -> str:
    if _RANGE_LOW.search(before[-30:]):  # 'between $500 and $1,000': a lower and an upper bound
        return "at_least"
    if _RANGE_HIGH.search(before[-40:]):
        return "at_most"
    m = _HEDGE_RE.search(before[-30:])
    if m and m.group(1).lower() == "up to" and _ADDS_UP.search(before[-30:]):
        return ""  # 'the positives add up to 0.39': a sum, not a bound
    return HEDGES[m.group(1).lower()] if m else ""


_ADDS_UP = re.compile(
    r"\b(?:add(?:s|ed|ing)?|sum(?:s|med|ming)?|total(?:s|led|ling)?|com(?:e|es|ing)|came|"
    r"amount(?:s|ed|ing)?)\s+up\s+to\b",
    re.IGNORECASE,
)


def matches(n: Number, fact: float, magnitude_ok: bool = True, truncated_ok: bool = True) -> bool:
    """Does ``n`` state ``fact``? ``magnitude_ok``: an unsigned number may state a negative fact's size ("lowered
    it by 0.4"). A written sign must agree with the fact's. ``truncated_ok``: digits cut off count as rounding."""
    if not math.isfinite(fact):
        return False  # (a ratio of a zero contribution: no number states it)
    if n.sign and (fact < 0) != (n.sign == "-") and fact != 0:
        return False
    target = fact if n.sign or not magnitude_ok else abs(fact)
    ratio = n.unit / max(abs(n.value), 1e-12)  # an alternative reading ('3/10' as 0.3) keeps the relative precision
    return any(_close(x, target, n.unit if x == n.value else ratio * abs(x), n.hedge, truncated_ok) for x in n.readings)


def percent_reading(n: Number, v: float) -> bool:
    """Does a percentage state a probability-like fact ('43 %' for 0.43, '12 points' for 0.12)?"""
    return abs(v) <= 1.0 and matches(replace(n, percent=False, alternatives=()), 100 * v)


def _half_up(v: float, step: float) -> float:
    """``v`` rounded to a multiple of ``step``, halves away from zero (as people and templates round)."""
    k = abs(v) / step
    if not math.isfinite(k) or k > 1e15:
        return v  # beyond a float's integer precision: already as round as it can be
    return math.copysign(math.floor(k + 0.5 + 1e-9) * step, v)


def _close(x: float, fact: float, step: float, hedge: str, truncated_ok: bool = True) -> bool:
    rounding = 0.5 * step + 1e-9 + 1e-6 * abs(fact)
    if abs(x - _half_up(_half_up(fact, step / 10), step)) <= 1e-9 + 1e-6 * abs(fact):
        return True  # rounded from an already rounded display: 2.345 -> 2.35 -> 2.4
    # truncated to the written digits ('6,157' for 6157.86) only with three significant digits or more: a short number
    # is rounded, and '0.42' for 0.4252 is more likely a wrong number than a truncation
    truncated = truncated_ok and abs(x) >= 100 * step and abs(x) <= abs(fact) < abs(x) + step and x * fact >= 0
    exact = abs(x - fact) <= rounding or truncated
    if not hedge:
        return exact
    near = exact or abs(x - fact) <= HEDGE_TOLERANCE * abs(fact)
    a, b = abs(fact), abs(x)
    if hedge == "approx":
        return near
    if hedge == "below":
        return near and a <= b + rounding
    if hedge == "above":
        return near and a >= b - rounding
    if hedge == "at_most":
        return a <= b + rounding
    return a >= b - rounding  # at_least


#: a unit a feature's name ends in ('next_drop_dist_km', 'wait_s'), when its policy gives none
