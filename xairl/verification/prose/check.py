"""Each resolved reading checked against the fact book: verified, contradicted, or unchecked.

A claim is contradicted only when its rule binds the name by adjacency or grammar; a number bound to nothing is
verified when it states a decision-level fact (the prediction, the baseline, a score, the margin) and else left
unchecked. A negated or hypothetical direction or rank ('did not raise', 'would have lowered') is left unchecked. A
categorical value's label and a closed-class word bind by what they are (:func:`label_claim`, :func:`_class`).
"""

from __future__ import annotations

from dataclasses import replace

from xairl.verification.prose.book import FactBook
from xairl.verification.prose.checks import EITHER, check_direction, over_keys, resolve_action
from xairl.verification.prose.comparisons import check_comparison
from xairl.verification.prose.decision import action, every, framed, mention, verb_of
from xairl.verification.prose.lexicon import lexicon
from xairl.verification.prose.numbers import matches, percent_reading
from xairl.verification.prose.parse import Sentence
from xairl.verification.prose.quantities import feature_number
from xairl.verification.prose.rules import Candidate
from xairl.verification.prose.vocabulary import split_words, stem
from xairl.verification.result import Claim


def view(s: Sentence, book: FactBook) -> str:
    """'chosen' for one output; for a decision between actions, 'margin' when the sentence names the runner-up or
    weighs the two ('rather than', 'over', 'margin'), else either view."""
    if not book.runner_up:
        return "chosen"
    actions = [t for t in s.doc if t.ent_type_ == "ACTION"]
    if any(resolve_action(mention(t), book) == book.runner_up for t in actions) or any(
        t.lower_ in ("rather", "instead", "margin", "lead", "over", "versus", "vs", "vs.") for t in s.doc
    ):
        return "margin"
    return EITHER


def coordinated(token) -> list:
    """What is said together with a name ('A and B raised it', 'A and the weather add 3'): the name first, then its
    conjuncts (any conjunct, named or not: a number said of them is a sum)."""
    head = token
    while head.dep_ == "conj":
        head = head.head
    if head.pos_ not in ("NOUN", "PROPN") and head.ent_type_ != "FEATURE":
        return [token]  # ('lowered it a little, and wind speed ...': a parse's slip, not a list of names)
    group = [
        t
        for t in head.subtree
        if t is head or (t.dep_ == "conj" and t.head.i in {head.i, *(x.i for x in head.conjuncts)})
    ]
    return [token] + [t for t in group if t is not token]


def claim(c: Candidate, s: Sentence, book: FactBook, unit_of, ctx: str, known: frozenset) -> Claim | None:
    """The claim a resolved reading makes, checked; contradicted only where its name is sure (module doc). ``known``:
    the words of every name and description (a phrase with one of them may mean a feature in other words)."""
    if c.rule.claim in ("output", "net"):
        made = _output(s.doc[c.anchor]._.number, c.rule.claim, book)
    elif c.rule.claim == "comparison":
        a, b = s.doc[c.name], s.doc[c.other]
        if len(b._.keys) != 1 or len(coordinated(a)) > 1:
            return None
        made = check_comparison(tuple(a._.keys), b._.keys[0], c.polarity, ctx, book, s.doc[c.anchor].text)
    elif c.rule.claim == "class":
        made = _class(s.doc[c.anchor], s, book)
    elif c.rule.claim == "category":
        made = _category(s.doc[c.name], s.doc[c.anchor], book, known)
    elif c.rule.claim == "invented":
        made = _invented(s.doc[c.name], s.doc[c.anchor], known)
    elif c.rule.claim == "action":
        made = action(c, s, book)
    elif c.rule.claim == "every":
        made = every(c, s, book, ctx)
    else:
        made = _checked(c, s, book, unit_of, ctx)
    if made is None:
        return None
    frame = "" if c.rule.claim == "action" else framed(s.doc[c.anchor])  # (an action reads its own frame)
    if frame and made.status != "unchecked" and not (c.rule.binding == "adjacent" and frame == "under a negation"):
        made = replace(made, status="unchecked", detail=f"{made.detail} ({frame})")
    if made.status == "contradicted" and c.rule.binding == "grammar":
        a, b = sorted((c.name, c.anchor))  # ('A gave it +3.58, then B, +0.83 and C, +0.02': +0.02 is C's, not A's)
        between = [t for t in s.doc[a + 1 : b] if t.ent_type_ == "FEATURE" and t.i not in {x.i for x in together(c, s)}]
        if c.rule.claim == "number" and between:
            made = replace(made, status="unchecked", detail=f"{made.detail} ('{between[-1].text}' stands between)")
        elif any(t.text in (";", "|") for t in s.doc[a + 1 : b]):  # (a list's items: no binding across them)
            made = replace(made, status="unchecked", detail=f"{made.detail} (across a list's items)")
        elif (
            c.rule.claim == "number" and c.name > c.anchor and any(t.ent_type_ == "FEATURE" for t in s.doc[: c.anchor])
        ):  # ('came from A (-1.25), by +3.00, then B': a name before the number may be the one it is said of)
            made = replace(made, status="unchecked", detail=f"{made.detail} (a name before it may be its own)")
    if made.status == "contradicted" and c.rule.binding not in ("adjacent", "grammar"):
        made = replace(made, status="unchecked", detail=f"{made.detail} (bound by position only)")
    name = s.doc[c.name]
    if made.status == "contradicted" and name._.form == "part" and name.lower_.strip() in lexicon()["generic"]:
        made = replace(made, status="unchecked", detail=f"{made.detail} ('{name.text}' alone: no sure binding)")
    return replace(made, rule=c.rule.id)


def together(c: Candidate, s: Sentence) -> list:
    """The names said together with a reading's name (itself first)."""
    return coordinated(s.doc[c.name])


def _checked(c: Candidate, s: Sentence, book: FactBook, unit_of, ctx: str) -> Claim:
    name = s.doc[c.name]
    keys = tuple(name._.keys)
    anchor = s.doc[c.anchor]
    if c.rule.id == "skip.span":  # 'over the last 3 frames', 'the past 24 hours': when, not a claim (its kind
        return Claim("span", anchor.text, "verified", "a span of time, no claim about the decision")  # counts not)
    if c.rule.claim == "skip":  # (one of the decision's own numbers, exactly: 'stayed at 0 of its 100 decisions')
        decided = free_number(anchor, book)
        if decided.status == "verified":
            return decided
        return Claim("number", anchor.text, "unchecked", "a ratio, a pair or a part of a total")
    together = coordinated(name)
    if c.rule.claim == "number":
        verb = verb_of(anchor)
        summed = len(together) > 1 or any(t.lower_ in lexicon()["together"] for t in verb.children)
        if summed and c.rule.binding == "grammar":  # ('A (+0.3) and B (+0.2) raised it': each its own number)
            return Claim("number", anchor.text, "unchecked", "said of several features together")
        made = feature_number(anchor._.number, keys, s.masked, book, ctx, unit_of)
        if made.status == "contradicted" and book.in_percent:  # '+0.096' for 9.6 points of a percent output
            n = anchor._.number
            scaled = replace(n, value=n.value * 100, unit=n.unit * 100, alternatives=())
            again = feature_number(scaled, keys, s.masked, book, ctx, unit_of)
            made = again if again.status == "verified" else made
        return made
    if c.rule.claim == "direction":
        word = anchor.text
        if c.negated:
            return Claim("direction", word, "unchecked", "a negated or hypothetical direction")
        before = [*_up_to(name, anchor), *s.doc[max(0, name.i - 2) : name.i]]  # ('all but A', 'except for A')
        if any(t.lower_ in ("but", "except", "excluding", "besides") and t.head.pos_ != "VERB" for t in before):
            return Claim("direction", word, "unchecked", f"{name.text} is named as an exception")
        if c.rule.polarity == "cause" and not book.runner_up:
            return Claim("direction", word, "unchecked", "a cause of a one-output value: which way is not read")
        subjects = {t.i for child in anchor.children if child.dep_ in ("nsubj", "csubj") for t in child.subtree}
        signed = [  # the verb's own signed number ('lowered it by -0.3'), not one of its subject ('A (+0.3) raised')
            t
            for t in anchor.subtree
            if t.ent_type_ == "NUM" and t.ent_id_ == "signed" and verb_of(t) == anchor and t.i not in subjects
        ]
        if signed and (signed[0]._.number.value > 0) != (c.polarity > 0):  # ('lowered it by +0.3': which is meant?)
            return Claim("direction", word, "unchecked", f"its number's sign ({signed[0].text}) says the way")
        polarity, where = c.polarity, ctx
        trend = _trend(c, s, book)
        if trend is not None:
            return trend
        target = next(  # (the action it is for, not the one it is weighed against: 'gave A the push over B')
            (t for t in s.doc[c.anchor].subtree if t.ent_type_ == "ACTION" and t.head.lower_ not in _AGAINST_OTHER),
            None,
        )
        if target is not None and book.runner_up:
            meant = resolve_action(mention(target), book)
            if meant == book.runner_up:  # 'A favoured recharging' when turning was chosen: against the margin
                polarity, where = -polarity, "margin"
            elif meant != book.chosen:
                return Claim("direction", word, "unchecked", "toward an action neither chosen nor runner-up")
        named = [t for t in together if t.ent_type_ in ("FEATURE", "LABEL") and t._.keys]
        checked = check_direction([mention(t) for t in named], polarity, where, word, book)
        if not checked:
            return Claim("direction", word, "unchecked", "said of no name")
        return next((x for x in checked if x.status == "contradicted"), checked[0])
    if c.negated:  # 'A was not the largest factor'
        return Claim("rank", anchor.text, "unchecked", "a negated rank")
    lex = lexicon()
    sides = set(lex["up"]) | set(lex["down"]) | set(lex["sign_up"]) | set(lex["sign_down"]) | set(lex["side_words"])
    one_side = any(t.lower_ in sides for t in s.doc)  # 'the biggest factor pulling it down': among the negatives
    return _rank(keys, c.rank, anchor.text, book, one_side)


def _up_to(token, top) -> list:
    """The tokens on the way from ``token`` up to ``top`` (not included), or to the root."""
    out = []
    while token.i != top.i and token.head.i != token.i:
        token = token.head
        out.append(token)
    return out


def _trend(c: Candidate, s: Sentence, book: FactBook) -> Claim | None:
    """'Patch B6 rose 14.0 over the last 3 frames': an intransitive rise or fall of a windowed signal is its trend
    (newest value minus oldest), not its push."""
    verb, keys = s.doc[c.anchor], s.doc[c.name]._.keys
    changes = {k: book.features[k].change for k in keys if k in book.features}
    if not changes or any(v is None for v in changes.values()) or any(t.dep_ == "dobj" for t in verb.children):
        return None
    ok = [k for k, v in changes.items() if v and (v > 0) == (c.polarity > 0)]
    k, v = next(iter(changes.items()))
    status = "verified" if len(ok) == len(changes) else "contradicted" if not ok else "unchecked"
    return Claim("direction", verb.text, status, f"{k} changed by {v:+.3g} over its window")


def _rank(keys: tuple[str, ...], rank: int, word: str, book: FactBook, one_side: bool) -> Claim:
    """A rank said of a name: its rank by |contribution| in either view, or among its own side's when the sentence
    speaks of one side."""

    def test(key):
        e = book.features[key]
        said = {r for r in e.ranks.values() if r}
        if one_side and rank not in said and rank in set(e.signed_ranks.values()):
            return None  # (its rank among its own side's: which side the words say is not read, so not verified)
        if not said:
            return None
        return rank in said, f"{key} ranks {', '.join(map(str, sorted(said)))}"

    return over_keys(keys, test, "", f"{word} ({rank})", "rank")


def label_claim(token, book: FactBook, named: set[str]) -> Claim | None:
    """A categorical value named: verified when it is its feature's value; contradicted when it is not and its
    feature is named in the same sentence (the label is then said of it); else unchecked."""
    (key,) = token._.keys if len(token._.keys) == 1 else (None,)
    if key is None or key not in book.features or book.features[key].label is None:
        return None
    actual = book.features[key].label
    if actual.lower() == token._.label.lower():
        return Claim("category", token.text, "verified", f"{key} is {actual}", "category.label")
    if _set_aside(token):  # 'unlike summer', 'winter rather than summer'
        return None
    status = "contradicted" if key in named else "unchecked"
    return Claim("category", token.text, status, f"{key} is {actual}, not {token._.label}", "category.label")


def _output(n, what: str, book: FactBook) -> Claim:
    """A number said of the output ('the estimate lands at 12.4 %') or of its net change from the baseline: verified
    when it states one (of any action, the baseline, the margin), contradicted when it states none."""
    scores = list(book.scores.values())
    if what == "net":
        facts = [s - book.base for s in scores] if book.base is not None else []
        facts += [book.margin] if book.margin is not None else []
    else:
        facts = [*scores, *([book.base] if book.base is not None else []), *book.decision_numbers]
    if not facts:
        return Claim("number", n.text, "unchecked", "no output to compare with")
    ok = any(matches(n, f, magnitude_ok=what == "net") or (n.percent and percent_reading(n, f)) for f in facts)
    told = ", ".join(f"{f:.4g}" for f in facts[:3])
    return Claim(
        "number",
        n.text,
        "verified" if ok else "contradicted",
        f"the {'net change' if what == 'net' else 'output'}: {told}",
    )


def action_score(s: Sentence, token, book: FactBook) -> Claim | None:
    """'stay, the only available action (score 31.0)': a number right after 'score' (or 'Q') in a sentence that
    names one action is that action's score (adjacency binds it)."""
    before = [t for t in s.doc[max(0, token.i - 3) : token.i] if t.text not in "(:=[,"]
    actions = {resolve_action(mention(t), book) for t in s.doc if t.ent_type_ == "ACTION"}
    if not before or before[-1].lower_ not in ("score", "q", "q-value") or len(actions) != 1 or None in actions:
        return None
    (action,) = actions
    if action not in book.scores or book.output != "actions":
        return None
    ok = matches(token._.number, book.scores[action], magnitude_ok=False)
    status = "verified" if ok else "contradicted"
    return Claim("number", token.text, status, f"{action}'s score is {book.scores[action]:.4g}", "number.score-of")


def free_number(token, book: FactBook, name=None, unit_of=None, ctx: str = EITHER, masked: str = "") -> Claim:
    """A number no rule bound to a name: verified when it is a decision-level fact or a fact of the name nearest it
    (``name``: a binding by position alone, so never contradicted), else unchecked."""
    n = token._.number
    summed = bool(_words(masked) & _SUMS)  # (a sum is cited only where the words say one: 'in total', 'together')
    facts = [
        *book.decision_numbers,
        *(v for k, v in book.aggregates.items() if k != "the number of features" and summed),
    ]
    if any(matches(n, f, magnitude_ok=False) for f in facts):
        return Claim("number", n.text, "verified", "a decision-level number", "number.decision")
    if name is not None and name._.keys:
        near = feature_number(n, tuple(name._.keys), masked, book, ctx, unit_of)
        if near.status == "verified":
            return replace(near, rule="number.nearest")
    return Claim("number", n.text, "unchecked", "bound to no name", "number.unbound")


_AGAINST_OTHER = frozenset({"over", "than", "versus", "vs", "vs.", "instead"})
_SUMS = frozenset({*lexicon()["together"], "sum", "sums", "total", "totals", "summed", "net", "overall"})


def _words(text: str) -> set[str]:
    words = {w for w in split_words(text) if w}
    return words | {stem(w).rstrip("~") for w in words}


_PHRASE_DEPS = ("compound", "amod", "npadvmod", "nmod", "nummod", "advmod", "neg", "punct", "hyph")


def _value_phrase(word, name) -> list:
    """The words that say a value: ``word`` and the modifiers before it ('ground-level field', 'north-facing'),
    without the name itself or anything the parse hangs after it."""
    out = [word]
    for child in word.lefts:
        if child.dep_ in _PHRASE_DEPS and child.i != name.i and name.i not in {t.i for t in child.subtree}:
            out += [t for t in child.subtree if not (t.is_punct and t.text != "-")]
    return sorted(out, key=lambda t: t.i)


def _category(name, word, book: FactBook, known: frozenset) -> Claim | None:
    """A word said of a categorical feature ('the hilly course', 'congestion is rated medium'): verified when it is
    a word of its value; contradicted when it reads as another value (a name, a number, a hyphenated compound, a
    word of the value's closed class, or the value without its 'non-'); else no claim ('the long contract')."""
    keys = [k for k in name._.keys if k in book.features and book.features[k].label is not None]
    if len(keys) != 1 or len(name._.keys) != 1:
        return None
    key, lex = keys[0], lexicon()
    label = book.features[key].label
    tokens = _value_phrase(word, name)
    said = " ".join(t.text for t in tokens).replace(" - ", "-")
    if word.lower_ in lex["plain_modifiers"] or word.lower_ in lex["generic"] or word.lower_ in lex["stated_as"]:
        return None
    if any(ch.isdigit() for ch in said):
        return None  # an id or a count ('T-90577', 'P3'), not a value's words
    compound = word.tag_ in ("VBN", "VBG") and any(t.text == "-" for t in tokens)
    if word.pos_ == "VERB" and word.dep_ == "amod" and not compound:
        return None  # a verb as a modifier is a value only in a compound ('north-facing'), not 'outweighs'
    if len(tokens) > 4 or any(t.ent_type_ == "NUM" and t.ent_id_ != "word" for t in tokens):
        return None
    label_words, said_words = _words(label), _words(said) - _words(key) - set(lex["plain_modifiers"])
    if not said_words or (said_words & known and not said_words & label_words):
        return None  # words of the names and descriptions ('the IP geolocation check'): no value said
    negated = label_words & {"non", "no", "not", "un", "without"}
    if said_words <= label_words | _words(key) and (not negated or said_words & negated):
        return Claim("category", said, "verified", f"{key} is {label}")
    same_class = any(said_words & group and label_words & group for group in lex["closed_classes"])
    near = (word.head, *word.head.children, word.head.head)
    stated = any(t.lower_ in lex["stated_as"] for t in near)  # 'is rated medium', 'was classed as an emergency'
    value_like = (
        stated
        or same_class
        or (negated and said_words & label_words)
        or any(t.pos_ == "PROPN" or t.like_num or t.text == "-" for t in tokens)
    )
    if not value_like or (said_words & label_words and not negated):
        return None
    return Claim("category", said, "contradicted", f"{key} is {label}, not {said}")


def _set_aside(token) -> bool:
    """Is a value set aside by a word up to three before it ('more than a north slope', 'unlike in June')?"""
    aside = lexicon()["set_aside"]
    return any(t.lower_ in aside for t in token.doc[max(0, token.i - 3) : token.i])


def _class(word, s: Sentence, book: FactBook) -> Claim | None:
    """A word of a closed class ('June', 'north', 'late') in a sentence that names exactly one feature whose value is
    of that class: its value, or another (contradicted). Not a word after 'than', 'since', 'from', 'unlike', nor a
    sentence that also says the right value ('more than in winter')."""
    lex = lexicon()
    group = next((g for g in lex["closed_classes"] if word.lower_ in g), None)
    named = {k for t in s.doc if t.ent_type_ in ("FEATURE", "LABEL") for k in t._.keys}
    owners = [
        k
        for k in named
        if book.features.get(k) and book.features[k].label and _words(book.features[k].label) & (group or set())
    ]
    aside = _set_aside(word)
    hyphened = any(0 <= word.i + d < len(word.doc) and word.doc[word.i + d].text == "-" for d in (-1, 1))
    if group is None or len(owners) != 1 or word.ent_type_ or aside or hyphened:
        return None  # ('since June', 'east-west traffic': a value of something else)
    key = owners[0]
    label_words = _words(book.features[key].label)
    if word.lower_ in label_words:
        return Claim("category", word.text, "verified", f"{key} is {book.features[key].label}")
    if any(t.lower_ in label_words & group for t in s.doc):
        return None  # the right value is said too: a comparison
    return Claim("category", word.text, "contradicted", f"{key} is {book.features[key].label}, not {word.text}")


def _invented(subject, verb, known: frozenset) -> Claim | None:
    """The subject of a direction verb that names nothing of the explanation ('construction dust raised it by 1.0'):
    contradicted, unless a word of it belongs to a name or a description (a vague mention) or it is the model, the
    output or a group of reasons. Whose it is ('the guest's', 'her') is no part of what it is."""
    lex = lexicon()
    owners = {t.i for c in subject.children if c.dep_ == "poss" for t in c.subtree}
    tokens = [t for t in subject.subtree if t.i not in owners]
    if (
        any(t.ent_type_ in ("FEATURE", "ACTION", "LABEL") for t in tokens)
        or any(t.ent_type_ == "NUM" and t.head.lower_ != "of" for t in tokens)
        or subject.lower_ in lex["vague"]
        or subject.tag_ == "VBG"
        or any(t.lower_ in lex["pointing"] for t in tokens)
    ):  # a name, a value, the output, a gerund, or a phrase that points back ('those two facts')
        return None
    content = [
        t
        for t in tokens
        if (t.pos_ in ("NOUN", "PROPN", "ADJ") or t.tag_ in ("VBG", "VBN")) and t.lower_ not in lex["generic"]
    ]
    nouns = [t for t in content if t.pos_ in ("NOUN", "PROPN")]
    if len(content) < 2 or not nouns or any(w in known for t in nouns for w in _words(t.text)):
        return None  # one plain noun ('the sunshine', 'youth') is more often a paraphrase than a new input
    phrase = " ".join(t.text for t in tokens)
    return Claim("feature", phrase, "contradicted", f"'{phrase}' {verb.text}: it names no input of the explanation")
