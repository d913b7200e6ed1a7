"""What a sentence says that no rule read: a claim word (a direction, rank, comparison, negation, cause, quantifier,
denial or choice, from lexicon.yaml) or a name that no claim bound. Each becomes an unchecked claim naming it, so the
sentence is unchecked and the text at most partly checked: a verified text is one whose every claim was read."""

from __future__ import annotations

import functools
import re

from xairl.policies.region_names import REGION_RE
from xairl.verification.prose.check import coordinated
from xairl.verification.prose.lexicon import lexicon
from xairl.verification.result import Claim

#: lists of verbs: a claim word only as a verb or an adjective ('the cost', 'a drive' are nouns of the domain)
_VERBS = ("up", "down", "output_up", "output_down", "outweigh", "choose", "win")
#: lists whose words claim whatever their part of speech
_WORDS = ("sign_up", "sign_down", "noun_up", "noun_down", "top", "more", "less", "superlatives", "ordinals")
#: a snake_case identifier ('battery_temperature'): a name in any text, so one the vocabulary lacks names nothing
_IDENTIFIER = re.compile(r"[A-Za-z][A-Za-z0-9]*_[A-Za-z0-9_]*[A-Za-z0-9]")
_UNKNOWN = "identifier.unknown"
#: the rule of a name no claim bound (its detail says the keys it names, in brackets, for the margin account)
UNREAD = "name.unread"
_AFTER_TIMES = frozenset(
    {
        "as",
        "more",
        "less",
        "the",
        "that",
        "what",
        "larger",
        "bigger",
        "smaller",
        "greater",
        "higher",
        "lower",
        "stronger",
        "weaker",
    }
)
#: words a clause's verb takes along with its claim (its negation, its 'because', its particle)
_TAKEN = ("neg", "aux", "auxpass", "mark", "prt", "agent")


@functools.cache
def _lists() -> tuple[frozenset, frozenset, frozenset]:
    lex = lexicon()
    verbs = frozenset(w for k in _VERBS for w in lex[k])
    words = frozenset(w for k in _WORDS for w in lex[k]) | frozenset(
        lex["negations"] + lex["cause"] + lex["falsity"] + lex["measure"]
    )
    particles = frozenset(lex["particle_up"] + lex["particle_down"])
    return verbs, words, particles


def read_tokens(s, made) -> set[int]:
    """The tokens the claims made read: each rule's matched words, the names said together with a direction or a
    number, the action a direction is toward, and the negation, auxiliaries and particle of its verb."""
    read: set[int] = set()
    lex = lexicon()
    choosing = {*lex["choose"], *lex["win"], *lex["top"]}
    for c, claim in made:
        anchor, name = s.doc[c.anchor], s.doc[c.name]
        if c.rule.claim == "action":  # (it reads the choice, not a feature's push toward it: 'A pushed toward turn')
            words = (*c.tokens, c.anchor, c.name)
            read |= {i for i in words if s.doc[i].ent_type_ == "ACTION" or s.doc[i].lower_ in choosing}
            read |= {t.i for t in anchor.children if t.dep_ in _TAKEN}  # ('did not choose': its negation)
            continue
        read |= {*c.tokens, c.anchor, c.name, *([c.other] if c.other >= 0 else [])}
        read |= {t.i for t in anchor.children if t.dep_ in _TAKEN}
        if c.rule.claim in ("direction", "number", "every") and claim.kind != "feature":
            read |= {t.i for t in coordinated(name)}
            read |= {t.i for t in anchor.subtree if t.ent_type_ == "ACTION"}
    directed = {c.name for c, claim in made if claim.kind == "direction" and claim.status != "unchecked"}
    for t in s.doc:  # 'because of A, which raised it': the cause is A's direction, checked
        if t.lower_ in lexicon()["cause"] and any(x.i in directed for x in t.subtree):
            read.add(t.i)
    return read


def _claim_word(t) -> bool:
    verbs, words, particles = _lists()
    w = t.lower_
    if w in verbs and t.pos_ in ("VERB", "ADJ"):
        return True
    if w == "times" and (t.i + 1 >= len(t.doc) or t.doc[t.i + 1].lower_ not in _AFTER_TIMES):
        return False  # 'handed over 100 times': a count ('3 times as much', 'twice the push' compare)
    if w in ("against", "versus") and any(x.ent_type_ == "NUM" for x in t.doc[t.i + 1 : t.i + 4]):
        return False  # 'set to 0.79, against 0.64 on average': two numbers compared, no direction
    if w in particles and t.dep_ in ("prt", "advmod", "prep") and t.head.pos_ == "VERB":
        return True
    if w in lexicon()["every"]:  # 'every feature', 'all three factors'
        return t.dep_ in ("det", "predet") and t.head.lower_ in lexicon()["rank_nouns"]
    if w in ("thanks", "due", "owing") and (t.i + 1 >= len(t.doc) or t.doc[t.i + 1].lower_ != "to"):
        return False  # ('thanks for your report'): a cause only with 'to'
    if w in lexicon()["ordinals"] and t.i == 0 and len(t.doc) > 1 and t.doc[1].text == ",":
        return False  # 'First, ...': the order of the telling
    return w in words


def unbound(s, read: set[int], book) -> list[Claim]:
    """An unchecked claim for each claim word and each name of the sentence that no claim read (module doc)."""
    actions = book.output == "actions" and not book.global_view
    out = []
    for t in s.doc:
        if t.i in read:
            continue
        if t.ent_type_ in ("FEATURE", "LABEL") or (t.ent_type_ == "ACTION" and actions):
            # (kind 'name': a mention no rule read; own narratives judge their literal names themselves)
            keys = " / ".join(t._.keys) or t.text
            out.append(Claim("name", t.text, "unchecked", f"named ({keys}), but nothing said of it was read", UNREAD))
        elif not t.ent_type_ and _IDENTIFIER.fullmatch(t.text):  # 'battery_temperature 41' of no such input
            out.append(Claim("name", t.text, "unchecked", "an identifier no input of the explanation has", _UNKNOWN))
        elif not t.ent_type_ and _claim_word(t):
            out.append(Claim("word", t.text, "unchecked", f"'{t.text}' claims something no rule read", "word.unread"))
    return out


def unknown_regions(masked: str) -> list[Claim]:
    """A region phrase left in ``masked`` (the sentence with every known name masked) names no region of the
    explanation ('patch K9 of frame 2' of a grid of 7 columns): contradicted, its words bind it."""
    return [
        Claim(
            "feature",
            m.group(0),
            "contradicted",
            "no region of this explanation has this name (regions are named by a grid reference, 'patch F6 of frame "
            "2': column letters from the left, row numbers from the top; or by their pixels, 'the 12x12 patch at rows "
            "60 to 71, columns 60 to 71 of frame 2', counting rows, columns, channels and frames from 0)",
            "region.unknown",
        )
        for m in REGION_RE.finditer(masked)
    ]
