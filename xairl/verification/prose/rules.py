"""The rule table (prose/rules.yaml) and its word lists (xairl/verification/lexicon.yaml), compiled into spaCy matchers.

A rule is data: an id, the claim it makes, how it binds a name (adjacent or grammar), a priority, a Matcher or
DependencyMatcher pattern over a parse whose names and numbers are single tokens (parse.py), and examples that must
fire and must not. :func:`candidates` runs every rule on a sentence and returns what each one read; which reading
wins is decided by resolve.py, never by the order of the table.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, replace
from pathlib import Path

import yaml
from spacy.matcher import DependencyMatcher, Matcher

from xairl.verification.prose.lexicon import lexicon


@dataclass(frozen=True, eq=False)
class Rule:
    id: str
    claim: str  # number | output | net | direction | every | rank | comparison | category | class | invented | action | skip
    binding: str  # adjacent | grammar
    priority: int
    pattern: list
    kind: str  # token | dependency
    polarity: str = ""
    same_clause: tuple = ()
    fires: tuple = ()
    silent: tuple = ()


@dataclass(frozen=True)
class Candidate:
    """One rule's reading of a sentence: the name token it binds, the anchor (the number, direction or rank word)
    and, for a direction, its polarity (+1 / -1), for a rank, the rank said."""

    rule: Rule
    name: int  # token index of the name
    anchor: int  # token index of the number / direction word / rank word
    polarity: int = 0
    rank: int = 0
    negated: bool = False
    other: int = -1  # a comparison's second name
    tokens: tuple[int, ...] = ()  # every token the rule's pattern matched (the words it read)


def _expand(node):
    """A pattern with every "$a+b" list replaced by the lexicon's lists a and b."""
    if isinstance(node, dict):
        return {k: _expand(v) for k, v in node.items()}
    if isinstance(node, list):
        return [_expand(v) for v in node]
    if isinstance(node, str) and node.startswith("$"):
        lex = lexicon()
        return sorted({w for part in node[1:].split("+") for w in lex[part]})
    return node


@functools.cache
def table() -> tuple[Rule, ...]:
    rules = []
    for entry in yaml.safe_load((Path(__file__).parent / "rules.yaml").read_text(encoding="utf-8")):
        kind = "token" if "token" in entry else "dependency"
        rules.append(
            Rule(
                entry["id"],
                entry["claim"],
                entry["binding"],
                int(entry["priority"]),
                _expand(entry[kind]),
                kind,
                entry.get("polarity", ""),
                tuple(entry.get("same_clause", ())),
                tuple(tuple(x) for x in entry.get("fires", ())),
                tuple(tuple(x) for x in entry.get("silent", ())),
            )
        )
    return tuple(rules)


@functools.cache
def by_id() -> dict[str, Rule]:
    return {r.id: r for r in table()}


@functools.cache
def matchers(vocab):
    """(Matcher, DependencyMatcher) holding every rule of the table, for spaCy vocabulary ``vocab``."""
    token, dependency = Matcher(vocab), DependencyMatcher(vocab)
    for r in table():
        (token if r.kind == "token" else dependency).add(r.id, [r.pattern])
    return token, dependency


def candidates(doc) -> list[Candidate]:
    """Every rule's readings of one parsed sentence."""
    token, dependency = matchers(doc.vocab)
    out = []
    for match_id, start, end in token(doc):
        rule = by_id()[doc.vocab.strings[match_id]]
        out += [replace(c, tokens=tuple(range(start, end))) for c in _token_reading(rule, doc, start, end)]
    for match_id, ids in dependency(doc):
        rule = by_id()[doc.vocab.strings[match_id]]
        roles = {node["RIGHT_ID"]: i for node, i in zip(rule.pattern, ids)}
        if rule.claim == "comparison":  # 'A outweighed B'
            out.append(Candidate(rule, roles["name"], roles["way"], 1, other=roles["other"], tokens=tuple(ids)))
            continue
        if rule.same_clause and _clause_between(doc, *(roles[k] for k in rule.same_clause)):
            continue
        anchor = next(roles[k] for k in ("num", "dir", "rank", "word") if k in roles)
        out.append(replace(_reading(rule, doc, roles["name"], anchor, roles), tokens=tuple(ids)))
    return [c for c in out if not (_dir_is_led(c.rule) and _own_subject(doc, c)) and not _across_cells(doc, c)]


def _across_cells(doc, c: Candidate) -> bool:
    """Does a reading bind a name to a word in another item of a list ('A 2.4 +7.2 | lag reading 48.2 +14.7'): an
    item with words of its own before the anchor? (A table's row, '| season | winter | -1.0 |', is one item.)"""
    a, b = sorted((c.name, c.anchor))
    cuts = [t.i for t in doc[a:b] if t.text in ("|", ";")]
    if not cuts:
        return False
    own = doc[cuts[-1] + 1 : b] if b == c.anchor else doc[a + 1 : cuts[0]]
    return any(t.is_alpha and t.ent_type_ != "LABEL" for t in own)


def _clause_between(doc, top: int, below: int) -> bool:
    """Is there a verb with a subject of its own on the way up from ``below`` to ``top`` (a relative clause)?"""
    t = doc[below].head
    while t.i != top and t.head.i != t.i:
        if t.pos_ in ("VERB", "AUX") and any(c.dep_ in ("nsubj", "nsubjpass", "csubj") for c in t.children):
            return True
        t = t.head
    return False


def _dir_is_led(rule: Rule) -> bool:
    """Is the direction word reached from another verb (a participle, 'adding ...'), not the pattern's root?"""
    return (
        rule.claim == "direction"
        and rule.kind == "dependency"
        and any(n["RIGHT_ID"] == "dir" and "LEFT_ID" in n for n in rule.pattern)
    )


def _token_reading(rule: Rule, doc, start: int, end: int) -> list[Candidate]:
    span = range(start, end)
    names = [i for i in span if doc[i].ent_type_ in ("FEATURE", "LABEL")]
    nums = [i for i in span if doc[i].ent_type_ == "NUM"]
    if rule.claim == "skip":  # every number it matches is left unchecked
        return [Candidate(rule, i, i) for i in nums]
    if rule.claim in ("output", "net"):  # a number of the output: its word heads its own phrase ('the forecast
        before = doc[start - 1] if start else None  # is 52', not 'the wind forecast of 3' nor 'raised the forecast:
        if (  # +7.2', where the output is an object)
            not nums
            or doc[start].dep_ in ("dobj", "pobj", "dative")
            or (before is not None and (before.pos_ in ("NOUN", "PROPN", "ADJ", "NUM") or before.ent_type_))
        ):
            return []
        return [Candidate(rule, nums[-1], nums[-1])]
    if rule.claim == "class":  # its name is found by its value's class, in check.py
        return [Candidate(rule, start, start)]
    if rule.claim == "action":  # 'rather than recharge': the action named last
        acts = [i for i in span if doc[i].ent_type_ == "ACTION"]
        return [Candidate(rule, acts[-1], acts[-1])] if acts else []
    if not names:
        return []
    if rule.claim == "number":
        if not nums:
            return []
        name = min(names, key=lambda i: abs(i - nums[-1]))  # the last number: 'A=48.2 -> +14.7' says +14.7 of A
        return [_reading(rule, doc, name, nums[-1], {})]
    if rule.claim == "comparison":  # the first name against the last, at the comparative
        way = next(i for i in span if doc[i].lower_ in lexicon()["more"] + lexicon()["less"])
        polarity = 1 if doc[way].lower_ in lexicon()["more"] else -1
        return [Candidate(rule, names[0], way, polarity, other=names[-1])] if len(names) > 1 else []
    if rule.claim == "category":  # the word said of the name: the last of the match, or the noun it modifies
        word = doc[end - 1]
        while word.dep_ in ("compound", "amod", "nmod", "npadvmod") and word.head.i > word.i:
            word = word.head
        return [_reading(rule, doc, names[0], word.i, {})]
    lex = lexicon()
    said = [i for i in span if doc[i].lower_ in lex["superlatives"] or doc[i].lower_ in lex["ordinals"]]
    anchor = said[0] if said else next(i for i in span if doc[i].ent_type_ != "FEATURE")
    return [_reading(rule, doc, names[0], anchor, {"span": (start, end)})]


def _reading(rule: Rule, doc, name: int, anchor: int, roles: dict) -> Candidate:
    lex = lexicon()
    polarity = rank = 0
    if rule.claim in ("direction", "every"):
        word = doc[anchor].lower_
        if rule.polarity == "cause":  # 'turned because of A': A favoured what was done
            polarity = 1
        elif rule.polarity == "particle":
            way = doc[roles["way"]].lower_
            polarity = 1 if way in lex["particle_up"] else -1
        elif rule.polarity == "sign":
            polarity = 1 if word in lex["sign_up"] else -1
        elif rule.polarity == "output":
            polarity = 1 if word in lex["output_up"] else -1
        elif rule.polarity == "noun":
            polarity = 1 if word in lex["noun_up"] else -1
        else:
            polarity = 1 if word in lex["up"] else -1
    if rule.claim == "rank":
        start, end = roles.get("span", (anchor, anchor + 1))
        words = [doc[i].lower_ for i in range(start, end)]
        if "attr" in roles:  # 'the second-largest factor': the ordinal is a modifier of the noun or of the superlative
            words += [t.lower_ for t in doc[roles["attr"]].children] + [t.lower_ for t in doc[anchor].children]
        rank = next((lex["ordinals"][w] for w in words if w in lex["ordinals"]), 1)
    verb = doc[anchor] if rule.claim == "direction" else doc[name].head
    negated = any(  # 'did not raise', 'would have raised', 'if A had raised'
        c.dep_ == "neg" or c.lower_ in lex["negations"] or c.lower_ in lex["hypothetical"] for c in verb.children
    )
    return Candidate(rule, name, anchor, polarity, rank, negated)


def _own_subject(doc, candidate: Candidate) -> bool:
    """Does a led direction verb belong to another name: a subject of its own that is not its name's phrase, or
    another name nearer before it ('A lowered it, and B pushed it up': 'pushed' is B's, not A's)?"""
    verb, name = doc[candidate.anchor], doc[candidate.name]
    subjects = [  # ('which', 'it': a pronoun stands for the name)
        c for c in verb.children if c.dep_ in ("nsubj", "nsubjpass", "csubj") and c.pos_ != "PRON"
    ]
    if subjects and not any(name.i in {t.i for t in s.subtree} for s in subjects):
        return True
    nearest = [t.i for t in doc[: verb.i] if t.ent_type_ == "FEATURE"]
    return bool(nearest) and nearest[-1] != name.i
