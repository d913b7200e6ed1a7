"""Read any text back against an Explanation: the verifier.

A small pipeline, one module per step:

1. :mod:`.numbers` normalises the text (Unicode minus, no-break spaces) and reads every number as people write
   it, with the hedge before it;
2. :mod:`.names` finds where features (any spelling, words of their name or description), actions (verb forms
   too) and categorical values are named, and masks them;
3. this module splits sentences into clauses and decides each clause's view (the chosen action's score, the margin
   over the runner-up, or either); :mod:`.clauses` reads each clause: :mod:`.binding` binds each number to the name it is about (the name before it
   in its clause, pairwise for 'A and B ... by x and y, respectively', an action's score, the margin, the
   prediction, a typical value (:mod:`.background`), the change from the baseline); :mod:`.directions` binds each direction word to
   the list of names nearest before it (or a list after it, 'Raising risk: A, B'), :mod:`.ranks` each rank and
   'barely matters' phrase, and :mod:`.comparisons` each 'A mattered more than B' and ratio;
4. :mod:`.quantities` (numbers), :mod:`.checks` (actions, categories, directions), :mod:`.ranks` and
   :mod:`.comparisons` check each
   claim against :mod:`.book` (values, contributions to the chosen action's score and to the margin over the
   runner-up, ranks, shares, labels, scores, domain comparisons) and say verified, contradicted or unchecked;
5. every sentence gets a status (contradicted if any claim is; verified if a claim was checked and none is
   contradicted; else unchecked), and the text a coverage (share of sentences with a checked claim).

A number bound by position alone and contradicted gets a second reading from the sentence's parse (:mod:`.parse`,
spaCy): the noun phrase it measures. Every claim names the reading that made it (``Claim.rule``).

Two verdicts: ``Verification.accurate``, nothing contradicted; ``Verification.ok``, accurate and coverage >=
:data:`MIN_COVERAGE` (0.5). How to read a trace and add a rule: docs/verifier.md; what is and is not checked: the
README ("What the verifier checks").
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from xairl.errors import InputError
from xairl.explanations.explanation import Explanation
from xairl.narrators.verify import binding, checks, clauses, directions, parse, quantities, regions, reread, sums
from xairl.narrators.verify.book import FactBook, add_facts, clean_surface, fact_book
from xairl.narrators.verify.checks import CHECKED, Claim
from xairl.narrators.verify.names import Mention, find_mentions, named_features
from xairl.narrators.verify.numbers import NUMBER_RE, find_numbers, matches, normalise, unit_in_name
from xairl.narrators.verify.vocabulary import split_words, vocabulary
from xairl.narrators.verify.window import add_window_facts, per_signal
from xairl.policies.policy import Policy
from xairl.policies.regions import in_regions
from xairl.policies.windows import window_of
from xairl.templates.prompts import bidi_controls

MIN_COVERAGE = 0.5  # share of sentences that must carry a checked claim for a text to be ok
#: the rule of a counterfactual sentence's claims (xairl.narrators.provenance.counterfactual): one left unchecked keeps
#: the whole text from 'verified'
COUNTERFACTUAL = "tracked.counterfactual"
MAX_CHARS = 200_000  # longer texts are cut here (and the cut reported)
#: a longer sentence is read in pieces of at most this many characters, cut at a clause boundary (commas, 'and'):
#: the clause readers look back over their sentence, so a bound on its length keeps the time linear in the text
MAX_SENTENCE = 600

__all__ = [
    "Claim",
    "Verification",
    "SentenceCheck",
    "verify",
    "clean_surface",
    "fact_book",
    "NUMBER_RE",
    "MIN_COVERAGE",
]


@dataclass(frozen=True)
class SentenceCheck:
    """One sentence: its claims and status (verified / contradicted / unchecked)."""

    text: str
    claims: tuple[Claim, ...]

    @property
    def status(self) -> str:
        if any(c.status == "contradicted" for c in self.claims):
            return "contradicted"
        if any(c.status == "verified" and c.kind in CHECKED for c in self.claims):
            return "verified"
        return "unchecked"


@dataclass(frozen=True)
class Verification:
    """The verdict on a text: every claim, every sentence, coverage and status.

    ``ok``: no claim contradicted and at least :data:`MIN_COVERAGE` of the sentences carry a checked claim.
    """

    sentences: tuple[SentenceCheck, ...]
    note: str = ""

    @property
    def claims(self) -> tuple[Claim, ...]:
        return tuple(c for s in self.sentences for c in s.claims)

    @property
    def coverage(self) -> float:
        return sum(s.status != "unchecked" for s in self.sentences) / len(self.sentences) if self.sentences else 0.0

    @property
    def status(self) -> str:
        if any(s.status == "contradicted" for s in self.sentences):
            return "contradicted"
        if any(c.rule == COUNTERFACTUAL and c.status == "unchecked" for c in self.claims):
            return "unchecked"  # a counterfactual stated in a form its check cannot read: never passed as verified
        return "verified" if self.sentences and self.coverage >= MIN_COVERAGE else "unchecked"

    @property
    def accurate(self) -> bool:
        """Nothing the text says is contradicted (what a person's accuracy label measures; coverage aside)."""
        return not any(s.status == "contradicted" for s in self.sentences)

    @property
    def ok(self) -> bool:
        """Accurate, and at least :data:`MIN_COVERAGE` of the sentences checked: what narration gates on."""
        return self.status == "verified"

    def problems(self) -> list[Claim]:
        """Contradicted claims first, then (for a text that is not ok) the sentences left unchecked."""
        bad = [c for c in self.claims if c.status == "contradicted"]
        if not bad and not self.ok:
            bad = [
                Claim("coverage", s.text, "unchecked", f"no checkable claim (coverage {self.coverage:.0%})")
                for s in self.sentences
                if s.status == "unchecked"
            ] or [Claim("coverage", "", "unchecked", "empty text")]
        return bad


_SENTENCE_RE = re.compile(r"(?<=[.!?])\s+(?=\S)|\n+\s*(?:[-•*]\s*)?")
_ABBREVIATION = re.compile(r"(?:^|[\s(])(?:e\.g|i\.e|vs|approx|ca|etc|no|fig|cf)\.$", re.IGNORECASE)
_ITEM_NUMBER = re.compile(r"\s*\d{1,2}\.")  # a list item's number, read in place (no copy of the text before it)
_CLAUSE_RE = re.compile(
    r";|(?<!everything)(?<!anything)(?<!\ball)\s(?:while|whereas|but|yet|although|though|"
    r"however)\b(?!,)"  # ('A, though, pushes it up': an aside)
    r"|,\s(?:and\s)?(?=but\b)|\s?[—–]\s?(?=(?:likely|possibly|perhaps|probably|since|as|because|"
    r"this|"
    r"which|suggesting|unsurprising)\b)|\s(?=because\b(?!\s+of\b))"
    r"|,\s(?=(?:as|since)\s(?!(?:well|a result|such|much|many|far|long|of)\b))",
    re.IGNORECASE,
)
#: ', while slightly elevated, was ...': an aside inside the clause (no subject of its own), not a clause
_APPOSITIVE = re.compile(
    r"\s(?:while|although|though)\s+(?:\w+ly\s+)?(?:[a-z]+ed|[a-z]+ing|high|low|above|below|"
    r"modest|small|large|elevated)\b[^,;.]{0,30},",
    re.IGNORECASE,
)
#: 'the house price decreases because A is x and B is y': the reason names what moved the output, in one clause
_OUTPUT_MOVED = re.compile(rf"\b(?:{checks.OUTPUT_WORDS})\s+(?:\w+ly\s+)?{checks.DIRECTION_RE.pattern}$", re.IGNORECASE)
_CELL = re.compile(r"[^|]+")
#: a table cell that is one item: a label, then a number ('price hike 12% +.141'), not a field's name and value
#: ('value: 2,112 sq ft') nor a number first ('+4.6 season=winter' after 'blh_m=310|': the number is the last item's)
_ITEM_CELL = re.compile(r"^[\s↑↓•*-]*(?![A-Za-z ]{1,20}:)[A-Za-z\0][^|]*\d")


def _item_cells(masked: str) -> list[int]:
    """Where a table row's items start: at a '||', and after a '|' between two cells that are items each
    ('M2M +.188 | price hike 12% +.141'; not '| value: 2,112 | SHAP: +39,960', not 'blh_m=310|+4.6')."""
    cells = list(_CELL.finditer(masked))
    return [
        b.start()
        for a, b in zip(cells, cells[1:])
        if masked[b.start() - 2 : b.start()] == "||" or (_ITEM_CELL.match(a.group(0)) and _ITEM_CELL.match(b.group(0)))
    ]


_IDENT_RE = re.compile(r"\b[A-Za-z][A-Za-z0-9]*(?:_[A-Za-z0-9]+)+\b")


def sentences(text: str) -> list[tuple[int, int]]:
    """Sentence spans: split after . ! ? before a capital or a sign, and at line breaks and bullets."""
    spans, start = [], 0
    for m in _SENTENCE_RE.finditer(text):
        if (
            _ABBREVIATION.search(text[max(0, m.start() - 8) : m.start()])
            or text[max(0, m.start() - 2) : m.start() - 1].isspace()
            or _ITEM_NUMBER.fullmatch(text, start, m.start())
        ):  # (the cheap tests first: '! ! !' after
            # 2,000 tabs read them 2,000 times over, issue 51's fuzz)
            continue  # 'e.g. X', '1. Living area ...', 'over ? (score 2.1)' (a name, not an end): no sentence end
        if text[start : m.start()].strip():
            spans.append((start, m.start()))
        start = m.end()
    if text[start:].strip():
        spans.append((start, len(text)))
    return [piece for span in spans for piece in _pieces(text, *span)]


def _pieces(text: str, a: int, b: int) -> list[tuple[int, int]]:
    """A sentence longer than :data:`MAX_SENTENCE` cut at its last clause boundary (';', ',', ' and ', a space) before
    the limit, again and again."""
    out = []
    while b - a > MAX_SENTENCE:
        window = text[a : a + MAX_SENTENCE]
        cut = max(window.rfind(";"), window.rfind(","), window.rfind(" and "))
        cut = cut if cut > MAX_SENTENCE // 3 else window.rfind(" ")
        cut = a + (cut if cut > 0 else MAX_SENTENCE)
        if text[a:cut].strip():
            out.append((a, cut))
        a = cut + 1 if text[cut : cut + 1] in ";, " else cut
    if text[a:b].strip():
        out.append((a, b))
    return out


def verify(
    text: str, explanation: Explanation, index: int | None = 0, policy: Policy | None = None, facts=None
) -> Verification:
    """Check every claim of ``text`` against the explanation of state ``index`` (``None``: the global view).

    :param policy: optional, for feature descriptions, aliases and units, action aliases and domain facts.
    :param facts: optional :class:`xairl.facts.DomainFacts` beyond the explanation (e.g. a flight's handover counts): its
        numbers may be cited, each comparison's value followed by its unit. With ``index=None`` the summary is
        taken to be made from them: a number that is none of the facts is contradicted, not unchecked.
    :returns: a :class:`Verification`; never raises on odd text (empty, very long, another language).
    """
    text, explanation, index, note = inputs(text, explanation, index)
    read_one = reader(explanation, index, policy, facts)
    spans = sentences(text)
    read = [read_one(text[a:b]) for a, b in spans]
    claims = iter(reread.swapped([c for cs in read for c in cs]))  # (two numbers that cross, anywhere in the text)
    return Verification(
        tuple(
            SentenceCheck(text[a:b].strip(), (*bidi_claims(text[a:b]), *(next(claims) for _ in cs)))
            for (a, b), cs in zip(spans, read)
        ),
        "; ".join(filter(None, [note, bidi_note(text)])),
    )


def bidi_claims(sentence: str) -> tuple[Claim, ...]:
    """A contradicted claim for a sentence holding bidirectional control characters: what a reader sees is not the
    text that was read ('by U+202E 5.03 U+202C' shows as 'by 30.5'), so it is never verified."""
    found = bidi_controls(sentence)
    return (Claim("text", found, "contradicted", f"holds bidirectional control characters ({found})"),) if found else ()


def bidi_note(text: str) -> str:
    """Why a text holding bidirectional control characters is not verified ('' for a text without)."""
    found = bidi_controls(text)
    return (
        f"not verified: the text holds bidirectional control characters ({found}) that reorder what is shown"
        if found
        else ""
    )


def inputs(text, explanation: Explanation, index: int | None, caller: str = "verify") -> tuple:
    """(text, explanation, index, note): a str checked (else a one-line error), the index checked (``None``: the
    global view), the explanation in regions or per signal (an image or a window is read as it is narrated), the
    text normalised and cut at
    :data:`MAX_CHARS` (the note says so). What every reader of prose does first."""
    if not isinstance(text, str):
        raise InputError(
            f"{caller}() reads text (a str), not {type(text).__name__}: decode it first, e.g. data.decode('utf-8')."
        )
    index = None if index is None else explanation.check_index(index)
    explanation, text, note = in_regions(explanation), normalise(text), ""
    if window_of(explanation) is not None:
        explanation = per_signal(explanation)
    if len(text) > MAX_CHARS:
        text, note = text[:MAX_CHARS], f"text cut at {MAX_CHARS} characters"
    return text, explanation, index, note


def aids(explanation: Explanation, index: int | None, policy: Policy | None = None, facts=None) -> tuple:
    """(fact book, vocabulary, unit_of): what a reader checks claims with, for state ``index`` of an explanation
    already in regions; ``unit_of(feature)`` is its unit (the policy's, else its name's ending)."""
    with np.errstate(all="ignore"):  # sums of contributions near 1e308 overflow: an infinite fact matches no number
        book = fact_book(explanation, index, policy)
    if facts is not None:
        add_facts(book, facts)
        book.closed = index is None  # a summary made from these facts: a number that is none of them is wrong
    if index is not None and "window" in (explanation.extras or {}):
        add_window_facts(book, explanation, index, policy)
    vocab = vocabulary(explanation, policy, clean_surface)

    def unit_of(f: str) -> str:
        info = policy.features.get(f) if policy else None
        return info.unit if info and info.unit else unit_in_name(f)

    return book, vocab, unit_of


def reader(
    explanation: Explanation, index: int | None, policy: Policy | None = None, facts=None
) -> Callable[[str], list[Claim]]:
    """The reader of one sentence (sentence -> its claims) for state ``index`` of an explanation already in regions:
    what :func:`verify` applies to each sentence, and :mod:`xairl.narrators.provenance` to the words an own narrative
    did not track."""
    book, vocab, unit_of = aids(explanation, index, policy, facts)
    return lambda sentence: _read_sentence(sentence, book, vocab, unit_of)


def _read_sentence(sentence: str, book: FactBook, vocab, unit_of) -> list[Claim]:
    """The claims of one sentence; a sentence without a word ('1 1 1') claims nothing. An unexpected failure of a
    reader leaves the sentence unchecked with the reason (never an exception to the caller; the fuzz test in
    tests/test_verify_robust.py requires that none happens)."""
    if not re.search(r"[^\W\d_]{2}", sentence):
        return []
    if sentence.rstrip().endswith("?"):  # 'Is the competitor offer the main reason?': a question asserts nothing
        mentions, _ = find_mentions(sentence, vocab)
        return [_mention_claim(sentence, m) for m in mentions if m.kind == "feature"]
    try:
        return _check_sentence(sentence, book, vocab, unit_of)
    except Exception as e:  # noqa: BLE001 - a verifier bug must not take the narration down with it
        return [Claim("internal", sentence.strip(), "unchecked", f"the verifier failed here ({type(e).__name__}: {e})")]


# a direction verb whose object is an option ('favoured turning', 'helped turning', '+22.0 toward the handover')
# weighs it against the other one as much as it raises its score: either view, unless the words name the score
_TOWARD_ACTION = re.compile(
    r"\b(favou?r(s|ed|ing)?|help(s|ed|ing)?|toward(s)?|held \w+ back|"
    r"matter\w* (?:more |less |most )?for|for)\s+(?:the |a |an )?$"
)


def _context(sentence: str, mentions: list[Mention], book: FactBook, offset: int = 0) -> str | None:
    """'margin' when the sentence compares with the runner-up, 'chosen' when it names the chosen action's score,
    None when it does not say (claims then hold if they hold in either view). ``offset``: where ``sentence`` (a
    clause) starts in the text the mentions' positions count from."""
    if not book.runner_up:
        return "chosen"
    low = sentence.lower()
    runner_named = any(m.kind == "action" and checks.resolve_action(m, book) == book.runner_up for m in mentions)
    if runner_named or re.search(
        r"\b(rather than|instead of|runner.up|relative to|compared (with|to)|versus|vs\.?|"
        r"margin|lead|edge|advantage|over (going|staying|turning|handing))\b",
        low,
    ):
        return "margin"
    names_score = re.search(r"\b(score|q.value|q\(|value of)\b", low)
    toward = any(
        m.kind == "action" and _TOWARD_ACTION.search(low[max(0, m.start - offset - 24) : m.start - offset])
        for m in mentions
    )
    if re.search(
        r"\b(argu\w* (for|against)|in favou?r of|in (?:the |its )?[\w' -]{0,40}?favou?r|tip(ped|s)? the "
        r"balance|case (for|against)|(?:counted|weighed) (?:\w+ )?against)\b",
        low,
    ) or (toward and not names_score):
        return checks.EITHER  # weighing two options: the margin, or the chosen action's own score
    if names_score or any(m.kind == "action" and checks.resolve_action(m, book) == book.chosen for m in mentions):
        return "chosen"
    return None


def _mention_claim(sentence: str, m) -> Claim:
    """A feature named: no claim by itself, but the trace shows which reading found it."""
    rule = "names.shorthand" if m.form == "shorthand" else "names.mention"
    return Claim("feature", sentence[m.start : m.end], "verified", " / ".join(m.keys), rule)


def _check_sentence(sentence: str, book: FactBook, vocab, unit_of) -> list[Claim]:
    mentions, masked = find_mentions(sentence, vocab)
    docs = []

    def parsed():  # the sentence's parse, made once and only when a reader asks for it
        if not docs:
            docs.append(parse.read(sentence, [(m.start, m.end, "|".join(m.keys)) for m in mentions]))
        return docs[0]

    ctx = _context(sentence, mentions, book)
    claims: list[Claim] = [_mention_claim(sentence, m) for m in mentions if m.kind == "feature"]
    # 'had X been better, it would have stayed': not what happened; only its numbers are checked
    hypothetical = bool(_HYPOTHETICAL.search(masked.replace("\0", "X")))  # a name first is a word, not space
    for m in mentions:
        c = (
            None
            if hypothetical
            else checks.check_action(sentence, m, book)
            if m.kind == "action"
            else checks.check_label(sentence, m, book)
            if m.kind == "label"
            else None
        )
        if c is not None:
            claims.append(binding.named(c, "action.choice" if m.kind == "action" else "category.label"))
            if m.kind == "label" and (c := checks.closed_class_category(masked, m, mentions, book, sentence)):
                claims.append(c)  # 'outside the ECA' of 'inside_ECA': its word right, its opposite said
        elif (
            not hypothetical
            and (
                c := checks.stated_category(masked, m, mentions, book)
                or checks.closed_class_category(masked, m, mentions, book, sentence)
                or checks.negated_category(masked, m, book)
            )
            is not None
        ):
            claims.append(c)  # 'aisle congestion is rated medium', 'the summer season' (in winter)
    bounds = sorted(
        [0]
        + [
            m.end()
            for m in _CLAUSE_RE.finditer(masked)
            if not _APPOSITIVE.match(masked, m.start()) and not _OUTPUT_MOVED.search(sentence, 0, m.start())
        ]
        + _item_cells(masked)
        + [len(masked)]
    )
    for a, b in zip(bounds, bounds[1:]):
        inside = [m for m in mentions if a <= m.start < b]
        own = _context(sentence[a:b], inside, book, a) if len(bounds) > 2 else None  # '..., yet against staying'
        found = clauses.check_clause(
            masked,
            a,
            b,
            inside,
            book,
            own or ctx,
            unit_of,
            parsed,
            vocab,
            {k for m in named_features(mentions) for k in m.keys},
            sentence,
        )
        found = [_unless_modifier(c, inside, book, parsed) for c in found]
        claims += [c for c in found if not hypothetical or c.kind == "number"]  # a value is still a value
    if hypothetical:
        claims += [binding.named(c, "direction.without") for c in directions.without(masked, mentions, book, ctx)]
    claims += [c for m in _IDENT_RE.finditer(masked) if (c := _identifier(m, masked, book, vocab.words))]
    return claims + regions.unknown_regions(masked)


#: (not a direction word: 'the number of credit cards push up' is an invented feature said to push, and a noun's
#: direction could be any feature's)
_BY_POSITION = frozenset({*binding.GUESSED, "rank.words"})


def _unless_modifier(c: Claim, mentions: list[Mention], book: FactBook, parsed) -> Claim:
    """A claim bound by position to a feature and contradicted, when every mention of that feature in the clause only
    qualifies another noun that names nothing ('the main reason is the 19-vehicle queue on the east approach':
    'vehicle' qualifies 'queue', which is not emergency_vehicle): the claim is about that noun, unchecked (rule
    parse.modifier)."""
    if c.status != "contradicted" or c.rule not in _BY_POSITION:
        return c
    keys = [
        k
        for k in book.features
        if c.detail.startswith((k + " ", k + "'s", k + ":"))
        or f"not {k}'s" in c.detail
        or c.detail.startswith(f"|{k}|")
    ]
    own = [m for m in mentions if m.kind == "feature" and set(m.keys) & set(keys)]
    if not own or len(keys) != 1:
        return c
    nouns = [parse.modified_noun(parsed(), m.start, m.end) for m in own]
    if not all(nouns):
        return c
    if c.kind == "number":  # the noun may be a feature in words the vocabulary lacks, or an invented one: only a
        n = next(iter(find_numbers(c.text)), None)  # number that states some feature's fact exactly is let go
        if n is None or quantities.any_fact(n, book, book.features, None, strict=True) is None:
            return c
    return Claim(
        c.kind,
        c.text,
        "unchecked",
        f"'{nouns[0]}' is what the words are about, and {keys[0]} only qualifies it (first read as {c.detail})",
        "parse.modifier",
    )


#: an identifier's word that names a decision-level quantity ('p_churn', 'y_hat', 'sum_shap', 'base_value')
_DECISION_KEY = re.compile(
    r"\b(?:pred\w*|yhat|y|hat|out|output|p|prob\w*|score|q|base\w*|ev|delta|margin|gap|"
    r"value)\b",
    re.IGNORECASE,
)


def _identifier(m: re.Match, masked: str, book: FactBook, known) -> Claim | None:
    """An identifier that is no name of the explanation ('battery_level', 'sum_phi', 'EXTEND_NS'): an invented
    feature when a number is given to it ('battery_level: +0.3') that is no decision-level fact ('sum_phi=-0.016' is
    the change from the baseline), or a direction word right after it ('wind_speed pushed ...'), and it is not one
    name's words shortened ('wait_max' may be 'waiting_time_max');
    else unchecked (a variable, a model's or an action's code: nothing is claimed of a feature)."""
    ident = m.group(0)
    if re.fullmatch(r"q_(\w+)", ident.lower()) and book.output == "actions":  # 'Q_recharge': an action's score
        if ident.lower()[2:] in {a.lower() for a in book.scores}:
            return None
        return Claim(
            "action",
            ident,
            "contradicted",
            f"no action of this explanation is named {ident[2:]!r}",
            "identifier.q-of-action",
        )
    given = re.match(r"\s?[:=(]?\s?(?=[+\-]?[$€£]?\.?\d)", masked[m.end() : m.end() + 6])
    number = next(iter(find_numbers(masked[m.end() : m.end() + 40])), None) if given else None
    pushes = checks.DIRECTION_RE.search(masked, m.end(), m.end() + 30)
    if pushes is not None and not re.fullmatch(r"(?:\s+[a-z]+){0,2}\s+", masked[m.end() : pushes.start()]):
        pushes = None  # only a direction word within the next two words: 'wind_speed pushed toward it
    words = [w for w in split_words(ident) if len(w) >= 3]
    ours = any(words and all(any(k.startswith(w) for k in own) for w in words) for own in known.values())
    spaced = ident.replace("_", " ")
    totals = list(book.aggregates.values()) if sums.AGGREGATE_CUE.search(spaced) else []
    decision = book.decision_numbers if _DECISION_KEY.search(spaced) else []
    # a log's field ('run_id=7781', 'latency_ms=42', 'n_features=10'): an unsigned value given with '=' or ':' is a
    # record of the run, not a push; an invented feature is given a signed contribution ('battery_temp=+0.3')
    field = number is not None and not number.sign and re.match(r"\s?[:=]", masked[m.end() : m.end() + 2])
    if (
        ours
        or field
        or (number is None and pushes is None)
        or (number is not None and any(matches(number, x, magnitude_ok=False) for x in [*decision, *totals]))
    ):
        return Claim(
            "feature", ident, "unchecked", "an identifier that names nothing of this explanation", "identifier.other"
        )
    said = f"given {number.text}" if number is not None else f"'{pushes.group(0)}' is said of it"
    return Claim(
        "feature",
        ident,
        "contradicted",
        f"{said}, but it is not a feature or action of this explanation",
        "identifier.claimed",
    )


#: a sentence about what did not happen: 'Had X been better, ...', 'Without X, it would have ...', 'If it were not
#: for X'; a modal elsewhere ('chose recharge, which could save battery', 'lower than it would be') leaves the rest
#: checked
_HYPOTHETICAL = re.compile(
    r"^\W*(?:if|had|without|were|absent|but for)\b|(?<!than it )(?<!than they )"
    r"\b(?:would|could|might)(?:\s+\w+ly)?\s+"
    r"(?:(?:not|never)\s+)?(?:have|be)\b(?!\s+(?:due|because|related|linked|attributed|"
    r"explained|caused|associated|indicative|a sign|the result|seen|viewed|considered|"
    r"interpreted|reflecting|influenced)\b)"  # ('which could be due to ...': a reason, not
    r"|\bif it (?:were|was)(?:n't| not) for\b",
    re.IGNORECASE,
)  # what would have been)
