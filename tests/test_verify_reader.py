"""The rule-table reader (xairl.verification.prose): every rule's examples from rules/rules.yaml, the table's
shape, and the claims it makes on sentences written for these tests."""

import pytest

from tests.rule_examples import example
from xairl.verification.prose import read, rules, trace

RULES = rules.table()


def test_every_rule_has_an_id_a_pattern_a_claim_and_examples():
    ids = [r.id for r in RULES]
    assert len(ids) == len(set(ids))
    for r in RULES:
        assert r.claim in (
            "number",
            "output",
            "net",
            "direction",
            "every",
            "action",
            "rank",
            "comparison",
            "category",
            "class",
            "invented",
            "skip",
        ) and r.binding in ("adjacent", "grammar", "position")
        assert r.pattern and r.fires, r.id
        if r.kind == "dependency":
            roles = {node["RIGHT_ID"] for node in r.pattern}
            assert "name" in roles and roles & {"num", "dir", "rank", "word", "other"}, r.id


@pytest.mark.slow
@pytest.mark.parametrize(
    "rule,case,text,fires",
    [(r.id, case, text, True) for r in RULES for case, text in r.fires]
    + [(r.id, case, text, False) for r in RULES for case, text in r.silent],
)
def test_rule_examples(rule, case, text, fires):
    made = {c.rule for c in read(text, example(case), 0).claims}
    assert (rule in made) == fires, "\n".join(trace(text, example(case), 0))


@pytest.mark.parametrize(
    "text,status",
    [
        ("Traffic index raised the forecast by 7.2.", "verified"),
        ("Traffic index lowered the forecast by 7.2.", "contradicted"),  # direction flipped
        ("traffic index: 3.5", "contradicted"),  # neither its value nor its contribution
        ("Wind speed (+14.7) and pm2_5_lag1 (+6.9) raised it.", "contradicted"),  # two numbers swapped
        ("The season (+1.0) raised it.", "contradicted"),  # the sign of a contribution
        ("pm2_5_lag1 was the biggest driver.", "verified"),
        ("Traffic index was the biggest driver.", "contradicted"),
        ("Traffic index did not lower the forecast.", "unchecked"),  # negated: not read as a direction
        ("In the city, 7.2 km of sensors were built for the traffic index.", "unchecked"),  # bound by no rule
    ],
)
def test_claims_only_where_grammar_or_adjacency_binds(text, status):
    assert read(text, example("air"), 0).sentences[0].status == status, "\n".join(trace(text, example("air"), 0))


def test_a_number_next_to_its_name_outranks_the_parse():
    lines = trace("The season lowered it a little, and wind speed (SHAP +6.9) pushed it up.", example("air"), 0)
    assert any(line.startswith("  * number.parenthesis") for line in lines), lines
    assert read("The season lowered it a little, and wind speed (SHAP +6.9) pushed it up.", example("air"), 0).accurate


def test_xairl_verify_is_a_plain_function():
    """``xairl.verify`` is the function of :mod:`xairl.verification` (no package of that name shadows it)."""
    import inspect

    import xairl
    from xairl.verification import verify

    assert xairl.verify is verify and inspect.isfunction(xairl.verify)
    assert xairl.verify("pm2_5_lag1 (+14.7) raised the forecast.", example("air"), 0).accurate
    assert not xairl.verify("pm2_5_lag1 (-3.0) lowered the forecast.", example("air"), 0).accurate


def test_tokens_show_names_and_numbers_as_the_rules_see_them():
    from xairl.verification.prose import tokens

    (sentence,) = tokens("The effect of the traffic index was +7.2.", example("air"))
    kinds = {text: kind for text, kind, _, _ in sentence}
    assert kinds["traffic index"] == "FEATURE" and kinds["+7.2"] == "NUM" and kinds["effect"] == ""


@pytest.mark.slow
def test_no_sentence_of_the_tuning_voices_breaks_the_reader():
    """Every narrative of two tuning files (outside voices: logs, letters, tables, Q&A) is read without a reader
    failure: a failure would leave its sentence unchecked, silently (the reader never raises)."""
    from tests.narrative_corpus import HELDOUT, load

    items = [it for name in ("voices_a", "voices_h") for it in load(HELDOUT / "tuning" / f"{name}.yaml")]
    failed = [
        (it["text"], c.detail)
        for it in items
        if not it["wrong_facts"]
        for c in read(it["text"], it["explanation"], 0).claims
        if c.kind == "internal"
    ]
    assert len(items) > 200 and not failed, failed[:3]
