"""What a text says about the background, not about this state: the baseline (the background's average output,
'the average sale price of $230,061', 'a base rate of 0.34') and a feature's typical value ('younger than the typical
borrower of about 48', 'the dataset average of 0.8', '(2 vs. ~5.75)'), checked against the background's quartiles.
:func:`statistic` reads the cue words before a number; :mod:`.binding` decides whose statistic it is."""

from __future__ import annotations

import re

from xairl.narrators.verify.book import FactBook
from xairl.narrators.verify.checks import Claim, over_keys
from xairl.narrators.verify.decision import reads_output
from xairl.narrators.verify.numbers import Number, matches

#: 'the typical borrower of about 48', 'the median home from 1966', 'the dataset average of 0.8', 'the average sale
#: price of $230,061', 'the baseline of 0.34': a statistic of the background, of a feature or of the output
_STAT_BEFORE = re.compile(
    r"\b(?P<word>average|typical|median|mean|usual|normal|(?:lower|upper) quartile|baseline|"
    r"base rate|base value|base|expected value)\b(?P<between>(?:\s+(?!(?:of|at|from|is|was)\b)"
    r"[A-Za-z'\0-]+){0,5}?)\s*(?:of|at|from|is|was|:|=|\()?\s*(?:about|around|roughly|nearly|"
    r"approximately|only|just|close to|over|under|above|below|~|≈)?\s*[$€£]?\s*"
    r"(?:[\d.,]+\s*(?:-|–|to)\s*)?$",
    re.IGNORECASE,
)
_OUTPUT_NOUN = re.compile(
    r"\b(?:predict\w*|estimat\w*|output|probabilit\w*|chances?|risk|rate|price|scores?|"
    r"q[- ]?values?)\b",
    re.IGNORECASE,
)

#: a sentence about the average case ('On average, a student has about an 18 % chance of dropping out')
_OPENS_AVERAGE = re.compile(r"^\W*(?:on average|typically|in general|for the (?:average|typical) \w+)\b", re.IGNORECASE)


def first_of_the_average(n: Number, masked: str) -> bool:
    """Is ``n`` the first number of a sentence about the average case? Then it is the baseline."""
    return bool(_OPENS_AVERAGE.match(masked)) and not re.search(r"\d", masked[: n.start])


#: '(2 vs. ~5.75)', '(18 vs. 16.8)' after a feature's value: the background's typical value (with one output; with
#: several, 'vs' sets a score against the runner-up's)
_VERSUS = re.compile(
    r"[\d%]\s*(?:\w+\s+)?(?:vs\.?|versus|compared (?:to|with))\s+(?:the\s+)?(?:average\s+(?:of\s+)?)?"
    r"[~≈]?\s*$",
    re.IGNORECASE,
)


def statistic(
    before: str, action_named: bool = False, several_outputs: bool = False, versus: bool = True
) -> str | None:
    """Is the number right after ``before`` a statistic of the background? 'output' (the baseline: 'the average
    prediction of', 'the base rate of'), 'feature' ('the typical borrower of about', 'the median of') or None.
    ``action_named``: an action is named between the statistic's word and the number ('the average sale price of');
    ``several_outputs``: 'vs' sets two scores side by side ('7.53 vs 7.38'), not a value and its typical one;
    ``versus``: the bracket the number opens goes on with 'vs' ('than average (2 vs. 3)': the first is the value)."""
    m = _STAT_BEFORE.search(before)
    if (
        m is not None
        and m.group(0).rstrip().endswith("(")
        and re.search(r"\bthan\s+(?:the\s+)?$", before[: m.start()])
        and versus
    ):
        m = None  # 'fewer absences than average (2 vs. ~5.75)': the bracket opens with the student's own value
    if (
        m is not None
        and re.search(r"\bby\b|\b\w+(?:ed|es)\b", m.group("between"), re.IGNORECASE)
        and not re.search(r"\b(?:typically|usually|normally|often)\b", m.group("between"), re.IGNORECASE)
    ):
        m = None  # 'the larger than average second floor increased the price by about': a verb, not a noun phrase
    if m is None:
        return "feature" if not several_outputs and _VERSUS.search(before) else None
    habit = re.search(r"\b(?:typically|usually|normally|often)\b", m.group("between"), re.IGNORECASE)
    output = m.group("word").lower().startswith(("base", "expected")) or (
        _OUTPUT_NOUN.search(m.group("between")) and not habit
    )  # 'the average team typically scores around
    return "output" if output or (action_named and "\0" in m.group("between")) else "feature"


def typical_number(n: Number, keys: tuple[str, ...], book: FactBook) -> Claim:
    """A feature's typical, average or median value ('younger than the typical borrower of about 48'), checked
    against the background's quartiles (the explanation keeps no mean): verified inside the 25-75 % band,
    contradicted past Tukey's fences (1.5 interquartile ranges beyond a quartile: an outlier, not a typical value),
    unchecked between or when the quartiles coincide. Categorical features are not checked."""

    def test(key):
        e = book.features[key]
        if e.quartiles is None or e.label is not None or n.percent:
            return None
        lo, _, hi = e.quartiles
        band = f"{key}'s background quartiles are {lo:.4g} to {hi:.4g}"
        if lo <= n.value <= hi or matches(n, lo, magnitude_ok=False) or matches(n, hi, magnitude_ok=False):
            return True, f"a typical value of {key} ({band})"
        # quartiles that coincide ('failures' 0 / 0 / 0, one value in most rows): the mean may lie anywhere
        if hi > lo and not lo - 1.5 * (hi - lo) <= n.value <= hi + 1.5 * (hi - lo):
            return False, f"{n.text} is no typical value of {key}: {band}"
        return None

    return over_keys(keys, test, "typical value", n.text, "number")


def base_number(n: Number, book: FactBook) -> Claim:
    """'the average prediction of $230,061', 'a base rate of 0.34': the baseline (the background's average output)."""
    ok = book.base is not None and reads_output(n, book.base, book)
    return Claim("number", n.text, "verified" if ok else "contradicted", f"the baseline is {book.base:.4g}")
