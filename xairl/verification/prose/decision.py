"""Claims about the decision itself (which action was chosen, what every feature did) and the frame a claim sits in
('it is false that ...', 'if ...', 'did not ...'): a claim under a denial or a hypothesis is not asserted as it
stands, so it is never verified."""

from __future__ import annotations

from xairl.verification.prose.book import FactBook
from xairl.verification.prose.checks import EITHER, check_direction, resolve_action
from xairl.verification.prose.lexicon import lexicon
from xairl.verification.prose.names import Mention
from xairl.verification.result import Claim

#: negation words that deny the clause they stand in ('no' and 'without' qualify a noun, not the clause)
_CLAUSE_NEGATIONS = ("not", "n't", "never", "neither", "nor", "hardly", "barely")


def framed(token, own: bool = True) -> str:
    """Why the clause of ``token`` is not asserted as it stands: a negation, a hypothesis or a denial on its way up
    to the root ('A did not add 0.3', 'if A had raised it', 'it is false that A raised it'); '' when none.
    ``own=False``: from the clause above ``token``, a verb whose own negation the caller reads."""
    lex = lexicon()
    t = token
    if not own:
        if t.head.i == t.i:
            return ""
        t = t.head
    while True:
        for ch in t.children:
            if ch.dep_ == "neg" or (ch.lower_ in _CLAUSE_NEGATIONS and ch.dep_ in ("advmod", "preconj", "cc")):
                return "under a negation"
            if ch.lower_ in lex["hypothetical"] and ch.dep_ in ("aux", "mark", "advmod"):
                return "a hypothesis"
            if ch.lower_ in lex["falsity"]:
                return "under a denial"
        if t.lower_ in lex["falsity"]:
            return "under a denial"
        if t.head.i == t.i:
            return ""
        t = t.head


def verb_of(token):
    """The token itself if it is a verb, else the nearest verb above it."""
    t = token
    while t.pos_ not in ("VERB", "AUX") and t.head.i != t.i:
        t = t.head
    return t


def mention(token) -> Mention:
    kind = {"FEATURE": "feature", "ACTION": "action", "LABEL": "label"}[token.ent_type_]
    return Mention(token.idx, token.idx + len(token), kind, tuple(token._.keys), token._.label, token._.form)


def action(c, s, book: FactBook) -> Claim | None:
    """'chose turn', 'turn was picked', 'the agent turned', 'turn won', 'recharge had the higher score': the named
    action is the chosen one (a negation of the verb says it is not); 'over recharge', 'rather than recharge': it is
    not (only verified, never contradicted: 'preferred over' may run either way); 'toward turn': one of the two
    weighed (the direction said toward it is another claim's)."""
    if book.output != "actions" or book.global_view or not book.chosen:
        return None
    name, word = s.doc[c.name], s.doc[c.anchor]
    meant = resolve_action(mention(name), book)
    if meant is None:
        return Claim("action", name.text, "unchecked", f"it may mean {' / '.join(name._.keys)}")
    if c.rule.polarity == "toward":  # 'the push toward turn': which way is the claim's own; it names the choice
        status = "verified" if meant in (book.chosen, book.runner_up) else "unchecked"
        return Claim("action", name.text, status, f"the policy chose {book.chosen} over {book.runner_up}")
    if c.rule.polarity == "lost":
        if meant == book.chosen:
            return Claim("action", name.text, "unchecked", f"{meant} was chosen: 'over' may run either way")
        return Claim("action", name.text, "verified", f"the policy chose {book.chosen}, not {meant}")
    verb = word if word.pos_ in ("VERB", "AUX") else verb_of(name)  # ('chose', 'the agent turned')
    lex = lexicon()
    if any(ch.lower_ in lex["hypothetical"] for ch in verb.children):
        return Claim("action", name.text, "unchecked", "a hypothetical choice")
    frame = framed(verb, own=False)  # 'it is false that the policy chose turn'
    if frame:
        return Claim("action", name.text, "unchecked", f"a choice {frame}")
    negated = any(ch.dep_ == "neg" or ch.lower_ in _CLAUSE_NEGATIONS for ch in verb.children)
    if word.lower_ in lex["top"] and word.lower_ in lex["more"] + ["higher", "better"] and len(book.scores) > 2:
        if meant != book.chosen:  # 'higher than forward' may be true of the runner-up
            return Claim("action", name.text, "unchecked", "higher than which action is not read")
    ok = (meant == book.chosen) != negated
    said = f"{'not ' if negated else ''}chosen"
    return Claim(
        "action", name.text, "verified" if ok else "contradicted", f"said {said}; the policy chose {book.chosen}"
    )


def every(c, s, book: FactBook, ctx: str) -> Claim | None:
    """'Every feature favoured turn': the direction of each feature with a contribution, in the sentence's view."""
    word = s.doc[c.anchor]
    if c.negated:
        return Claim("direction", word.text, "unchecked", "a negated or hypothetical direction")
    if any(t.lower_ in ("but", "except", "save", "bar", "apart", "besides") for t in s.doc[c.name].subtree):
        return Claim("direction", word.text, "unchecked", "every feature but some: which ones is not read")
    polarity, where = c.polarity, ctx
    target = next((t for t in word.subtree if t.ent_type_ == "ACTION"), None)
    if target is not None and book.runner_up:
        meant = resolve_action(mention(target), book)
        if meant == book.runner_up:
            polarity, where = -polarity, "margin"
        elif meant != book.chosen:
            return Claim("direction", word.text, "unchecked", "toward an action neither chosen nor runner-up")
    everyone = [Mention(0, 0, "feature", (k,)) for k in book.features]
    checked = check_direction(everyone, polarity, where if where != EITHER else EITHER, word.text, book)
    wrong = [x for x in checked if x.status == "contradicted"]
    if wrong:
        return Claim("direction", word.text, "contradicted", f"said of every feature, but {wrong[0].detail}")
    if checked and all(x.status == "verified" for x in checked):
        return Claim("direction", word.text, "verified", "every feature's contribution has that sign")
    return Claim("direction", word.text, "unchecked", "not every feature's sign is known")
