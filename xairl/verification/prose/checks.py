"""One function per kind of claim (numbers in :mod:`.quantities`, ranks and magnitude in :mod:`.ranks`). Each takes a
clause (or sentence) already read into mentions and returns :class:`Claim`\\ s: verified, contradicted, or unchecked
(with the reason)."""

from __future__ import annotations

import re

import numpy as np

from xairl.verification.prose.book import FactBook
from xairl.verification.prose.names import Mention
from xairl.verification.prose.vocabulary import split_words, stem
from xairl.verification.prose.words import CLOSED_CLASSES
from xairl.verification.result import Claim

CHECKED = {"number", "direction", "rank", "action", "category", "magnitude"}
EITHER = "either"  # a sentence's view when its words weigh two options without naming the view (margin or score)

_POS = (
    r"rais\w*|increas\w*|boost\w*|lift\w*|add(?:s|ed|ing)?|supports?|supported|supporting|favou?r(?:s|ed|ing)?|"
    r"in favou?r of|toward|towards|push(?:es|ed|ing)? (?:\w+ ){0,2}up|pull(?:s|ed|ing)? (?:\w+ ){0,2}up|"
    r"nudg\w* (?:\w+ )?up|drives?|driven by|driving|tipped|tips|argu\w* for|counted for|counts for|"
    r"positive(?:ly)?|more likely|up by|help(?:s|ed|ing)?|more high|less low"
)
_NEG = (
    r"lower\w*|decreas\w*|reduc\w*|cut(?:s|ting)?|drag\w*|pull(?:s|ed|ing)? (?:\w+ ){0,2}down|"
    r"push(?:es|ed|ing)? (?:\w+ ){0,2}down|nudg\w* (?:\w+ )?down|subtract\w*|"
    r"tak(?:es|ing|e) (?:[\w.,$€£]+ ){0,4}(?:off|away)|"
    r"took (?:[\w.,$€£]+ ){0,4}(?:off|away)|cost(?:s|ing)?|knock\w*|against|away from|oppos(?:e|es|ed|ing)|"
    r"negative(?:ly)?|"
    r"less likely|more low|less high|"
    r"less attractive|weigh\w* against|argu\w* against|drops?|down by|works? against|worked against|loses?|"
    r"los(?:t|ing)|diminish\w*|penali[sz]\w*|hurt(?:s|ing)?|h[eo]ld(?:s|ing)? (?:\w+ ){0,2}back(?: from)?|"
    r"discourag\w*"
)
#: words that name a one-output model's output ('the house price', 'the predicted probability')
OUTPUT_WORDS = r"price|prediction|probability|risk|estimate|output|score"
VALENCE_RE = re.compile(r"^(?:help|hurt)", re.IGNORECASE)  # whose side? a direction only toward a named action
DIRECTION_RE = re.compile(rf"\b(?:(?P<pos>{_POS})|(?P<neg>{_NEG}))\b", re.IGNORECASE)
#: a negation before a direction word ('does not increase', 'not effective in increasing', 'failed to raise')
_NEGATION = re.compile(
    r"(?:\b(?:not|never|no longer|neither|nor)|n't)\b[^.]{0,12}$|"  # ("didn't": no \b before n)
    r"(?:\bnot|n't)\s+(?:\w+\s+){1,2}(?:in|at)\s+$|"
    r"\b(?:fail\w*|unable|insufficient)\s+(?:\w+\s+)?(?:to|in)\s+$",
    re.IGNORECASE,
)


def over_keys(keys: tuple[str, ...], test, what: str, text: str, kind: str) -> Claim:
    """A claim about a mention that may mean several features: verified when it holds for all of them,
    contradicted when for none, else unchecked (ambiguous)."""
    results = [test(k) for k in keys]
    known = [r for r in results if r is not None]
    if not known:
        return Claim(kind, text, "unchecked", f"nothing known to check it against ({what})")
    if all(r[0] for r in known) and len(known) == len(results):
        return Claim(kind, text, "verified", known[0][1])
    if not any(r[0] for r in known):
        return Claim(kind, text, "contradicted", known[0][1])
    return Claim(kind, text, "unchecked", f"ambiguous: it may mean {', '.join(keys)}")


# -- actions ---------------------------------------------------------------------------------------------------
_CHOICE_BEFORE = re.compile(
    r"(?:[:→]|->|=>|\b(?:made|makes|led|leads) (?:it|the \w+) (?:to )?)\s*$|"
    r"\b(chose|chooses|choose|picked|picks|selected|selects|decided on|decided to|decides to|"
    r"preferred|prefers|opted for|opted to|went for|goes for|went to|switched to|moved to)\s+"
    r"(?:to\s+)?$",
    re.IGNORECASE,
)
_CHOICE_AFTER = re.compile(
    r"^\W{0,3}(?:\([^)]*\)\s*)?(?:was|is|got)?\s*(?:chosen|picked|selected|preferred|"
    r"the choice)\b|"
    r"^\W{0,3}(?:\([^)]*\)\s*)?(?:narrowly\s+|clearly\s+)?(?:won|wins|beat|beats|edged out|"
    r"prevailed|comes? out ahead|came out ahead|comes? out on top|came out on top)\b",
    re.IGNORECASE,
)
_RUNNER_AFTER = re.compile(
    r"^\W{0,3}(?:\([^)]*\)\s*)?(?:came|was|is|as)?\s*(?:the\s+|a\s+)?(?:close\s+|distant\s+)?"
    r"(?:second|runner.up)\b",
    re.IGNORECASE,
)


_RUNNER_BEFORE = re.compile(
    r"\b(?:runner[\s-]?up|second(?: choice| best| place)?|next best|alternative)\s*[:=→]\s*$", re.IGNORECASE
)


def resolve_action(m: Mention, book: FactBook) -> str | None:
    """The action a mention means: itself, or for a head word shared by several actions the chosen (else the
    runner-up) one among them."""
    if len(m.keys) == 1:
        return m.keys[0]
    for a in (book.chosen, book.runner_up):
        if a in m.keys:
            return a
    return None


def check_action(sentence: str, m: Mention, book: FactBook) -> Claim | None:
    """A named action: a statement of what was chosen ('chose X', 'X was chosen', 'it recharged', 'X won') must name
    the chosen action; 'X came second' the runner-up. A plain mention asserts nothing."""
    text = sentence[m.start : m.end]
    if book.global_view or book.output != "actions":
        return None
    a = resolve_action(m, book)
    runner_header = _RUNNER_BEFORE.search(sentence[: m.start])  # 'Runner-up: recharge (3.88)'
    choice = not runner_header and (
        m.form == "past"
        or bool(_CHOICE_BEFORE.search(sentence[: m.start]))
        or bool(_CHOICE_AFTER.match(sentence[m.end :]))
    )
    if (_RUNNER_AFTER.match(sentence[m.end :]) or runner_header) and not choice:
        ok = a is not None and a == book.runner_up
        return Claim("action", text, "verified" if ok else "contradicted", f"the runner-up was {book.runner_up}")
    if choice:
        if re.search(r"(?:\b(?:not|instead of|rather than|over)|n't)\s*$", sentence[: m.start], re.IGNORECASE):
            return None
        ok = a == book.chosen
        return Claim(
            "action",
            text,
            "verified" if ok else "contradicted",
            "the chosen action" if ok else f"the policy chose {book.chosen}, not {a or ' / '.join(m.keys)}",
        )
    return None


# -- categorical values ------------------------------------------------------------------------------------------
def check_label(sentence: str, m: Mention, book: FactBook) -> Claim | None:
    """A categorical value named ('in CollgCr', 'odor: foul', 'self-employed') must be the state's value."""
    if re.search(
        r"(?:\b(?:not|no|non|never|rather than|instead of|unlike|than|compared (?:to|with)|versus|vs|"
        r"relative to)|n't)(?:\s+\w+){0,3}?\W*$",
        sentence[: m.start],
        re.IGNORECASE,
    ):  # 'not self-employed', "wasn't in the 'other' category"
        return None
    f = m.keys[0]
    actual = book.features[f].label
    text = sentence[m.start : m.end]
    if m.form == "legend":  # 'being male' of 'sex (1 = male)': the meaning of the state's code
        e = book.features[f]
        code = int(e.value) if e.value is not None and e.value == int(e.value) else None
        ok = code is not None and e.legend.get(code, "").lower() == m.label.lower()
        return Claim(
            "category",
            text,
            "verified" if ok else "contradicted",
            f"{f} is {code if code is not None else e.value} ({e.legend.get(code, 'not ' + m.label)})",
        )
    if actual is None:
        return None
    ok = actual.lower() == m.label.lower()
    return Claim(
        "category",
        text,
        "verified" if ok else "contradicted",
        f"{f} is {actual}" if ok else f"{f} is {actual}, not {m.label}",
    )


#: a categorical feature's value stated in words right after its name: 'F is rated medium', "F was flagged as
#: 'late'", 'F on the panels is listed as full', "F is 'returning'"; a word as a value ends its clause (not 'F was
#: listed as a minor factor', 'F is set to lower it')
_STATED = re.compile(
    r"(?:'s\s+\w+)?(?:\s+(?:on|of|for|in|at)\s+(?:the\s+|its\s+|her\s+|his\s+)?[\w-]+)?\s+"
    r"(?:is|was|were|are|came|comes|got)\s+(?:(?P<verb>rated|classed|classified|flagged|listed|"
    r"reported|marked|labell?ed|recorded|coded|set|registered|logged)\s+(?:as\s+|to\s+)?|"
    r"(?=['\"‘“]))(?:an?\s+|the\s+)?(?P<value>['\"‘“][^'\"’”\0]{1,30}['\"’”]|"
    r"(?!(?:as|to|by|a|an|the)\b)[A-Za-z][\w-]*(?=\s*(?:[,.;:!?)]|$|\s(?:and|but|yet|which|so|"
    r"while|though)\b)))",
    re.IGNORECASE,
)
#: a capitalised value right before the name, after a determiner: 'the Midwifery course', 'the Cavado sub-region'
_VALUE_BEFORE = re.compile(
    r"\b(?:the|a|an|her|his|their|its|your)\s+(?P<value>[A-Z][a-z]+(?:-[A-Z]?[a-z]+)?|"
    r"[A-Z]{2,}\d*)\s+$"
)  # (or in capitals: 'a FOLFIRI regimen')
#: a log's field and its value: 'course_profile=flat', 'tier: gold' (one word, letters first)
_FIELD_VALUE = re.compile(
    r"\s?(?:=\s?|:\s?(?=[A-Za-z][\w-]*\s*(?:[,;|)\]]|$|[+\-]?\d|\w+=)))"  # (':' only as a
    r"(?!(?:negative|positive|up|down|plus|minus|na|n/a)\b)"  # field: not 'a deposit: three
    r"(?P<value>[A-Za-z][\w-]*)(?![\w'])",
    re.IGNORECASE,
)  # signals', 'season: negative -1.0')
_BOOLEAN = frozenset({"yes", "no", "true", "false", "0", "1", "y", "n", "none", "present", "absent", "on", "off"})


def stated_category(masked: str, m: Mention, mentions: list[Mention], book: FactBook) -> Claim | None:
    """'Aisle congestion is rated medium' when the state's label is 'low': a value the words give a categorical
    feature right after its name ('is rated', 'was flagged as', 'is listed as', a quoted value, a log's 'F=flat') or
    capitalised right before it after a determiner ('the Midwifery course', not in a title) that shares no word with
    its label (nor is the label's initials, 'SE' of 'south-east') is contradicted. Labels that are yes/no answers are
    left to the direction words ('is missing' may mean 'No')."""
    if (
        m.kind not in ("feature", "label")
        or len(m.keys) != 1
        or m.keys[0] not in book.features
        or not (label := book.features[m.keys[0]].label)
    ):  # (a label's word names its feature: 'outside the ECA')
        return None
    s = (
        _STATED.match(masked, m.end)
        or _FIELD_VALUE.match(masked, m.end)
        or (
            _VALUE_BEFORE.search(masked, max(0, m.start - 40), m.start)
            if not re.match(r"\s+[A-Z]", masked[m.end :])
            else None
        )
    )  # (not in a
    # title: 'How the Current Season Shapes the Forecast')
    if (
        s is None
        or label.lower() in _BOOLEAN
        or any(x.start < s.end("value") and x.end > s.start("value") for x in mentions)
    ):
        return None  # (a value that is a name of the vocabulary: a label the label reader checks)
    said = s.group("value").strip("'\"‘’“”")
    words, own = {stem(w) for w in split_words(said)}, {stem(w) for w in split_words(label)}
    initials = ("".join(w[0] for w in split_words(said)), "".join(w[0] for w in split_words(label)))
    ok = bool(words & own) or initials[0] == label.lower().replace(" ", "") or initials[1] == said.lower()
    f = m.keys[0]
    return Claim(
        "category",
        said,
        "verified" if ok else "contradicted",
        f"{f} is {label}" if ok else f"{f} is {label}, not {said}",
        "category.stated",
    )


def closed_class_category(
    masked: str, m: Mention, mentions: list[Mention], book: FactBook, written: str = ""
) -> Claim | None:
    """A member of a closed class (a month, weekday, season, compass point or time of day:
    :data:`~.lexicon.CLOSED_CLASSES`) in a sentence that names a categorical feature whose label holds another member
    of that class: contradicted ('The summer season added ...' when the season is winter). Not when another named
    feature's label is of the same class (whose value would it be?), nor a member inside a name, nor one the words
    before it set aside (:data:`_ASIDE`, read in the ``written`` sentence)."""
    if (
        m.kind not in ("feature", "label")
        or len(m.keys) != 1
        or m.keys[0] not in book.features
        or not (label := book.features[m.keys[0]].label)
    ):  # (a label's word names its feature: 'outside the ECA')
        return None
    own = set(split_words(label))
    cls = next((c for c in CLOSED_CLASSES if own & c), None)
    if cls is None or any(
        set(split_words(book.features[k].label or "")) & cls
        for x in mentions
        for k in x.keys
        if x.kind == "feature" and k != m.keys[0] and k in book.features
    ):
        return None
    words = [w for w in re.finditer(r"[A-Za-z]+", masked) if w.group(0).lower() in cls]
    if any(w.group(0).lower() in own for w in words):
        return None  # the right value is said too: the other is a comparison ('more than in winter')
    for w in words:
        proper = cls & _PROPER and not w.group(0)[0].isupper()  # ('crews will march in early')
        if not proper and not _ASIDE.search(written or masked, max(0, w.start() - 24), w.start()):
            return Claim(
                "category",
                w.group(0),
                "contradicted",
                f"{m.keys[0]} is {label}, not {w.group(0)}",
                "category.closed-class",
            )
    return None


#: months and weekdays are written with a capital; words before a member that make it no value of the state:
#: 'since June', 'than in winter', 'unlike a Monday', 'from the north', 'not north-east', 'compared with last winter'
_PROPER = CLOSED_CLASSES[0] | CLOSED_CLASSES[1]
_ASIDE = re.compile(
    r"\b(?:since|than|from|unlike|not|until|till|before|after|last|next|ago|to|compared (?:with|to)|"
    r"versus|vs|through|between|of|in any|each|every)\s+(?:the\s+|a\s+|an\s+|early\s+|late\s+|"
    r"mid-?\s*)?(?:\w+\s+)?$",
    re.IGNORECASE,
)


_NEGATOR = r"(?:\bno|\bnot|\bnon|\bnever|\bwithout|n't|\bun)"
_NEGATED_BEFORE = re.compile(_NEGATOR + r"[\s-]*(?:the\s+|a\s+|an\s+|any\s+)?$", re.IGNORECASE)
_YES = frozenset({"yes", "true", "y", "present"})
#: a label's absence said right before its name ('no fever', 'without the fever'; not 'not the fever': a contrast)
_NO_BEFORE = re.compile(
    r"\b(?:no|without|(?:is|was|are|were|be|been|being)\s+not|isn't|wasn't|aren't|weren't)\s+"
    r"(?:the\s+|any\s+)?$",
    re.IGNORECASE,
)  # ('was not oak-aged')
#: a sentence that speaks of the value both ways, or of another case than this one
_CONTRAST = re.compile(
    r"\bor not\b|\bunlike\b|\bwhereas\b|\bif\b|\bwould\b|\bnot\s+(?:un|non)|"
    r",\s*not\s+(?:the\s+)?\0",
    re.IGNORECASE,
)


def negated_category(masked: str, m: Mention, book: FactBook) -> Claim | None:
    """A label said the other way: 'no fever' (or 'without the fever') when Fever_38C is 'yes'; 'the income was
    verified' when verification_status is 'Not Verified'; 'unverified' or 'not verified' when it is 'Verified'."""
    if (
        m.kind not in ("feature", "label")
        or len(m.keys) != 1
        or m.keys[0] not in book.features
        or not (label := book.features[m.keys[0]].label)
    ):  # (a label's word names its feature: 'outside the ECA')
        return None
    f, words = m.keys[0], split_words(label)
    if _CONTRAST.search(masked):
        return None  # ('Verified or not, ...', 'unlike for unverified borrowers', 'if the income were unverified')
    if label.lower() in _YES:
        said = _NO_BEFORE.search(masked, max(0, m.start - 16), m.start)
        if (
            said is None
            or re.match(r"[\w-]", masked[m.end : m.end + 1])
            or _NEGATED_BEFORE.search(masked, max(0, said.start() - 12), said.start())
        ):
            return None  # ('no fever-reducing medication', 'not without fever')
        return Claim(
            "category",
            masked[said.start() : m.start].strip() + " " + f,
            "contradicted",
            f"{f} is {label}",
            "category.negated",
        )
    negated = words[0] in ("not", "no", "non") and len(words) == 2
    core = words[-1] if negated or len(words) == 1 else None
    if core is None or len(core) < 4 or core in _BOOLEAN:
        return None
    for w in re.finditer(rf"(?<![\w\0])(?:un|non-?)?{re.escape(stem(core).rstrip('~'))}\w*", masked, re.IGNORECASE):
        said_not = (
            bool(re.match(r"(?:un|non)", w.group(0), re.IGNORECASE) and not core.startswith(("un", "non")))
            or bool(_NEGATED_BEFORE.search(masked, max(0, w.start() - 12), w.start()))
            or bool(re.search(r"(?:\bnot|n't|\bnever)\s+(?:\w+\s+)?$", masked[max(0, w.start() - 16) : w.start()]))
        )
        if said_not != negated:
            return Claim("category", w.group(0), "contradicted", f"{f} is {label}", "category.negated")
    return None


# -- directions --------------------------------------------------------------------------------------------------
def action_object(m: re.Match, mentions: list[Mention]) -> Mention | None:
    """The action a direction word is said of, when one is named right after it ('favoured forward', 'helped the
    turn decision')."""
    return next((x for x in mentions if x.kind == "action" and 0 <= x.start - m.end() <= 16), None)


_TOWARD_NO = re.compile(
    r"(?:[\w\0']+\s+){0,4}?towards?\s+(?:a\s+|the\s+)?[\"'“‘]?(?:no|negative|0|not|false)\b", re.IGNORECASE
)


def toward_no(masked: str, at: int) -> bool:
    """'toward "no"', 'towards a negative', 'toward 0' within a few words after ``at``: the lower side of one output."""
    return bool(_TOWARD_NO.match(masked, at))


def direction_target(
    masked: str, m: re.Match, mentions: list[Mention], book: FactBook, ctx: str | None
) -> tuple[int, str]:
    """(polarity, context) of a direction word: toward the runner-up ('favoured forward', 'argued for staying')
    means against the chosen action in the margin."""
    polarity = 1 if m.group("pos") else -1
    if _NEGATION.search(masked[max(0, m.start() - 30) : m.start()]):
        polarity = -polarity
    if book.output != "actions" and toward_no(masked, m.start()):
        polarity = -polarity  # 'tipped the prediction toward "no"': a one-output classifier's lower side
    obj = action_object(m, mentions)
    if obj is not None and book.runner_up:
        a = resolve_action(obj, book)
        if a == book.runner_up:
            return -polarity, "margin"
        if a == book.chosen:
            return polarity, ctx or "chosen"
    return polarity, ctx or "chosen"


#: a direction word that names a place, not a push: 'on the positive side', 'the lower quartile', 'lower than average'
_NOT_A_PUSH = re.compile(
    r"(?:on|to)\s+the\s+(?:positive|negative)\s+side|\blower(?:\s+|-)(?:quartile|end|bound|"
    r"half|tail|third|range|percentile|band|limit)\b|\blower(?:\s+|-)than(?:\s+|-)(?:the\s+)?"
    r"(?:average|median|typical|usual|mean|norm|normal|most)\b|"
    r"\b(?:their|its|his|her|whose)\s+lower\b|"
    r"\b(?:might|may|could|would)\s+(?:\w+ly\s+)?(?:seem|appear|look|sound|suggest|imply|"
    r"indicate)\s+"
    r"(?:\w+ly\s+)?(?:an?\s+)?\w+|\b(?:positive|negative)\s+(?:prediction|outcome|diagnosis|class|"
    r"result|label|case|classification)\b|\b(?:raised?|raising|rais\w+)\s+(?:some\s+|serious\s+)?"
    r"(?:concerns?|questions?|doubts?|eyebrows|(?:red\s+)?flags?|alarms?)\b|"
    r"\b(?:this|that|these|those|such|the same)\s+(?:(?:small|slight|modest|mild|minor|large|"
    r"big|strong|major|initial|early|upward|downward|positive|negative)\s+)?(?:positive|negative|"
    r"boost|increase|lift|gain|reduction|decrease|drag|push|rise|drop)\b|"
    r"\b(?:potential|possible)\s+(?:positive|negative)\b|"  # 'the potential negative effects of'
    r"\bopposing\s+(?:team|side|player|defen[cs]e|goal|club|squad)|"  # the other team
    r"\b(?:positive|negative)\s+(?:and\s+(?:positive|negative)\s+)?(?:risk\s+)?(?:factors|"
    r"aspects|indicators|signals|features|influences|contributions|effects|impacts)\b"
    r"(?!\s+(?:of|from)\b)",
    re.IGNORECASE,
)  # 'a mix of positive and negative risk factors', 'outweigh the negative
# contributions' (said of nothing named: 'negative contributions from A' is A's)


def is_frame(masked: str, m: re.Match) -> bool:
    """Not a direction: 'against' that compares ('7.53 against 7.38', 'Against recharge, ...', 'against that'), a
    word that names a side or a place ('on the positive side', 'the lower quartile', 'lower than the median'), an
    adjective of the subject ('their lower efficiency'), an appearance ('might seem positive') and the first word of a
    compound ('add-on')."""
    if re.match(r"-[^\W\d_]", masked[m.end() : m.end() + 2]):
        return True  # the first word of a compound ('the warranty add-on', 'a cut-off'): a thing, not a push
    near = _NOT_A_PUSH.search(masked, max(0, m.start() - 40), min(len(masked), m.end() + 16))
    if near is not None and near.start() <= m.start() < near.end():
        return True
    if m.group(0).lower() != "against":
        return False
    if re.search(
        r"\b(?:balanc\w*|weigh\w*|set|sets|pitt\w*)\s+(?:[\w\0'’-]+\s+){1,8}$",
        masked[max(0, m.start() - 70) : m.start()],
        re.IGNORECASE,
    ):
        return True  # 'balanced the customer's gaps against their savings': two things set side by side
    after = masked[m.end() : m.end() + 30]
    return bool(
        re.match(r"^\s*(?:a\s+|an\s+|the\s+)?[+\-]?[$€£]?[+\-]?\s*[\d.]|^\s*(that|this)\b", after)
        or re.search(r"(^|[.;:\n]\s*)$", masked[: m.start()])
    )


def check_direction(subjects: list[Mention], polarity: int, ctx: str, word: str, book: FactBook) -> list[Claim]:
    def test(key):
        contribs = book.features[key].contribs
        views = [v for v in book.contexts if v in contribs] if ctx == EITHER else [ctx if ctx in contribs else "chosen"]
        cs = [(v, contribs.get(v)) for v in views if contribs.get(v)]
        if not cs:
            return None
        ok = [(v, c) for v, c in cs if np.sign(c) == polarity]
        v, c = (ok or cs)[0]
        return bool(ok), f"{key}'s contribution ({v}) is {c:+.3g}"

    return [over_keys(s.keys, test, ctx, word, "direction") for s in subjects]
