"""Each resolved reading checked against the fact book: verified, contradicted, or unchecked.

A claim is contradicted only when its rule binds the name by adjacency or grammar; a number bound to nothing is
verified when it states a decision-level fact (the prediction, the baseline, a score, the margin) and else left
unchecked. A negated direction ('did not raise') is left unchecked.
"""

from __future__ import annotations

from dataclasses import replace

from ..narrators.verify.book import FactBook
from ..narrators.verify.checks import EITHER, Claim, check_direction, over_keys, resolve_action
from ..narrators.verify.names import Mention
from ..narrators.verify.numbers import matches
from ..narrators.verify.quantities import feature_number
from .lexicon import lexicon
from .parse import Sentence
from .rules import Candidate


def view(s: Sentence, book: FactBook) -> str:
    """'chosen' for one output; for a decision between actions, 'margin' when the sentence names the runner-up or
    weighs the two ('rather than', 'over', 'margin'), else either view."""
    if not book.runner_up:
        return "chosen"
    actions = [t for t in s.doc if t.ent_type_ == "ACTION"]
    if any(resolve_action(_mention(t), book) == book.runner_up for t in actions) or any(
        t.lower_ in ("rather", "instead", "margin", "lead", "over", "versus", "vs", "vs.") for t in s.doc
    ):
        return "margin"
    return EITHER


def _mention(token) -> Mention:
    kind = {"FEATURE": "feature", "ACTION": "action", "LABEL": "label"}[token.ent_type_]
    return Mention(token.idx, token.idx + len(token), kind, tuple(token._.keys), token._.label, token._.form)


def coordinated(token) -> list:
    """The features said together with a name ('A and B raised it'): the name first, then its conjuncts."""
    head = token
    while head.dep_ == "conj" and head.head.ent_type_ == "FEATURE":
        head = head.head
    group = [t for t in head.subtree if t.ent_type_ == "FEATURE" and (t is head or t.dep_ == "conj")]
    return [token] + [t for t in group if t is not token]


def claim(c: Candidate, s: Sentence, book: FactBook, unit_of, ctx: str) -> Claim:
    """The claim a resolved reading makes, checked; contradicted only where its name is sure (module doc)."""
    made = _checked(c, s, book, unit_of, ctx)
    name = s.doc[c.name]
    if made.status == "contradicted" and name._.form == "part" and name.lower_.strip() in lexicon()["generic"]:
        made = replace(made, status="unchecked", detail=f"{made.detail} ('{name.text}' alone: no sure binding)")
    return replace(made, rule=c.rule.id)


def _checked(c: Candidate, s: Sentence, book: FactBook, unit_of, ctx: str) -> Claim:
    name = s.doc[c.name]
    keys = tuple(name._.keys)
    anchor = s.doc[c.anchor]
    if c.rule.claim == "skip":
        return Claim("number", anchor.text, "unchecked", "a ratio, a pair or a part of a total")
    together = coordinated(name)
    if c.rule.claim == "number":
        if len(together) > 1:
            return Claim("number", anchor.text, "unchecked", "said of several features together")
        return feature_number(anchor._.number, keys, s.masked, book, ctx, unit_of)
    if c.rule.claim == "direction":
        word = anchor.text
        if c.negated:
            return Claim("direction", word, "unchecked", "a negated direction")
        signed = [t for t in anchor.subtree if t.ent_type_ == "NUM" and t._.numform == "signed"]
        if signed:
            return Claim("direction", word, "unchecked", f"its number's sign ({signed[0].text}) says the way")
        polarity, where = c.polarity, ctx
        target = next((t for t in s.doc[c.anchor].subtree if t.ent_type_ == "ACTION"), None)
        if target is not None and book.runner_up:
            meant = resolve_action(_mention(target), book)
            if meant == book.runner_up:  # 'A favoured recharging' when turning was chosen: against the margin
                polarity, where = -polarity, "margin"
            elif meant != book.chosen:
                return Claim("direction", word, "unchecked", "toward an action neither chosen nor runner-up")
        checked = check_direction([_mention(t) for t in together], polarity, where, word, book)
        return next((x for x in checked if x.status == "contradicted"), checked[0])
    return _rank(keys, c.rank, anchor.text, book)


def _rank(keys: tuple[str, ...], rank: int, word: str, book: FactBook) -> Claim:
    def test(key):
        e = book.features[key]
        said = {r for r in (*e.ranks.values(), *e.signed_ranks.values()) if r}
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
    status = "contradicted" if key in named else "unchecked"
    return Claim("category", token.text, status, f"{key} is {actual}, not {token._.label}", "category.label")


def free_number(token, book: FactBook) -> Claim:
    """A number no rule bound to a name: verified when it is a decision-level fact, else unchecked."""
    n = token._.number
    facts = [*book.decision_numbers, *book.aggregates.values()]
    if any(matches(n, f, magnitude_ok=False) for f in facts):
        return Claim("number", n.text, "verified", "a decision-level number", "number.decision")
    return Claim("number", n.text, "unchecked", "bound to no name", "number.unbound")
