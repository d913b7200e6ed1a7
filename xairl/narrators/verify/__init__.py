"""Read any text back against an Explanation: the verifier.

A small pipeline, one module per step:

1. :mod:`.numbers` normalises the text (Unicode minus, no-break spaces) and reads every number as people write
   it, with the hedge before it;
2. :mod:`.names` finds where features (any spelling, words of their name or description), actions (verb forms
   too) and categorical values are named, and masks them;
3. this module splits sentences into clauses, decides each clause's view (the chosen action's score, the margin
   over the runner-up, or either) and binds each number to the name it is about (the name before it in its clause,
   pairwise for 'A and B ... by x and y, respectively', an action's score, the margin, the prediction);
   :mod:`.directions` binds each direction word to the list of names nearest before it (or a list after it,
   'Raising risk: A, B'), and :mod:`.ranks` each rank, 'barely matters' and 'A mattered more than B' phrase;
4. :mod:`.quantities` (numbers), :mod:`.checks` (actions, categories, directions) and :mod:`.ranks` check each
   claim against :mod:`.book` (values, contributions to the chosen action's score and to the margin over the
   runner-up, ranks, shares, labels, scores, domain comparisons) and say verified, contradicted or unchecked;
5. every sentence gets a status (contradicted if any claim is; verified if a claim was checked and none is
   contradicted; else unchecked), and the text a coverage (share of sentences with a checked claim).

``Verification.ok``: nothing contradicted and coverage >= :data:`MIN_COVERAGE` (0.5). What is and is not checked
is listed in the README ("What the verifier checks").
"""
from __future__ import annotations

import re
from dataclasses import dataclass, replace

from ...explanation import Explanation
from ...policy import Policy
from . import checks, directions, quantities, ranks
from .book import add_facts, FactBook, clean_surface, fact_book
from .checks import CHECKED, Claim
from .names import Mention, find_mentions, named_features, vocabulary
from .numbers import NUMBER_RE, find_numbers, matches, normalise

MIN_COVERAGE = 0.5  # share of sentences that must carry a checked claim for a text to be ok
MAX_CHARS = 200_000  # longer texts are cut here (and the cut reported)

__all__ = ["Claim", "Verification", "SentenceCheck", "verify", "clean_surface", "fact_book", "NUMBER_RE",
           "MIN_COVERAGE"]


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
        return "verified" if self.sentences and self.coverage >= MIN_COVERAGE else "unchecked"

    @property
    def ok(self) -> bool:
        return self.status == "verified"

    def problems(self) -> list[Claim]:
        """Contradicted claims first, then (for a text that is not ok) the sentences left unchecked."""
        bad = [c for c in self.claims if c.status == "contradicted"]
        if not bad and not self.ok:
            bad = [Claim("coverage", s.text, "unchecked", f"no checkable claim (coverage {self.coverage:.0%})")
                   for s in self.sentences if s.status == "unchecked"] or [
                Claim("coverage", "", "unchecked", "empty text")]
        return bad


_SENTENCE_RE = re.compile(r"(?<=[.!?])\s+(?=\S)|\n+\s*(?:[-•*]\s*)?")
_ABBREVIATION = re.compile(r"(?:^|[\s(])(?:e\.g|i\.e|vs|approx|ca|etc|no|fig|cf)\.$", re.IGNORECASE)
_CLAUSE_RE = re.compile(r";|(?<!everything)(?<!anything)(?<!\ball)\s(?:while|whereas|but|yet|although|though|however)\b"
                        r"|,\s(?:and\s)?(?=but\b)|\s?[—–]\s?(?=(?:likely|possibly|perhaps|probably|since|as|because|this|"
                        r"which|suggesting|unsurprising)\b)|\s(?=because\b(?!\s+of\b))", re.IGNORECASE)
#: ', while slightly elevated, was ...': an aside inside the clause (no subject of its own), not a clause
_APPOSITIVE = re.compile(r"\s(?:while|although|though)\s+(?:\w+ly\s+)?(?:[a-z]+ed|[a-z]+ing|high|low|above|below|"
                         r"modest|small|large|elevated)\b[^,;.]{0,30},", re.IGNORECASE)
_IDENT_RE = re.compile(r"\b[A-Za-z][A-Za-z0-9]*(?:_[A-Za-z0-9]+)+\b")
def sentences(text: str) -> list[tuple[int, int]]:
    """Sentence spans: split after . ! ? before a capital or a sign, and at line breaks and bullets."""
    spans, start = [], 0
    for m in _SENTENCE_RE.finditer(text):
        if _ABBREVIATION.search(text[max(0, m.start() - 8):m.start()]) or re.fullmatch(r"\s*\d{1,2}\.",
                                                                                          text[start:m.start()]):
            continue  # 'e.g. X', '1. Living area ...': no sentence end
        if text[start:m.start()].strip():
            spans.append((start, m.start()))
        start = m.end()
    if text[start:].strip():
        spans.append((start, len(text)))
    return spans


def verify(text: str, explanation: Explanation, index: int | None = 0, policy: Policy | None = None,
           facts=None) -> Verification:
    """Check every claim of ``text`` against the explanation of state ``index`` (``None``: the global view).

    :param policy: optional, for feature descriptions, aliases and units, action aliases and domain facts.
    :param facts: optional :class:`xairl.DomainFacts` beyond the explanation (e.g. a flight's handover counts): its
        numbers may be cited, each comparison's value followed by its unit. With ``index=None`` the summary is
        taken to be made from them: a number that is none of the facts is contradicted, not unchecked.
    :returns: a :class:`Verification`; never raises on odd text (empty, very long, another language).
    """
    note = ""
    text = normalise(text if isinstance(text, str) else str(text))
    if len(text) > MAX_CHARS:
        text, note = text[:MAX_CHARS], f"text cut at {MAX_CHARS} characters"
    book = fact_book(explanation, index, policy)
    if facts is not None:
        add_facts(book, facts)
        book.closed = index is None  # a summary made from these facts: a number that is none of them is wrong
    vocab = vocabulary(explanation, policy, clean_surface)

    def unit_of(f: str) -> str:
        info = policy.features.get(f) if policy else None
        return info.unit if info else ""

    out = [SentenceCheck(text[a:b].strip(), tuple(_check_sentence(text[a:b], book, vocab, unit_of)))
           for a, b in sentences(text)]
    return Verification(tuple(out), note)


# a direction verb whose object is an option ('favoured turning', 'helped turning', '+22.0 toward the handover')
# weighs it against the other one as much as it raises its score: either view, unless the words name the score
_TOWARD_ACTION = re.compile(r"\b(favou?r(s|ed|ing)?|help(s|ed|ing)?|toward(s)?|held \w+ back|"
                            r"matter\w* (?:more |less |most )?for|for)\s+(?:the |a |an )?$")


def _context(sentence: str, mentions: list[Mention], book: FactBook, offset: int = 0) -> str | None:
    """'margin' when the sentence compares with the runner-up, 'chosen' when it names the chosen action's score,
    None when it does not say (claims then hold if they hold in either view). ``offset``: where ``sentence`` (a
    clause) starts in the text the mentions' positions count from."""
    if not book.runner_up:
        return "chosen"
    low = sentence.lower()
    runner_named = any(m.kind == "action" and checks.resolve_action(m, book) == book.runner_up for m in mentions)
    if runner_named or re.search(r"\b(rather than|instead of|runner.up|relative to|compared (with|to)|versus|vs\.?|"
                                 r"margin|lead|edge|advantage|over (going|staying|turning|handing))\b", low):
        return "margin"
    names_score = re.search(r"\b(score|q.value|q\(|value of)\b", low)
    toward = any(m.kind == "action" and _TOWARD_ACTION.search(low[max(0, m.start - offset - 24):m.start - offset])
                 for m in mentions)
    if re.search(r"\b(argu\w* (for|against)|in favou?r of|in (?:the |its )?[\w' -]{0,40}?favou?r|tip(ped|s)? the "
                 r"balance|case (for|against)|(?:counted|weighed) (?:\w+ )?against)\b", low) or (
            toward and not names_score):
        return checks.EITHER  # weighing two options: the margin, or the chosen action's own score
    if names_score or any(
            m.kind == "action" and checks.resolve_action(m, book) == book.chosen for m in mentions):
        return "chosen"
    return None


def _check_sentence(sentence: str, book: FactBook, vocab, unit_of) -> list[Claim]:
    mentions, masked = find_mentions(sentence, vocab)
    ctx = _context(sentence, mentions, book)
    claims: list[Claim] = [Claim("feature", sentence[m.start:m.end], "verified", " / ".join(m.keys))
                           for m in mentions if m.kind == "feature"]
    # 'had X been better, it would have stayed': not what happened; only its numbers are checked
    hypothetical = bool(_HYPOTHETICAL.search(masked.replace("\0", "X")))  # a name first is a word, not space
    for m in mentions:
        c = None if hypothetical else checks.check_action(sentence, m, book) if m.kind == "action" else \
            checks.check_label(sentence, m, book) if m.kind == "label" else None
        if c is not None:
            claims.append(c)
    bounds = [0] + [m.end() for m in _CLAUSE_RE.finditer(masked) if not _APPOSITIVE.match(masked, m.start())] + [
        len(masked)]
    for a, b in zip(bounds, bounds[1:]):
        inside = [m for m in mentions if a <= m.start < b]
        own = _context(sentence[a:b], inside, book, a) if len(bounds) > 2 else None  # '..., yet against staying'
        found = _check_clause(masked, a, b, inside, book, own or ctx, unit_of, vocab.name_words,
                              {k for m in named_features(mentions) for k in m.keys})
        claims += [c for c in found if not hypothetical or c.kind == "number"]  # a value is still a value
    if hypothetical:
        claims += directions.without(masked, mentions, book, ctx)
    for ident in _IDENT_RE.findall(masked):
        claims.append(Claim("feature", ident, "contradicted", "not a feature or action of this explanation"))
    return claims


def _check_clause(masked: str, a: int, b: int, mentions: list[Mention], book: FactBook, ctx: str | None,
                  unit_of, name_words=frozenset(), sentence_keys=frozenset()) -> list[Claim]:
    out: list[Claim] = []
    names = named_features(mentions)
    numbers = [n for n in find_numbers(masked[:b]) if n.start >= a and not quantities.skip_number(n, masked)]
    # 'A and B ... by x and y, respectively': numbers after the last name pair up with the names in order
    tail = [n for n in numbers if names and n.start > names[-1].end  # not the last name's own '(−22.5 dB)'
            and not re.fullmatch(r"\s?\([^()]*", masked[names[-1].end:n.start])]
    paired = {}
    if len({m.keys for m in names}) >= 2 and len(tail) == len(names) and (
            "respectively" in masked[a:b].lower() or quantities.CONTRIB_BEFORE.search(masked[a:tail[0].start][-40:])
            or (_PAIR_RE.match(masked[tail[0].start - 1:tail[-1].end + 1])
                and re.search(r"[A-Za-z]{2}", masked[names[-1].end:tail[0].start]))):  # not 'A (26, SHAP -0.07)' 
        paired = {id(n): m for n, m in zip(tail, names)}
    actions = [m for m in mentions if m.kind == "action"]
    scored = {}
    if not names and len(actions) >= 2 and len(numbers) == len(actions) and numbers[0].start >= actions[-1].end:
        scored = {id(n): m for n, m in zip(numbers, actions)}  # 'turn beat recharge 6.30 to 2.37'
    # 'A and B together add x': one number after the names (not B's own '(+5.31)', not a list 'x and y'), without a
    # quantity of its own ('most of the $91,462 above the baseline')
    summed = len(tail) == 1 and len(names) >= 2 and _SUM_CUE.search(masked, a, b) and not _OWN_QUANTITY.search(
        masked[max(a, tail[0].start - 12):tail[0].start]) and not quantities.CHANGE_AFTER.match(masked[tail[0].end:b])
    # 'not the garage but the quality', 'X, rather than Y, is ...': what is said of the sentence is not said of Y
    said = [m for m in mentions if m.kind == "action" or not _NEGATED.search(masked[max(a, m.start - 40):m.start])]
    said_names = named_features(said)
    for n in numbers:
        if summed and n is tail[0]:
            members = list(dict.fromkeys(m.keys for m in said_names))
            out.append(quantities.sum_number(n, members, ctx, book))
            continue
        c = _bind_number(n, masked, mentions, names, paired, scored, book, ctx, unit_of)
        if c.status == "contradicted" and id(n) not in paired:  # 'respectively' binds for sure
            c = _unless_guessed(c, n, masked, mentions, names, book, ctx, sentence_keys)
        out.append(c)
    first = numbers[0] if numbers else None
    if first is not None and first.sign and not any(m.start < first.start for m in mentions):
        out += directions.unknown_label(masked[a:first.start], name_words)  # '; roof condition -12.1k;'
    out += directions.directions(masked, a, b, said, book, ctx, name_words)
    out += ranks.find_ranks(masked, a, b, said, book, ctx)
    out += ranks.find_comparisons(masked, a, b, said, book, ctx)
    for m in ranks.MINOR_RE.finditer(masked, a, b):
        owner = next((x for x in reversed(said_names) if x.end <= m.start()), None) or next(
            (x for x in said_names if x.start >= m.end()), None)
        if owner is not None:
            out.append(ranks.check_minor(owner.keys, ctx, book, m.group(0)))
    return out


#: 'A and B together add x', 'combined', 'sum to', 'between them': the number is their sum
_SUM_CUE = re.compile(r"\b(?:together|combined|jointly|in total|taken together|between them|sum(?:s|med)? to|add up to|"
                      r"in sum)\b", re.IGNORECASE)
_OWN_QUANTITY = re.compile(r"\bof\s+(?:the\s+)?[$€£]?$", re.IGNORECASE)
_NEGATED = re.compile(r"\b(?:rather than|instead of|unlike|not(?! only)|n't)\s+"
                      r"(?:(?:because of|due to|about|the|its|their|a|an)\s+){0,3}$", re.IGNORECASE)
_SCORE_GAP = re.compile(r"^\W{0,3}(?:\(|=|:|\s)*(?:q(?:[\s-]*value)?\s*(?:=|:|of)?|scored|scores|score of|"
                        r"with a score of|came second at|"
                        r"second at|score|at|of|was|=)?\s*\(?(?:q\s*=\s*)?$", re.IGNORECASE)


_ENDS_AT = re.compile(r"\b(?:down|up|falls?|fell|drops?|dropped|rises?|rose|lands?|landed|ends? up|ended up|settles?|"
                      r"settled)\s+(?:at|to)\s+(?:about|around|roughly|only|just)?\s*[$€£]?$", re.IGNORECASE)
_FROM = re.compile(r"\bfrom\s+(?:(?:an?|the|its)\s+)?(?:(?:average|base(?:line)?|base rate|starting point|typical)"
                   r"(?:\s+(?:rate|value|estimate|prediction))?\s+(?:of\s+)?)?[$€£]?\s*$", re.IGNORECASE)
_FROM_TO = re.compile(r"\bfrom\s+[^;]{1,40}?\s+(?:down\s+|up\s+)?to\s+(?:about|around|roughly)?\s*[$€£]?$",
                      re.IGNORECASE)
#: 'the handover's lead of 3.9', 'turning's lead over going forward was 1.55'
_LEAD_OF = re.compile(r"\b(?:lead|margin|edge|advantage)(?:\s+over\s+[^\d;]{0,30}?)?\s+(?:of|was|is|=|:)\s+"
                      r"(?:about|around|roughly|only|just)?\s*$", re.IGNORECASE)
#: 'which typically scores around 1.3 goals': a habit of the background, when the number reads as a typical value
_TYPICALLY = re.compile(r"\b(?:typically|usually|normally|on average)\s+(?:[\w\0']+\s+){0,2}?(?:about|around|roughly|"
                        r"nearly|over|under|just|at least|at most|more than|less than)?\s*$", re.IGNORECASE)
#: ', year ' right before a number, after an item that had its number: a list's next item, named by a word the
#: vocabulary lacks (not ', by', ', at', ', worth' that go on with the same name)
_NEW_ITEM = re.compile(r",\s*(?!(?:by|at|of|with|and|to|from|for|in|on|adding|worth|costing|contributing|taking|"
                       r"about|around|roughly|some|nearly|almost|just|only|over|under|which|that|i\.e|e\.g)\b)"
                       r"(?P<words>[A-Za-z][A-Za-z ]{0,20})(?:[\d.,]+\s*[A-Za-z%]{0,5}\s*)?$", re.IGNORECASE)
#: 'a 43% predicted probability of default', 'an estimated $316,107 price' (not 'a 12% risk increase')
_OUTPUT_AFTER = re.compile(r"\s*(?:predicted|estimated|modell?ed)?\s*(?:probability|chance|likelihood|prediction|"
                           r"estimate)\b(?!\s+(?:increase|rise|drop|decrease|reduction|change|shift|gain|loss)\b)",
                           re.IGNORECASE)
#: 'speed argued for X (-5.48)', 'obstacle barely affected the turn score (-0.09)': the feature's contribution
_ARGUED = re.compile(r"\b(argu\w*|favou?r\w*|support\w*|help\w*|affect\w*|impact\w*|influenc\w*|matter\w*|"
                     r"shift\w*|worth)\b", re.IGNORECASE)


def _unless_guessed(c: Claim, n, masked: str, mentions, names, book: FactBook, ctx, sentence_keys) -> Claim:
    """A contradicted number that states another fact of a feature named in the sentence exactly (not truncated): the
    binding was a guess, so it is unchecked ('which is unclear'). A difference in a unit ('4.0 dB above') and a number
    right after its name ('battery +1.70') bind for sure; a bracket right after a name ('distance (2.33)') may only be
    that name's own fact, with its sign."""
    if quantities.DIFFERENCE_AFTER.match(masked[n.end:n.end + 16]):
        return c
    owner = next((m for m in reversed(mentions) if m.end <= n.start), None)
    if owner in names and re.fullmatch(r" ?", masked[owner.end:n.start]) and n.sign:
        return c  # 'battery +1.70': a signed number right after its name, a sure binding
    if owner in names and re.fullmatch(r"\s?\(", masked[owner.end:n.start]):
        other = quantities.other_reading(n, set(owner.keys), book, ctx, signed=True)
    else:
        other = quantities.other_reading(n, sentence_keys, book, ctx)
    return c if other is None else Claim("number", n.text, "unchecked",
                                         f"read as {c.detail}, but it is {other}: which is unclear")


def _bind_number(n, masked: str, mentions, names, paired, scored, book: FactBook, ctx, unit_of) -> Claim:
    """Which name a number belongs to, then its check: a pair of a 'respectively' list; an action right before it
    ('Turn (4.07)', 'staying scored 26.26') or right after it ('7.38 for staying'); a name right after it ('a 7-year
    credit history'); the name before it in its clause unless a new noun phrase starts between them; else none."""
    if id(n) in paired:
        return quantities.feature_number(n, paired[id(n)].keys, masked, book, ctx, unit_of)
    if quantities.is_change(n, masked):  # '$91,462 above the baseline', 'net uplift: +$86,046', 'below base by $34,184'
        return quantities.free_number(n, masked, book)
    if id(n) in scored:
        return quantities.action_number(n, checks.resolve_action(scored[id(n)], book), masked, book)
    span = max(0, n.start - 60)
    stat = quantities.statistic(masked[span:n.start], any(m.kind == "action" and span <= m.start < n.start
                                                          for m in mentions), book.output == "actions")
    if stat == "output" and book.output != "actions":  # 'the average sale price of $230,061', 'the baseline of 0.34'
        c = quantities.base_number(n, book)  # ... unless it is the prediction ('at the average risk: 33 %')
        if c.status == "verified" or not quantities.output_number(n, book).status == "verified":
            return c
    owner = next((m for m in reversed(names) if m.end <= n.start), None) or next(
        (m for m in names if 0 <= m.start - n.end <= 2), None)  # '... typically scores around 1.3 goals'
    habit = _TYPICALLY.search(masked[span:n.start])
    if habit and owner is not None and stat is None:  # 'the average team, which typically scores around 1.3 goals'
        c = quantities.typical_number(n, owner.keys, book)  # one reading; the number's plain binding is the other
        if c.status == "verified":
            return c
    if stat == "feature" and owner is not None:  # 'a ratio of 0.51, above the average of roughly 0.4'
        c = quantities.typical_number(n, owner.keys, book)
        return c if c.status == "verified" or book.base is None or not matches(n, book.base) else \
            quantities.base_number(n, book)  # 'with a 7-year history, the risk is above the average of 0.34'
    if stat == "feature" and book.output != "actions" and book.base and not 0.1 < abs(n.value / book.base) < 10:
        return Claim("number", n.text, "unchecked", "the typical value of something not named (not the output's "
                                                    "average: another order of magnitude)")
    if book.output != "actions" and _OUTPUT_AFTER.match(masked, n.end):
        return quantities.output_number(n, book)  # 'leading to a 43% predicted probability of default'
    if book.output != "actions" and _FROM.search(masked[max(0, n.start - 40):n.start]):
        return quantities.output_number(n, book, start=True)  # 'from 34.1 % to 43.0 %': where the output starts ...
    if book.output != "actions" and (_ENDS_AT.search(masked[max(0, n.start - 30):n.start]) or _FROM_TO.search(
            masked[max(0, n.start - 60):n.start])):
        return quantities.output_number(n, book)  # ... and ends up ('pull it down to 0.142')
    if book.margin is not None and _LEAD_OF.search(masked[max(0, n.start - 30):n.start]):
        return quantities.free_number(n, masked, book)  # "the handover's lead of 3.9": the margin, whatever is named
    after = masked[n.end:n.end + 24]
    nxt = next((m for m in mentions if m.start >= n.end and m.start - n.end <= 14), None)
    # '+22.0 for the handover' after a feature, 'worth 11.5 for ...': the feature's push, not the action's score
    pushes = (n.sign == "+" or re.search(r"\bworth\s*$", masked[:n.start])) and any(x.end <= n.start for x in names)
    if pushes and nxt is not None and nxt.kind == "action" and re.match(r"^\s*(?:for|to|toward|towards)\s+(?:the\s+)?$",
                                                                   masked[n.end:nxt.start]):
        owner = next(x for x in reversed(names) if x.end <= n.start)  # for one option over the other: either view
        return quantities.feature_number(n, owner.keys, masked, book, checks.EITHER, unit_of)
    if nxt is not None and nxt.kind == "action" and not pushes and re.match(r"^\s*(?:for|by)\s+(?:a\s+|an\s+|the\s+)?$",
                                                           masked[n.end:nxt.start]):
        return quantities.action_number(n, checks.resolve_action(nxt, book), masked, book)
    gap = masked[n.end:nxt.start] if nxt is not None else ""
    if nxt is not None and nxt.kind != "action" and re.match(r"^[\s-]*(?:[a-z]+[\s-]+){0,2}(?:of\s+)?$", gap,
                                                               re.IGNORECASE) \
            and not re.search(r"\b(and|or|but|while|with)\b", gap, re.IGNORECASE):
        return quantities.feature_number(n, nxt.keys, masked, book, ctx, unit_of, name_after=True)
    prev = next((m for m in reversed(mentions) if m.end <= n.start), None)
    feature_before = next((m for m in reversed(names) if m.end <= n.start), None)
    if prev is not None and prev.kind == "action" and n.sign and feature_before is not None and book.runner_up \
            and checks.resolve_action(prev, book) == book.runner_up and not masked[prev.end:n.start].strip():
        # 'speed gives recharging +5.48' when turning was chosen: -5.48 in the chosen action's margin
        flipped = replace(n, value=-n.value, sign="-" if n.sign == "+" else "+")
        return quantities.feature_number(flipped, feature_before.keys, masked, book, "margin", unit_of)
    if prev is not None and prev.kind == "action" and (
            n.sign == "+" or re.match(r"^\s*(over|than|versus|vs)\b", after, re.IGNORECASE) or (
            feature_before is not None and any(r.search(masked, feature_before.end, prev.start)
                                               for r in (checks.DIRECTION_RE, _ARGUED)))):
        prev = feature_before  # '(+2.05)' after 'supported recharging': the feature's contribution
    if prev is not None and prev.kind == "action":
        if _SCORE_GAP.match(masked[prev.end:n.start]) or quantities.MARGIN_BEFORE.search(masked[prev.end:n.start]):
            return quantities.action_number(n, checks.resolve_action(prev, book), masked, book)
        prev = next((m for m in reversed(names) if m.end <= n.start), None)
    gap_text = re.sub(r"\([^()]*\)", "()", masked[prev.end:n.start]) if prev is not None else ""
    item = _NEW_ITEM.search(gap_text)
    if item is not None and re.search(r"\d", gap_text[:item.start()]) and not re.search(
            r"ed\b|\b(?:adds|raises|lowers|costs|pushes|cuts)\b", item.group("words")) and not checks.DIRECTION_RE.search(
            item.group("words")):  # '1,270 sq ft -12.1k, year 1945': a new item (not '..., added 6.8')
        prev = None
    if prev is not None and not re.search(r"(?:,\s*|\sand\s+)(?:and\s+)?(?:a|an|the|its|their|his|her|zero|no)\s"
                                          r"(?!(?:most|second|third|main|largest|biggest|top|strongest)\b)",
                                          masked[prev.end:n.start], re.IGNORECASE):
        return quantities.feature_number(n, prev.keys, masked, book, ctx, unit_of)
    return quantities.free_number(n, masked, book)


#: a sentence about what did not happen: 'Had X been better, ...', 'Without X, it would have ...', 'If it were not
#: for X'; a modal elsewhere ('chose recharge, which could save battery') leaves the rest of the sentence checked
_HYPOTHETICAL = re.compile(r"^\W*(?:if|had|without|were|absent|but for)\b|\b(?:would|could|might)(?:\s+\w+ly)?\s+"
                           r"(?:(?:not|never)\s+)?(?:have|be)\b|\bif it (?:were|was)(?:n't| not) for\b", re.IGNORECASE)
_PAIR_RE = re.compile(r"^\((?:[^()\0]*?(?:,|\band\b|/)\s*)+[^()\0]*\)$")  # '(+9.45 and +8.66)' after 'A and B'

