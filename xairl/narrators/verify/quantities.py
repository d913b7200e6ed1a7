"""What a number in a text states and its check: a feature's value, contribution or share, an action's score, the
margin, the prediction, the baseline, the change from it, or a domain comparison in its unit (sums over several
features are :mod:`.sums`). The cue words around the number decide which (:func:`feature_number`, :func:`free_number`); which numbers are no
claim at all is :mod:`.noclaims`."""
from __future__ import annotations

import re
from dataclasses import dataclass, replace

from .book import FactBook
from .checks import EITHER, Claim, over_keys
from .numbers import Number, find_numbers, matches, percent_reading, written_scale

CONTRIB_BEFORE = re.compile(
    r"(?:\bby|\badds?|\badded|\badding|contribut\w*|\bworth|\bcosts?|\bcosting|subtract\w*|\boff|\baway|\bcut\w*|"
    r"knock\w*|lifts?|lower\w*|rais\w*|reduc\w*|increas\w*|decreas\w*|shap(?: value)?(?: of| is| was|:|=)?|"
    r"contribution(?: of| was| is|:)?|attributions?:?|phi\([^)]*\)\s*=|\|φ\|:?|impact of|effect of|push\w*|"
    r"another|\banother|drops?|takes|took|loses|gains?|\bby a margin of|\|shap\|:?|"
    r"edge of|favou?red \w+ by|for \w+ by|\bdown|\bup)\s*(?:(?:\(|about|around|roughly|nearly|almost|"
    r"approximately|some|only|just|a further|another|over|under|(?:somewhere |anywhere )?between)\s*){0,2}"
    r"[+\-]?[$€£]?\s*$",
    re.IGNORECASE)
_LISTS_CONTRIBUTIONS = re.compile(r"shap|attribution|contribut|impact|effect|φ|phi|importance|weight|push|margin",
                                  re.IGNORECASE)
MARGIN_BEFORE = re.compile(r"\b(margin|lead|edge|gap|advantage|difference)(?: of)?\W*(?:about|around|roughly|only|"
                            r"just)?\s*$|\b(won|wins|beat\w*|ahead|stayed ahead|led|edged out|outscored)\s+"
                            r"(?:[\w\0']+\s+|\([^()]*\)\s+){0,4}by\s+(?:a\s+(?:whisker|hair|nose|wide margin|"
                            r"narrow margin|small margin|large margin|mile)\s*,?\s*)?(?:about|around|roughly|only|just|"
                            r"a bit over|a little over|some|nearly|almost)?\s*$", re.IGNORECASE)
_ON_AVERAGE = re.compile(r"^\s*(?:on average|over the background|across the background|at baseline|by default)\b",
                         re.IGNORECASE)
#: '3.9 points ahead', 'the 8.32-point lead', '3.9 points of margin': the margin
MARGIN_AFTER = re.compile(r"^\s*(?:points?\s+)?(?:above|ahead|higher|more than)\b|"
                          r"^(?:-?\s*points?)?\s+(?:lead|margin|gap|edge|advantage)\b|"
                          r"^\s+points?\s+of\s+(?:lead|margin|gap)\b", re.IGNORECASE)
_RUNNER_BEFORE = re.compile(r"(?<!bit )(?<!little )(?<!just )(?<!well )(?<!slightly )(?<!touch )(?<!hair )"
                            r"\b(vs\.?|versus|against|compared with|over)\s*(?:a\s+|an\s+)?[$€£]?\s*$",
                            re.IGNORECASE)
SCORE_BEFORE = re.compile(r"\b(scor\w+|q[- ]?values?|q\s*\([^)]*\)|q)\s*(?:of|=|:|at|was|is)?\s*$", re.IGNORECASE)
_BASE_AFTER = re.compile(r"^\s*(?!vs\b|versus\b|against\b|compared\b)(?:\w+\s+)?(baseline|base value|base rate|base|"
                         r"average|typical|expected|mean)\b", re.IGNORECASE)  # not '0.14 vs base 0.34'
_BASE_WORDS = re.compile(r"\b(baseline|base value|base|average|typical|expected value|mean|on average)\b",
                         re.IGNORECASE)
#: 'the average prediction of $230,061'
_BASE_BEFORE = re.compile(r"\b(?:baseline|average|typical|mean|expected)\s+(?:prediction|estimate|output|predicted \w+)"
                          r"\s*(?:of|is|was|:|=)?\s*[$€£]?\s*$", re.IGNORECASE)
_OUT_WORDS = re.compile(r"\b(predict\w*|estimat\w*|valu\w*|puts|sits|probability|chance|risk|price|output|final)\b",
                        re.IGNORECASE)
#: '$91,462 above the baseline' (not '0.38 is slightly above the base value': there the number is the prediction)
_CHANGE_BEFORE = re.compile(r"\b(?:exceed\w*|above|below|under|higher than|lower than|more than|less than)\b[^;]{0,40}"
                            r"\bby\s+(?:about|around|roughly|nearly|almost|some|only|just)?\s*[$€£]?\s*$",
                            re.IGNORECASE)
CHANGE_AFTER = re.compile(r"^\s*(?!(?:\w+\s+)?(?:is|was|are|were|sits|lies|stands|remains)\b)(?:\w+\s+){0,2}"
                           r"(above|below|under|over|more|less)\s+(the\s+)?"
                           r"(average|baseline|base|typical|expected|mean)"
                           r"|^\W*(?:premium|uplift|markup|discount)\b", re.IGNORECASE)
#: 'Net effect of the eight features: +0.089', 'Net uplift over the base value: +$86,046': the change from the baseline
NET_BEFORE = re.compile(r"\b(?:net (?:effect|uplift|change|shift|push|contribution)|total (?:effect|shift|change)|"
                        r"(?<![\w.])delta(?=\s*[=:])|"  # ('base=27.0 delta=-22.0')
                        r"(?:uplift|premium|change|shift) (?:over|above|from|relative to) (?:the )?(?:base(?:line)?|"
                        r"base value|base rate|average))\b(?:\s+(?:of|over|from|across)\s+[^.;:()\d]{1,30}?)?\s*"
                        r"(?:[:=]|\bis\b|\bwas\b|\bof\b)?\s*(?:about|around|roughly)?\s*[$€£]?$", re.IGNORECASE)
_COMPARISON_WORDS = r"(above|below|stronger|weaker|better|worse|higher|lower)"
#: '1.9 dB above the serving BS's RSRP': a difference in a unit, neither a value nor a contribution
DIFFERENCE_AFTER = re.compile(rf"\s*[A-Za-z]+\s+{_COMPARISON_WORDS}\b", re.IGNORECASE)
_COMPARE_AFTER = re.compile(rf"^\s*(?:dB|dBm)?\s*(?:{_COMPARISON_WORDS}|more|less)\b",
                            re.IGNORECASE)


_SIGNED_NAMED = re.compile(r"(?<![|\w])(?:shap(?: value)?|contribution|attribution)\s*(?:of|is|was|:|=)\s*$",
                           re.IGNORECASE)


def signed_named(before: str) -> bool:
    """'a SHAP value of 0.3' names the signed quantity: unsigned, it states a positive one (not 'a negative SHAP
    value of 0.3', not '|SHAP| 0.3')."""
    return bool(_SIGNED_NAMED.search(before)) and "negative" not in before.lower()


@dataclass(frozen=True)
class _Cues:
    """What the words around a number say it is, whichever feature it is tied to."""

    after: str           # the 16 characters after it
    contribution: bool   # 'by', 'adds', 'SHAP value of' right before it
    signed: bool         # 'a SHAP value of 0.3' names the signed quantity: unsigned, it is positive
    slot: bool           # an unsigned number in brackets right after a name: its value ('distance (0.84)'), unless
    #                      the sentence lists contributions ('Top features by absolute SHAP value: A (0.11)')
    fill: bool           # '8 % full': a fill of a capacity
    in_points: bool      # a sentence that counts in points: points of a probability too
    pushes: bool         # the words before it speak of contributions at all ('The SHAP value of serving_bs is 0.00')


#: a change of the feature itself over time, not a push: 'a GPA trend, down 0.4 since last term'
_SINCE_AFTER = re.compile(r"\s*(?:points?\s+|[a-zA-Z%]{1,4}\s+)?(?:since\s+(?:last|the last|the previous|"
                          r"yesterday|\d)|from last|on last|versus last|vs\.? last)\b", re.IGNORECASE)


def _cues(n: Number, masked: str, book: FactBook) -> _Cues:
    before, after = masked[max(0, n.start - 40):n.start], masked[n.end:n.end + 16]
    contribution = bool(CONTRIB_BEFORE.search(before)) and not _SINCE_AFTER.match(after)
    lists = bool(_LISTS_CONTRIBUTIONS.search(masked[:n.start]))
    slot = not n.sign and not n.currency and not n.percent and bool(re.search(r"\0\s?\($", before)) and \
        masked[n.end:n.end + 1] in (")", ",") and not lists
    fill = bool(n.percent and re.match(r"\s*(full|of (?:its |the )?capacity)\b", after, re.IGNORECASE))
    in_points = book.output != "actions" and not n.percent and bool(re.search(r"\b(?:points?|pts|pp)\b", masked))
    return _Cues(after, contribution, signed_named(before), slot, fill, in_points, contribution or lists)


def feature_number(n: Number, keys: tuple[str, ...], masked: str, book: FactBook, ctx: str | None,
                   unit_of, name_after: bool = False) -> Claim:
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
        value_cue = (bool(unit) and bool(re.match(rf"{re.escape(unit.split()[0])}(?![a-z])", after.strip().lower()))
                     or cue.slot or bool(prefix)) \
            and not contrib_cue
        meaning = None if contrib_cue or n.percent else _code_meaning(n, e)
        if meaning is not None:  # 'a balance above 200 DM' for status 4 ('200 DM or more'), before any rounding
            return meaning
        cands = []
        if (not contrib_cue or name_after) and e.value is not None and not (n.points and unit not in ("points", "pts")):
            cands.append(("value" if scale == 1 else f"value in {prefix}" + ("" if " " in prefix else unit_of(key)),
                          e.value / scale))
        if n.percent and not contrib_cue and e.fill is not None:
            cands.append(("fill (% of capacity)", e.fill))
        if not value_cue and (cue.pushes or not e.identifier):
            cands += [(f"contribution ({c})", e.contribs[c]) for c in contexts if c in e.contribs]
        for what, v in cands:
            contribution = what.startswith("contribution")
            m = n if contribution else replace(n, alternatives=tuple(x for x in n.alternatives if x != 100 * n.value))
            if " (not " in what and abs(n.value - v) > 0.05 * abs(v):
                continue  # a value in another unit: its rounding is not the coarser unit's ('2 minutes' is no 90 s)
            if matches(m, v, magnitude_ok=not (cue.signed and contribution)) or (
                    (n.percent or (cue.in_points and contribution)) and percent_reading(n, v)):
                return True, f"{key}: {what}"
        share = _share(n, e, contexts)
        if share:
            return True, f"{key}: {share}"
        shown = ", ".join(f"{w} {v:.4g}" for w, v in cands)
        return False, f"{n.text} is not {key}'s {shown or 'value'}"

    if DIFFERENCE_AFTER.match(after):
        ok = comparison(n, after, book)
        return Claim("number", n.text, "verified" if ok else ("contradicted" if book.by_unit else "unchecked"),
                     "a domain comparison in its unit" if ok else "a difference no fact states")
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
    others = [t for k, t in e.legend.items() if k != int(e.value)
              and any(n.value == x.value for x in find_numbers(t))]
    return (False, f"{n.text} is the meaning of another code ({others[0]}); its code {int(e.value)} means "
                   f"{here or 'nothing in the legend'}") if others else None


def other_reading(n: Number, keys: set[str], book: FactBook, ctx: str | None, signed: bool = False) -> str | None:
    """Another fact the number states exactly when the words bound it to the wrong one: the value, share or
    contribution (in the sentence's view when it names one, else any) of a feature named in the same sentence. The
    binding was a guess, so the number is not called wrong; only unhedged numbers of two significant digits or more
    qualify ('0.06' or 'about 0.1' may match by chance). ``signed``: a contribution only with its sign."""
    if n.hedge or abs(n.value) < 10 * n.unit:
        return None
    views = book.contexts if ctx in (None, EITHER) else (ctx,)
    for key in sorted(keys):
        e = book.features[key]
        if n.percent and not n.points:  # a percentage is a share (or a fill the binding already tried), or a value
            facts = [(f"share ({c})", e.shares.get(c), True) for c in views] + [("value", e.value, False)]  # ('12 %')
        else:  # a value as written, sign included; a contribution may be its size
            facts = [("value", e.value, False), *((f"contribution ({c})", e.contribs.get(c), not signed)
                                                  for c in views)]
        for what, v, size_ok in facts:
            if v is not None and (matches(replace(n, percent=False), v, magnitude_ok=size_ok, truncated_ok=False) or (
                    n.points and percent_reading(n, abs(v) if size_ok and not n.sign else v))):  # '12.3 pp'
                return f"{key}'s {what}"
    return None


def comparison(n: Number, after: str, book: FactBook) -> bool:
    unit = re.match(r"\s*([A-Za-z]+)", after)
    values = book.by_unit.get(unit.group(1).lower(), []) if unit else []
    return any(matches(n, v) for v in values)


def action_number(n: Number, action: str | None, masked: str, book: FactBook) -> Claim:
    """A number next to an action: its score, or the margin when the words say so ('won by', 'a lead of')."""
    if book.global_view:  # over many states no single action has a score: a count or another flight-level fact
        return free_number(n, masked, book)
    before = masked[max(0, n.start - 40):n.start]
    if MARGIN_BEFORE.search(before) and book.margin is not None:
        if _ON_AVERAGE.match(masked[n.end:n.end + 40]) and book.base_margin is not None:
            ok = matches(n, book.base_margin)  # 'it led by 3.4 on average over the background'
            return Claim("number", n.text, "verified" if ok else "contradicted",
                         f"the margin over the background is {book.base_margin:.4g}")
        ok = matches(n, book.margin)
        return Claim("number", n.text, "verified" if ok else "contradicted", f"the margin is {book.margin:.4g}")
    if action is None or action not in book.scores:
        return Claim("number", n.text, "unchecked", "an action that could not be told apart")
    ok = matches(n, book.scores[action], magnitude_ok=False)
    return Claim("number", n.text, "verified" if ok else "contradicted", f"{action}'s score is "
                 f"{book.scores[action]:.4g}")


def is_change(n: Number, masked: str) -> bool:
    """Is ``n`` the change from the baseline? '$91,462 above the baseline', 'exceeds the base rate (0.34) by 0.09',
    'below base by $34,184', 'Net uplift over the base value: +$86,046'."""
    before = masked[max(0, n.start - 60):n.start]
    return bool(CHANGE_AFTER.match(masked[n.end:n.end + 30]) or NET_BEFORE.search(before) or (
        _CHANGE_BEFORE.search(before[-40:]) and _BASE_WORDS.search(before[-40:])) or (
        _NET_MOVE.search(before) and "\0" not in masked[:n.start]))


#: 'a net increase of 18.7 h' in a sentence that names no feature before it (else it may be that name's push:
#: 'Traffic gives a net increase of 7.2')
_NET_MOVE = re.compile(r"\bnet (?:increase|decrease|rise|drop|gain|reduction)\s+(?:of\s+)?(?:about\s+|around\s+|"
                       r"roughly\s+)?[$€£]?$", re.IGNORECASE)


#: a number after a base word: the base word's own ('base=22.0 delta=+30.1 n=6': no cue for the 6)
_NUMBERED = re.compile(r"\d")


def free_number(n: Number, masked: str, book: FactBook) -> Claim:
    """A number tied to no name: a decision-level quantity when the words around it name one (margin, runner-up
    score, prediction, baseline, change from the baseline, a domain comparison in its unit), else any decision-level
    fact or, when it is a contribution, the one feature whose contribution it is."""
    before, after = masked[max(0, n.start - 40):n.start], masked[n.end:n.end + 30]
    named = None
    if is_change(n, masked) and book.base is not None:  # '$91,462 above the baseline', 'exceeds ... (0.34) by 0.09'
        change = book.scores[book.chosen] - book.base
        ok = matches(n, change) or (n.percent and percent_reading(n, abs(change)))
        return Claim("number", n.text, "verified" if ok else "contradicted", f"the change from the baseline is "
                     f"{change:.4g}")
    if (MARGIN_BEFORE.search(before) or MARGIN_AFTER.match(after)) and book.output != "actions" and \
            book.base is not None and book.chosen in book.scores:  # one output: 'the 47.5-point gap' to the average
        change = book.scores[book.chosen] - book.base
        named = ("the change from the baseline", [change, abs(change)])
    elif MARGIN_BEFORE.search(before) or MARGIN_AFTER.match(after):
        named = ("the margin", [book.margin if book.margin is not None else 0.0])  # one available action: 0
    elif (SCORE_BEFORE.search(before) or (book.output == "actions" and re.match(r"^\s*(vs\.?|versus)\s", after))) \
            and book.chosen in book.scores:
        named = ("the chosen action's score", [book.scores[book.chosen]])
    elif _RUNNER_BEFORE.search(before) and book.runner_up:
        named = ("the runner-up's score", [book.scores[book.runner_up]])
    elif _COMPARE_AFTER.match(after) and book.by_unit:
        named = ("a comparison", [v for vs in book.by_unit.values() for v in vs])
    elif CONTRIB_BEFORE.search(before) and (owners := _owners(n, book)):
        if len(owners) == 1:
            return Claim("number", n.text, "verified", f"{owners[0]}'s contribution (the only one it matches)")
        return Claim("number", n.text, "unchecked", f"a contribution of one of {', '.join(owners)}: which is unsaid")
    elif book.output != "actions" and not book.global_view:
        near = before[-24:]
        base_at = max((m.end() for m in _BASE_WORDS.finditer(near) if not _NUMBERED.search(near, m.end())), default=-1)
        out_at = max((m.end() for m in _OUT_WORDS.finditer(_BASE_WORDS.sub(lambda m: " " * len(m.group(0)), near))),
                     default=-1)  # 'value' inside 'base value' is the baseline's word
        if base_at > out_at or _BASE_AFTER.match(after) or _BASE_BEFORE.search(before):  # the nearer cue decides
            if book.base and not 0.1 < abs(n.value / (100 if n.percent else 1) / book.base) < 10 and not re.search(
                    r"\bbase", near, re.IGNORECASE):  # 'older than average (18 vs. 16.8)': not the output's average
                return Claim("number", n.text, "unchecked", "an average of another order of magnitude than the "
                                                            "output's: of something not named")
            prediction = book.scores[book.chosen]
            if not re.search(r"\bbase", near, re.IGNORECASE) and (matches(n, prediction, magnitude_ok=False) or (
                    n.percent and percent_reading(n, prediction))):
                return Claim("number", n.text, "verified", "the prediction (next to a word for the average)")
            named = ("the baseline", [book.base])  # ('your risk is about average (33%)': the prediction)
        elif _OUT_WORDS.search(before) and n.sign != "+":  # ('made extending more valuable (+1.0)', 'Price +0.051':
            named = ("the prediction", [book.scores[book.chosen]])  # a plus sign marks a push, not where it ends)
    if named is not None and named[1]:
        ok = any(matches(n, v, magnitude_ok=False) or (n.percent and percent_reading(n, v)) for v in named[1])
        return Claim("number", n.text, "verified" if ok else "contradicted", f"{named[0]} is {named[1][0]:.4g}")
    if any(matches(n, v) or (n.percent and percent_reading(n, v)) for v in book.decision_numbers):
        if CONTRIB_BEFORE.search(before) or re.match(r"\s*(?:points?\s+)?more\b", after):
            return Claim("number", n.text, "unchecked", "a push by its words ('adds', '8 more'), equal to a "
                                                        "decision-level number but to no feature's contribution")
        return Claim("number", n.text, "verified", "a decision-level fact")
    if n.sign == "+" and (owners := _owners(n, book)):  # '(+1.0)' of a thing the vocabulary lacks: whose push
        return Claim("number", n.text, "verified" if len(owners) == 1 else "unchecked",
                     f"{owners[0]}'s contribution (the only one it matches)" if len(owners) == 1 else
                     f"a contribution of one of {', '.join(owners)}: which is unsaid")
    if book.closed:
        return Claim("number", n.text, "contradicted", "none of the facts the summary was made from")
    return Claim("number", n.text, "unchecked", "tied to no feature or quantity of this explanation")


def output_number(n: Number, book: FactBook, start: bool = False) -> Claim:
    """A number said to be where the output ends up ('pulls it down to 0.142'): the prediction; ``start``: where it
    starts ('from 34.1 % to ...'), the baseline."""
    v, what = (book.base, "baseline") if start else (book.scores[book.chosen], "prediction")
    ok = matches(n, v, magnitude_ok=False) or (n.percent and percent_reading(n, v))
    return Claim("number", n.text, "verified" if ok else "contradicted", f"the {what} is {v:.4g}")


def _owners(n: Number, book: FactBook) -> list[str]:
    """The features whose contribution (in any view) the number states: the one it states as written rounds ('about
    $8,300' for -8,251.83) when only one does, else all it states within its hedge."""
    found = []
    for strict in (True, False):
        m = replace(n, hedge="") if strict else n
        found = [f for f, e in book.features.items()
                 if any(matches(m, c) or (m.percent and percent_reading(m, c)) for c in e.contribs.values())]
        if len(found) == 1:
            return found
    return found


def any_fact(n: Number, book: FactBook, keys, ctx: str | None, strict: bool = False, contribution: bool = False,
             signed: bool = False) -> str | None:
    """Another fact of the sentence the number states: a value, contribution (either view, its size) or share of a
    feature named in it (``keys``); a decision-level number; an action's score. ``None``
    when it states none (then it is wrong wherever it is bound). A feature the sentence does not name is no
    candidate: with a dozen features, some fact would match any rounded number by chance. ``strict``: any feature
    may be meant, so only an unhedged number of two significant digits or more may match.
    ``contribution``: the words say the number is a push ('by -0.22'): no decision-level number or score.
    ``signed``: the words name a signed quantity ('a SHAP value of 0.3'): a contribution only with its sign.
    ``ctx``: the sentence's view (contributions and shares in it only), or None / either view."""
    if strict and (n.hedge or abs(n.value) < 10 * n.unit):
        return None  # ('0.06' or 'about 0.1' may match by chance)
    def states(v: float | None, size_ok: bool = True) -> bool:
        return v is not None and (matches(n, v, magnitude_ok=size_ok) or (n.percent and percent_reading(n, v)) or (
            n.points and percent_reading(n, abs(v))))

    views = book.contexts if ctx in (None, EITHER) else (ctx,)
    for key, e in ((k, book.features[k]) for k in sorted(keys) if k in book.features):
        shares = [("fill", e.fill), *((f"share ({c})", e.shares.get(c)) for c in views),
                  *((f"share of its side ({c})", e.side_shares.get(c)) for c in views)] if n.percent and not \
            n.points else []  # (a share is a percentage)
        for what, v in (("value", e.value), *shares):
            if states(v, size_ok=False):
                return f"{key}'s {what}"
        for c, x in ((c, e.contribs.get(c)) for c in views):
            if states(x, size_ok=not signed):
                return f"{key}'s contribution ({c})"
    if contribution:
        return None
    for what, v in (*(("a decision-level fact", x) for x in book.decision_numbers),
                    *((f"{a}'s score", x) for a, x in book.scores.items())):  # (a sum needs its cue words)
        if states(v):
            return what
    return None


#: a count of things a name after it holds: 'three robots in the charger queue', 'seven cars waiting at the junction'
_COUNTED_IN = re.compile(r"^\s+(?:[a-z\0]+\s+){1,2}(?:(?:already|still|now|waiting|queued|parked)\s+)?"
                         r"(?:in|on|at|inside)\s+(?:the\s+|a\s+|its\s+)?$", re.IGNORECASE)


def owned_by_unit_or_place(n: Number, masked: str, mentions, book: FactBook, unit_of) -> Claim | None:
    """A number first read as another name's and contradicted, that states exactly the value of the one feature its
    unit belongs to ('parked barely 4 m from a charger' of dist_to_charger_m, 4.2) or of the name that holds the things
    it counts ('three robots in the charger queue' of charger_queue_len, 3): verified as that value; else None."""
    unit = re.match(r"\s*([A-Za-zµ°/%]+)\b", masked[n.end:])
    owners = [f for f in book.features if unit and unit_of(f) and unit_of(f).lower() == unit.group(1).lower()]
    nxt = next((m for m in mentions if m.kind == "feature" and m.start >= n.end and len(m.keys) == 1
                and _COUNTED_IN.match(masked[n.end:m.start])), None)  # (past the counted noun's own mention)
    if nxt is not None:
        owners, rule = list(nxt.keys), "number.counted-in"
    elif len(owners) == 1:
        rule = "number.unit-owner"
    else:
        return None
    e = book.features.get(owners[0])
    if n.hedge not in ("", "approx"):  # ('under 0.6 km', 'over 1000 DM': a bound, not this value)
        return None
    if e is None or e.value is None or not matches(replace(n, hedge=""), e.value, magnitude_ok=False):
        return None
    return Claim("number", n.text, "verified", f"{owners[0]}: value", rule)
