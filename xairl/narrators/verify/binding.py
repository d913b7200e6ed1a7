"""Which fact a number states: the name it is bound to (a pair of a 'respectively' list, an action right before or
after it, a name right after it, the name before it in its clause) or a decision-level quantity its cue words name
(the change from the baseline, a typical value, the baseline, where the output starts or ends, the margin), then its
check in :mod:`.quantities` or :mod:`.decision` (a contradicted guess is read again in :mod:`.reread`)."""

from __future__ import annotations

import functools
import re
from dataclasses import replace

from xairl.narrators.verify import background, checks, decision, quantities, sums
from xairl.narrators.verify.book import FactBook
from xairl.narrators.verify.checks import Claim
from xairl.narrators.verify.numbers import matches
from xairl.narrators.verify.vocabulary import split_words

_SCORE_GAP = re.compile(
    r"^\W{0,3}(?:\(|=|:|\s)*(?:(?:q(?:[\s-]*value)?(?:\s*(?:=|:|of))?|scored|scores|score of|"
    r"with a score of|came second (?:at|with)|"
    r"second at|score|at|of|was|=)\s*)?\(?(?:q\s*=\s*)?$",
    re.IGNORECASE,
)


_ENDS_AT = re.compile(
    r"\b(?:down|up|falls?|fell|drops?|dropped|rises?|rose|lands?|landed|ends? up|ended up|settles?|"
    r"settled)\s+(?:at|to)\s+(?:about|around|roughly|only|just)?\s*[$€£]?$|"
    r"\b(?:drags?|dragged|pushe?s?|pushed|pulls?|pulled|brings?|brought|takes?|took|moves?|moved|"
    r"lowers?|lowered|raises?|raised|lifts?|lifted)\b[^.;]{0,40},?(?<!close)(?<!due)(?<!thanks)"
    r"(?<!up)(?<!next)(?<!compared)(?<!relative)(?<!similar)\s+to\s+(?:about|around|roughly|only|"
    r"just)?\s*[$€£]?$",
    re.IGNORECASE,
)  # ('drags it well below the 34 % base, to about 14 %')
_FROM = re.compile(
    r"\bfrom\s+(?:(?:an?|the|its)\s+)?(?:(?:average|base(?:line)?|base rate|starting point|typical)"
    r"(?:\s+(?:rate|value|estimate|prediction|q(?:[\s-]?value)?))?\s+(?:of\s+)?)?[$€£]?\s*$",
    re.IGNORECASE,
)
_FROM_TO = re.compile(
    r"\bfrom\s+[^;]{1,40}?\s+(?:down\s+|up\s+)?to\s+(?:(?:about|around|roughly)\s*)?[$€£]?$", re.IGNORECASE
)
#: '..., giving 39.5%': where the output ends (an unsigned number; '..., giving +14.7' is a push)
_GIVING = re.compile(
    r"(?:,\s*|\bwhich\s+)(?:giving|gives|for a final|to give|yielding|yields)\s+(?:about\s+|"
    r"roughly\s+|around\s+)?[$€£]?$",
    re.IGNORECASE,
)
#: 'the handover's lead of 3.9', 'turning's lead over going forward was 1.55'
_LEAD_OF = re.compile(
    r"\b(?:lead|margin|edge|advantage)(?:\s+over\s+[^\d;]{0,30}?)?\s+(?:of|was|is|=|:)\s+"
    r"(?:about|around|roughly|only|just)?\s*$",
    re.IGNORECASE,
)
#: 'which typically scores around 1.3 goals': a habit of the background, when the number reads as a typical value
_TYPICALLY = re.compile(
    r"\b(?:typically|usually|normally|on average)\s+(?:[\w\0']+\s+){0,2}?(?:about|around|roughly|"
    r"nearly|over|under|just|at least|at most|more than|less than)?\s*$",
    re.IGNORECASE,
)
#: ', year ' right before a number, after an item that had its number: a list's next item, named by a word the
#: vocabulary lacks (not ', by', ', at', ', worth' that go on with the same name)
_NEW_ITEM = re.compile(
    r",\s*(?!(?:by|at|of|with|and|to|from|for|in|on|adding|worth|costing|contributing|taking|"
    r"about|around|roughly|some|nearly|almost|just|only|over|under|which|that|i\.e|e\.g)\b)"
    r"(?P<words>[A-Za-z]+(?: [A-Za-z]+){0,2} ?)(?:[\d.,]+\s*[A-Za-z%]{0,5}\s*)?$",
    re.IGNORECASE,
)
#: verbs that go on with the same name ('..., accounts for some 14 points'), not a new item's label
_ITEM_VERB = re.compile(
    r"ed\b|\b(?:is|was|are|were|has|had|have|accounts?|adds?|gives?|takes?|brings?|makes?|puts?|"
    r"contributes?|explains?|costs?|counts?|weighs?|pulls?|pushes?|lowers?|raises?|cuts?|"
    r"drives?|moves?|shifts?|sits?|comes?)\b",
    re.IGNORECASE,
)
#: "it's worth about $316k", 'your chance of default is put at 43 in 100': the thing the model is about, valued
OUTPUT_BEFORE = re.compile(
    r"\b(?:estimated\s+|predicted\s+)?q[\s-]?values?\s+(?:of|at|is|was|=|:)\s*(?:about|around|roughly|"
    r"approximately|just under|just over|nearly|almost)?\s*$|"
    r"\b(?:it|this house|the house|the home|this home|the property|your home|your house)"
    r"(?:'s| is| was| would be|'d be)\s+(?:now\s+|still\s+)?(?:worth|valued at|priced at|"
    r"estimated at|put at)\s+"
    r"(?:about|around|roughly|some|just under|just over|nearly|almost)?\s*[$€£]?$|"
    r"\b(?:chance|risk|probability|likelihood) of [\w\s]{1,20}? is (?:put |estimated |rated )?"
    r"at\s+(?:about|around|roughly)?\s*$|"
    r"\b(?:predicted\s+|estimated\s+)?(?:probability|chance|likelihood)\s+(?:of|is|was|=|:)\s*"
    r"(?:about|around|roughly|only|just)?\s*$",  # 'a predicted probability of 66%'
    re.IGNORECASE,
)
#: 'a 43% predicted probability of default', 'an estimated $316,107 price' (not 'a 12% risk increase')
_OUTPUT_AFTER = re.compile(
    r"\s*(?:(?:predicted|estimated|modell?ed)\s*)?(?:probability|chance|likelihood|prediction|"
    r"estimate)\b(?!\s+(?:increase|rise|drop|decrease|reduction|change|shift|gain|loss)\b)"
    r"|\s*(?:predicted|forecast)\s*(?:[.;,)]|$)",  # ('$1,850 baseline, $2,739 predicted.')
    re.IGNORECASE,
)
#: a percentage, one word and the output's noun: 'a 9.2% return chance', '41.6% return risk' (not '5 points of
#: risk', '7.2 extra risk')
_PERCENT_OUTPUT = re.compile(
    r"\s*(?!(?:of|in|to|for|the|a|an|and|or|at|by|on|more|extra|additional|less|added|"
    r"points?|pp|pts|units?)\b)(?:[a-z]+|\0+)\s+(?:probability|chance|likelihood|risk)\b"
    r"(?!\s+(?:increase|rise|drop|decrease|reduction|change|shift|gain|loss)\b)",
    re.IGNORECASE,
)
#: 'speed argued for X (-5.48)', 'obstacle barely affected the turn score (-0.09)': the feature's contribution
_ARGUED = re.compile(
    r"\b(argu\w*|favou?r\w*|support\w*|help\w*|affect\w*|impact\w*|influenc\w*|matter\w*|"
    r"shift\w*|worth)\b",
    re.IGNORECASE,
)


#: what a push comes from, right after its number: '19 points of that come from the contract', 'about 14 from the
#: 12% price increase' (a value of the name may stand before it)
_FROM_NAME = re.compile(
    r"\s*(?:(?:percentage points?|points?|pts|pp)\s*)?(?:of (?:that|it|this)\s+)?"
    r"(?:comes?\s+|came\s+)?"
    r"(?:from|due to|thanks to|because of)\s+(?:the\s+|its\s+|their\s+|his\s+|her\s+|a\s+|an\s+)?"
    r"(?:[\d.,]+(?:\s*%)?\s+)?(?=\0)",
    re.IGNORECASE,
)


def bind_number(n, masked: str, mentions, names, paired, scored, book: FactBook, ctx, unit_of) -> Claim:
    """Which fact a number states, then its check: a pair of a 'respectively' list; the change from the baseline, a
    statistic of the background (the baseline, a feature's typical value), the prediction or the margin when its cue
    words say so; an action right before it ('Turn (4.07)', 'staying scored 26.26') or right after it ('7.38 for
    staying'); a name right after it ('a 7-year credit history'); the name before it in its clause unless a new noun
    phrase or list item starts between them; else none."""
    if id(n) in paired:
        return named(
            quantities.feature_number(n, paired[id(n)].keys, masked, book, ctx, unit_of), "number.respectively"
        )
    if decision.in_output_name(n, masked, book):  # 'sending unit 7' of "Q-value of the action 'send unit 7'"
        return Claim("number", n.text, "unchecked", "a number of the output's name", "number.output-name")
    summed = sums.sum_reading(n, masked, names, book)
    if summed is not None:  # 'the positives add up to +0.39', 'without the add-on's contribution it would be 12.4%'
        return summed
    if decision.is_change(n, masked):  # '$91,462 above the baseline', 'net uplift: +$86,046', 'below base by $34,184'
        return named(decision.free_number(n, masked, book), "number.change")
    if id(n) in scored:
        return named(
            decision.action_number(n, checks.resolve_action(scored[id(n)], book), masked, book), "number.action-scores"
        )
    by_cue = _by_cue(n, masked, mentions, names, book)
    if by_cue is not None:
        return named(by_cue, "number.cue")
    src = _FROM_NAME.match(masked, n.end)
    owner = next((m for m in names if src and m.start == src.end()), None)
    if owner is not None:  # 'about 14 from the 12% price increase': that name's push
        return named(quantities.feature_number(n, owner.keys, masked, book, ctx, unit_of), "number.from-name")
    nxt = next((m for m in mentions if m.start >= n.end and m.start - n.end <= 14), None)
    # '+22.0 for the handover' after a feature, 'worth 11.5 for ...': the feature's push, not the action's score
    pushes = (n.sign == "+" or re.search(r"\bworth\s*$", masked[: n.start])) and any(x.end <= n.start for x in names)
    if (
        pushes
        and nxt is not None
        and nxt.kind == "action"
        and re.match(r"^\s*(?:for|to|toward|towards)\s+(?:the\s+)?$", masked[n.end : nxt.start])
    ):
        owner = next(x for x in reversed(names) if x.end <= n.start)  # for one option over the other: either view
        return named(quantities.feature_number(n, owner.keys, masked, book, checks.EITHER, unit_of), "number.push-for")
    if (
        nxt is not None
        and nxt.kind == "action"
        and book.output != "actions"
        and re.match(
            r"^\s*(?:in|of|as)?\s*(?:the\s+|an?\s+)?(?:predicted\s+|expected\s+|estimated\s+)?$",
            masked[n.end : nxt.start],
        )
    ):
        return named(decision.output_number(n, book), "number.output-after")  # '$2,603 in expected claim cost'
    if (
        nxt is not None
        and nxt.kind == "action"
        and not pushes
        and re.match(r"^\s*(?:for|by)\s+(?:a\s+|an\s+|the\s+)?$", masked[n.end : nxt.start])
    ):
        return named(decision.action_number(n, checks.resolve_action(nxt, book), masked, book), "number.for-action")
    gap = masked[n.end : nxt.start] if nxt is not None else ""
    ends_item = bool(n.sign) or bool(re.search(r"[=:]\s*$", masked[: n.start]))  # 'wait_max -2.31 elapsed -1.46',
    # 'E[Q]=1.20 battery_pct=31': a signed number or a field's value ends the item before, it does not start the next
    if (
        nxt is not None
        and nxt.kind != "action"
        and not ends_item
        and re.match(r"^[\s-]*(?:[a-z]+[\s-]+){0,2}(?:of\s+)?$", gap, re.IGNORECASE)
        and not re.search(r"\b(and|or|but|while|with)\b", gap, re.IGNORECASE)
    ):
        return named(quantities.feature_number(n, nxt.keys, masked, book, ctx, unit_of, name_after=True), GUESSED[0])
    return named(_by_name_before(n, masked, mentions, names, book, ctx, unit_of), GUESSED[1])


#: the bindings made by position alone (the name right after a number, the name before it, no name at all): a
#: parse may correct them
GUESSED = ("number.name-after", "number.name-before", "number.free")


def named(c: Claim, rule: str) -> Claim:
    """``c`` with the id of the reading that made it, unless a more specific one already named it."""
    return c if c.rule else replace(c, rule=rule)


#: a log line's key before its value ('pred=0.469', 'yhat: 2738.6', 'base=0.26', 'ev=1850'): what the value is
_KEY_OUTPUT = re.compile(
    r"(?:^|[\s,;|(\[{])(?:pred\w*|yhat|y_hat|y|out|output|p|prob\w*|p_\w+|score|q)\s*[=:]\s*$", re.IGNORECASE
)
_KEY_BASE = re.compile(
    r"(?:^|[\s,;|(\[{])(?:base\w*|ev|e\[f\(x\)\]|expected_value|mean_pred\w*|avg)\s*[=:]\s*$", re.IGNORECASE
)


def _output_is(before: str, book: FactBook) -> bool:
    """'the forecast is 53', 'the expected claim cost stands at $2,738.60': one output's word, then its number."""
    return bool(_output_words(tuple(book.scores)).search(before))


@functools.lru_cache(maxsize=64)
def _output_words(outputs: tuple[str, ...]) -> re.Pattern:
    words = {w for a in outputs for w in split_words(a) if len(w) >= 4} | {"forecast", "prediction", "estimate"}
    return re.compile(
        rf"\b(?:{'|'.join(map(re.escape, sorted(words)))})\s+(?:(?:is|was|stands at|stood at|comes out at|"
        rf"came out at|sits at|=|:)\s*(?:about|around|roughly|approximately|just under|just over|"
        rf"nearly|almost)?|about|around|roughly|approximately)\s*[$€£]?$",
        re.IGNORECASE,
    )  # (and 'to cost
    # around $2,600' of a claim cost)


def _by_cue(n, masked: str, mentions, names, book: FactBook) -> Claim | None:
    """A number whose cue words say what it is, whatever name is near: a statistic of the background (the baseline,
    a feature's typical value), the prediction ('a 43% predicted probability', 'from x to y'), the margin ('the
    8.32-point lead'); None when they say nothing."""
    span = max(0, n.start - 60)
    if book.output != "actions" and book.base is not None:
        if (
            background.first_of_the_average(n, masked) and not any(m.start < n.start + 16 for m in names)
        ) or _KEY_BASE.search(masked[span : n.start]):  # ('On average, 23-year-old drivers': a driver's age)
            return background.base_number(n, book)  # 'On average, a student has about an 18% chance', 'base=0.3'
        if _KEY_OUTPUT.search(masked[span : n.start]) or _output_is(masked[span : n.start], book):
            return decision.output_number(n, book)
    stat = background.statistic(
        masked[span : n.start],
        any(m.kind == "action" and span <= m.start < n.start for m in mentions),
        book.output == "actions",
        bool(re.match(r"[^()]*?\b(?:vs\.?|versus|compared)\b", masked[n.end : n.end + 40])),
    )
    if stat == "output" and book.output != "actions":  # 'the average sale price of $230,061', 'the baseline of 0.34'
        c = background.base_number(n, book)  # ... unless it is the prediction ('at the average risk: 33 %')
        if c.status == "verified" or decision.output_number(n, book).status != "verified":
            return c
    owner = next((m for m in reversed(names) if m.end <= n.start), None) or next(
        (m for m in names if 0 <= m.start - n.end <= 2), None
    )  # '... typically scores around 1.3 goals'
    if _TYPICALLY.search(masked[span : n.start]) and owner is not None and stat is None:
        c = background.typical_number(n, owner.keys, book)  # 'which typically scores around 1.3 goals': one reading,
        if c.status == "verified":  # the number's plain binding is the other
            return c
    if stat == "feature" and owner is not None:  # 'a ratio of 0.51, above the average of roughly 0.4'
        c = background.typical_number(n, owner.keys, book)
        return (
            c
            if c.status == "verified" or book.base is None or not matches(n, book.base)
            else background.base_number(n, book)
        )  # 'with a 7-year history, the risk is above the average of 0.34'
    if (
        stat == "feature"
        and book.output != "actions"
        and book.base
        and not 0.1 < abs(n.value / (100 if n.percent else 1) / book.base) < 10
    ):
        return Claim(
            "number",
            n.text,
            "unchecked",
            "the typical value of something not named (not the output's average: another order of magnitude)",
        )
    if book.output != "actions" and (
        _OUTPUT_AFTER.match(masked, n.end)
        or (n.percent and not n.points and _PERCENT_OUTPUT.match(masked, n.end))
        or OUTPUT_BEFORE.search(masked[span : n.start])
    ):  # '... leading to a 43% predicted probability', "it's worth $316k"
        return decision.output_number(n, book)
    if book.output != "actions" and _FROM.search(masked[max(0, n.start - 40) : n.start]):
        return decision.output_number(n, book, start=True)  # 'from 34.1 % to 43.0 %': where the output starts ...
    if book.output != "actions" and (
        _ENDS_AT.search(masked[max(0, n.start - 70) : n.start])
        or (not n.sign and _GIVING.search(masked[max(0, n.start - 40) : n.start]))
        or _FROM_TO.search(masked[span : n.start])
    ):
        return decision.output_number(n, book)  # ... and ends up ('pull it down to 0.142')
    if book.margin is not None and (
        _LEAD_OF.search(masked[max(0, n.start - 30) : n.start])
        or decision.MARGIN_AFTER.match(masked[n.end : n.end + 30])
    ):  # 'the 8.32-point lead'
        return decision.free_number(n, masked, book)  # "the handover's lead of 3.9": the margin, whatever is named
    return None


def _by_name_before(n, masked: str, mentions, names, book: FactBook, ctx, unit_of) -> Claim:
    """The name before a number: an action's score ('staying scored 26.26') or, after it, a feature's push
    ('supported recharging (+2.05)'); else the feature nearest before it in its clause unless a new noun phrase or
    list item starts between them; else a number tied to no name."""
    after = masked[n.end : n.end + 24]
    prev = next((m for m in reversed(mentions) if m.end <= n.start), None)
    feature_before = next((m for m in reversed(names) if m.end <= n.start), None)
    if (
        prev is not None
        and prev.kind == "action"
        and n.sign
        and feature_before is not None
        and book.runner_up
        and checks.resolve_action(prev, book) == book.runner_up
        and not masked[prev.end : n.start].strip()
    ):
        # 'speed gives recharging +5.48' when turning was chosen: -5.48 in the chosen action's margin
        flipped = replace(n, value=-n.value, sign="-" if n.sign == "+" else "+")
        return named(
            quantities.feature_number(flipped, feature_before.keys, masked, book, "margin", unit_of),
            "number.gives-runner-up",
        )
    if (
        prev is not None
        and prev.kind == "action"
        and (
            n.sign == "+"
            or re.match(r"^\s*(over|than|versus|vs)\b", after, re.IGNORECASE)
            or (
                feature_before is not None
                and any(r.search(masked, feature_before.end, prev.start) for r in (checks.DIRECTION_RE, _ARGUED))
            )
        )
    ):
        prev = feature_before  # '(+2.05)' after 'supported recharging': the feature's contribution
    if prev is not None and prev.kind == "action":
        if _SCORE_GAP.match(masked[prev.end : n.start]) or decision.MARGIN_BEFORE.search(masked[prev.end : n.start]):
            return named(
                decision.action_number(n, checks.resolve_action(prev, book), masked, book), "number.action-before"
            )
        prev = next((m for m in reversed(names) if m.end <= n.start), None)
    gap_text = re.sub(r"\([^()]*\)", "()", masked[prev.end : n.start]) if prev is not None else ""
    listed = re.search(r"\(\),\s(?P<rest>[^()]*)\(?$", gap_text)
    if (
        listed
        and not re.search(
            r"\b(?:by|which|that|who|with|at|of|and|to|for|worth|it|its)\b", listed.group("rest"), re.IGNORECASE
        )
        and not _ITEM_VERB.search(listed.group("rest"))
        and not checks.DIRECTION_RE.search(listed.group("rest"))
    ):
        prev = None  # 'Tuesday (+0.3), 31.5 °C (+0.7)': a list's next item, its label the vocabulary lacks (not
        # 'A (2.04), by +7.86', 'A (-0.45), which favoured B by 2.03': the same name's)
    item = _NEW_ITEM.search(gap_text)
    if (
        item is not None
        and re.search(r"\d", gap_text[: item.start()])
        and not _ITEM_VERB.search(item.group("words"))
        and not checks.DIRECTION_RE.search(item.group("words"))
    ):  # '..., year 1945' (not '..., added 6.8')
        prev = None
    if (
        prev is not None
        and not re.search(
            r"(?:,\s*|\sand\s+)(?:and\s+)?(?:a|an|the|its|their|his|her|zero|no)\s"
            r"(?!(?:most|second|third|main|largest|biggest|top|strongest|shap|"
            r"contribution|attribution|impact|effect)\b)",  # (not 'and a SHAP value of':
            # the same name's)
            masked[prev.end : n.start],
            re.IGNORECASE,
        )
    ):
        return quantities.feature_number(n, prev.keys, masked, book, ctx, unit_of)
    return named(decision.free_number(n, masked, book), "number.free")
