"""What a number tied to a feature states and its check: the feature's value, contribution or share, or a domain
comparison in its unit (:func:`feature_number`); another fact it states when the words bound it to the wrong one
(:func:`other_reading`, :func:`any_fact`). Decision-level numbers (a score, the margin, the prediction, the baseline,
the change from it) are :mod:`.decision`, sums over several features :mod:`.sums`, numbers that are no claim at all
:mod:`.noclaims`."""

from __future__ import annotations

import re
from dataclasses import dataclass, replace

from xairl.verification.prose.book import FactBook
from xairl.verification.prose.checks import EITHER, over_keys
from xairl.verification.prose.numbers import Number, find_numbers, matches, percent_reading
from xairl.verification.prose.units import written_scale
from xairl.verification.result import Claim

CONTRIB_BEFORE = re.compile(
    r"(?:\bby|\badds?|\badded|\badding|contribut\w*|\bworth|\bcosts?|\bcosting|subtract\w*|\boff|\baway|\bcut\w*|"
    r"knock\w*|lifts?|lower\w*|rais\w*|reduc\w*|increas\w*|decreas\w*|shap(?: value)?(?: of| is| was|:|=)?|"
    r"contribution(?: of| was| is|:)?|attributions?:?|phi\([^)]*\)\s*=|\|φ\|:?|impact of|effect of|push\w*|"
    r"another|\banother|drops?|takes|took|loses|gains?|\bby a margin of|\|shap\|:?|"
    r"edge of|favou?red \w+ by|for \w+ by|\bdown|\bup)\s*(?:(?:\(|about|around|roughly|nearly|almost|"
    r"approximately|some|only|just|a further|another|over|under|(?:somewhere |anywhere )?between)\s*){0,2}"
    r"[+\-]?[$€£]?\s*$",
    re.IGNORECASE,
)
_LISTS_CONTRIBUTIONS = re.compile(
    r"shap|attribution|contribut|impact|effect|φ|phi|importance|weight|push|margin", re.IGNORECASE
)
COMPARISON_WORDS = r"(above|below|stronger|weaker|better|worse|higher|lower)"
#: '1.9 dB above the serving BS's RSRP': a difference in a unit, neither a value nor a contribution
DIFFERENCE_AFTER = re.compile(rf"\s*[A-Za-z]+\s+{COMPARISON_WORDS}\b", re.IGNORECASE)


_SIGNED_NAMED = re.compile(
    r"(?<![|\w])(?:shap(?: value)?|contribution|attribution)\s*(?:of|is|was|:|=)\s*$", re.IGNORECASE
)


def signed_named(before: str) -> bool:
    """'a SHAP value of 0.3' names the signed quantity: unsigned, it states a positive one (not 'a negative SHAP
    value of 0.3', not '|SHAP| 0.3')."""
    return bool(_SIGNED_NAMED.search(before)) and "negative" not in before.lower()


@dataclass(frozen=True)
class _Cues:
    """What the words around a number say it is, whichever feature it is tied to."""

    after: str  # the 16 characters after it
    contribution: bool  # 'by', 'adds', 'SHAP value of' right before it
    signed: bool  # 'a SHAP value of 0.3' names the signed quantity: unsigned, it is positive
    slot: bool  # an unsigned number in brackets right after a name: its value ('distance (0.84)'), unless
    #                      the sentence lists contributions ('Top features by absolute SHAP value: A (0.11)')
    fill: bool  # '8 % full': a fill of a capacity
    in_points: bool  # a sentence that counts in points: points of a probability too
    pushes: bool  # the words before it speak of contributions at all ('The SHAP value of serving_bs is 0.00')


#: a change of the feature itself over time, not a push: 'a GPA trend, down 0.4 since last term'
_SINCE_AFTER = re.compile(
    r"\s*(?:points?\s+|[a-zA-Z%]{1,4}\s+)?(?:since\s+(?:last|the last|the previous|"
    r"yesterday|\d)|from last|on last|versus last|vs\.? last)\b",
    re.IGNORECASE,
)


#: words that carry a value's minus sign when the number is written without it. Right before it, a movement or a
#: loss ('a drop of 1.46', 'fell by about 1.46', 'down 1.46', 'a deficit of 1.46'); a few words before it, a sign or
#: a side of zero ('negative at 1.46', 'a negative reading of 1.46', 'below zero at 1.46'); after it, a side of zero
#: or of a reference ('1.46 below zero', '1.46 standard deviations under the mean', '1.46 points lower than usual',
#: '1.46 (negative)', '1.46 in the red', a coordinate's '704 m west')
_SIGN_BEFORE = re.compile(
    r"\b(?:(?:deficits?|shortfalls?|drop(?:s|ped|ping)?|declin(?:e|es|ed|ing)|fell|fall(?:s|en|ing)?|"
    r"decreas(?:e|es|ed|ing)|down(?:ward)?|dip(?:s|ped)?|sank|sunk|slump(?:s|ed)?|plung(?:e|es|ed)|loss(?:es)?|lost|"
    r"losing|reduc\w*|lower(?:ed)?|less|short|under|below|minus)"
    r"\s+(?:(?:of|by|at|about|around|roughly|nearly|almost|approximately|some|only|just|a|an|fully)\s+){0,3}|"
    r"(?:negative(?:ly)?|minus|sub-?zero|below\s+(?:zero|average|the\s+mean|normal|the\s+average))"
    r"(?:[^\w\0();]+[^\W\d]+){0,4}?[^\w\0();]*)[$€£]?$",
    re.IGNORECASE,
)
_SIGN_AFTER = re.compile(
    r"^\s*(?:(?:down|lower|less|negative)\b|\(?negative\b|"
    r"(?:[^\W\d]+[\s/°%.]+){0,4}?(?:below|under|beneath|(?:lower|less|short)\s+(?:than|of)|negative|minus|deficit|"
    r"in\s+the\s+red|sub-?zero|west|south)\b)",
    re.IGNORECASE,
)
#: the mark of a value written without its sign in a claim's detail (:func:`unsigned_negative`)
WITHOUT_SIGN = "without its minus sign"


def sign_in_words(n: Number, masked: str) -> bool:
    """Do the words around an unsigned number say that it is below zero ('1.46 below zero', 'a drop of 1.46',
    'minus 1.46')?"""
    before = re.split(r"[\d.;]\s", masked[max(0, n.start - 48) : n.start])[-1]  # (not an earlier number's words)
    return bool(_SIGN_BEFORE.search(before) or _SIGN_AFTER.match(masked[n.end : n.end + 48]))


def unsigned_negative(n: Number, v: float, masked: str) -> bool:
    """A negative value (beyond rounding of zero at the written digits) written without its sign, and no word says
    so ('wind_gust (1.46)' when it is -1.463): the number does not state it. A bound below ('under 2') is true of
    it as written."""
    return v < 0 and not n.sign and n.hedge != "at_most" and abs(v) >= 0.5 * n.unit and not sign_in_words(n, masked)


def _cues(n: Number, masked: str, book: FactBook) -> _Cues:
    before, after = masked[max(0, n.start - 40) : n.start], masked[n.end : n.end + 16]
    contribution = bool(CONTRIB_BEFORE.search(before)) and not _SINCE_AFTER.match(after)
    lists = bool(_LISTS_CONTRIBUTIONS.search(masked[: n.start]))
    slot = (
        not n.sign
        and not n.currency
        and not n.percent
        and bool(re.search(r"\0\s?\($", before))
        and masked[n.end : n.end + 1] in (")", ",")
        and not lists
    )
    fill = bool(n.percent and re.match(r"\s*(full|of (?:its |the )?capacity)\b", after, re.IGNORECASE))
    in_points = book.output != "actions" and not n.percent and bool(re.search(r"\b(?:points?|pts|pp)\b", masked))
    return _Cues(after, contribution, signed_named(before), slot, fill, in_points, contribution or lists)


def feature_number(
    n: Number, keys: tuple[str, ...], masked: str, book: FactBook, ctx: str | None, unit_of, name_after: bool = False
) -> Claim:
    """A number tied to a feature: its value, its contribution (in the sentence's context, or any context when the
    sentence does not say), its share, or a percentage of a probability-like contribution. Cue words before it
    ('by', 'adds', 'SHAP value of') say it is a contribution; the feature's unit after it that it is a value.
    ``name_after``: the name follows the number ('took 7 corners'): its value, whatever the verb before. An
    identifier's number is its value ('the serving BS's id at 10') unless the words before it speak of contributions:
    an identifier is never narrated as a reason."""
    cue = _cues(n, masked, book)
    after, contrib_cue = cue.after, cue.contribution
    # a sentence that names no view, or weighs the two options without saying which ('argued against it'): either
    # view (the chosen action's score or the margin over the runner-up)
    contexts = book.contexts if ctx in (EITHER, None) else (ctx,)

    def test(key):
        e = book.features[key]
        if cue.fill and e.fill is not None:  # '8 % full': the fill, nothing else
            return matches(n, e.fill), f"{key}'s fill is {e.fill:.3g} % of its capacity"
        unit = unit_of(key).lower()
        prefix, scale = written_scale(after, unit_of(key))
        value_cue = (
            bool(unit)
            and bool(re.match(rf"{re.escape(unit.split()[0])}(?![a-z])", after.strip().lower()))
            or cue.slot
            or bool(prefix)
        ) and not contrib_cue
        meaning = None if contrib_cue or n.percent else _code_meaning(n, e)
        if meaning is not None:  # 'a balance above 200 DM' for status 4 ('200 DM or more'), before any rounding
            return meaning
        cands = []
        if (not contrib_cue or name_after) and e.value is not None and not (n.points and unit not in ("points", "pts")):
            cands.append(
                (
                    "value" if scale == 1 else f"value in {prefix}" + ("" if " " in prefix else unit_of(key)),
                    e.value / scale,
                )
            )
        if n.percent and not contrib_cue and e.fill is not None:
            cands.append(("fill (% of capacity)", e.fill))
        if not contrib_cue and e.change is not None:  # 'fell 4 dB over the last second': its size, or signed
            cands += [("change over the window", e.change), ("change over the window", abs(e.change))]
        if not value_cue and (cue.pushes or not e.identifier):
            cands += [(f"contribution ({c})", e.contribs[c]) for c in contexts if c in e.contribs]
        unsigned = None  # a value the number states in size only, its sign neither written nor said
        for what, v in cands:
            contribution = what.startswith("contribution")
            m = n if contribution else replace(n, alternatives=tuple(x for x in n.alternatives if x != 100 * n.value))
            if " (not " in what and abs(n.value - v) > 0.05 * abs(v):
                continue  # a value in another unit: its rounding is not the coarser unit's ('2 minutes' is no 90 s)
            if what.startswith("value") and unsigned_negative(n, v, masked):
                unsigned = unsigned or ((what, v) if matches(m, v) else None)
                continue  # ('wind_gust (1.46)' when it is -1.463: a wrong value, unless the words say 'below zero')
            if matches(m, v, magnitude_ok=not (cue.signed and contribution)) or (
                (n.percent or (cue.in_points and contribution)) and percent_reading(n, v)
            ):
                return True, f"{key}: {what}"
        share = _share(n, e, contexts)
        if share:
            return True, f"{key}: {share}"
        shown = ", ".join(f"{w} {v:.4g}" for w, v in cands)
        if unsigned is not None:
            others = ", ".join(f"{w} {v:.4g}" for w, v in cands if (w, v) != unsigned)
            return False, (
                f"{n.text} is {key}'s {unsigned[0]} {unsigned[1]:.4g} {WITHOUT_SIGN}, and no word says it is "
                f"negative ('-{n.text}', '{n.text} below zero')" + (f"; nor is it {key}'s {others}" if others else "")
            )
        return False, f"{n.text} is not {key}'s {shown or 'value'}"

    if DIFFERENCE_AFTER.match(after):
        ok = comparison(n, after, book)
        return Claim(
            "number",
            n.text,
            "verified" if ok else ("contradicted" if book.by_unit else "unchecked"),
            "a domain comparison in its unit" if ok else "a difference no fact states",
        )
    claim = over_keys(keys, test, "feature", n.text, "number")
    if claim.status == "contradicted" and comparison(n, after, book):
        return Claim("number", n.text, "verified", "a domain comparison in its unit")
    return claim


def _share(n: Number, e, contexts) -> str:
    """Which share of the total a percentage states: of all |contributions| ('share'), of its own side's ('57 %
    of all the positive push'), of the net change ('explains another 32 %' of the net drop); '' for none
    (percentage points are never a share)."""
    if not n.percent or n.points:
        return ""
    if any(matches(n, e.shares[c]) for c in contexts if c in e.shares):
        return "share"
    if any(matches(n, e.side_shares[c]) for c in contexts if c in e.side_shares):
        return "share of its side (the contributions of its sign)"
    if any(matches(n, e.net_shares[c]) for c in contexts if c in e.net_shares):
        return "share of the net change"
    return ""


def _code_meaning(n: Number, e) -> tuple[bool, str] | None:
    """A number of the meaning of the feature's code in its legend ('over 200 DM' for status 4 = '200 DM or more'):
    verified; a number only other codes' meanings have: contradicted; else nothing to say."""
    if not e.legend or e.value is None or e.value != int(e.value) or n.value == e.value:
        return None  # (the code itself, 'value 1', is its value)
    here = e.legend.get(int(e.value), "")
    if any(n.value == x.value for x in find_numbers(here)):  # a legend's numbers are exact
        return True, f"the meaning of its code {int(e.value)}: {here}"
    others = [t for k, t in e.legend.items() if k != int(e.value) and any(n.value == x.value for x in find_numbers(t))]
    return (
        (
            False,
            f"{n.text} is the meaning of another code ({others[0]}); its code {int(e.value)} means "
            f"{here or 'nothing in the legend'}",
        )
        if others
        else None
    )


def comparison(n: Number, after: str, book: FactBook) -> bool:
    unit = re.match(r"\s*([A-Za-z]+)", after)
    values = book.by_unit.get(unit.group(1).lower(), []) if unit else []
    return any(matches(n, v) for v in values)
