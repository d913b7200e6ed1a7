"""Comparisons between features: 'A mattered more than B', 'about as much as', 'A outweighs B', 'A and B outweighed
C', ratios ('1.7 times as much as', '35 % more than') and a bracket setting their numbers side by side ('(0.88 vs
0.49)'); the phrases that state them and their checks."""

from __future__ import annotations

import re

from xairl.verification.prose.book import FactBook
from xairl.verification.prose.checks import EITHER, over_keys
from xairl.verification.prose.names import Mention, named_features
from xairl.verification.prose.words import RATIO_HEDGE
from xairl.verification.result import Claim

#: 'A mattered more than B', 'a bigger effect on the margin than B', 'lowers the risk less than B does', 'A outweighs
#: B', 'cuts it by about as much as B adds': how large |contribution| is beside another feature's
COMPARE_RE = re.compile(
    r"\b(?:(?P<more>more|bigger|larger|greater|stronger|heavier)|(?P<less>less|smaller|weaker)|"
    r"(?P<same>as much|as large|as big))\b(?P<gap>(?:\s+[\w'\-\0]+){0,6}?)\s+(?:than|as)\s+"
    r"|\b(?P<out>outweigh\w*|dwarf\w*|overshadow\w*)\s+"
    r"|(?<=\d)\s*(?P<of>(?:%|percent)\s+of|times(?:\s+of)?)\s+(?=(?:the\s+|its\s+|their\s+)?\0)"
    r"|\b(?P<sized>(?:about\s+|roughly\s+|nearly\s+|almost\s+)?(?:twice|double|half|"
    r"three times|four times|\d+(?:\.\d+)?\s*(?:times|x)))\s+(?:the\s+(?:size|magnitude|strength|"
    r"weight)|that)\s+of\s+(?=(?:the\s+|its\s+|their\s+)?\0)",
    re.IGNORECASE,
)  # ('60 % of the alcohol effect', '3.7 times the pedestrian-call penalty',
#                                          'roughly twice the size of the B effect', 'more than twice that of B')
#: the words between 'outweighs' (or 'than') and the name compared with: a determiner, a count's words ('than the
#: number of browsing sessions')
_BEFORE_B = re.compile(
    r"\s*(?:the\s+|its\s+|their\s+|the\s+\w+'s\s+)?(?:(?:number|count|amount|level|size) of\s+"
    r"(?:the\s+|its\s+)?(?:(?!(?:any|all|other|combined|every|each)\b)[a-z-]+\s+)?)?",
    re.IGNORECASE,
)
#: after 'than': also a determiner or owner and up to four words that are no name, number or word of a whole ("than
#: the shopper's choice of", 'than being close to the', 'than the three size-related'); not 'any other', 'the rest'
_AFTER_THAN = re.compile(
    r"\s*(?:the|its|their|his|her|a|an|being|[\w-]+'s)\s+(?:(?!(?:any|all|other|others|combined|"
    r"every|each|rest|remaining|half|twice|double|third|quarter|most|least|sum|total|expected|"
    r"usual|typical|average|previous|one|anything|everything|and|or|with|for|would|did|does|"
    r"base|baseline|prediction|forecast|output|score)\b)[a-z'-]+\s+){0,4}",
    re.IGNORECASE,
)
#: a ratio after the name compared with: '... than the pacing plan (-1.4) by a factor of ~2.6'
#: or 'outweighed the gusts by roughly 1.5 to 1', 'outweighs fever roughly two to one (1.46 vs 0.77)'
_FACTOR_AFTER = re.compile(
    r"(?:\s*\([^()]*\))?\s*(?:(?:did|does)\s+)?(?:,\s*)?(?:by\s+a\s+factor\s+of\s+"
    r"(?:about\s+|roughly\s+|around\s+|nearly\s+|almost\s+|~\s*)?(\d+(?:\.\d+)?)\b|"
    rf"(?:by\s+)?{RATIO_HEDGE}"
    r"(\d+(?:\.\d+)?|one|two|three|four|five|ten)\s*(?:to|:)\s*(1|one|[2-9]|two|three|four)"
    r"(?!\w|\.\d))",
    re.IGNORECASE,
)  # ('by about 3 to 2': 1.5)
_FACTOR_WORDS = {"one": 1.0, "two": 2.0, "three": 3.0, "four": 4.0, "five": 5.0, "ten": 10.0}
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
RATIO_WITHIN = 0.25  # a ratio in words ('roughly twice') holds within 25 % of the sizes' ratio


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


def _factor(m: re.Match) -> float:
    """The ratio a factor after B states: 'by a factor of 2.6', 'roughly 1.5 to 1', 'two to one', 'about 3 to 2'
    (0 for odds of a smaller number to a larger one: a range, '2 to 3', not odds)."""

    def value(text: str) -> float:
        return _FACTOR_WORDS.get(text.lower()) or float(text)

    if m.group(1):
        return float(m.group(1))
    over = value(m.group(3))
    return value(m.group(2)) / over if value(m.group(2)) >= over else 0.0


def _sized(words: str) -> float:
    """The ratio 'twice the size of B', 'roughly 1.7 times that of B' states: 2, 1.7."""
    core = re.sub(r"^(?:about|roughly|nearly|almost)\s+", "", words.lower())
    number = re.match(r"(\d+(?:\.\d+)?)", core)
    return (
        float(number.group(1))
        if number
        else {"twice": 2.0, "double": 2.0, "half": 0.5, "three times": 3.0, "four times": 4.0}[core]
    )


def _of_ratio(before: str, unit: str) -> float | None:
    """The ratio '60 % of B' (0.6) or '3.7 times B' (3.7) states, from the number right before the unit."""
    m = re.search(r"(\d+(?:\.\d+)?)\s*$", before)
    if m is None:
        return None
    return float(m.group(1)) / (1 if unit.lower().startswith("times") else 100)


def check_ratio(a_keys: tuple[str, ...], b_key: str, ratio: float, ctx: str | None, book: FactBook, text: str) -> Claim:
    """'A mattered 1.7 times as much as B': |A| / |B| within :data:`RATIO_WITHIN` of the ratio, in the sentence's
    view (any view when it names none)."""

    def test(key):
        pairs = _sizes(key, b_key, ctx, book)
        if not pairs or not ratio > 0:
            return None
        ok = [c for x, y, c in pairs if y > 0 and abs(x / y - ratio) <= RATIO_WITHIN * ratio]
        x, y, c = pairs[0]
        return bool(ok), f"|{key}| / |{b_key}| is {x / y if y else float('inf'):.3g}, said {ratio:.3g} ({c})"

    return over_keys(a_keys, test, "ratio", text, "rank")


def check_outweighs(a_keys: list[str], b_keys: list[str], ctx: str | None, book: FactBook, text: str) -> Claim:
    """'A and B outweighed C': A's and B's |contributions| together against C's (in any view the sentence allows)."""
    contexts = [c for c in views(ctx, book) if all(c in book.features[k].contribs for k in a_keys)]
    if not contexts:
        return Claim("rank", text, "unchecked", "nothing known to check it against (comparison)")
    sizes = [
        (
            sum(abs(book.features[k].contribs[c]) for k in a_keys),
            sum(abs(book.features[k].contribs.get(c, 0.0)) for k in b_keys),
            c,
        )
        for c in contexts
    ]
    ok = [c for x, y, c in sizes if x > y]
    x, y, c = sizes[0]
    return Claim(
        "rank",
        text,
        "verified" if ok else "contradicted",
        f"|{' + '.join(a_keys)}| {x:.3g} vs |{' + '.join(b_keys)}| {y:.3g} ({ok[0] if ok else c})",
    )


def views(ctx: str | None, book: FactBook) -> tuple[str, ...]:
    """The views a rank or magnitude claim is checked in: the one its sentence names, else any."""
    return (ctx,) if ctx and ctx != EITHER else book.contexts


def find_comparisons(
    masked: str, a: int, b: int, mentions: list[Mention], book: FactBook, ctx: str | None, written: str = ""
) -> list[Claim]:
    """'A mattered more than B' (and 'which in turn mattered more than C'), 'A and B both mattered more than C', 'A
    outweighs B': A's |contribution| against B's. B must be one feature named right after 'than' or 'outweighs'
    (:data:`_BEFORE_B`, :data:`_AFTER_THAN`); A the names since the previous comparison, else the last name before the
    comparative (a relative 'which'); 'by a factor of 2.6' after B is the ratio of one name to B. ``written``: the
    sentence as written (claims quote it)."""
    out, start, written, earlier = [], a, written or masked, []
    names = named_features(mentions)
    for m in COMPARE_RE.finditer(masked, a, b):
        b_name = next((x for x in names if x.start >= m.end()), None)
        if (
            b_name is None
            or len(b_name.keys) != 1
            or not (
                _BEFORE_B.fullmatch(masked, m.end(), b_name.start)
                or (not m.group("out") and _AFTER_THAN.fullmatch(masked, m.end(), b_name.start))
            )
        ):
            continue  # 'more than $500', 'bigger than any other feature': no feature to compare with
        subjects = [x for x in names if start <= x.start and x.end <= m.start()]
        if not subjects or m.group("of") or m.group("sized"):  # ('A ..., and the B term is about 1.5 times the C
            subjects = [x for x in names if x.end <= m.start()][-1:]  # term': B's)
        if (
            m.group("sized")
            and earlier
            and re.search(r"\band\b", masked[start : m.start()])
            and not any(start <= x.start < m.start() for x in names)
        ):  # 'A is 1.6 times that of B and three times that of C'
            subjects = earlier
        earlier = earlier or subjects
        way = 1 if m.group("more") or m.group("out") else -1 if m.group("less") else 0
        ratio = (
            _of_ratio(masked[max(a, m.start() - 12) : m.start()], m.group("of"))
            if m.group("of")
            else _sized(m.group("sized"))
            if m.group("sized")
            else _ratio(masked[max(a, m.start() - 40) : m.start()], way)
        )
        if m.group("sized") and re.search(
            r"\bmore than\s+$", masked[max(a, m.start() - 12) : m.start()], re.IGNORECASE
        ):  # 'more than twice that of B':
            out += [
                check_comparison(
                    x.keys,
                    b_name.keys[0],
                    1,
                    ctx,
                    book,
                    written[m.start() : m.end()].strip(),
                    at_least=ratio * (1 - RATIO_WITHIN),
                )
                for x in subjects
            ]  # at least about 2x
            start = b_name.end
            continue
        factor = _FACTOR_AFTER.match(masked, b_name.end, b)  # 'larger than B (-1.4) by a factor of ~2.6' (of one
        stated = _factor(factor) if factor else 0.0
        if ratio is None and factor is not None and way and len(subjects) == 1 and stated > 0:
            ratio = stated**way  # name; 'smaller than B by a factor of 5': a fifth)
        else:
            factor = None
        if ratio is not None and (not m.group("out") or factor is not None):  # 'roughly 1.7 times as much as B',
            # '35 % more than B', 'A outweighed B by a factor of 1.7'
            out += [
                check_ratio(x.keys, b_name.keys[0], ratio, ctx, book, written[m.start() : m.end()].strip())
                for x in subjects
            ]
        elif (
            m.group("out")
            and len(subjects) > 1
            and all(len(x.keys) == 1 for x in subjects)
            and not re.search(
                r"\b(?:both|each|all|individually)\b", masked[subjects[0].start : m.start()], re.IGNORECASE
            )
        ):
            out.append(
                check_outweighs(
                    [x.keys[0] for x in subjects], [b_name.keys[0]], ctx, book, written[m.start() : m.end()].strip()
                )
            )
        else:
            for x in subjects:
                out.append(
                    check_comparison(x.keys, b_name.keys[0], way, ctx, book, written[m.start() : m.end()].strip())
                )
        start = b_name.end
    return out


#: two numbers in brackets set side by side: '(0.88 versus 0.49)', '(8.5 against 4.4 points)', '(0.188 vs 0.097)'
_SIDE_BY_SIDE = re.compile(r"\s*\(\s*[^()\0]{0,20}?\s+(?:vs\.?|versus|against|compared with|to)\s+[^()\0]{0,20}\)")


_B_NOUN = re.compile(r"\s+(?:effect|term|contribution|push|impact|factor)s?\b", re.IGNORECASE)


def compared_pairs(masked: str, a: int, b: int, names: list[Mention], numbers) -> dict:
    """'A mattered about twice as much as B (0.88 vs 0.49)': the bracket's first number is A's, the second B's
    (A the comparison's subject as :func:`find_comparisons` reads it); with no comparison word it knows, a clause
    that names two features and ends in such a bracket pairs them in order ('A's effect is roughly twice that of B
    (0.188 vs 0.097)'); id(number) -> mention."""
    out = {}
    for m in COMPARE_RE.finditer(masked, a, b):
        b_name = next((x for x in names if x.start >= m.end()), None)
        if b_name is None or not re.fullmatch(r"\s*(?:the\s+|its\s+|their\s+)?", masked[m.end() : b_name.start]):
            continue
        factor = _FACTOR_AFTER.match(masked, b_name.end)  # ('A outweighs B roughly two to one (x vs y)')
        noun = _B_NOUN.match(masked, b_name.end)  # ('twice the size of the B effect (x vs y)')
        bracket = _SIDE_BY_SIDE.match(masked, noun.end() if noun else b_name.end) or (
            factor and _SIDE_BY_SIDE.match(masked, factor.end())
        )
        subjects = [x for x in names if x.end <= m.start()][-1:]
        inside = [n for n in numbers if bracket and b_name.end <= n.start and n.end <= bracket.end()]
        if bracket and subjects and len(inside) == 2:
            out[id(inside[0])], out[id(inside[1])] = subjects[0], b_name
    if not out and len({x.keys for x in names}) == 2 and len(names) == 2:  # 'A's effect is twice that of B (x vs y)'
        bracket = _SIDE_BY_SIDE.match(masked, names[1].end)
        inside = [n for n in numbers if bracket and names[1].end <= n.start and n.end <= bracket.end()]
        if bracket and len(inside) == 2 and not re.search(r"\d", masked[names[0].end : names[1].start]):
            out[id(inside[0])], out[id(inside[1])] = names[0], names[1]
    return out
