"""Rank and magnitude claims: 'the most important feature', 'second', 'the top three', 'mostly because of',
'followed by', 'barely matters'; the phrases that state them and their checks (comparisons between features:
:mod:`.comparisons`)."""

from __future__ import annotations

import re

import numpy as np

from xairl.narrators.verify.book import FactBook
from xairl.narrators.verify.checks import DIRECTION_RE, Claim, over_keys, resolve_action
from xairl.narrators.verify.comparisons import check_comparison, check_outweighs, views
from xairl.narrators.verify.names import Mention, named_features

ORD = {"first": 1, "1st": 1, "second": 2, "2nd": 2, "third": 3, "3rd": 3, "fourth": 4, "4th": 4, "fifth": 5}
COUNT = {"two": 2, "three": 3, "four": 4, "five": 5, "2": 2, "3": 3, "4": 4, "5": 5}
NOUN = (
    r"(?:features?|factors?|drivers?|reasons?|contributors?|contributions?|influences?|inputs?|effects?|things?|"
    r"terms?|positives?|negatives?|boosts?|push(?:es)?|arguments?|concerns?|variables?|predictors?|"
    r"attributions?|story)"
)
TOPWORD = (
    r"(?:most important|most influential|most significant|most decisive|biggest|largest|strongest|main|top|"
    r"primary|key|dominant|leading|greatest|decisive|deciding|single biggest|single largest|one big|big)"
)
RANK_RE = re.compile(
    rf"\b(?:(?P<ord>second|third|fourth|fifth|2nd|3rd|4th)(?:[\s-]most[\s-]important|[\s-]most[\s-]influential|"
    rf"[\s-]biggest|[\s-]largest|[\s-]strongest)?\s+(?:single\s+)?{NOUN}"
    rf"|(?P<because>(?:mostly|mainly|chiefly|largely|primarily) (?:because of|due to|thanks to|on|driven by))"
    rf"|(?:the\s+)?(?P<plural>(?:two|three|four|2|3|4)\s+(?:most important|largest|biggest|strongest|main)|"
    rf"(?:top|the)[\s-]+(?P<k>two|three|four|2|3|4)(?:\s+most important|\s+largest|\s+biggest)?)\s+{NOUN}"
    rf"|(?<!next-)(?<!next )(?P<top>{TOPWORD})(?:\s+single)?\s+(?:(?:risk|margin|score|shap)\s+)?(?P<noun>{NOUN})"
    rf"|(?:mattered|matters|matter|counted|counts|weighed) most|dominat\w+(?!\s+(?:the\s+)?(?:game|match|play|"
    rf"possession|opponents?|proceedings|the\s+ball))|ranks? (?P<rk>first|second|third)"
    rf"|(?:is|was|(?P<plverb>being|were|are)) the (?:single )?(?:largest|biggest|strongest|greatest|most important|"
    rf"most influential|most significant)(?![ \w]*\w)"
    rf"|top[\s-](?P<topk>\d)\b)",
    re.IGNORECASE,
)
AFTER_ORD = re.compile(
    r"^\W{0,3}(?:[a-z]+\s+)?(?:was\s+|is\s+|came\s+|a\s+(?:distant|close)\s+)?"
    r"(?P<o>second|third|fourth|first(?=\s*[(,;:]|\s+(?:then|and|followed)\b|\s*$))\b",
    re.IGNORECASE,
)
FOLLOWED = re.compile(
    r"\b(?:followed(?: closely)? by|then|next(?: came| was)?|after that|ahead of|second only to)\s*$", re.IGNORECASE
)
MINOR_RE = re.compile(
    r"\b(?:barely|hardly|scarcely)\s+(?:\w+\s+)?(?:matter\w*|mov\w*|regist\w*|chang\w*|affect\w*|"
    r"counts?|counted)|\b(?:no real|almost no|essentially no|next to no|practically no|virtually no|"
    r"little|negligible|minimal|no)\s+(?:\w+\s+)?(?:effect|influence|impact|role|difference)\b|"
    r"\bnegligible\b",
    re.IGNORECASE,
)
MINOR_SHARE = 10.0  # % of the sum of |contributions| below which 'barely matters' holds


def rank_claim(m: re.Match, masked: str) -> tuple[int, bool, int]:
    """(rank or top-k, plural, sign restriction) a rank phrase states."""
    text = m.group(0).lower()
    sign = (
        1
        if re.search(r"positive|boost|plus|argument for|push", text)
        else -1
        if re.search(r"negative|drag|minus", text)
        else 0
    )
    if m.group("ord"):
        return ORD[m.group("ord").lower()], False, sign
    if m.group("because"):
        return 1, False, 0
    if m.group("rk"):
        return ORD[m.group("rk").lower()], False, sign
    if m.group("topk"):
        return int(m.group("topk")), True, sign
    if m.group("plverb"):  # 'A and B were the most important', '... with A and B being the most significant': as
        return 0, True, sign  # many as the list names (one: the first)
    if m.group("plural") or m.group("k"):
        k = next((v for w, v in COUNT.items() if re.search(rf"\b{w}\b", text)), 0)
        return k, True, sign
    if m.group("noun") and m.group("noun").lower().endswith("s") and m.group("noun").lower() != "story":
        return 0, True, sign
    return 1, False, sign


#: a rank among the contributions of the feature's own sign, whichever it is ('the strongest factor pulling the other
#: way')
OWN_SIDE = 2
#: 'the biggest factor working against default': a participle between the rank and its direction word
_PARTICIPLE = re.compile(
    r"\s(?:working|pulling|pushing|acting|weighing|counting|going|tilting|leaning)\s+", re.IGNORECASE
)
#: a participle with its object before the direction word: 'holding the number down', 'keeping the risk up'
_HOLDING = re.compile(
    r"\s(?:holding|keeping|pulling|pushing|dragging|bringing|driving|taking)\s+(?:the|its|this|that|it)"
    r"(?:\s+[\w\0]+)?\s+(?P<way>down|up|low|high)\b",
    re.IGNORECASE,
)
_OTHER_WAY = re.compile(r"\s(?:\w+ing\s+)?(?:in\s+)?the\s+(?:other|opposite)\s+(?:way|direction)\b", re.IGNORECASE)


def check_rank(
    keys: tuple[str, ...], rank: int, plural_k: int | None, sign: int, ctx: str | None, book: FactBook, text: str
) -> Claim:
    """Does a feature hold rank ``rank`` (or, ``plural_k``, one of the top k) by |contribution|? ``sign`` +1 / -1:
    among the contributions of that sign; :data:`OWN_SIDE`: among those of its own sign."""
    contexts = views(ctx, book)

    def test(key):
        e = book.features[key]
        for c in contexts:
            if c not in e.ranks or (sign and sign != OWN_SIDE and np.sign(e.contribs[c]) != sign):
                continue
            actual = e.signed_ranks[c] if sign else e.ranks[c]
            if actual is None:  # an identifier: context, not a reason
                continue
            if (plural_k is not None and actual <= plural_k) or (plural_k is None and actual == rank):
                return True, f"{key} ranks {actual} ({c})"
        shown = ", ".join(f"{e.ranks[c]} ({c})" for c in contexts if c in e.ranks)
        return False, f"{key} ranks {shown}"

    return over_keys(keys, test, "rank", text, "rank")


def check_minor(keys: tuple[str, ...], ctx: str | None, book: FactBook, text: str) -> Claim:
    contexts = views(ctx, book)

    def test(key):
        shares = [book.features[key].shares[c] for c in contexts if c in book.features[key].shares]
        if not shares:
            return None
        return min(shares) < MINOR_SHARE, f"{key} has {min(shares):.1f} % of the total |contribution|"

    return over_keys(keys, test, "magnitude", text, "magnitude")


#: 'Two inputs dominate', 'both features dominate': a plural rank of that many
_COUNTED = re.compile(r"\b(two|three|four|both)\s+(?:[\w-]+\s+)?$", re.IGNORECASE)
#: a rank in what would (not) be: 'enough to make X a dominant predictor', 'would make X the main reason'
_WOULD_MAKE = re.compile(r"\b(?:enough to|would|could|might|to)\s+(?:make|render|become)\b[^.;]{0,30}$", re.IGNORECASE)
#: a rank said of several features at once
_COLLECTIVE = re.compile(
    r"\b(?:combination of|together|combined|collectively|jointly|taken together|"
    r"(?:contributions|effects|influences|impacts) (?:from|of))\b",
    re.IGNORECASE,
)


def check_collective(members: list[tuple[str, ...]], ctx: str | None, book: FactBook, text: str) -> Claim:
    """'The combination of A, B and C dominated': their |contributions| together against all the others'."""
    if any(len(k) != 1 for k in members):
        return Claim("rank", text, "unchecked", "ambiguous: a member may mean several features")
    named = sorted({k[0] for k in members})
    return check_outweighs(named, [f for f in book.features if f not in named], ctx, book, text)


#: 'Among the positives, X is the largest', 'Of the factors lowering the risk, X matters most': the rank's scope
_SCOPE = re.compile(r"^\W*(?:among|of)\s+(?:all\s+)?the\s+([^,]{3,60}),", re.IGNORECASE)


#: a one-output side a rank is scoped to: what its factors led to ('... that led to the model's prediction of a low
#: probability': the lowering ones)
_TOWARD_SIDE = re.compile(
    r"\s+(?:that\s+|which\s+)?(?:(?:led|leading|lead|contribut\w+|point\w*)\s+)?to\s+"
    r"(?:the\s+|a\s+|an\s+|its\s+|their\s+)?(?:model's\s+)?(?:(?:prediction|predicted\s+outcome|"
    r"outcome)\s+of\s+(?:a\s+|an\s+)?)?(?:(?P<low>low|lower|not|no)|high|higher)\b",
    re.IGNORECASE,
)
#: what may open a clause before its subject list: discourse words, a subordinator
_LEAD_IN = re.compile(
    r"^.*\b(?:that|which|while|whereas|when|because|since|if)\s+|^\W*(?:overall|in summary|in short|"
    r"in the end|ultimately|together|finally|also|then|thus|so|however|but|and)\b\W*",
    re.IGNORECASE,
)


def _items(masked: str, a: int, targets: list[Mention], m: re.Match) -> int:
    """How many things a plural rank's list names, those the verifier does not know included ('low absences, no
    failures, and a balanced social life were the key drivers': 3; 'a low level of socializing and no failures were
    the most important factors': 2, from the clause's start)."""
    if not targets:
        return 0
    first, last = targets[0], targets[-1]
    if first.start < m.start():
        head = masked[a : first.start]
        lead = _LEAD_IN.match(head)
        start = first.start if re.search(r"[,;:]", head) else a + (len(lead.group(0)) if lead else 0)
        span = masked[start : m.start()]
    else:
        span = masked[m.end() : last.end]
    span = re.split(r"\s(?:were|are|was|is|had|have|made|make)\b", span)[0]
    return len([x for x in re.split(r",\s*(?:and\s+|or\s+)?|\s+(?:and|or)\s+", span) if x.strip()])


#: 'After A (and B), the biggest / next most important factor is C': C ranks one below the names after 'after'
_AFTER_TOP = re.compile(
    rf"\W*(?:after|behind)\s+(?P<lead>[^,;]{{1,80}}),\s+(?P<top>(?:the\s+)?(?:next[\s-]+)?"
    rf"(?:single\s+)?(?:biggest|largest|strongest|most important|most influential|main|key)\s+"
    rf"(?:single\s+)?{NOUN})",
    re.IGNORECASE,
)


def find_ranks(
    masked: str, a: int, b: int, mentions: list[Mention], book: FactBook, ctx: str | None, written: str = ""
) -> list[Claim]:
    """The rank phrases of clause ``masked[a:b]``, each bound to its names ('A was the main reason', 'the top three
    were A, B and C', 'followed by B', 'A second') and checked; ``written``: the sentence as written (the claims'
    names as written)."""
    written = written or masked
    out = []
    names = named_features(mentions)
    after = _AFTER_TOP.match(masked, a, b)
    if after:  # 'After A, the biggest single factor is B': B ranks second
        lead = {x.keys for x in names if x.end <= after.end("lead")}
        target = next((x for x in names if x.start >= after.end()), None)
        if lead and target is not None:
            said = f"{written[after.start('top') : after.end()].strip()}: {written[target.start : target.end]}"
            out.append(check_rank(target.keys, len(lead) + 1, None, 0, ctx, book, said))
            a = after.end()
    for m in RANK_RE.finditer(masked, a, b):
        if _WOULD_MAKE.search(masked, max(a, m.start() - 50), m.start()) or re.search(
            r"\b(?:another|one|a|an|other)\s+$", masked[max(a, m.start() - 10) : m.start()], re.IGNORECASE
        ):
            continue  # 'not severe enough to make age a dominant predictor', 'another key factor': no rank said
        rank, plural, sign = rank_claim(m, masked)
        count = _COUNTED.search(masked, max(a, m.start() - 30), m.start())
        if count and m.group(0).lower().startswith("dominat"):  # 'Two inputs dominate ...: A ..., B ...'
            rank, plural = COUNT.get(count.group(1).lower(), 2), True
        elif (
            m.group(0).lower().startswith("dominat")
            and len({x.keys for x in names if x.end <= m.start()}) >= 2
            and not _COLLECTIVE.search(masked, a, m.start())
        ):
            rank, plural = 0, True  # 'A -0.152 and B -0.094 dominate': the top two
        sign = sign or _rank_sign(m, masked, a, b, mentions, book)
        if plural:  # 'A and B had the largest effects' (before) or 'The top three were A, B and C' (after)
            before = [x for x in names if x.end <= m.start()]
            after = [x for x in names if x.start >= m.end()]
            header = after and re.match(r"^\W*(?:were|are|was|is|include\w*)?\W*$", masked[m.end() : after[0].start])
            targets = after if header or not before else before
            k = rank or max(len(targets), _items(masked, a, targets, m))  # 'A, B and a balanced life were the key ...'

            for t in targets:
                out.append(check_rank(t.keys, k, k, sign, ctx, book, f"{m.group(0)}: {written[t.start : t.end]}"))
            continue
        before = [x for x in names if x.end <= m.start()]
        if len(before) >= 2 and _COLLECTIVE.search(masked, a, m.start()):  # 'the combination of A, B and C dominated'
            out.append(check_collective([x.keys for x in before], ctx, book, m.group(0)))
            continue
        target = before[-1] if before else next((x for x in names if x.start >= m.end()), None)
        if target is None:
            continue
        out.append(check_rank(target.keys, rank, None, sign, ctx, book, m.group(0)))
        out += _followed(masked, a, m.end(), names, rank, sign, ctx, book, written)  # 'followed by B', 'B second'
    for x in names:
        o = AFTER_ORD.match(masked[x.end : b])
        if o and not RANK_RE.match(masked[x.end : b].lstrip(" ,(")):
            rank = ORD[o.group("o").lower()]
            out.append(check_rank(x.keys, rank, None, 0, ctx, book, f"{written[x.start : x.end]} {o.group('o')}"))
            if rank == 1:  # 'A first (+11.0), then B'
                out += _followed(masked, a, x.end + 1, names, rank, 0, ctx, book, written)
    out += _chain(masked, a, b, names, book, ctx)
    out += _in_order(masked, a, b, names, book, ctx)
    return out


def _followed(
    masked: str,
    a: int,
    start: int,
    names: list[Mention],
    rank: int,
    sign: int,
    ctx: str | None,
    book: FactBook,
    written: str,
) -> list[Claim]:
    """'..., followed by B, then C' after a rank: the names after ``start`` with such a word before them, next in
    rank."""
    out = []
    for x in names:
        if x.start >= start and FOLLOWED.search(masked[max(a, x.start - 24) : x.start]):
            rank += 1
            out.append(check_rank(x.keys, rank, None, sign, ctx, book, f"then {written[x.start : x.end]}"))
    return out


def _rank_sign(m: re.Match, masked: str, a: int, b: int, mentions: list[Mention], book: FactBook) -> int:
    """The sign a rank phrase ranks among, from the words around it: a direction right after it ('key factors
    decreasing the risk', 'the biggest factor working against default'), a scope ('Among the positives, ...'), 'the
    strongest reason' (for what was decided), 'pulling the other way' (its own sign), 'the main argument for staying';
    0 when they say none."""
    gap = _PARTICIPLE.match(masked, m.end(), b)
    said = (
        DIRECTION_RE.match(masked, gap.end() if gap else m.end() + 1, b)
        if masked[m.end() : m.end() + 1] == " "
        else None
    )
    held = _HOLDING.match(masked, m.end(), b)
    if said is None and held:  # 'the main thing holding the number down'
        return 1 if held.group("way").lower() in ("up", "high") else -1
    if said and (said.group(0).lower() not in ("for", "against", "toward", "towards") or book.output != "actions"):
        return 1 if said.group("pos") else -1  # (one output: 'the biggest factor working against it')
    side = re.match(r"\s+(?:(for|in favou?r of|toward)|against)\b", masked[m.end() : b])
    scope = _SCOPE.match(masked[a : m.start()])
    if scope:  # 'Among the positives, ...', 'Of the factors lowering the risk, ...'
        said = DIRECTION_RE.search(scope.group(1))
        sign = (
            1
            if re.search(r"positive|reasons? (?:to|for)", scope.group(1), re.IGNORECASE)
            else -1
            if re.search(r"negative", scope.group(1), re.IGNORECASE)
            else (1 if said.group("pos") else -1)
            if said
            else 0
        )
        if sign:
            return sign
    if not side and book.output == "actions" and re.search(r"(argument|reason)s?$", m.group(0), re.IGNORECASE):
        return 1  # 'the strongest reason': a reason for what was decided
    if _OTHER_WAY.match(masked, m.end(), b):
        return OWN_SIDE  # 'the strongest factor pulling the other way'
    toward = _TOWARD_SIDE.match(masked, m.end(), b)
    if toward and book.output != "actions":  # 'the primary factors that led to ... a low probability', 'the main
        return -1 if toward.group("low") else 1  # contributors to the predicted outcome of not having diabetes'
    if (
        side
        and side.group(1)
        and book.outcome_sign
        and re.match(
            r"\s+for\s+(?:the\s+|this\s+|its\s+)?(?:model's\s+)?(?:prediction|outcome|decision|result|predicted|low|"
            r"high)\b",
            masked[m.end() : b],
            re.IGNORECASE,
        )
    ):
        return book.outcome_sign  # 'the primary reasons for the model's prediction': for where it went
    if side and re.search(r"(argument|reason|push)s?$", m.group(0), re.IGNORECASE):
        sign = 1 if side.group(1) else -1  # 'the main argument for staying': the largest that favours it
        obj = next((x for x in mentions if x.kind == "action" and 0 <= x.start - m.end() - side.end() <= 6), None)
        return -sign if obj is not None and resolve_action(obj, book) == book.runner_up else sign  # ('for the
        # handover' when staying was chosen)
    return 0


#: 'In order of size: A, B, C', 'Largest first: A, B', '1. A ...' / '2) B ...' (a numbered item, by the importance
#: its number gives)
_ORDER_CUE = re.compile(
    r"\b(?:in (?:descending )?order of (?:size|importance|magnitude|influence|impact|effect)|"
    r"(?:largest|biggest|strongest|most important) first|ranked(?: by [\w|]+)?|"
    r"by (?:importance|size|magnitude|\|shap\|))\s*[:\-—]\s*",
    re.IGNORECASE,
)
_ITEM_NUMBER = re.compile(r"^\W{0,2}(?P<k>[1-5])[.)]\s+(?=\0)")


def _in_order(masked: str, a: int, b: int, names: list[Mention], book: FactBook, ctx: str | None) -> list[Claim]:
    """A list said to be in order of size ranks its names 1, 2, 3 ...; a numbered item starting with a name ranks it
    by its number."""
    item = _ITEM_NUMBER.match(masked[a:b])
    if item and names and names[0].start == a + item.end():
        k = int(item.group("k"))
        return [check_rank(names[0].keys, k, None, 0, ctx, book, f"item {k}")]
    cue = _ORDER_CUE.search(masked, a, b)
    if cue is None:
        return []
    listed = [x for x in names if x.start >= cue.end()]
    return [
        check_rank(x.keys, k, None, 0, ctx, book, f"{cue.group(0).strip()} #{k}") for k, x in enumerate(listed[:5], 1)
    ]


def _chain(masked: str, a: int, b: int, names: list[Mention], book: FactBook, ctx: str | None) -> list[Claim]:
    """'|phi| ranking: employment > age > DTI': each name's |contribution| above the next one's."""
    out = []
    for x, y in zip(names, names[1:]):
        if re.fullmatch(r"\s*>\s*(?:the\s+)?", masked[x.end : y.start]) and len(y.keys) == 1:
            out.append(check_comparison(x.keys, y.keys[0], 1, ctx, book, ">"))
    return out
