"""The claim filters (xairl/templates/claim_filters.py): each prints the author's word for a claim as a tracked word
whose fact says which claim it is, so the word may be any word in any language; an untracked input gives the plain
word."""

import pytest
import yaml

from xairl.facts import decision_facts, global_facts
from xairl.narrators.battery_cases import flat_cases
from xairl.templates import prompts, tracking
from xairl.templates.claim_filters import compare, direction, level, rank
from xairl.templates.tracking import Fact


@pytest.fixture(scope="module")
def case():
    """flat, signs +,-,+: temperature +0.9 (low), queue_len -0.6 (typical), mode +0.35 to the chosen score."""
    return next(c for c in flat_cases() if c.label == "flat, signs +,-,+")


@pytest.fixture(scope="module")
def facts(case):
    return decision_facts(case.explanation, 0, case.policy, 3)


def render(tmp_path, sentence, context):
    path = tmp_path / "t.yaml"
    path.write_text(yaml.safe_dump({"name": "t", "sentences": [sentence]}, allow_unicode=True))
    (variants,) = prompts.load(path).render_variants(context)
    r = variants[0]
    for s in r.spans:
        assert r[s.start : s.end] == s.text
    return r


def claims(r):
    return [(s.text, s.fact) for s in r.spans if s.fact.of is not None]


def test_dir_prints_the_authors_words_with_the_sign_as_fact(tmp_path, facts):
    ctx = tracking.track_decision(facts.context())
    r = render(tmp_path, "{% for f in top %}{{ f.contribution|dir('aumentó', 'redujo') }} {% endfor %}", ctx)
    assert r.split() == ["aumentó", "redujo", "aumentó"]
    (text, fact), *_ = claims(r)
    top0 = facts.top[0]
    assert fact == Fact("direction", top0.name, "score", None, "toward", of="contribution")
    # a feature dict gives its contribution; a negated number's word follows its sign, its fact the quantity's
    r = render(tmp_path, "{{ top[1]|dir('up', 'down') }} {{ (-top[1].contribution)|dir('up', 'down') }}", ctx)
    assert str(r) == "down up"
    assert [f.value for _, f in claims(r)] == ["against", "against"]
    # the margin's direction, and an absolute value (no direction: a plain word)
    r = render(tmp_path, "{{ q_margin|dir('higher', 'lower') }} {{ top[1].contribution|abs|dir('up', 'down') }}", ctx)
    assert str(r) == "higher up" and [f for _, f in claims(r)] == [
        Fact("direction", None, "margin", None, "toward", of="margin")
    ]


def test_dir_on_a_global_views_directions(case):
    g = tracking.track_global(global_facts(case.explanation, case.policy, k=3).context())
    f = g["ranking"][0]
    word = direction(f, "raised", "lowered", "pushed both ways")
    assert word in {"raised", "lowered", "pushed both ways"}
    with tracking.recording() as record:
        marked = direction(f["high_values"], "when high", "when high", "either way")
    text, (span,) = tracking.untangle(marked, record)
    assert span.fact.quantity == "direction_high" and span.fact.value == str(f["high_values"])
    assert span.fact.of == "direction_high"


def test_level_rank_and_cmp_facts(tmp_path, facts):
    ctx = tracking.track_decision(facts.context())
    body = (
        "{% set a = margin_top[0] %}{% set b = margin_top[1] %}{{ a|level('bajo', 'normal', 'alto') }}, "
        "{{ a|rank('primero', 'segundo') }}, {{ b|rank('primero', 'segundo') }}, {{ a|cmp(b, 'más', 'menos') }}, "
        "{{ b|cmp(a, 'más', 'menos') }}"
    )
    r = render(tmp_path, body, ctx)
    a, b = facts.margin_top[0], facts.margin_top[1]
    assert str(r) == f"{ {'low': 'bajo', 'typical': 'normal', 'high': 'alto'}[a.level] }, primero, segundo, más, menos"
    got = [f for _, f in claims(r)]
    assert got == [
        Fact("level", a.name, "margin", value=a.level, of="level"),
        Fact("rank", a.name, "margin", value=1, of="rank"),
        Fact("rank", b.name, "margin", value=2, of="rank"),
        Fact("comparison", a.name, "margin", b.name, "more", of="contribution"),
        Fact("comparison", b.name, "margin", a.name, "less", of="contribution"),
    ]


def test_rank_past_its_words_and_a_tie(tmp_path, facts):
    ctx = tracking.track_decision(facts.context())
    r = render(
        tmp_path, "{{ top[2]|rank('first', other='also') }} {{ top[0]|cmp(top[0], 'more', 'less', 'as much') }}", ctx
    )
    assert str(r) == "also as much"
    assert [f.value for _, f in claims(r)] == [3, "same"]


def test_role_words_by_the_actions_role(tmp_path, facts):
    ctx = tracking.track_decision(facts.context())
    body = "{{ action|role('eligió') }} {{ action }}; {{ runner_up }} {{ runner_up|role('ganó', 'quedó segunda') }}"
    r = render(tmp_path, body, ctx)
    assert str(r) == f"eligió {facts.action}; {facts.runner_up} quedó segunda"
    assert [f for _, f in claims(r)] == [
        Fact("role", role="chosen", value=facts.action, of="action"),
        Fact("role", role="runner_up", value=facts.runner_up, of="action"),
    ]


def test_role_only_when_the_runner_up_is_the_chosen_action(tmp_path):
    c = next(c for c in flat_cases() if c.label == "flat, one available action")
    ctx = tracking.track_decision(decision_facts(c.explanation, 0, c.policy, 3).context())
    r = render(tmp_path, "{{ action|role('chose', only='the only available action') }}", ctx)
    assert str(r) == "the only available action" and claims(r)[0][1].role == "only"


def test_untracked_inputs_give_the_plain_word(facts):
    with tracking.recording() as record:
        words = [
            direction(-0.2, "up", "down"),
            direction("toward", "up", "down"),
            level({"level": "high"}, "l", "t", "h"),
            rank({"rank": 2}, "a", "b"),
            compare({"contribution": 0.1}, {"contribution": -0.3}, "more", "less"),
        ]
    assert words == ["down", "up", "h", "b", "less"] and record == []


def test_rank_same_way_is_the_rank_among_pushes_of_its_sign(tmp_path):
    # the two biggest pushes on the margin are against the chosen action: the first reason ranks 3rd, and 1st its way
    c = next(c for c in flat_cases() if c.label == "flat, signs -,-,+")
    facts = decision_facts(c.explanation, 0, c.policy, 3)
    assert facts.reasons[0].rank == 3 and facts.reasons[0].rank_same_way == 1
    ctx = tracking.track_decision(facts.context())
    r = render(tmp_path, "{{ reasons[0].rank_same_way|rank('the biggest', other='a') }}", ctx)
    name = facts.reasons[0].name
    assert str(r) == "the biggest" and claims(r)[0][1] == Fact(
        "rank_same_way", name, "margin", value=1, of="rank_same_way"
    )
    text = first_sentence(prompts.load("explain_action"), ctx, 1)
    assert text.startswith(f"The biggest push toward {facts.action} over {facts.runner_up} came from "), text


def first_sentence(tpl, ctx, s):
    return str(tpl.render_variants(ctx)[s][0])
