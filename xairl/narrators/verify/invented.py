"""An invented feature said to push: a feature-like identifier (``wind_speed``, ``windSpeed``, ``obs[7]``, or what
follows 'the feature': 'the feature humidity') that names nothing of the explanation, and that its clause gives a
contribution, a number or a direction after it ('The feature wind_speed contributed +0.50 toward this action'):
contradicted, rule ``identifier.invented``. An identifier with a number or a direction word right after it
('wind_speed=+0.3', 'wind_speed pushed ...') is the sentence reader's (``identifier.claimed``); plain words that are no
identifiers are never read here ('the weather raised it by 0.3' may name a feature in words the vocabulary lacks)."""

from __future__ import annotations

import re

from xairl.narrators.verify import checks, sums
from xairl.narrators.verify.book import FactBook
from xairl.narrators.verify.checks import Claim
from xairl.narrators.verify.lexicon import GENERIC, STOP, UNIT_PARTS
from xairl.narrators.verify.names import Mention
from xairl.narrators.verify.numbers import matches
from xairl.narrators.verify.quantities import CONTRIB_BEFORE
from xairl.narrators.verify.vocabulary import split_words, stem

#: identifiers: snake_case ('wind_speed'), camelCase ('windSpeed'), a name and its index ('obs[7]', 'sensor_data[2,3]')
_INDEX = r"\[\s*[+\-]?\d+(?:\s*,\s*[+\-]?\d+)*\s*\]"
_IDENT = re.compile(
    r"(?<![\w\0\-./@#'])(?:"
    r"(?:(?P<snake>[A-Za-z][A-Za-z0-9]*(?:_[A-Za-z0-9]+)+)|(?P<camel>[a-z]{2,}[0-9]*(?:[A-Z][a-z0-9]+)+))"
    rf"(?P<idx>{_INDEX})?|[A-Za-z_][A-Za-z0-9_]*{_INDEX})(?![\w\0\-@]|\.\w)"
)
#: 'the feature humidity', 'the input feature called "relative humidity"', 'feature wind_speed'
_THE_FEATURE = re.compile(
    r"\b(?:the|a|an|one|input|state|observation)\s+(?:(?:input|state|observation|model)\s+)?"
    r"(?:feature|variable|input)\s+(?:(?:called|named|labell?ed)\s+)?"
    r"(?:(?P<q>[\"'“‘`])(?P<quoted>[A-Za-z][\w \-\[\],]{1,40}?)[\"'”’`]|(?P<word>[A-Za-z][A-Za-z0-9]{2,}))",
    re.IGNORECASE,
)
#: words after 'the feature' that are no name: 'the feature importance', 'the feature that ...', 'the feature most ...'
_NOT_A_NAME = frozenset(
    """importance importances values value attribution attributions contribution contributions name names space set
    sets vector vectors map maps list lists ranking rankings that which who whose with without most least alone itself
    here there is was are were has had have did does do can could would will may might should must also still only
    just then thus again mattered matters pushed pushes pulled pulls added adds raised raises lowered lowers drove
    drives dominated dominates explains explained itself this those these its their matrix table column columns row
    rows effect effects impact impacts weight weights level levels count counts group groups engineering selection
    extraction scaling store pipeline wise""".split()
)
#: words of no feature: a method or a library ('deep_shap', 'kernel_shap', 'integrated_gradients'), a
#: decision-level quantity ('base_value', 'q_value', 'y_hat', 'p_default'), a record of the run ('run_id', 'n_samples')
_NOT_A_FEATURE = frozenset(
    """shap deepshap kernelshap treeshap lime captum gradient gradients integrated saliency deeplift lrp occlusion
    attribution attributions explainer explainers phi sum total net abs base baseline expected value values pred
    predicted prediction predictions yhat hat output outputs logit logits prob proba probability score scores margin
    delta gap q v id ids uuid run runs seed seeds step steps episode episodes epoch epochs version ts timestamp
    sample samples samples batch lr n k np torch sklearn pandas df data dataset model models policy policies agent env
    obs observation observations action actions reward rewards return returns""".split()
)
#: an unsigned number after only these words is given to what precedes it ('humidity_pct of 71', 'windSpeed was 8')
_GIVEN = re.compile(
    r"^\W{0,3}(?:(?:value|reading|level)\s+)?(?:(?:is|was|were|are|of|at|stood at|reads?|read|equals?|"
    r"came in at|sat at|measured)\b|[=:(])\W{0,2}(?:(?:about|around|roughly|nearly|almost|approximately|some|only|"
    r"just)\s+)?[+\-]?[$€£]?\s*$",
    re.IGNORECASE,
)
#: a negation or a contrast before the identifier: 'not wind_speed', 'rather than wind_speed', 'unlike windSpeed'
_NEGATED = re.compile(
    r"(?:\b(?:not|no|never|rather than|instead of|unlike|than|without|ignoring|excluding|except|nor|neither)|n't)"
    r"\s+(?:(?:the|a|an|its|their|feature|variable|input)\s+){0,3}$",
    re.IGNORECASE,
)
_SADJACENT = re.compile(r"\s?[:=(]?\s?(?=[+\-]?[$€£]?\.?\d)")
_TWO_WORDS = re.compile(r"(?:\s+[a-z]+){0,2}\s+")


def _norm(s: str) -> str:
    return re.sub(r"[^a-z0-9]", "", s.lower())


def _reader_takes(masked: str, end: int) -> bool:
    """Does the sentence reader's own identifier reading (``identifier.claimed`` / ``identifier.other``) judge this
    one: a number or a direction word right after it? Then it is not read twice."""
    if _SADJACENT.match(masked[end : end + 6]):
        return True
    pushes = checks.DIRECTION_RE.search(masked, end, end + 30)
    return pushes is not None and bool(_TWO_WORDS.fullmatch(masked[end : pushes.start()]))


def _known(token: str, book: FactBook, vocab, unit_of) -> bool:
    """Does ``token`` name, or belong to, something of the explanation: a feature (any word of one feature's name,
    description or aliases, their stems, a run of one feature's name), an action, a category label, a unit?"""
    norm = _norm(token)
    if not norm:
        return True
    names = [*book.features, *book.scores]
    labels = [e[3] for e in vocab.entries if e[1] == "label" and e[3]]
    units = {_norm(unit_of(f)) for f in book.features if unit_of(f)}
    if any(norm == _norm(x) for x in [*names, *labels]) or norm in units:
        return True
    if len(norm) >= 4 and any(norm in _norm(f) for f in book.features):
        return True  # part of a known feature's name ('charger_queue' of charger_queue_len)
    words = [w for w in split_words(token) if not w.isdigit()]
    if any(w in _NOT_A_FEATURE for w in words) or any(w.startswith(("shap", "phi")) for w in words):
        return True  # ('kernel_shap', 'base_value', 'run_id', 'sum_phi')
    words = [w for w in words if len(w) >= 3 and w not in UNIT_PARTS and w not in STOP and w not in _ITS_PUSH]
    if not words:
        return True  # ('x_t', 's_1', 'avg_ms': notation or a statistic, nothing a feature is named by)
    for own in vocab.words.values():  # every word one feature's own, or a word it starts ('wait_max' of waiting_max)
        if all(_covered(w, own) for w in words):
            return True  # ('door_dwell_effect' of door_dwell: its push)
    others = {w for x in [*book.scores, *labels] for w in split_words(x)}
    return all(_covered(w, others) for w in words)  # an action's or a label's words ('reduce_12kn', 'turn_left')


#: words that name a feature's push, not another feature ('door_dwell_effect', 'speed_contrib')
_ITS_PUSH = frozenset(
    "effect effects impact contrib contribution importance term weight push share attr influence".split()
)


def _covered(word: str, pool) -> bool:
    """Is ``word`` one of ``pool``'s, a start of one or started by one ('wait' of 'waiting', '12kn' of '12'), or its
    stem?"""
    s = stem(word)
    return any(
        k.startswith(word) or (word.startswith(k) and (len(k) >= 3 or k.isdigit())) or stem(k) == s
        for k in pool
        if len(k) >= 2
    )


def _candidates(masked: str, a: int, b: int):
    """(start, end, token, identifier) of each feature-like identifier or 'the feature X' in clause ``a..b``."""
    out = []
    for m in _IDENT.finditer(masked, a, b):
        token = m.group(0)
        if token.isupper() or re.search(r"[=:]\s*$", masked[max(a, m.start() - 3) : m.start()]):
            continue  # a constant or an action's code ('EXTEND_NS'), a field's value ('act=reduce_12kn')
        out.append((m.start(), m.end(), token, bool(m.group("snake")) and not m.group("idx")))
    for m in _THE_FEATURE.finditer(masked, a, b):
        g = "quoted" if m.group("quoted") else "word"
        token, start, end = m.group(g), m.start(g), m.end(g) + (1 if g == "quoted" else 0)
        if any(s <= start < e for s, e, _, _ in out):
            continue
        if g == "word" and (
            token.lower() in _NOT_A_NAME
            or token.lower() in STOP
            or token.lower() in GENERIC
            or token.lower().endswith(("ly", "ed", "ing"))
        ):
            continue
        out.append((start, end, token, False))
    return sorted(out)


def invented(
    masked: str, a: int, b: int, mentions: list[Mention], numbers, book: FactBook, vocab, unit_of, claimed=()
) -> list[Claim]:
    """The invented features of clause ``a..b`` (rule ``identifier.invented``): a candidate (:func:`_candidates`) that
    names nothing of the explanation (:func:`_known`), not negated, followed in its clause, before any known name, by
    a signed number, a number after contribution words ('contributed 0.5'), an unsigned number given to it ('of
    71', 'was 8'; not a decision-level number) or a direction word. ``claimed``: texts already contradicted as
    features in the clause (not read twice)."""
    out: list[Claim] = []
    for start, end, token, snake in _candidates(masked, a, b):
        if "\0" in token or (snake and _reader_takes(masked, end)) or any(token in c for c in claimed):
            continue
        if _NEGATED.search(masked, a, start) or _known(token, book, vocab, unit_of):
            continue
        nxt = next((m.start for m in mentions if m.start >= end and m.kind in ("feature", "label")), b)
        said = _said_of(masked, end, min(nxt, b), numbers, book)
        if said is None:
            continue
        names = sorted(book.features)
        shown = ", ".join(names[:12]) + (f" and {len(names) - 12} more" if len(names) > 12 else "")
        acts = [x for x in book.scores if book.output == "actions"]
        out.append(
            Claim(
                "feature",
                token,
                "contradicted",
                f"{said}, but no feature of this explanation is named {token!r} (its features: {shown}"
                + (f"; its actions: {', '.join(acts[:8])}" if acts else "")
                + ")",
                "identifier.invented",
            )
        )
    return out


def _said_of(masked: str, end: int, stop: int, numbers, book: FactBook) -> str | None:
    """What the words after an identifier, up to ``stop``, give it: a signed number, a number after contribution
    words, a number given to it, a direction word; None for nothing."""
    pushes = next((m for m in checks.DIRECTION_RE.finditer(masked, end, stop) if not checks.is_frame(masked, m)), None)
    for n in (n for n in numbers if end <= n.start < stop):
        if pushes is not None and pushes.start() < n.start:
            break
        before = masked[end : n.start]
        if re.search(r"[A-Za-z_]\w*['\"]?\s*[=:]", before):
            return None  # another field's number ('a=EXTEND_NS Q=-18.63')
        if any(matches(n, x, magnitude_ok=False) for x in book.decision_numbers) or sums.AGGREGATE_CUE.search(before):
            return None  # ('y_hat rose to 52.1': the prediction, named by a variable; a sum)
        if not n.sign and re.fullmatch(r"['\"]?\s*[:=]\s*", before):
            return None  # a record's field ('"eta_h": 19.7'); an invented feature is given a push ('"wind": +0.3')
        if n.sign or CONTRIB_BEFORE.search(before[-40:]) or _GIVEN.match(before):
            return f"given {n.text}"
        return None  # (a number of something else first: 'n_trees of the forest, 300 in all')
    if pushes is not None:
        return f"'{pushes.group(0)}' is said of it"
    return None
