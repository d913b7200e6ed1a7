"""Second readings of a number whose first reading (:mod:`.binding`) bound it by position alone and contradicted it:
a fact of another name the sentence holds ('which is unclear'), what the sentence's parse says it measures, a field
of a log line, a word of one categorical label. Each returns the claim unchanged when the first reading was sure."""

from __future__ import annotations

import re
from dataclasses import replace

from xairl.narrators.verify import decision, quantities
from xairl.narrators.verify.binding import GUESSED
from xairl.narrators.verify.book import FactBook
from xairl.narrators.verify.checks import EITHER, Claim
from xairl.narrators.verify.numbers import find_numbers, matches
from xairl.narrators.verify.parse import quantified, same_clause
from xairl.narrators.verify.vocabulary import split_words, stem


def read_again(
    c: Claim, n, masked: str, mentions, names, book: FactBook, ctx, unit_of, parsed, vocab, sentence_keys
) -> Claim:
    """A contradicted number read again, each reading only while it stays contradicted: a fact of another name the
    sentence holds (:func:`unless_guessed`), what the parse says it measures (:func:`by_parse`), a fact it states
    elsewhere (:func:`unless_elsewhere`), a name in another clause (:func:`unless_other_clause`). ``parsed()``
    gives the sentence's parse, made only when asked for."""
    units = frozenset(u.lower() for u in map(unit_of, book.features) if u)
    found = []

    def measured():  # what the parse says the number measures, read at most once
        if not found:
            found.append(quantified(parsed(), n.start, n.end, units))
        return found[0]

    if n.percent and (share := side_share(c, n, masked, book, ctx, sentence_keys)) is not None:
        return share
    c = unless_guessed(c, n, masked, mentions, names, book, ctx, sentence_keys)
    if c.status == "contradicted":
        c = by_parse(c, n, masked, book, ctx, unit_of, measured, vocab)
    if c.status == "contradicted":
        c = unless_elsewhere(c, n, masked, mentions, book, ctx, measured, sentence_keys)
    if c.status == "contradicted":
        c = unless_other_clause(c, n, masked, names, parsed)
    return c


#: a percentage of one side's sum: '46% of all upward contributions', '40% of the downward total'
_SIDE_SHARE = re.compile(
    r"\s*of\s+(?:all\s+)?(?:the\s+)?(?:total\s+)?"
    r"(?P<side>upward|positive|upside|downward|negative|downside)\b",
    re.IGNORECASE,
)


def side_share(c: Claim, n, masked: str, book: FactBook, ctx, keys) -> Claim | None:
    """'Lead time (+14.2) is roughly 1.5 times the deposit effect (-9.6) and about 46% of all upward contributions':
    a percentage of one side is the share of its side of a feature the sentence names on that side: verified when
    one has it; contradicted when the sentence names one feature of that side only (it is that one's); else
    unchecked. None when the words name no side."""
    m = _SIDE_SHARE.match(masked, n.end)
    if m is None:
        return None
    up = m.group("side").lower() in ("upward", "positive", "upside")
    views = book.contexts if ctx in (None, EITHER) else (ctx,)
    sided = [
        (k, v)
        for k in sorted(keys)
        if k in book.features
        for v in views
        if v in book.features[k].side_shares and (book.features[k].contribs.get(v, 0.0) > 0) == up
    ]
    for k, v in sided:
        if matches(n, book.features[k].side_shares[v]):
            return Claim("number", n.text, "verified", f"{k}: share of its side ({v})", "number.side-share")
    if len({k for k, _ in sided}) == 1:
        k, v = sided[0]
        return Claim(
            "number",
            n.text,
            "contradicted",
            f"{k}'s share of the {m.group('side')} side is {book.features[k].side_shares[v]:.3g} % ({v})",
            "number.side-share",
        )
    return Claim(
        "number",
        n.text,
        "unchecked",
        f"a share of the {m.group('side')} side, of no feature the sentence names there (first read as {c.detail})",
        "number.side-share",
    )


#: a number right after its name ('A +0.3', 'A (0.3)', 'A: 0.3', 'A=0.3', "the serving BS's id at -12"): bound for sure
_RIGHT_AFTER = re.compile(r"\s?[:=(]?\s?|\s?[:=]\s*| at ")


def unless_other_clause(c: Claim, n, masked: str, names, parsed) -> Claim:
    """A number bound by position to the name nearest before or after it, contradicted, that the parse puts in
    another clause than that name ('A higher deductible means the insurer pays less per claim, so the model lowers
    the cost by $200': not the claims'): the name was only near, so the claim is unchecked. A number right after its
    name ('A +0.3', 'A (0.3)', 'A: 0.3') and a push by its cue words in a clause naming one feature are bound for
    sure."""
    if c.rule not in GUESSED[:2]:
        return c
    owner = (
        next((m for m in reversed(names) if m.end <= n.start), None)
        if c.rule == GUESSED[1]
        else next((m for m in names if m.start >= n.end), None)
    )
    if owner is None or (c.rule == GUESSED[1] and _RIGHT_AFTER.fullmatch(masked, owner.end, n.start)):
        return c
    if _one_name_pushes(n, masked, names) or same_clause(parsed(), n.start, n.end, owner.start, owner.end):
        return c
    return Claim(
        "number",
        n.text,
        "unchecked",
        f"the parse puts it in another clause than {'/'.join(owner.keys)} (first read as {c.detail})",
        "parse.other-clause",
    )


def _one_name_pushes(n, masked: str, mentions) -> bool:
    """'...; B (-86.1 dBm) pushed against stay by -32.0': a number its cue words call a push, in a clause that names
    one feature before it, is that feature's push for sure."""
    names = {m.keys for m in mentions if m.kind == "feature"}
    return (
        len(names) == 1
        and any(m.kind == "feature" and m.end <= n.start for m in mentions)
        and bool(quantities.CONTRIB_BEFORE.search(masked[max(0, n.start - 40) : n.start]))
    )


def unless_guessed(c: Claim, n, masked: str, mentions, names, book: FactBook, ctx, sentence_keys) -> Claim:
    """A contradicted number that states another fact of a feature named in the sentence exactly (not truncated): the
    binding was a guess, so it is unchecked ('which is unclear'). A difference in a unit ('4.0 dB above'), a number
    right after its name ('battery +1.70') and a name 'at' a number bind for sure; a bracket right after a name
    ('distance (2.33)') may only be that name's own fact, with its sign."""
    if quantities.DIFFERENCE_AFTER.match(masked[n.end : n.end + 16]):
        return c
    owner = next((m for m in reversed(mentions) if m.end <= n.start), None)
    if owner in names and re.fullmatch(r" ?", masked[owner.end : n.start]) and n.sign:
        return c  # 'battery +1.70': a signed number right after its name, a sure binding
    if owner in names and masked[owner.end : n.start] == " at ":
        return c  # "the serving BS's id at -12": its value, as sure
    if _one_name_pushes(n, masked, names):
        return c
    if owner in names and re.fullmatch(r"\s?\(", masked[owner.end : n.start]):
        other = quantities.other_reading(n, set(owner.keys), book, ctx, signed=True)
    else:
        other = quantities.other_reading(
            n, sentence_keys, book, ctx, signed=quantities.signed_named(masked[max(0, n.start - 40) : n.start])
        )
    return (
        c
        if other is None
        else Claim(
            "number",
            n.text,
            "unchecked",
            f"read as {c.detail}, but it is {other}: which is unclear",
            "number.unclear",
            _crosses(c, other, book, n, masked, mentions),
        )
    )


def _crosses(c: Claim, other: str, book: FactBook, n, masked: str, mentions) -> tuple[str, str]:
    """(the feature a number's first reading bound it to, the feature whose fact it states instead), for a text where
    two numbers cross this way (:func:`swapped`); () when either is not one feature, or when the stated feature is
    named before the bound one with no number of its own between them: it may be the subject the number is said of
    ('Traffic outweighs wind with 7.2'), not a swapped item of a list ('contract +0.214, tenure +0.127')."""
    bound = next((k for k in book.features if f" is not {k}'s " in c.detail), None)
    stated = next((k for k in book.features if other.startswith(f"{k}'s ")), None)
    if bound is None or stated is None or bound == stated:
        return ()
    near = next((m for m in reversed(mentions) if bound in m.keys and m.end <= n.start), None)
    said = [m for m in mentions if stated in m.keys and near is not None and m.end <= near.start]
    if said and not any(said[-1].end <= x.start < near.start for x in find_numbers(masked[: near.start])):
        return ()
    return bound, stated


def swapped(claims: list[Claim]) -> list[Claim]:
    """'contract +0.214, tenure +0.127' when the contract's contribution is 0.127 and the tenure's 0.214: a number
    bound to A that states B's fact, left unchecked as unclear, and another bound to B that states A's. Each name
    holds the other's number, anywhere in the text (two lines of a table): the two are swapped, not misread, so
    both are contradicted."""
    pairs = {c.crosses: c for c in claims if c.crosses}
    out = []
    for c in claims:
        twin = pairs.get(c.crosses[::-1]) if c.crosses else None
        if twin is not None and twin.text != c.text:
            a, b = c.crosses
            first = re.sub(r"^read (?:by position )?as ", "", c.detail.split(", but it ")[0])
            c = replace(
                c,
                status="contradicted",
                rule="number.crossed",
                detail=f"{first}; it states {b}'s fact, and "
                f"{twin.text} (bound to {b}) states {a}'s: the two are swapped",
            )
        out.append(c)
    return out


#: nouns a number may measure that are facts of an explanation (a score, the margin, a contribution, the output):
#: a number measuring one of these keeps its reading; any other noun ('30 days', '41 GB', 'the 47.5-point gap')
#: is something the explanation does not hold
FACT_NOUNS = frozenset(
    {
        "score",
        "scores",
        "margin",
        "lead",
        "edge",
        "contribution",
        "contributions",
        "effect",
        "effects",
        "impact",
        "impacts",
        "attribution",
        "attributions",
        "value",
        "values",
        "shap",
        "prediction",
        "predictions",
        "probability",
        "chance",
        "risk",
        "estimate",
        "output",
        "baseline",
        "base",
        "average",
        "mean",
        "expectation",
        "price",
        "push",
        "boost",
        "penalty",
        "bonus",
        "drop",
        "rise",
        "increase",
        "decrease",
        "change",
        "gap",
        "difference",
        "weight",
        "share",
        "sum",
        "total",
        "q",
        "q-value",
        "importance",
        "influence",
        "gain",
        "loss",
        "uplift",
        "bump",
        "nudge",
        "hit",
        "swing",
        "cost",
        "lift",
        "pull",
        "drag",
        "net",
        "reason",
        "reasons",
        "driver",
        "drivers",
        "factor",
        "factors",
        "feature",
        "features",
        "variable",
        "variables",
        "signal",
        "mass",
        "magnitude",
        "deviation",
        "delta",
        "jump",
        "fall",
        "spread",
        "bar",
        "rank",
    }
)


#: fact nouns that only name a decision-level quantity, never one feature's ('distance (score 1.15)' is no whole)
AGGREGATE_NOUNS = frozenset(
    {
        "total",
        "sum",
        "net",
        "gap",
        "difference",
        "change",
        "mass",
        "prediction",
        "predictions",
        "baseline",
        "margin",
        "lead",
        "output",
        "delta",
    }
)


#: an identifier that is no name, then '=' or ':', right before a number ('run_id=7781', 'latency_ms: 42')
_LOG_KEY = re.compile(r"(?<![\w\0])([A-Za-z][A-Za-z0-9]*(?:_[A-Za-z0-9]+)+)\s?[:=]\s?$")


#: an identifier that is no name right before a number, with or without its own value ('wait_max -2.31',
#: 'blh_m=310|+4.6', 'humidity_pct=+3.1'): the number is given to it (:func:`._identifier` judges the identifier)
_GIVEN_TO = re.compile(
    r"(?<![\w\0])([A-Za-z][A-Za-z0-9]*(?:_[A-Za-z0-9]+)+)(?:\s?[:=]\s?[^\s|()\0]{1,16})?"
    r"(?:\s?[:=|(]\s?|\s)$"
)


def _one_word_of_many(m) -> bool:
    """A mention that is one short word while every name it may mean has four words or more ('bill' of
    price_increase_last_bill_pct): a word the text shares with the name, not the name."""
    return m.kind == "feature" and m.end - m.start <= 9 and all(len(split_words(k)) >= 4 for k in m.keys)


def unless_elsewhere(c: Claim, n, masked: str, mentions, book: FactBook, ctx, measured, keys) -> Claim:
    """A number bound by position alone (:data:`GUESSED`), contradicted, that states another fact of the explanation:
    the position was a guess, so it is unchecked. The binding is sure, and the number stays contradicted, when it
    comes right after its name ('A +0.3', 'A (0.3)', 'A: 0.3', 'A=0.3') or the parse ties it to a name ('A lowered
    it by about 5 points': the verb's subject); so does a number that states no fact at all."""
    if c.rule not in GUESSED[:2] or quantities.DIFFERENCE_AFTER.match(masked[n.end : n.end + 16]):
        return c  # ('4.0 dB above': a difference in a unit, bound for sure; a number tied to no name is contradicted
        # only by the quantity its words name: '(4.45 vs 4.44)' after 'rather than recharge')
    owner = next((m for m in reversed(mentions) if m.end <= n.start), None)
    if (
        owner is not None
        and c.rule == GUESSED[1]
        and _one_word_of_many(owner)
        and (other := quantities.any_fact(n, book, set(book.features) - set(owner.keys), ctx, strict=True))
    ):
        return Claim(
            "number",
            n.text,
            "unchecked",
            f"read by position as {c.detail}, but it states {other}, and the name before it is one word of a long name",
            "number.other-feature",
            _crosses(c, other, book, n, masked, mentions),
        )  # ('bill $109.9' of
        # price_increase_last_bill_pct, when $109.9 is the monthly charge)
    if owner is not None and _RIGHT_AFTER.fullmatch(masked, owner.end, n.start):
        return c  # ('the serving BS's id at -12': its value)
    key = _LOG_KEY.search(masked, max(0, n.start - 40), n.start)
    if key is not None and not n.sign:  # 'run_id=7781' after a name: the value of a field of the log, not the name's
        return Claim(
            "number", n.text, "unchecked", f"the value of the log's field {key.group(1)!r}", "number.log-field"
        )
    key = key or _GIVEN_TO.search(masked, max(0, n.start - 40), n.start)
    if key is not None:  # 'wait_max -2.31', 'blh_m=310|+4.6': the identifier's, which its own claim judges
        return Claim(
            "number",
            n.text,
            "unchecked",
            f"given to {key.group(1)!r}, an identifier that names nothing (first read as {c.detail})",
            "number.of-identifier",
        )
    q = measured()
    if q.key or (not q.subject and _one_name_pushes(n, masked, mentions)):
        return c
    if n.text.isalpha():  # 'one and a half times', 'a factor of two', 'semester one': a count or an idiom
        return Claim(
            "number",
            n.text,
            "unchecked",
            f"a number word that the words tie to no name (first read as {c.detail})",
            "number.word",
        )
    # a push by its cue words ('by -0.22') or by the noun it measures ('a bump of 19.1'): not a decision-level number
    pushes = bool(quantities.CONTRIB_BEFORE.search(masked[max(0, n.start - 40) : n.start])) or (
        q.noun in FACT_NOUNS and q.noun not in AGGREGATE_NOUNS and not q.subject
    )
    signed = quantities.signed_named(masked[max(0, n.start - 40) : n.start])
    if q.subject and q.noun not in FACT_NOUNS:  # said of 'claim', a noun the vocabulary lacks: any feature it may
        # name in words of its own
        other = quantities.any_fact(n, book, book.features, ctx, strict=True, contribution=pushes, signed=signed)
        if other is not None:
            return Claim(
                "number",
                n.text,
                "unchecked",
                f"said of '{q.noun}', which names no feature; it states {other}",
                "parse.said-of-other",
                _crosses(c, other, book, n, masked, mentions),
            )
    other = quantities.any_fact(n, book, keys, ctx, strict=True, contribution=pushes, signed=signed)
    if other is not None:
        return Claim(
            "number",
            n.text,
            "unchecked",
            f"read by position as {c.detail}, but it states {other}",
            "number.elsewhere",
            _crosses(c, other, book, n, masked, mentions),
        )
    if q.noun in FACT_NOUNS:
        return c  # 'A is responsible for an increase of 1.2': A's increase, whatever else 1.2 may be
    # 'bill $109.9', 'its Q3 grade of 54 (+0.096)': a thing the vocabulary has no words for, or a wrong word match
    other = quantities.any_fact(n, book, book.features, ctx, strict=True, contribution=pushes, signed=signed)
    return (
        c
        if other is None
        else Claim(
            "number",
            n.text,
            "unchecked",
            f"read by position as {c.detail}, but it "
            f"states {other}, a feature the sentence may name in words of its own",
            "number.other-feature",
            _crosses(c, other, book, n, masked, mentions),
        )
    )


def by_parse(c: Claim, n, masked: str, book: FactBook, ctx, unit_of, measured, vocab) -> Claim:
    """A second reading of a number bound by position alone (:data:`GUESSED`) and contradicted, from the sentence's
    parse (:func:`.parse.quantified`): a number that measures another name (or a noun of one feature's name only)
    is checked against that name; one inside a categorical label ('a two-year contract') against the label; one that
    measures a noun the explanation holds no fact of ('30 days', '41 GB') is unchecked; one that measures a whole
    ('the total effect (1.41)') is checked as a decision-level number; otherwise the first reading stands.
    ``measured()`` gives what the parse says the number measures."""
    if c.rule not in GUESSED:
        return c  # bound by its cue words or a list: sure
    q = measured()
    if q.subject:
        return c  # said of a subject that names nothing: :func:`unless_elsewhere` decides
    if decision.SCORE_BEFORE.search(masked[max(0, n.start - 24) : n.start]):
        return c  # 'the only available action (score -74.6)': a score by its own word
    if "|" in q.key:
        return c  # an ambiguous name: the first reading stands
    if q.key in book.features:
        other = quantities.feature_number(n, (q.key,), masked, book, ctx, unit_of)
        return replace(other, rule="parse.measures-name") if other.status != "contradicted" else c
    if q.noun and (labelled := _label_number(n, q.noun, book)) is not None:
        return labelled  # 'a two-year contract' when the contract is 'One year'
    owners = [
        f
        for f, words in vocab.words.items()
        if f in book.features and q.noun and q.noun not in FACT_NOUNS and stem(q.noun) in {stem(w) for w in words}
    ]
    if len(owners) == 1:  # 'twelve years without a claim': the one feature with years in its name (ncd_years)
        other = quantities.feature_number(n, (owners[0],), masked, book, ctx, unit_of)
        if other.status == "verified":
            return replace(other, rule="parse.measures-name")
    known = vocab.name_words
    if q.noun and q.noun not in FACT_NOUNS and q.noun not in known and stem(q.noun) not in known:
        return Claim(
            "number",
            n.text,
            "unchecked",
            f"it counts '{q.noun}', which the explanation holds no fact of (first read as {c.detail})",
            "parse.counts-other",
        )
    if q.noun in AGGREGATE_NOUNS or q.aggregate:  # 'the total effect (1.41)', 'the net drop of 1.21 points'
        other = decision.free_number(n, masked, book)
        return replace(other, rule="parse.measures-whole") if other.status == "verified" else c
    return c  # 'a bump of 19.1' after a name: that name's push, as first read


def _label_number(n, noun: str, book: FactBook) -> Claim | None:
    """A number counting a word of one categorical value's label ('two-year' of the label 'One year', '24 months')
    states that label: verified when the label holds the number, else contradicted; None when no single label has
    the word and a number."""
    held = [
        (f, ff.label)
        for f, ff in book.features.items()
        if ff.label and stem(noun) in {stem(w) for w in split_words(ff.label)} and find_numbers(ff.label)
    ]
    if len(held) != 1:
        return None
    f, label = held[0]
    ok = any(x.value == abs(n.value) for x in find_numbers(label))
    return Claim("category", n.text, "verified" if ok else "contradicted", f"{f} is '{label}'", "parse.label-number")
