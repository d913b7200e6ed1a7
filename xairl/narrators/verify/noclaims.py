"""Numbers in a text that are no claims: list markers, identifiers, counts of the method's inputs or of the factors
a sentence lists, ratios read by :mod:`.comparisons`, the window a feature's name holds."""

from __future__ import annotations

import re

from xairl.narrators.verify.lexicon import RATIO_HEDGE
from xairl.narrators.verify.numbers import Number

_SKIP_AFTER = re.compile(
    r"^\s*(?:(?:background|samples?|rows?|states?|draws|features|narratives|coalitions|"
    r"(?:and an? (?:half|third|quarter)\s+)?times|"
    r"-fold|outcomes|options|classes|sides|factors|reasons|drivers|categories|possibilities|"
    r"scenarios|-?points?\s+scale|scale)\b|[x×](?![\w])|"
    r"(?:of\s+(?:the|its|these|those)\s+)?(?:[A-Za-z\0][\w\0'-]*\s+){0,2}(?:factors|reasons|"
    r"drivers|features|things|variables|inputs)\b)",
    re.IGNORECASE,
)  # ('the three upward drivers', 'any two of the other factors')
_LABEL_BEFORE = re.compile(
    r"\b(candidates?|bs|cell|id|#|step|case|top|row|state|outcome|class|type|acct|account|ref|"
    r"ticket|order|episode|ep|seed|run|version|customer|patient|flight|no\.)[\s\-=:#]*$",
    re.IGNORECASE,
)
_OF_PEOPLE = re.compile(
    r"\s+of\s+(?:the\s+|their\s+|its\s+|all\s+)?(?:[\w-]+\s+){0,2}?(?:peers|students|people|"
    r"customers|clients|applicants|borrowers|teams|players|cases|samples|population|dataset|"
    r"houses|homes|users|patients|rows|records)\b",
    re.IGNORECASE,
)


#: a ratio's words right before its number: 'by a factor of ~2.6'
_FACTOR_BEFORE = re.compile(
    r"\bby\s+a\s+factor\s+of\s+(?:about\s+|roughly\s+|around\s+|nearly\s+|almost\s+|~\s*)?$", re.IGNORECASE
)


#: a ratio written as odds: the number before 'to 1' ('1.5 to 1', 'two to one', '3:1'), and the 1 after it
_TO_ONE = re.compile(r"\s*(?:to|:)\s*(?:1|one)(?!\w|\.\d)(?!\s*(?:%|percent|points?|pp)\b)", re.IGNORECASE)
_TO_ONE_BEFORE = re.compile(
    r"(?<![\w.])(?<!from )(?<!between )(?:\d+(?:\.\d+)?|one|two|three|four|five|ten)\s*"
    r"(?:to|:)\s*$",
    re.IGNORECASE,
)  # (not 'fell from 3 to 1': a value)
#: odds of a larger whole number to a smaller one after a comparison's 'by': 'outweighs B by about 3 to 2'
_ODDS = re.compile(
    rf"\bby\s+{RATIO_HEDGE}(\d)\s*(?:to|:)\s*(\d)(?!\w|\.\d|\s*(?:%|percent|points?|pp)\b)", re.IGNORECASE
)


def skip_number(n: Number, masked: str) -> bool:
    """Numbers that are not claims: list markers ('1.' at a line start), identifiers ('candidate 2', 'top-3'),
    counts of the method's inputs ('100 background rows')."""
    before = masked[: n.start]
    if re.search(r"(^|\n)\s*$", before) and re.match(r"^[.)]\s", masked[n.end : n.end + 2]):
        return True
    if (masked[n.start - 1 : n.start] == "\0" and not masked[n.start].isspace()) or masked[n.end : n.end + 1] == "\0":
        return True  # glued to a name: 'PM2.5' of a masked 'PM2', '2nd' of a name
    if re.search(r"\bout of\s*$", before, re.IGNORECASE):  # 'rated 4 out of 5': the scale's top
        return True
    if n.percent and _OF_PEOPLE.match(masked, n.end):  # 'unlike 95% of their peers': a share of the background
        return True
    if n.percent and re.match(r"\s*of\s+(?:the\s+|its\s+|their\s+)?\0", masked[n.end :]):
        return True  # '60 % of the alcohol effect': a ratio to that name (:mod:`.comparisons`)
    if re.search(r"\[\s*$", before[-3:]) and re.match(r"\s*\]", masked[n.end :]) and n.text.isdigit():
        return True  # a citation mark: 'the lag removed 1.2 [2]'
    if _FACTOR_BEFORE.search(before[-30:]) and not n.percent and not n.text.isalpha():
        return True  # 'larger than B by a factor of ~2.6': a ratio (:mod:`.comparisons`)
    if not (n.percent or n.currency or n.sign) and (
        (_TO_ONE.match(masked, n.end) and not re.search(r"\b(?:from|between)\s+$", before, re.IGNORECASE))
        or (n.value == 1 and _TO_ONE_BEFORE.search(before))
    ):
        return True  # 'outweighed B by roughly 1.5 to 1', 'two to one': a ratio (:mod:`.comparisons`)
    odds = next(
        (
            m
            for m in _ODDS.finditer(masked, max(0, n.start - 20), n.end + 8)
            if m.start(1) <= n.start < m.end(2) and int(m.group(1)) > int(m.group(2))
        ),
        None,
    )
    if odds is not None:
        return True  # 'outweighs B by about 3 to 2'

    if re.match(r"^\s+(?:most|largest|biggest|main|top|strongest|key)\b", masked[n.end :]):  # 'the two largest'
        return True
    if not n.text[0].isdigit() and re.search(r"\b(all|these|those|the other)\s+$", before, re.IGNORECASE):
        return True  # all three
    if n.text[0].isalpha() and re.search(r"\b(?:of|among) the\s+$", before, re.IGNORECASE):
        return True  # 'the strongest of the three'
    if n.text.lower() == "one" and re.match(r"\s+of\s+(?:the|its|their|our|these|those)\b", masked[n.end :]):
        return True  # 'one of the pricier neighbourhoods'
    if n.text.lower() == "one" and re.search(
        r"\b(this|that|the|which|each|every|any|no|a)\s+(?:[a-z]+\s+)?$", before, re.IGNORECASE
    ):
        return True  # 'this one', 'the big one': a pronoun
    return bool(_LABEL_BEFORE.search(before)) or bool(_SKIP_AFTER.match(masked[n.end :]))


def _windows(keys) -> set[tuple[str, str]]:
    """The windows the names hold, as (number, first letter of its unit): ('30', 'd') of ``data_usage_gb_30d``."""
    return {(m.group(1), m.group(2)) for k in keys for m in re.finditer(r"(\d+)([a-z])", k.lower())}


_PERIOD_AFTER = re.compile(r"\s*(days?|weeks?|months?|years?|hours?)\b", re.IGNORECASE)


def window_of_name(n: Number, keys, masked: str = "", all_keys=()) -> bool:
    """An integer that is the window or range a named feature's name holds ('fires within 200 km' of
    ``fire_count_200km``, 'in the last 30 days' of ``data_usage_gb_30d``): a part of the name, not a claim. A period
    ('the past twelve months') is also the window of a feature the sentence names in words of its own
    (``prior_returns_12m``)."""
    if n.sign or n.percent or n.currency or n.hedge or n.value != int(n.value):
        return False
    if any(number == str(int(n.value)) for number, _ in _windows(keys)):
        return True
    period = _PERIOD_AFTER.match(masked, n.end)
    window = (str(int(n.value)), period.group(1)[0].lower()) if period else None
    return window is not None and window in _windows(all_keys)


def identifier_after_word(n: Number, masked: str, mentions) -> bool:
    """A bare whole number right after one word of a longer name that a preposition comes before, ending its phrase
    ('queued at charger 3', 'even though charger 2 was free', 'unit 5 on floor 2'): an identifier of a thing, not that
    name's value."""
    digits = masked.find(n.text, n.start)
    owner = next((m for m in mentions if m.kind == "feature" and digits > 0 and masked[m.end : digits] == " "), None)
    if owner is None or owner.form != "part" or not n.text.isdigit():
        return False
    if not re.match(
        r"\s*(?:$|[,;:.)!?](?!\d)|(?:was|is|were|had|has|on|in|at|of|to|and|or|which|that|yesterday|"
        r"today)\b)",
        masked[n.end :],
        re.IGNORECASE,
    ):
        return False  # '3.5', '3 km', '9 robots': a quantity
    return bool(re.search(r"\b(?:at|on|in|to|near|from|by|for|though|unit)\s+$", masked[: owner.start], re.IGNORECASE))


def without_window_words(mentions, written: str, features) -> list:
    """``mentions`` less the one-word parts of a name that only spell another name's window in the ``written``
    sentence ('days' of days_since_last_upgrade in 'support calls in the last 90 days', the window of
    support_calls_90d)."""
    windows = _windows(features)

    def spells_window(m) -> bool:  # 'the last 90 days': both words of the window, next to its number
        if m.kind != "feature" or m.form != "part":
            return False
        before = re.search(r"(\d+)\s*$", written[: m.start])
        after = re.match(
            r"\s*(\d+)\s*(?=(?:days?|weeks?|months?|years?|hours?|d|w|m|y|h)\b)([a-z])", written[m.end :], re.IGNORECASE
        )
        window = (
            (before.group(1), written[m.start : m.start + 1].lower())
            if before
            else ((after.group(1), after.group(2).lower()) if after else None)
        )
        return window in windows and not any("".join(window) in k.lower() for k in m.keys)

    return [m for m in mentions if not spells_window(m)]
