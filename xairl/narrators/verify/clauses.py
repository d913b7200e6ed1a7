"""One clause's claims: each number bound (:mod:`.binding`) and checked, then its direction words
(:mod:`.directions`; in a clause that names no feature, by the feature its number is: :func:`_by_number`; a list
item's label that names no feature: :func:`unknown_label`), rank words
(:mod:`.ranks`) and comparisons (:mod:`.comparisons`). The sentence reader in :mod:`xairl.narrators.verify` splits
sentences into clauses and decides each clause's view."""

from __future__ import annotations

import functools
import re
from dataclasses import replace

from xairl.narrators.verify import (
    background,
    binding,
    checks,
    comparisons,
    decision,
    directions,
    invented,
    noclaims,
    quantities,
    ranks,
    reread,
    sums,
)
from xairl.narrators.verify.book import FactBook
from xairl.narrators.verify.checks import Claim
from xairl.narrators.verify.names import Mention, named_features
from xairl.narrators.verify.numbers import find_numbers, matches
from xairl.narrators.verify.vocabulary import split_words, stem

#: the numbers of one clause that are read (the rest: unchecked, 'number.too-many')
MAX_NUMBERS = 40


def check_clause(
    masked: str,
    a: int,
    b: int,
    mentions: list[Mention],
    book: FactBook,
    ctx: str | None,
    unit_of,
    parsed,
    vocab,
    sentence_keys=frozenset(),
    written: str = "",
) -> list[Claim]:
    out: list[Claim] = []
    name_words = vocab.name_words
    if written:  # ('the last 90 days' of support_calls_90d: not days_since_last_upgrade)
        mentions = noclaims.without_window_words(mentions, written, book.features)
    names = named_features(mentions)
    numbers, unread = _numbers(masked, a, b, book, sentence_keys, written)
    out.extend(
        Claim("number", n.text, "unchecked", f"more than {MAX_NUMBERS} numbers in one clause", "number.too-many")
        for n in unread
    )
    tail, paired, summed = _lists(masked, a, b, names, numbers)
    paired |= comparisons.compared_pairs(masked, a, b, names, numbers)  # 'A mattered twice as much as B (0.88 vs 0.49)'
    actions = [m for m in mentions if m.kind == "action"]
    scored = {}
    if not names and len(actions) >= 2 and len(numbers) == len(actions) and numbers[0].start >= actions[-1].end:
        scored = {id(n): m for n, m in zip(numbers, actions)}  # 'turn beat recharge 6.30 to 2.37'
    # 'not the garage but the quality', 'X, rather than Y, is ...': what is said of the sentence is not said of Y
    said = [m for m in mentions if m.kind == "action" or not _NEGATED.search(masked[max(a, m.start - 40) : m.start])]
    said_names = named_features(said)
    for n in numbers:
        if summed and (n is tail[0] or (n.percent and not n.points and len(tail) == 2 and n is tail[1])):
            members = list(dict.fromkeys(m.keys for m in said_names))  # (', about 87 % of it'; not 'of the
            counted = _counted(masked, a, said_names)  # 28.3-point rise')
            if counted and ranks.COUNT[counted.group("k").lower()] != len(members):  # 'the four weather terms
                out.append(
                    Claim(
                        "number",
                        n.text,
                        "unchecked",
                        f"a sum over {counted.group('k')} things, "  # (...)'
                        f"{len(members)} of them named",
                        "number.sum-unnamed",
                    )
                )  # with three named
            else:
                out.append(binding.named(sums.sum_number(n, members, ctx, book), "number.sum"))
            continue
        c = binding.bind_number(n, masked, mentions, names, paired, scored, book, ctx, unit_of)
        if c.status == "contradicted" and id(n) not in paired:  # 'respectively' binds for sure
            c = reread.read_again(c, n, masked, mentions, names, book, ctx, unit_of, parsed, vocab, sentence_keys)
        if (
            c.status == "contradicted"
            and len({m.keys for m in said_names}) == 1
            and id(n) not in paired
            and _SUM_CUE.search(masked, a, n.start)
            and re.search(r"\band\b|\bplus\b", masked[a : n.start])
        ):
            c = Claim(
                "number",
                n.text,
                "unchecked",
                "a sum over things the words name but the vocabulary does not "
                "all know ('the mileage and garage offsets together')",
                "number.sum-unnamed",
            )
        if c.status == "contradicted" and c.rule in binding.GUESSED:
            c = quantities.owned_by_unit_or_place(n, masked, mentions, book, unit_of) or c
        if c.status == "contradicted" and noclaims.identifier_after_word(n, masked, mentions):
            c = Claim(
                "number",
                n.text,
                "unchecked",
                f"an identifier after a word of a longer name ('charger 3'; first read as {c.detail})",
                "number.identifier-after-word",
            )
        if c.status == "contradicted" and quantities.WITHOUT_SIGN in c.detail:
            c = replace(c, rule="number.value-sign")  # ('wind_gust (1.46)' when it is -1.463)
        out.append(c)
    out += _word_claims(masked, a, b, mentions, said, numbers, book, ctx, name_words, parsed, written)
    claimed = [c.text for c in out if c.kind == "feature" and c.status == "contradicted"]
    return out + invented.invented(masked, a, b, mentions, numbers, book, vocab, unit_of, claimed)


def _word_claims(
    masked: str,
    a: int,
    b: int,
    mentions: list[Mention],
    said: list[Mention],
    numbers,
    book: FactBook,
    ctx: str | None,
    name_words,
    parsed,
    written: str,
) -> list[Claim]:
    """The clause's claims in words: direction words (with their names, or by the feature their number is), rank
    words, comparisons and 'barely mattered'; ``said`` the mentions the clause says something of."""
    out: list[Claim] = []
    said_names = named_features(said)
    first = numbers[0] if numbers else None
    bracketed = first is not None and re.search(r"\(\s*$", masked[a : first.start]) and directions.is_fact(first, book)
    if first is not None and first.sign and not any(m.start < first.start for m in mentions) and not bracketed:
        # ('The heat itself (-2.35) hurt ...': a feature in other words, its push beside it; 'roof condition -12.1k'
        # with another feature's number is still an invented name)
        out += [
            binding.named(c, "direction.unknown-name") for c in unknown_label(masked[a : first.start], name_words)
        ]  # '; roof condition -12.1k;'
    out += [
        binding.named(c, "direction.subject")
        for c in directions.directions(masked, a, b, said, book, ctx, name_words, parsed)
    ]
    if not said_names:  # '...; it actually raised the risk by 1.6 points': whose push the number says
        out += [binding.named(c, "direction.by-number") for c in _by_number(masked, a, b, numbers, mentions, book, ctx)]
    out += [binding.named(c, "rank.words") for c in ranks.find_ranks(masked, a, b, said, book, ctx, written)]
    out += [
        binding.named(c, "rank.comparison")
        for c in comparisons.find_comparisons(masked, a, b, said, book, ctx, written)
    ]
    for m in ranks.MINOR_RE.finditer(masked, a, b):
        owner = next((x for x in reversed(said_names) if x.end <= m.start()), None) or next(
            (x for x in said_names if x.start >= m.end()), None
        )
        if owner is not None:
            out.append(binding.named(ranks.check_minor(owner.keys, ctx, book, m.group(0)), "rank.minor"))
    return out


_COST = re.compile(r"^cost", re.IGNORECASE)
_WOULD = re.compile(r"\b(?:would|could|might|should|must|need(?:s|ed)? to|has to|have to)\b", re.IGNORECASE)


def _by_number(
    masked: str, a: int, b: int, numbers, mentions: list[Mention], book: FactBook, ctx: str | None
) -> list[Claim]:
    """Each direction word of a clause that names no feature, followed (before the next one) by an unsigned number
    that is one feature's contribution in size and no decision-level number ('The ban did nothing to help; it
    actually raised the risk by 1.6 points', where only campfire_ban's contribution is 1.6 in size): that feature's
    push, checked. Not in a clause of what would or needs to happen, nor for a cost word (a cost may be what the
    output counts: 'it costs him about 7 minutes' of a finish time)."""
    found = [m for m in checks.DIRECTION_RE.finditer(masked, a, b) if not checks.is_frame(masked, m)]
    if not found or _WOULD.search(masked, a, found[0].start()):  # ('It would need to drop by 2.2 to reach ...')
        return []
    blanked = " " * a + masked[a:]  # a negation before the clause is not its own ('did not hurt; it subtracted 0.16')
    out = []
    for m, nxt in zip(found, [x.start() for x in found[1:]] + [b]):
        if directions.no_push(m, masked, mentions, book) or _COST.match(m.group(0)):
            continue
        after = [n for n in numbers if m.end() <= n.start < nxt]  # the first number after it, unsigned (a sign is
        if not after or after[0].sign:  # its own claim: 'the positives add up to 31.1 and the negatives to -1.0')
            continue
        n, owners = after[0], quantities.contribution_owners(after[0], book)
        if len(owners) != 1 or any(matches(n, v) for v in book.decision_numbers):
            continue
        polarity, where = checks.direction_target(blanked, m, mentions, book, ctx)
        out += checks.check_direction(
            [Mention(n.start, n.end, "feature", (owners[0],))],
            directions.as_said_after(blanked, m, polarity),
            where,
            f"{m.group(0)} (by {n.text}: {owners[0]}'s contribution)",
            book,
        )
    return out


def _lists(masked: str, a: int, b: int, names: list[Mention], numbers) -> tuple[list, dict, bool]:
    """The numbers after the clause's last name (``tail``), paired with the names in order when they list one number
    per name ('A and B ... by x and y, respectively': id(number) -> mention), and whether the first of them is the
    names' sum ('A and B together add x')."""
    # 'A and B ... by x and y, respectively': numbers after the last name pair up with the names in order
    tail = [
        n
        for n in numbers
        if names
        and n.start > names[-1].end  # not the last name's own '(−22.5 dB)'
        and not re.fullmatch(r"\s?\([^()]*", masked[names[-1].end : n.start])
    ]
    paired = {}
    own_cue = any(
        background.statistic(masked[max(0, n.start - 60) : n.start])
        or binding.OUTPUT_BEFORE.search(masked[max(0, n.start - 60) : n.start])
        for n in tail
    )  # '... worth about $316k instead of the usual $230k'
    listed = all(_listed(masked[x.end : y.start]) for x, y in zip(tail, tail[1:]))  # 'x and y', not 'x, which is y'
    respectively = "respectively" in masked[a:b].lower()
    if (
        len({m.keys for m in names}) >= 2
        and len(tail) == len(names)
        and not own_cue
        and not _SUM_CUE.search(masked, names[-1].end, tail[0].start)
        and (respectively or listed)
        and (  # ('A and B together add x, y %
            respectively
            or quantities.CONTRIB_BEFORE.search(masked[a : tail[0].start][-40:])  # of it': a sum)
            or (
                _PAIR_RE.match(masked[tail[0].start - 1 : tail[-1].end + 1])
                and re.search(r"[A-Za-z]{2}", masked[names[-1].end : tail[0].start])
            )  # not 'A (26, SHAP -0.07)'
            or (masked[names[-1].end : tail[0].start].rstrip().endswith(":") and all(n.sign for n in tail))
        )
    ):
        # ('A and B hardly matter: +0.03 and -0.02')
        paired = {id(n): m for n, m in zip(tail, names)}
    # 'A and B together add x': one number after the names (not B's own '(+5.31)', not a list 'x and y'), without a
    # quantity of its own ('most of the $91,462 above the baseline')
    # (with more numbers after: the cue between the names and the first, 'A, B and C together add x, y % of it', and
    # not one number per name, '(+10.97 and +22.02)')
    summed = (
        len(tail) >= 1
        and len(names) >= 2
        and not paired
        and (
            _SUM_CUE.search(masked, a, b)
            if len(tail) == 1
            else _SUM_CUE.search(masked, names[-1].end, tail[0].start)
            and (not listed or len(tail) != len({m.keys for m in names}) or tail[1].percent)
            or (not listed and _SUM_CUE.search(masked, a, names[0].start))
        )
        and not _OWN_QUANTITY.search(masked[max(a, tail[0].start - 12) : tail[0].start])
        and not decision.CHANGE_AFTER.match(masked[tail[0].end : b])
    )
    return tail, paired, bool(summed)


def _listed(gap: str) -> bool:
    """Is ``gap``, the text between two numbers, that of a list ('+1.3 and +0.8', '1.3, 0.8', '(queue +1.10,
    forecast +0.72)' is not: a name between), not a new phrase ('22.4 points, which is roughly 84%')?"""
    words = re.sub(
        r"\b(?:and|or|points?|pts|pp|min|mins|minutes|h|hours?|kw|kwh|mw|days?|dB|dBm)\b", "", gap, flags=re.IGNORECASE
    )
    return len(gap) <= 24 and not re.search(r"[A-Za-z]{2}|\0", words)


def _numbers(masked: str, a: int, b: int, book: FactBook, sentence_keys, written: str) -> tuple[list, list]:
    """(the numbers of clause ``a..b`` that may be claims, the ones left unread): a clause of more numbers than
    prose holds (a table, or hostile text) reads its first ``MAX_NUMBERS`` only, since each number's readings search
    the clause and reading them all would grow with the numbers times the clause's length."""
    found = [n for n in find_numbers(masked[:b]) if n.start >= a]
    found, unread = found[: 2 * MAX_NUMBERS], found[2 * MAX_NUMBERS :]
    worded = _worded(book, written)
    numbers = [
        n
        for n in found
        if not noclaims.skip_number(n, masked)
        and not noclaims.window_of_name(n, sentence_keys, written or masked, worded)
    ]
    if book.in_percent:  # 'p_dropout=0.469' of a prediction of 46.9 %: a fraction may state a percentage
        numbers = [
            replace(n, alternatives=(*n.alternatives, 100 * n.value))
            if not n.percent and abs(n.value) < 1 and "." in n.text
            else n
            for n in numbers
        ]
    return numbers[:MAX_NUMBERS], numbers[MAX_NUMBERS:] + unread


def _worded(book: FactBook, written: str) -> list[str]:
    """The features with a window in their name ('prior_returns_12m') whose other words the sentence uses in some
    form ('returned'): the ones a period in it ('the past twelve months') may be the window of."""
    said = {stem(w) for w in split_words(written)}
    return [f for f in book.features if said & _window_words(f)]


@functools.lru_cache(maxsize=4096)
def _window_words(feature: str) -> frozenset[str]:
    """The stems of the words beside the window in a feature's name ('prior_returns_12m': 'prior', 'return~'); none
    where the name has no window."""
    if not re.search(r"\d+[a-z]", feature.lower()):
        return frozenset()
    return frozenset(stem(w) for w in split_words(feature) if len(w) >= 4 and not any(c.isdigit() for c in w))


#: 'A and B together add x', 'combined', 'sum to', 'between them': the number is their sum
_SUM_CUE = re.compile(
    r"\b(?:together|combined|jointly|in total|taken together|between them|sum(?:s|med)? to|add up to|"
    r"in sum|make up|(?:they|these|those)\s+(?:(?:only|just|all|three|two|four)\s+)?"
    r"(?:add|contribute|account for))\b",
    re.IGNORECASE,
)  # ('A, B and C, and they add just 1.85')
#: how many things a sum is over, in words (:data:`.ranks.COUNT`): 'the three vehicle-and-history factors'
_COUNTED = re.compile(rf"\b(?P<k>{'|'.join(ranks.COUNT)})\s+(?:[\w-]+\s+){{0,3}}?{ranks.NOUN}\b", re.IGNORECASE)


def _counted(masked: str, a: int, names):
    """The count of a sum's things said before its names ('the four weather terms (irradiance, ...)', 'the two things
    working against a return, the loyalty tier and ...'), not a partitive ('of the six factors, A and B ...')."""
    counted = list(_COUNTED.finditer(masked, a, names[0].start if names else a))
    c = counted[-1] if counted else None  # the last count before the names
    if c is None or re.search(
        r"\b(?:of|among|out of|from)\s+(?:the\s+|all\s+|these\s+|those\s+)?$", masked[a : c.start()], re.IGNORECASE
    ):
        return None
    return c


_OWN_QUANTITY = re.compile(r"\bof\s+(?:the\s+)?[$€£]?$", re.IGNORECASE)
_NEGATED = re.compile(
    r"(?:\b(?:rather than|instead of|unlike|not(?! only))|n't)\s+"
    r"(?:(?:because of|due to|about|the|its|their|a|an)\s+){0,3}$",
    re.IGNORECASE,
)
_PAIR_RE = re.compile(r"^\((?:[^()\0]*?(?:,|\band\b|/)\s*)+[^()\0]*\)$")  # '(+9.45 and +8.66)' after 'A and B'


#: a list item's label before its signed number: 'roof condition -12.1k', 'Pool: +6,500'
_LIST_LABEL = re.compile(r"\W*(?P<label>(?:[A-Za-z][A-Za-z'-]*\s+){0,3}[A-Za-z][A-Za-z'-]*)\s*[:=(]?\s*")
#: labels of decision-level quantities, not features
_QUANTITY_LABELS = {
    "net",
    "sum",
    "total",
    "delta",
    "change",
    "diff",
    "difference",
    "base",
    "baseline",
    "risk",
    "price",
    "estimate",
    "probability",
    "prediction",
    "output",
    "score",
    "gap",
    "margin",
    "lead",
    "effect",
    "shap",
    "phi",
    "value",
    "contribution",
    "attribution",
    "result",
    "overall",
    "uplift",
    "premium",
}
_OWNERS = {"its", "their", "your", "his", "her", "our", "my"}


def unknown_label(text: str, name_words=frozenset()) -> list[Claim]:
    """A list item named by a label that is no feature and carries a signed number ('; roof condition -12.1k')."""
    m = _LIST_LABEL.fullmatch(text)
    if m is None or any(w.lower() in _QUANTITY_LABELS | _OWNERS for w in m.group("label").split()):
        return []  # ('Its signal quality of -3.2 dB': something named before, vaguely)
    return directions.unknown_subject(m.group("label"), "a signed number", [], name_words)
