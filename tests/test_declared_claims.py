"""Claims declared in templates and checked by identity (issue 65, items 1-3): a claim word printed by a filter is
checked by its fact whatever the author's words; a claim word, name, identifier or number the template wrote itself
leaves its sentence unchecked (never verified, never contradicted); a value is never re-bound to another name by its
position. Each false sentence the issue quotes is contradicted, or unchecked with the narrative not verified.

robot (tests/rule_examples.py): turn (3.2) chosen over recharge (2.0); margin view: speed +0.7, battery -1.5,
obstacle +2.0 (ranks: obstacle 1, battery 2, speed 3); chosen score: speed +0.5, battery -0.3, obstacle +2.0.
"""

import pytest
import yaml

import xairl
from tests.rule_examples import example
from xairl.facts import decision_facts
from xairl.narrators.base import first_phrasings
from xairl.templates import prompts, tracking

MARGIN = "{% set f = margin_top|selectattr('name', 'equalto', NAME)|first %}"


@pytest.fixture(scope="module")
def robot():
    return example("robot")


def render(tmp_path, sentences, exp, i=0):
    path = tmp_path / "t.yaml"
    path.write_text(yaml.safe_dump({"name": "t", "sentences": list(sentences)}, allow_unicode=True))
    ctx = tracking.track_decision(decision_facts(exp, i).context())
    return first_phrasings(prompts.load(path).render_variants(ctx))


def verdict(tmp_path, sentence, exp, **names):
    for key, value in names.items():
        sentence = sentence.replace(key, repr(value))
    text = render(tmp_path, [sentence], exp)
    return text, xairl.verify(text, exp, 0, provenance=text.spans)


@pytest.mark.parametrize(
    "words",
    [("grew", "shrank"), ("added", "took"), ("to", "from"), ("aumentó", "redujo"), ("hob", "senkte")],
)
@pytest.mark.parametrize("name", ["obstacle", "battery"])
def test_a_direction_in_the_authors_own_words_is_checked_by_its_fact(tmp_path, robot, words, name):
    """dir takes any two words: identity says which way, so no word list is consulted (issue 65, set B)."""
    up, down = words
    said = f"dir('{up}', '{down}')"
    sentence = MARGIN + "{{ f.label|cap }} {{ f.contribution|" + said + " }} {{ f.contribution|abs|num }}."
    text, v = verdict(tmp_path, sentence, robot, NAME=name)
    assert v.status == "verified", (text, v.problems())
    assert (up if name == "obstacle" else down) in text


def test_every_claim_filter_verifies_its_true_rendering(tmp_path, robot):
    sentences = [
        "The policy {{ action|role('chose') }} {{ action }} {{ runner_up|role('', 'over') }} {{ runner_up }}.",
        "{% set f = margin_top[0] %}{{ f.label|cap }} was {{ f|rank('the strongest', 'the second') }} reason.",
        "{% set a = margin_top[1] %}{% set b = margin_top[2] %}{{ a.label|cap }} weighed "
        "{{ a|cmp(b, 'more than', 'less than') }} {{ b.label }}.",
    ]
    for sentence in sentences:
        text = render(tmp_path, [sentence], robot)
        v = xairl.verify(text, robot, 0, provenance=text.spans)
        assert v.status == "verified", (text, v.problems())


@pytest.mark.parametrize(
    ("sentence", "words"),
    [
        # 'The policy did not choose turn.' / 'It is false that the policy chose turn.'
        ("The policy did not choose {{ action }}.", {"not", "choose"}),
        ("It is false that the policy chose {{ action }}.", {"false", "chose"}),
        # 'Every feature favoured turn.' (battery was against it)
        ("Every feature favoured {{ action }}.", {"favoured"}),
        # 'Without wind, the policy would still have chosen recharge.'
        ("Without {{ margin_top[2].label }}, the policy would still have chosen {{ runner_up }}.", {"without"}),
        # a literal made-up feature: '...came from obstacle (+2), helped by cell_load.'
        (
            "The push came from {{ margin_top[0].label }} ({{ margin_top[0].contribution|signed }}), helped by "
            "cell_load.",
            {"cell_load"},
        ),
        # 'The margin was increased most strongly by X' (judged once against X's overall rank)
        ("The margin was increased most strongly by {{ margin_top[1].label }}.", {"increased", "most"}),
        # 'The policy chose recharge.' (the runner-up)
        ("The policy chose {{ runner_up }}.", {"chose"}),
    ],
)
def test_a_claim_the_template_wrote_itself_leaves_the_sentence_unchecked(tmp_path, robot, sentence, words):
    text, v = verdict(tmp_path, sentence, robot)
    assert v.status == "partly checked" and not v.ok, text
    said = {c.text.lower() for c in v.claims if c.rule == "tracked.undeclared"}
    assert words & said, (text, said)
    assert all(c.detail for c in v.problems())  # each says what to write instead, never an empty note


def test_a_direction_word_of_another_feature_is_not_verified(tmp_path, robot):
    """'Wind raised the margin.' where the tracked word is another feature's direction: unchecked, not verified."""
    sentence = "{{ margin_top[2].label|cap }} {{ margin_top[1].contribution|dir('raised', 'lowered') }} the margin."
    text, v = verdict(tmp_path, sentence, robot)
    assert v.status == "partly checked", (text, v.claims)
    assert any(c.rule == "tracked.binding" and c.status == "unchecked" for c in v.claims)


def test_a_value_beside_another_name_is_never_contradicted_by_position(tmp_path, robot):
    """Crossed numbers ('A contributed b's, B contributed a's') are not verified, and never contradicted: which name a
    value belongs to is a binding by position."""
    sentence = (
        "{% set a = margin_top[0] %}{% set b = margin_top[1] %}{{ a.label|cap }} contributed "
        "{{ b.contribution|signed }} and {{ b.label }} contributed {{ a.contribution|signed }}."
    )
    text, v = verdict(tmp_path, sentence, robot)
    assert v.status == "partly checked", (text, v.claims)


def test_a_share_after_to_the_margin_is_read_as_a_share(tmp_path, robot):
    """'+2 to the margin, 47.1 % of the total': the share is not bound to 'margin' (issue 65, set B)."""
    sentence = (
        MARGIN + "{{ f.label|cap }}: {{ f.contribution|signed }} to the margin, {{ f.share|num }} % of the total."
    )
    text, v = verdict(tmp_path, sentence, robot, NAME="obstacle")
    assert v.status == "verified", (text, v.problems())


def test_a_canonical_word_replaced_keeps_its_fact_and_is_contradicted(tmp_path, robot):
    """'|replace' keeps a fact: battery's 'against' printed as 'toward' is false."""
    sentence = MARGIN + "{{ f.label|cap }} pushed {{ f.direction|replace('against', 'toward') }} {{ action }}."
    text, v = verdict(tmp_path, sentence, robot, NAME="battery")
    assert v.status == "contradicted", (text, v.claims)


def test_a_bullet_list_keeps_its_lines_and_each_value_its_name(tmp_path, robot):
    """The template's line structure is kept, so each bullet's value sits beside its own name (issue 65, set A)."""
    sentence = (
        "Why {{ action }}:\n{% for f in margin_top %}- {{ f.label }}: {{ f.contribution|signed }} "
        "({{ f.contribution|dir('for', 'against') }} {{ action }})\n{% endfor %}"
    )
    text, v = verdict(tmp_path, sentence, robot)
    assert text.count("\n- ") == 3, text
    assert v.status == "verified", (text, v.problems())
    assert len(v.sentences) == 4
