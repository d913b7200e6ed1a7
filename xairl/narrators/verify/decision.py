"""What a decision-level number states and its check: an action's score or the margin (:func:`action_number`), the
change from the baseline (:func:`is_change`), where the output ends or starts (:func:`output_number`), and a number
tied to no name (:func:`free_number`: the quantity its cue words name, any decision-level fact, or the one feature
whose contribution it is). Numbers tied to a feature are :mod:`.quantities`."""

from __future__ import annotations

import math
import re

from xairl.narrators.verify import quantities
from xairl.narrators.verify.book import FactBook
from xairl.narrators.verify.checks import Claim
from xairl.narrators.verify.numbers import Number, matches, percent_reading

MARGIN_BEFORE = re.compile(
    r"\b(margin|lead|edge|gap|advantage|difference)(?: of)?\W*(?:about|around|roughly|only|"
    r"just)?\s*$|\b(won|wins|beat\w*|ahead|stayed ahead|led|edged out|outscored)\s+"
    r"(?:[\w\0']+\s+|\([^()]*\)\s+){0,4}by\s+(?:a\s+(?:whisker|hair|nose|wide margin|"
    r"narrow margin|small margin|large margin|mile)\s*,?\s*)?(?:about|around|roughly|only|just|"
    r"a bit over|a little over|some|nearly|almost)?\s*$",
    re.IGNORECASE,
)
_ON_AVERAGE = re.compile(
    r"^\s*(?:on average|over the background|across the background|at baseline|by default)\b", re.IGNORECASE
)
#: '3.9 points ahead', 'the 8.32-point lead', '3.9 points of margin': the margin
MARGIN_AFTER = re.compile(
    r"^\s*(?:points?\s+)?(?:above|ahead|higher|more than)\b|"
    r"^(?:-?\s*points?)?\s+(?:lead|margin|gap|edge|advantage)\b|"
    r"^\s+points?\s+of\s+(?:lead|margin|gap)\b",
    re.IGNORECASE,
)
_RUNNER_BEFORE = re.compile(
    r"(?<!bit )(?<!little )(?<!just )(?<!well )(?<!slightly )(?<!touch )(?<!hair )"
    r"\b(vs\.?|versus|against|compared with|over)\s*(?:a\s+|an\s+)?(?:[$€£]\s*)?$",
    re.IGNORECASE,
)
SCORE_BEFORE = re.compile(r"\b(scor\w+|q[- ]?values?|q\s*\([^)]*\)|q)\s*(?:of|=|:|at|was|is)?\s*$", re.IGNORECASE)
_BASE_AFTER = re.compile(
    r"^\s*(?!vs\b|versus\b|against\b|compared\b)(?:\w+\s+)?(baseline|base value|base rate|base|"
    r"average|typical|expected|mean)\b",
    re.IGNORECASE,
)  # not '0.14 vs base 0.34'
_BASE_WORDS = re.compile(
    r"\b(baseline|base value|base|average|typical|expected value|mean|on average)\b", re.IGNORECASE
)
#: 'the average prediction of $230,061'
_BASE_BEFORE = re.compile(
    r"\b(?:baseline|average|typical|mean|expected)\s+(?:prediction|estimate|output|predicted \w+)"
    r"\s*(?:of|is|was|:|=)?\s*[$€£]?\s*$",
    re.IGNORECASE,
)
_OUT_WORDS = re.compile(
    r"\b(predict\w*|estimat\w*|valu\w*|puts|sits|probability|chance|risk|price|output|final)\b", re.IGNORECASE
)
#: '$91,462 above the baseline' (not '0.38 is slightly above the base value': there the number is the prediction)
_CHANGE_BEFORE = re.compile(
    r"\b(?:exceed\w*|above|below|under|higher than|lower than|more than|less than)\b[^;]{0,40}"
    r"\bby\s+(?:about|around|roughly|nearly|almost|some|only|just)?\s*[$€£]?\s*$",
    re.IGNORECASE,
)
CHANGE_AFTER = re.compile(
    r"^\s*(?!(?:\w+\s+)?(?:is|was|are|were|sits|lies|stands|remains)\b)(?:\w+\s+){0,2}"
    r"(above|below|under|over|more|less)\s+(the\s+)?"
    r"(average|baseline|base|typical|expected|mean)"
    r"|^\W*(?:premium|uplift|markup|discount)\b",
    re.IGNORECASE,
)
#: 'Net effect of the eight features: +0.089', 'Net uplift over the base value: +$86,046': the change from the baseline
NET_BEFORE = re.compile(
    r"\b(?:net (?:effect|uplift|change|shift|push|contribution)|total (?:effect|shift|change)|"
    r"(?<![\w.])delta(?=\s*[=:])|"  # ('base=27.0 delta=-22.0')
    r"(?:uplift|premium|change|shift) (?:over|above|from|relative to) (?:the )?(?:base(?:line)?|"
    r"base value|base rate|average))\b(?:\s+(?:of|over|from|across)\s+[^.;:()\d]{1,30}?)?\s*"
    r"(?:[:=]|\bis\b|\bwas\b|\bof\b)?\s*(?:about|around|roughly)?\s*[$€£]?$",
    re.IGNORECASE,
)
_COMPARE_AFTER = re.compile(rf"^\s*(?:(?:dB|dBm)\s*)?(?:{quantities.COMPARISON_WORDS}|more|less)\b", re.IGNORECASE)


def action_number(n: Number, action: str | None, masked: str, book: FactBook) -> Claim:
    """A number next to an action: its score, or the margin when the words say so ('won by', 'a lead of')."""
    if book.global_view:  # over many states no single action has a score: a count or another flight-level fact
        return free_number(n, masked, book)
    before = masked[max(0, n.start - 40) : n.start]
    if MARGIN_BEFORE.search(before) and book.margin is not None:
        if _ON_AVERAGE.match(masked[n.end : n.end + 40]) and book.base_margin is not None:
            ok = matches(n, book.base_margin)  # 'it led by 3.4 on average over the background'
            return Claim(
                "number",
                n.text,
                "verified" if ok else "contradicted",
                f"the margin over the background is {book.base_margin:.4g}",
            )
        ok = matches(n, book.margin)
        return Claim("number", n.text, "verified" if ok else "contradicted", f"the margin is {book.margin:.4g}")
    if action is None or action not in book.scores:
        return Claim("number", n.text, "unchecked", "an action that could not be told apart")
    ok = matches(n, book.scores[action], magnitude_ok=False)
    return Claim(
        "number", n.text, "verified" if ok else "contradicted", f"{action}'s score is {book.scores[action]:.4g}"
    )


def is_change(n: Number, masked: str) -> bool:
    """Is ``n`` the change from the baseline? '$91,462 above the baseline', 'exceeds the base rate (0.34) by 0.09',
    'below base by $34,184', 'Net uplift over the base value: +$86,046'."""
    before = masked[max(0, n.start - 60) : n.start]
    return bool(
        CHANGE_AFTER.match(masked[n.end : n.end + 30])
        or NET_BEFORE.search(before)
        or (_CHANGE_BEFORE.search(before[-40:]) and _BASE_WORDS.search(before[-40:]))
        or (_NET_MOVE.search(before) and "\0" not in masked[: n.start])
    )


#: 'a net increase of 18.7 h' in a sentence that names no feature before it (else it may be that name's push:
#: 'Traffic gives a net increase of 7.2')
_NET_MOVE = re.compile(
    r"\bnet (?:increase|decrease|rise|drop|gain|reduction)\s+(?:of\s+)?(?:about\s+|around\s+|"
    r"roughly\s+)?[$€£]?$",
    re.IGNORECASE,
)


#: a number after a base word: the base word's own ('base=22.0 delta=+30.1 n=6': no cue for the 6)
_NUMBERED = re.compile(r"\d")


def in_output_name(n: Number, masked: str, book: FactBook) -> bool:
    """The number is one of the output's name, written with a word it has there: 'sending unit 7' of "Q-value of the
    action 'send unit 7'", 'slowing to 12 knots' of "... 'reduce to 12 knots'" (a one-output model's name holds the
    action it scores): no fact of the explanation."""
    if book.output == "actions" or not book.chosen or not _NUMBERED.search(book.chosen):
        return False
    before = re.search(r"([^\W\d_]+)\W{0,2}$", masked[max(0, n.start - 30) : n.start])
    after = re.match(r"\W{0,2}([^\W\d_]+)", masked[n.end : n.end + 30])
    for m in re.finditer(r"\d+(?:\.\d+)?", book.chosen):
        if float(m.group()) != abs(n.value) or n.percent:
            continue
        word_before = re.search(r"([^\W\d_]+)\W{0,2}$", book.chosen[: m.start()])
        word_after = re.match(r"\W{0,2}([^\W\d_]+)", book.chosen[m.end() :])
        if (before and word_before and before.group(1).lower() == word_before.group(1).lower()) or (
            after and word_after and after.group(1).lower() == word_after.group(1).lower()
        ):
            return True
    return False


def free_number(n: Number, masked: str, book: FactBook) -> Claim:
    """A number tied to no name: a decision-level quantity when the words around it name one (margin, runner-up
    score, prediction, baseline, change from the baseline, a domain comparison in its unit), else any decision-level
    fact or, when it is a contribution, the one feature whose contribution it is."""
    before, after = masked[max(0, n.start - 40) : n.start], masked[n.end : n.end + 30]
    named = None
    if is_change(n, masked) and book.base is not None:  # '$91,462 above the baseline', 'exceeds ... (0.34) by 0.09'
        change = book.scores[book.chosen] - book.base
        ok = matches(n, change) or (n.percent and percent_reading(n, abs(change)))
        return Claim(
            "number", n.text, "verified" if ok else "contradicted", f"the change from the baseline is {change:.4g}"
        )
    if (
        (MARGIN_BEFORE.search(before) or MARGIN_AFTER.match(after))
        and book.output != "actions"
        and book.base is not None
        and book.chosen in book.scores
    ):  # one output: 'the 47.5-point gap' to the average
        change = book.scores[book.chosen] - book.base
        named = ("the change from the baseline", [change, abs(change)])
    elif MARGIN_BEFORE.search(before) or MARGIN_AFTER.match(after):
        named = ("the margin", [book.margin if book.margin is not None else 0.0])  # one available action: 0
    elif (
        SCORE_BEFORE.search(before) or (book.output == "actions" and re.match(r"^\s*(vs\.?|versus)\s", after))
    ) and book.chosen in book.scores:
        named = ("the chosen action's score", [book.scores[book.chosen]])
    elif _RUNNER_BEFORE.search(before) and book.runner_up:
        named = ("the runner-up's score", [book.scores[book.runner_up]])
    elif _COMPARE_AFTER.match(after) and book.by_unit:
        named = ("a comparison", [v for vs in book.by_unit.values() for v in vs])
    elif quantities.CONTRIB_BEFORE.search(before) and (owners := quantities.contribution_owners(n, book)):
        if len(owners) == 1:
            return Claim("number", n.text, "verified", f"{owners[0]}'s contribution (the only one it matches)")
        return Claim("number", n.text, "unchecked", f"a contribution of one of {', '.join(owners)}: which is unsaid")
    elif book.output != "actions" and not book.global_view:
        named = _by_output_words(n, before, after, book)
        if isinstance(named, Claim):
            return named
    if named is not None and named[1]:
        ok = (
            reads_output(n, named[1][0], book)
            if named[0] in ("the prediction", "the baseline")
            else any(
                matches(n, v, magnitude_ok=False) or (n.percent and not book.log_odds and percent_reading(n, v))
                for v in named[1]
            )
        )  # (log-odds are no percentages)
        return Claim("number", n.text, "verified" if ok else "contradicted", f"{named[0]} is {named[1][0]:.4g}")
    if any(matches(n, v) or (n.percent and percent_reading(n, v)) for v in book.decision_numbers) or (
        book.base is not None
        and book.chosen in book.scores
        and any(probability(n, v, book) for v in (book.scores[book.chosen], book.base))
    ):
        if quantities.CONTRIB_BEFORE.search(before) or re.match(r"\s*(?:points?\s+)?more\b", after):
            return Claim(
                "number",
                n.text,
                "unchecked",
                "a push by its words ('adds', '8 more'), equal to a "
                "decision-level number but to no feature's contribution",
            )
        return Claim("number", n.text, "verified", "a decision-level fact")
    if n.sign == "+" and (owners := quantities.contribution_owners(n, book)):  # '(+1.0)' of a thing the vocabulary
        # lacks: whose push
        return Claim(
            "number",
            n.text,
            "verified" if len(owners) == 1 else "unchecked",
            f"{owners[0]}'s contribution (the only one it matches)"
            if len(owners) == 1
            else f"a contribution of one of {', '.join(owners)}: which is unsaid",
        )
    if book.closed:
        return Claim("number", n.text, "contradicted", "none of the facts the summary was made from")
    return Claim("number", n.text, "unchecked", "tied to no feature or quantity of this explanation")


def _by_output_words(n: Number, before: str, after: str, book: FactBook) -> Claim | tuple | None:
    """One output's number by the nearer of its cue words: a word for the average ('the typical 8 percent') names
    the baseline (or the prediction it equals, or an average of something else when far from the output's size); a
    word of the output ('puts the risk at') names the prediction. A Claim when that settles it, else (what, [value])
    or None."""
    near = before[-24:]
    base_at = max((m.end() for m in _BASE_WORDS.finditer(near) if not _NUMBERED.search(near, m.end())), default=-1)
    out_at = max(
        (m.end() for m in _OUT_WORDS.finditer(_BASE_WORDS.sub(lambda m: " " * len(m.group(0)), near))), default=-1
    )  # 'value' inside 'base value' is the baseline's word
    if base_at > out_at or _BASE_AFTER.match(after) or _BASE_BEFORE.search(before):  # the nearer cue decides
        if (
            book.base
            and not 0.1 < abs(n.value / (100 if n.percent else 1) / book.base) < 10
            and not re.search(r"\bbase", near, re.IGNORECASE)
        ):  # 'older than average (18 vs. 16.8)': not the output's average
            return Claim(
                "number",
                n.text,
                "unchecked",
                "an average of another order of magnitude than the output's: of something not named",
            )
        prediction = book.scores[book.chosen]
        if not re.search(r"\bbase", near, re.IGNORECASE) and (
            matches(n, prediction, magnitude_ok=False) or (n.percent and percent_reading(n, prediction))
        ):
            return Claim("number", n.text, "verified", "the prediction (next to a word for the average)")
        return ("the baseline", [book.base])  # ('your risk is about average (33%)': the prediction)
    if _OUT_WORDS.search(before) and n.sign != "+":  # ('made extending more valuable (+1.0)', 'Price +0.051': a
        return ("the prediction", [book.scores[book.chosen]])  # plus sign marks a push, not where it ends)
    return None


def output_number(n: Number, book: FactBook, start: bool = False) -> Claim:
    """A number said to be where the output ends up ('pulls it down to 0.142'): the prediction; ``start``: where it
    starts ('from 34.1 % to ...'), the baseline."""
    v, what = (book.base, "baseline") if start else (book.scores[book.chosen], "prediction")
    return Claim("number", n.text, "verified" if reads_output(n, v, book) else "contradicted", f"the {what} is {v:.4g}")


def reads_output(n: Number, v: float, book: FactBook) -> bool:
    """Does ``n`` state the output's value ``v`` (the prediction or the baseline): as written, as the percentage of
    a probability-like output, or, for a log-odds output, as the probability ``v`` stands for (:func:`probability`;
    log-odds are no percentages)?"""
    return (
        matches(n, v, magnitude_ok=False)
        or (n.percent and not book.log_odds and percent_reading(n, v))
        or probability(n, v, book)
    )


def probability(n: Number, v: float, book: FactBook) -> bool:
    """Is ``n`` a percentage that states log-odds ``v`` of a log-odds output as the probability it stands for
    ('the log-odds rise to -0.27, a probability of roughly 43 %')?"""
    return n.percent and book.log_odds and percent_reading(n, 1.0 / (1.0 + math.exp(-min(max(v, -700.0), 700.0))))
