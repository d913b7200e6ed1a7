"""Which names a direction word is said of, and the direction claims that follow: the list of names nearest before
it ('A, B and C raise'), a list after it ('Raising risk: A, B'), 'everything but X', 'despite X', a feature taken
away ('without X, it would be higher'), and subjects that name no feature (invented, or only vague)."""

from __future__ import annotations

import functools
import re
from dataclasses import replace

from xairl.narrators.verify import checks
from xairl.narrators.verify.book import FactBook
from xairl.narrators.verify.checks import Claim
from xairl.narrators.verify.lexicon import GENERIC
from xairl.narrators.verify.names import Mention, named_features
from xairl.narrators.verify.numbers import find_numbers, matches
from xairl.narrators.verify.parse import said_of, same_clause
from xairl.narrators.verify.ranks import NOUN
from xairl.narrators.verify.vocabulary import split_words, stem

_GENERIC_SUBJECT = re.compile(
    r"^\W*(?:[qa]\s*:\s*)?(?:and\s+|but\s+|also\s+|so\s+)?(?:(?:nearly|almost|virtually|"
    r"practically|just about)\s+)?(?:it|this|that|they|these|those|which|everything"
    r"|anything|something"
    r"(?: else)?|every \w+|all(?: \w+)?|both|each|none|nothing|the rest|others?|the model"
    r"|the policy|the agent|the dqn|the uav|another|what|overall|together|in total"
    r"|the prediction|the predicted \w+|the estimate|the output|the model's \w+"
    r"|(?:the|its|their)\s+(?:(?:house|home|property|patient|applicant|customer|student|"
    r"team)(?:'s)?\s+)?(?:sale\s+)?(?:price|(?:q[- ]?)?value|cost|risk|probability|chance|odds|"
    r"likelihood)"
    r"|(?:the )?(?:q[- ]?value |score )?(?:gap|margin|lead|difference))\b(?!'s)",
    re.IGNORECASE,
)

#: 'If it were not for X, the price would be much lower', 'Had X not been Y, the risk would be higher', 'Without X,
#: it would be lower': what X did, said by taking it away
_WITHOUT = re.compile(
    r"^\W*(?:if it (?:were|was)(?:n't| not) for|but for|without|absent|had)\s+(?P<subject>[^,;]+?)"
    r"\s*,\s*(?P<rest>[^;]*?\bwould\s+(?:\w+ly\s+)?(?:be|have been)\s+(?:\w+\s+){0,2}?"
    r"(?:much\s+|far\s+|a lot\s+|slightly\s+|a bit\s+|even\s+)?(?P<way>higher|lower|more|less|"
    r"greater|smaller|bigger))\b",
    re.IGNORECASE,
)


def without(masked: str, mentions: list[Mention], book: FactBook, ctx: str | None) -> list[Claim]:
    """A direction said by taking a feature away: the output 'would be higher' without X means X lowered it. 'Had X
    not been ...' only with its 'not' (else it is another value, not X's absence)."""
    m = _WITHOUT.match(masked)
    if m is None or (masked.lstrip().lower().startswith("had") and not re.search(r"\bnot\b", m.group("subject"))):
        return []
    subjects = list(
        {
            x.keys: x
            for x in named_features(mentions)  # 'the odor' and its label 'foul': one subject
            if m.start("subject") <= x.start < m.end("subject")
        }.values()
    )
    polarity = -1 if m.group("way").lower() in ("higher", "more", "greater", "bigger") else 1
    return checks.check_direction(subjects, polarity, ctx or "chosen", f"without it: {m.group('way')}", book)


_SIDE_WORD = re.compile(
    r"^(?:against|in favou?r of|favou?r\w*|toward\w*|supports?|support\w*|works? against|"
    r"worked against)$",
    re.IGNORECASE,
)
#: an object that is not the model's output: the applicant, the house, them
_PERSON_OBJECT = re.compile(
    r"^\s+(?:the\s+|this\s+|that\s+)?(?:applicant|borrower|customer|client|person|buyer|seller|"
    r"owner|house|home|property|him|her|them|it|us|you)\b",
    re.IGNORECASE,
)
_LINKS = {"but", "and", "also", "yet", "then", "still", "even", "only", "while", "though", "thus", "hence"}
#: words that say how much or which one, not what: a subject made only of them and the names' generic words, after
#: the thing it belongs to ('the house's small size', 'its size of around 800 sq ft'), is a vague mention, not an
#: invented feature
_VAGUE = {
    "small",
    "smaller",
    "large",
    "larger",
    "big",
    "bigger",
    "short",
    "long",
    "little",
    "bit",
    "lot",
    "the",
    "this",
    "that",
    "its",
    "their",
    "about",
    "around",
    "roughly",
    "nearly",
    "almost",
    "some",
    "over",
    "under",
    "than",
    "net",
    "combined",
    "whole",
    "entire",
    "final",  # ('the net increase of 30.1': the whole's)
    "half",
    "third",
    "quarter",
    "most",
    "much",
    "part",
    "share",
    "bulk",
    "majority",
    "all",
}  # (of a whole)
#: the thing a model is about, as a possessor ('the house's', 'the applicant's'): not a feature of its own
_POSSESSOR = re.compile(
    r"^\W*(?:the\s+|this\s+|its\s+|their\s+)?(?:house|home|property|file|document|applicant|"
    r"borrower|customer|client|user|patient|loan|account|uav|drone|robot|agent|vehicle|device|"
    r"sample|instance|case|item)'s\s+",
    re.IGNORECASE,
)
#: '... everything else was positive except the lot': the exception after the direction word
_EXCEPT_AFTER = re.compile(
    r"\b(?:except|but not|apart from|other than)(?: for)?\s+(?:the\s+|its\s+|their\s+)?\W*$", re.IGNORECASE
)
_ALL_RE = re.compile(r"\b(?:everything|all|every\w*|anything)\b", re.IGNORECASE)
_DESPITE = re.compile(r"\b(?:despite|in spite of|notwithstanding|even with)\b[^,;]*$", re.IGNORECASE)
_EXCEPT = re.compile(
    r"\b(?:everything|all|anything|every\w*)\s+(?:\w+\s+)?(?:but|except(?: for)?|apart from|"
    r"other than)\s+(?:the\s+|its\s+)?\W*$",
    re.IGNORECASE,
)


#: the output as the subject of a direction word: 'the house price decreases (because ...)', 'it rises'
_OUTPUT_BEFORE = re.compile(rf"\b(?:{checks.OUTPUT_WORDS}|value|it)\s+(?:\w+ly\s+)?$", re.IGNORECASE)


def _reason_moved_output(
    masked: str, prev: int, m: re.Match, sub: re.Match, subjects: list[Mention], mentions: list[Mention]
) -> bool:
    """'The house price decreases because A is x and B is y': the output is the direction word's subject (named, or
    the output's own name right before it) and a 'because'/'since' reason names what moved it, with no direction word
    of its own."""
    if sub.group(0).lower() not in ("because", "since") or checks.DIRECTION_RE.search(
        masked, sub.end(), subjects[-1].end
    ):
        return False
    return bool(_OUTPUT_BEFORE.search(masked, prev, m.start())) or any(
        x.kind == "action" and re.fullmatch(r"\s+(?:\w+ly\s+)?", masked[x.end : m.start()]) for x in mentions
    )


#: a clause with a subject of its own after a comma: ', this effect was', ', it was'
_NEW_SUBJECT = re.compile(
    r",\s*(?:this|that|these|those|it|they)\s+(?:\w+\s+)?(?:is|was|are|were|has|had)\b", re.IGNORECASE
)
#: a subordinate clause between a direction word and a name: the name is that clause's subject
_SUBORDINATE = re.compile(
    r"\b(?:after|before|when|while|because|since|although|though|if|once|until|whereas)\b", re.IGNORECASE
)
#: a participle after a comma says what the clause's subject does, not its last object
_PARTICIPLE_AFTER_COMMA = re.compile(
    r"(?:tak|add|rais|lower|push|pull|cutt|reduc|increas|boost|cost|shav|knock|drag|"
    r"lift|decreas|subtract)\w*ing\b",
    re.IGNORECASE,
)
#: 'toward X', 'in favour of X' after a direction word: X says which side of a one-output model it is
_SIDE = re.compile(
    r"(?:[\w\0']+\s+){0,4}?(?:towards?|in favou?r of)\s+(?:a\s+|an\s+|the\s+)?[\"'“‘]?"
    r"(?P<obj>[\w\0]+)",
    re.IGNORECASE,
)
_UP_SIDE = re.compile(r"(?:higher|increase|up|upward|yes|positive|1|true|approval|approve|acceptance)$", re.IGNORECASE)


def _unsaid_side(masked: str, m: re.Match, mentions: list[Mention], book: FactBook) -> bool:
    """A side word whose object is neither the output (named), an up word, nor a down word ('toward "no"'): a class
    of a one-output classifier the text does not tie to the output ('toward failure', 'in favor of repayment')."""
    side = _SIDE.match(masked, m.start())
    if side is None or side.start("obj") - m.start() > 60:
        return False
    output = (
        any(x.kind == "action" and x.start == side.start("obj") for x in mentions)
        or side.group("obj").lower() == (split_words(book.chosen or "") or [""])[0]
    )  # 'toward diabetes' (diabetes_...)
    return not (output or _UP_SIDE.match(side.group("obj")) or checks.toward_no(masked, m.start()))


#: words of an output that is a good outcome (its risk is the inverse framing)
_GOOD_OUTCOME = {"good", "pass", "approval", "approved", "repay", "repayment", "success", "survival", "win"}


def _good_outcome(book: FactBook) -> bool:
    """The one output is the probability of a good outcome (credit repaid, a pass): a risk is its other side."""
    return book.output != "actions" and bool(_GOOD_OUTCOME & set(split_words(book.chosen or "")))


#: 'positive contributions from A and B': the names after the direction word are its subject
_OF_WHAT = re.compile(r"\s+(?:contributions?|effects?|impacts?|influences?|pushe?s?)\s+(?:from|of|by)\s", re.IGNORECASE)
#: a coordinated clause with a subject of its own after an earlier direction word: 'A lowered it by x, and B cost y'
_NEW_CLAUSE = re.compile(r",\s+(?:and|while|whereas|plus)\s+(?=(?:the|a|an|its|their)\s)(?!.*,)", re.IGNORECASE)


def directions(
    masked: str,
    a: int,
    b: int,
    mentions: list[Mention],
    book: FactBook,
    ctx: str | None,
    name_words=frozenset(),
    parsed=None,
) -> list[Claim]:
    """The direction claims of clause ``masked[a:b]``: each direction word with the names it is said of, checked."""
    out, prev, bare = [], a, False  # bare: the previous direction word found no subject at all
    names = named_features(mentions)
    found = [m for m in checks.DIRECTION_RE.finditer(masked, a, b) if not checks.is_frame(masked, m)]
    for i, m in enumerate(found):
        if no_push(m, masked, mentions, book):
            continue
        polarity, where = checks.direction_target(masked, m, mentions, book, ctx)
        polarity = as_said_after(masked, m, polarity)
        if re.match(
            r"\s+to\s+(?:the\s+)?(?:negative|downside|risks?|concerns?|worries)\b", masked[m.end() :]
        ) and _good_outcome(book):
            polarity = -polarity  # 'added to the negative outlook' of a good-credit probability (of a diabetes
            # probability, 'contributed positively to the risk' raises it)
        nxt = found[i + 1].start() if i + 1 < len(found) else b  # where the next direction word starts
        subjects = _subject_list([x for x in names if prev <= x.start < m.start()], masked, prev)
        own = (
            _FRONTED.match(masked, prev, subjects[0].start) and _OWN_SUBJECT.search(masked, subjects[-1].end, m.start())
            if subjects
            else None
        )
        if own:  # 'Beyond alcohol and sulphates, the wine's tannin level added 0.09': the tannin level's push
            subjects, prev = [], own.start() + 1
        agents = _passive_agents(masked, m, names, nxt)
        if agents:
            subjects = agents  # 'it is pushed up by the battery level': the battery
        if (
            _PARTICIPLE_AFTER_COMMA.match(m.group(0))
            and re.search(r",\s*$", masked[a : m.start()])
            and names
            and names[0].start < m.start()
        ):
            subjects = [names[0]]  # 'Retirement offsets the push from age and debt, taking 12.3 pp off': retirement
        if _OF_WHAT.match(masked, m.end()):  # 'the slightly positive contributions from corners and attempts'
            subjects = [x for x in names if m.end() <= x.start < nxt]
        if not subjects:  # a header ('Raising risk: A, B') or a verb before its subject ('pushed up by A')
            subjects = [x for x in names if m.end() <= x.start < nxt]
            sub = _SUBORDINATE.search(masked, m.end(), subjects[0].start) if subjects else None
            if sub is not None and _reason_moved_output(masked, prev, m, sub, subjects, mentions):
                sub = None  # 'the price decreases because the living area is 1256 sq ft and ...': the area's push
            if subjects and (sub is not None or _NEW_SUBJECT.search(masked, m.end(), subjects[0].start)):
                subjects = []  # 'raised your risk the most after retirement lowered it', '..., which increased the
                # risk, this effect was outweighed by the glucose': not the later clause's name
            if bare and subjects and ":" in masked[m.end() : subjects[0].start]:
                subjects = []  # 'Negative drivers outweighed positive ones: A, B': whose list is it? unsaid
            elif not subjects:
                out += _invented_subject(masked, a, b, prev, i == 0, m, mentions, book, name_words, parsed)
        conceded = [
            x
            for x in subjects
            if _DESPITE.search(masked[max(prev, x.start - 40) : x.start]) and "," in masked[x.end : m.start()]
        ]
        subjects = [x for x in subjects if x not in conceded]  # 'Despite being unemployed (+0.128), ... pull it down'
        flipped = [
            x
            for x in subjects
            if _EXCEPT.search(masked, prev, x.start)
            or (  # 'everything but the kitchen'
                _EXCEPT_AFTER.search(masked, m.end(), x.start) and _ALL_RE.search(masked, a, m.start())
            )
        ]
        kept = [x for x in subjects if x not in flipped]
        out += _unless_other_clause(
            checks.check_direction(kept, polarity, where, m.group(0), book), kept, m, masked, parsed
        )
        out += checks.check_direction(flipped, -polarity, where, f"{m.group(0)} (all but it)", book)
        bare, prev = not subjects and not flipped, m.end()
    return out


def _invented_subject(
    masked: str,
    a: int,
    b: int,
    prev: int,
    first: bool,
    m: re.Match,
    mentions: list[Mention],
    book: FactBook,
    name_words,
    parsed,
) -> list[Claim]:
    """A direction word that no name is said of: an invented feature when the words before it (from the clause's
    start, or after a new coordinated clause: '..., and the basement cost another $12,000') are a noun phrase of
    their own and the parse agrees (:func:`_parse_agrees`). Not in a 'because' clause (the writer's reasoning about
    the world, not about this model's features), nor a pronoun of a policy's actions."""
    subject = masked[prev : m.start()]
    inside = [x for x in mentions if prev <= x.start < m.start()]
    if re.match(rf"\s+{NOUN}\b", masked[m.end() :], re.IGNORECASE):
        return []  # 'because of several positive terms': the word says which terms, of no subject
    if first:
        pronoun = re.search(r"\b(it|this|that)\b", subject, re.IGNORECASE)
        if (book.output == "actions" and pronoun) or re.match(r"\W*(?:because|since|as)\b", masked[a:b], re.IGNORECASE):
            return []
        opener = masked[max(0, prev - 12) : prev]
        if _fact_in_brackets(masked[prev : m.end() + 16], book):
            return []  # 'The heat itself (-2.35) hurt ...': a feature in other words, its push beside it
        return _parse_agrees(unknown_subject(subject, m.group(0), inside, name_words, opener), m, parsed, book)
    joined = _NEW_CLAUSE.search(subject)
    if joined is None:
        return []
    rest = prev + joined.end()
    return _parse_agrees(
        unknown_subject(masked[rest : m.start()], m.group(0), [x for x in inside if x.start >= rest], name_words),
        m,
        parsed,
        book,
    )


def is_fact(n, book: FactBook) -> bool:
    """The number is some feature's contribution as written (a value is not enough: an invented name is often given
    a value a feature has)."""
    return any(matches(n, v) for f in book.features.values() for v in f.contribs.values())


def _fact_in_brackets(words: str, book: FactBook) -> bool:
    """A number in brackets that is a feature's contribution ('the heat itself (-2.35) hurt ...')."""
    return any(is_fact(n, book) for inner in re.findall(r"\(([^()]{1,24})\)", words) for n in find_numbers(inner))


#: a neutral verb of amount ('adds', 'contributes', 'gives') followed by what it adds: a signed number ('adds -0.04')
#: or a noun of loss ('adds a smaller penalty of about 0.07', 'gives a reduction'): the object says the way
_AMOUNT_VERB = re.compile(
    r"^(?:add(?:s|ed|ing)?|contribut\w*|giv\w*|brings?|brought|supplies|provides?)$", re.IGNORECASE
)
_LOSS_OBJECT = re.compile(
    r"\s+(?:(?:a|an|the|its|another|further|small\w*|slight\w*|modest|large\w*|big\w*|"
    r"sizeable|hefty|noticeable|minor|mild)\s+){0,3}(?:penalty|penalties|reduction|discount|"
    r"deduction|drag|decrease|drop|loss|cut|downgrade|drawback|malus|haircut)\b",
    re.IGNORECASE,
)
_SIGNED_OBJECT = re.compile(
    r"\s+(?:(?:about|around|roughly|only|just|nearly|almost|some)\s*)?(?P<sign>[+\-])\s?"
    r"[$€£]?\d"
)


def as_said_after(masked: str, m: re.Match, polarity: int) -> int:
    """The way an amount verb says, read from what follows it: 'adds a penalty' lowers, 'adds -0.04' lowers, 'adds
    +0.3' raises; any other direction word keeps its own way."""
    if not _AMOUNT_VERB.match(m.group(0)):
        return polarity
    after = masked[m.end() : m.end() + 60]
    signed = _SIGNED_OBJECT.match(after)
    if signed is not None:
        return 1 if signed.group("sign") == "+" else -1
    return -abs(polarity) if _LOSS_OBJECT.match(after) else polarity


_BE_BEFORE = re.compile(r"\b(?:is|are|was|were|be|been|being|gets?|got)\s+(?:\w+ly\s+)?$", re.IGNORECASE)


def _passive_agents(masked: str, m: re.Match, names: list[Mention], end: int) -> list[Mention]:
    """The names after 'by' of a direction word in the passive ('the value is pushed up by the battery level'):
    what it is said of; [] when the word is not in the passive or no name follows its 'by'."""
    if not _BE_BEFORE.search(masked, max(0, m.start() - 24), m.start()):
        return []
    by = re.match(r"\s+(?:\w+\s+){0,2}?by\s+", masked[m.end() : end])
    if by is None:
        return []
    start = m.end() + by.end()
    return [x for x in names if start <= x.start < min(end, start + 40)][:1]


def no_push(m: re.Match, masked: str, mentions: list[Mention], book: FactBook) -> bool:
    """A direction word that claims no checkable push here: 'helps'/'hurts' without a named action ('a salaried job
    helps': the applicant?; but 'It turned, helped by X'), a side of a person ('working against the applicant'), a
    value said of a feature ('relatively lower glucose levels'), 'driven by' of one output (what mattered, either way),
    the inverse framing of a good outcome ('reduced risk' of a good-credit probability), a class the text does not
    tie to the one output ('toward failure')."""
    one_output = book.output != "actions"
    if (
        checks.VALENCE_RE.match(m.group(0))
        and not checks.action_object(m, mentions)
        and not (
            re.match(r"\s+by\b", masked[m.end() :])
            and not one_output
            and any(x.kind == "action" and checks.resolve_action(x, book) == book.chosen for x in mentions)
        )
    ):
        return True
    if one_output and _SIDE_WORD.match(m.group(0)) and _PERSON_OBJECT.match(masked[m.end() : m.end() + 30]):
        return True
    if any(x.kind == "feature" and 0 < x.start - m.end() <= 1 for x in mentions):
        return True
    if re.fullmatch(r"against", m.group(0), re.IGNORECASE) and _VERSUS.match(masked, m.end()):
        return True  # 'roughly 7% against a typical 26%': a comparison of two numbers, no push
    if (
        one_output
        and re.fullmatch(r"driv\w+(?: by)?", m.group(0), re.IGNORECASE)
        and not re.match(
            r"\s+(?:\w+\s+){0,3}?(?:up|down|higher|lower)\b", masked[m.end() : m.end() + 30], re.IGNORECASE
        )
    ):
        return True  # 'the prediction was driven by the glucose', 'X drives this estimate': what mattered, no way
    if _good_outcome(book) and re.match(
        r"\s+(?:the\s+|their\s+|its\s+|default\s+|credit\s+)?risk\b", masked[m.end() :]
    ):
        return True
    if one_output and stem(split_words(m.group(0))[0]).rstrip("~") in _output_stems(book.chosen or ""):
        return True  # the output's own word ('claims expected to cost $2,600' of a claim cost, 'students drop out
        # more often' of a dropout probability): what is predicted, not a push
    if re.search(
        r"\b(?:in|to)\s+(?:your|our|my|his|her|their)\s+(?:own\s+)?$|\bheav\w*\s+$",
        masked[max(0, m.start() - 16) : m.start()],
        re.IGNORECASE,
    ):
        return True  # 'works in your favour' (whose side is the reader's), 'does the heaviest lifting' (an idiom of
        # size, not of way)
    return one_output and _unsaid_side(masked, m, mentions, book)


@functools.lru_cache(maxsize=64)
def _output_stems(output: str) -> frozenset[str]:
    return frozenset(stem(w).rstrip("~") for w in split_words(output) if len(w) >= 4)


#: 'against a typical 26 %', 'against the average of 5.6', 'against 26 %': 'against' as 'versus'
_VERSUS = re.compile(
    r"\s+(?:(?:a|an|the|its|their)\s+)?(?:(?:typical|average|usual|baseline|base|expected|mean|norm\w*|"
    r"overall|portfolio|population)\b|[+\-]?[$€£]?\d)",
    re.IGNORECASE,
)
#: what may stand between two names of one subject list: commas, and/or, their values ('A (22) and B of 3'). Each
#: text is read in one way only, so a text that fails fails in linear time (issue 51: '999...9 !' took 4x per 2 more
#: digits): a number takes all its digits, commas (',' alone is one) and spaces, and its unit is never a whole word
#: of the list ('3 and' is '3', 'and')
_JOIN = re.compile(
    r"^(?:\s|[;&/:=]|\b(?:and|or|plus|as well as|(?:together|along) with|both|either|its|their|the|of|"
    r"at)\b|\([^()]*\)|[+\-]?[$€£]?[\d.,]+(?![\d.,])\s*(?!\s)[a-zA-Z%]{0,4}(?!(?:(?<=\band)|(?<=\bor)|"
    r"(?<=\bplus)|(?<=\bboth)|(?<=\bits)|(?<=\bthe)|(?<=\bof)|(?<=\bat))\b))*$",
    re.IGNORECASE,
)


#: a clause that opens with a phrase of its own before its subject: 'Beyond A and B, ...', 'Alongside A, ...'
_FRONTED = re.compile(
    r"\W*(?:beyond|besides|alongside|apart from|aside from|in addition to|on top of|as well as|"
    r"next to|other than|except for)\s",
    re.IGNORECASE,
)
#: after the fronted phrase's names, a comma and a noun phrase that names nothing, right up to the direction word
_OWN_SUBJECT = re.compile(r",\s+(?:the|a|an|his|her|its|their|this|that|these|those)\b[^,;\0]*$", re.IGNORECASE)
_PREPOSITION = re.compile(
    r"\b(?:with|given|despite|after|because of|due to|thanks to|at|for|from|on|in|by|beyond|"
    r"besides|alongside|apart from|aside from|in addition to|on top of|other than|except for)\s+"
    r"(?:a\s+|an\s+|the\s+|its\s+|their\s+)?$",
    re.IGNORECASE,
)


def _subject_list(before: list[Mention], masked: str, start: int) -> list[Mention]:
    """The subject of a direction word: the list of names that ends nearest to it ('A, B and C raise'), not names
    from an earlier phrase ('With A at 5, B lowered it': B)."""
    out = before[-1:]
    for i in range(len(before) - 2, -1, -1):
        x = before[i]
        lead = masked[before[i - 1].end if i else start : x.start]
        if not _JOIN.match(masked[x.end : out[0].start]) or _PREPOSITION.search(lead):
            break
        out.insert(0, x)
    return out


#: a clause that opens with a subordinator and names no noun phrase of its own
_ELLIPTIC = re.compile(
    r"^\W*(?:while|although|though|whereas|if|when)\b(?![^,;]*\b(?:the|a|an|its|their|his|her|this|"
    r"that|these|those)\b)",
    re.IGNORECASE,
)


#: a name right before its direction word: its own value in brackets and two words at most between ('speed (0.22)
#: pushed toward', 'A slightly lowers')
_RIGHT_BEFORE = re.compile(r"\s*(?:\([^()]*\)\s*)?(?:[A-Za-z]+\s+){0,2}")
#: a list after its header's colon: 'Raising risk: A, B', 'push it up: A (+1.8), B'
_HEADER = re.compile(r"(?:\W*\w[\w']*(?![\w'])){0,3}\W*:")  # (each word whole: no backtracking)


def _unless_other_clause(claims: list[Claim], subjects: list[Mention], m: re.Match, masked: str, parsed) -> list[Claim]:
    """A direction contradicted of a name stands only when the parse puts the two in one clause
    (:func:`.parse.same_clause`), or the name is right before the word ('speed (0.22) pushed toward') or in a list after
    the word's colon ('Raising it: A, B'); else the name was only near the word, and the claim is unchecked."""
    if parsed is None:
        return claims
    return [
        Claim(
            "direction",
            c.text,
            "unchecked",
            f"the parse puts '{m.group(0)}' in another clause than {'/'.join(x.keys)} (first read as: {c.detail})",
            "parse.direction-other-clause",
        )
        if c.status == "contradicted"
        and not _HEADER.match(masked, m.end(), x.start)
        and not _RIGHT_BEFORE.fullmatch(masked, x.end, m.start())
        and not same_clause(parsed(), m.start(), m.end(), x.start, x.end)
        else c
        for c, x in zip(claims, subjects)
    ]


def _parse_agrees(claims: list[Claim], m: re.Match, parsed, book: FactBook) -> list[Claim]:
    """An invented feature found by the words before a direction word stands only when the parse agrees: the
    word's verb has a subject of its own that names nothing (:func:`.parse.said_of`); that subject's words are the
    claim's."""
    if not claims or parsed is None:
        return claims
    subject = said_of(parsed(), m.start(), m.end(), frozenset(book.features))
    return [replace(c, text=subject) for c in claims] if subject else []


#: a reporting clause before the subject: 'The SHAP value says that ...', 'This shows that ...'
_REPORTED = re.compile(
    r"^.*\b(?:says?|shows?|indicates?|suggests?|means?|tells? us|reveals?|implies|explains?)\s+"
    r"that\s+",
    re.IGNORECASE,
)


def unknown_subject(
    subject: str, word: str, mentions: list[Mention], name_words=frozenset(), opener: str = ""
) -> list[Claim]:
    """A direction claimed for something that names no feature ('the swimming pool adds ...'): contradicted when
    the subject is a noun phrase of its own, not a pronoun or the decision itself, and has no word of a feature's
    name (then it may be a vague mention: 'a quality rating of 10/10 adds ...')."""
    subject = _REPORTED.sub("", subject)  # 'The SHAP value says that the house price increases': the house price
    words = [w for w in re.findall(r"[A-Za-z]{3,}", subject.replace("\0", " ")) if w.lower() not in _LINKS]
    head = re.findall(r"[A-Za-z]{3,}", _POSSESSOR.sub("", subject.replace("\0", " ")))
    if all(
        w.lower() in _VAGUE or w.lower() in GENERIC or w.lower() in _LINKS or w.lower().endswith("ly") for w in head
    ):
        return []  # vague: perhaps a feature, not an invented one
    if re.search(r"\b(?:it|this|that|they|these|those|which|who)\W*$", subject.replace("\0", " "), re.IGNORECASE):
        return []  # 'Rated fair, it takes $23,750 off': a pronoun for something named before
    if _ELLIPTIC.match(re.sub(r".*\b(while|although|though|whereas|if|when)\s*$", r"\1 ", opener) + subject):
        return []  # '..., while slightly elevated, was still lower ...': the subject is the main clause's
    said = {w.lower() for w in words} | {stem(w) for w in words if w.lower().endswith("ing")}  # 'scoring': scored
    if (
        mentions
        or _GENERIC_SUBJECT.match(subject.replace("\0", " "))
        or any(re.fullmatch(NOUN, w, re.IGNORECASE) for w in words)
        or any(x in said if isinstance(x, str) else x <= said for x in name_words)
    ):
        return []
    return [
        Claim(
            "feature",
            subject.strip(" ,:-\0"),
            "contradicted",
            f"'{word}' is said of something that is not a feature of this model",
        )
    ]
