"""Verification of xairl's own words by provenance (xairl/verification/own/, issues 52 and 65): a tracked span is
checked by its fact, a declared claim word by its fact, the literal words right beside a value by the rules of
provenance.RULES, each rule shown on a template sentence it must catch and a correct paraphrase that verifies."""

import dataclasses

import numpy as np
import pytest
import torch
import yaml

import xairl
from tests.conftest import mlp
from tests.rule_examples import example
from xairl import Explanation
from xairl.facts import decision_facts
from xairl.narrators.base import first_phrasings
from xairl.templates import prompts, tracking
from xairl.templates.tracking import Fact, Span
from xairl.toy import toy_background, toy_policy
from xairl.verification import own as provenance
from xairl.verification.prose import read as read_prose

#: robot: turn (3.2) over recharge (2.0); chosen score: speed +0.5, battery -0.3, obstacle +2.0; margin: speed +0.7,
#: battery -1.5, obstacle +2.0; values 0.4, 0.3, 0.9; with these quartiles speed is low, battery and obstacle high
QUARTILES = np.array([[0.5, 0.2, 0.5], [0.6, 0.25, 0.6], [0.7, 0.28, 0.7]])


@pytest.fixture(scope="module")
def exps():
    robot = example("robot")
    return {
        "robot": robot,
        "gust": example("gust"),  # wind_gust -1.463 (+0.10 to turn_left's score, +0.15 to the margin)
        "levels": dataclasses.replace(robot, background_quantiles=QUARTILES),
    }


@pytest.fixture(scope="module")
def toy():
    p = toy_policy()
    return p, xairl.explain(p, toy_background(10, seed=3), background=toy_background(30))


def rendered(tmp_path, sentences, exp, i=0, policy=None):
    """The template's first phrasings on tracked facts (what narrate verifies)."""
    path = tmp_path / "t.yaml"
    path.write_text(yaml.safe_dump({"name": "t", "sentences": list(sentences)}, allow_unicode=True))
    ctx = tracking.track_decision(decision_facts(exp, i, policy).context())
    return first_phrasings(prompts.load(path).render_variants(ctx))


def check(tmp_path, sentence, exp, i=0, policy=None):
    text = rendered(tmp_path, [sentence], exp, i, policy)
    assert text.spans, "the sentence prints tracked values"
    return text, xairl.verify(text, exp, i, policy, provenance=text.spans)


def by_rule(v, rule, status="contradicted"):
    return [c for c in v.claims if c.rule == rule and c.status == status]


def contradicted(v):
    return [(c.rule, c.text, c.detail) for c in v.claims if c.status == "contradicted"]


#: rule -> (explanation, a template sentence it must catch, a correct paraphrase that verifies, the text of the
#: wrong rendering, the status the rule gives it: contradicted where a fact or adjacency binds it, else unchecked)
CASES = {
    "tracked.binding": (
        "robot",
        "{{ top[0].label }}: {{ top[1].contribution|signed }}.",
        "{{ top[0].label }}: {{ top[0].contribution|signed }}; {{ top[1].label }}: {{ top[1].contribution|signed }}.",
        "obstacle: +0.50.",
        "unchecked",
    ),
    "tracked.sign": (
        "gust",
        "{% set f = top|selectattr('name', 'equalto', 'wind_gust')|first %}{{ f.label }} was {{ f.value|abs|num }}.",
        "{% set f = top|selectattr('name', 'equalto', 'wind_gust')|first %}{{ f.label }} was {{ f.value|num }}.",
        "wind_gust was 1.46.",
        "contradicted",
    ),
    "tracked.label": (
        "robot",
        "score={{ q_margin|num }}",
        "margin={{ q_margin|num }}, score={{ score|num }}",
        "score=1.20",
        "contradicted",
    ),
    "tracked.view": (
        "robot",
        "{% set f = reasons[0] %}{{ f.label }}: {{ f.contribution|signed }} to the score.",
        "{% set f = reasons[0] %}{{ f.label }}: {{ f.contribution|signed }} to the margin.",
        "obstacle: +2 to the score.",
        "contradicted",
    ),
    "tracked.role": (
        "robot",
        "{{ action }} (score {{ runner_up_score|num }}).",
        "{{ action }} (score {{ score|num }}), {{ runner_up|role('', 'runner-up') }} {{ runner_up }} (score "
        "{{ runner_up_score|num }}).",
        "turn (score 2).",
        "contradicted",
    ),
    "tracked.undeclared": (
        "robot",
        "{{ concession.label }} raised it by {{ concession.contribution|abs|num }}.",
        "{{ concession.label }} {{ concession.contribution|dir('raised', 'lowered') }} it by "
        "{{ concession.contribution|abs|num }}.",
        "battery raised it by 1.50.",
        "unchecked",
    ),
}
BY_HAND = {"tracked.fact", "tracked.unknown"}  # provenance given by hand: a template cannot print a wrong fact
BY_HAND |= {"tracked.counterfactual"}  # needs a counterfactual fact: its corpus is tests/test_counterfactual_words.py
BY_HAND |= {"tracked.trend"}  # needs a window: tests/test_windows.py


def test_every_rule_has_a_case():
    assert set(provenance.RULES) <= set(CASES) | BY_HAND
    assert all(rule.startswith("tracked.") and provenance.RULES[rule] for rule in provenance.RULES)


@pytest.mark.parametrize("rule", sorted(CASES))
def test_rule_catches_the_wrong_sentence_and_not_its_paraphrase(tmp_path, exps, rule):
    name, wrong, right, wrong_text, status = CASES[rule]
    exp = exps[name]
    text, v = check(tmp_path, wrong, exp)
    assert str(text) == wrong_text
    assert by_rule(v, rule, status), (rule, str(text), v.claims)
    assert not v.ok and v.status == ("contradicted" if status == "contradicted" else "partly checked")
    assert all(c.status == "verified" for c in v.claims if c.rule == "tracked.fact")  # every value printed is right
    text, v = check(tmp_path, right, exp)
    assert v.ok, (str(text), v.problems())
    assert not by_rule(v, rule, status)


def test_each_value_beside_its_own_name_in_any_order_verifies(tmp_path, exps):
    robot = exps["robot"]
    for sentence in (
        "{{ top[0].label }} and {{ top[2].label }}: {{ top[0].contribution|signed }} and "
        "{{ top[2].contribution|signed }}.",
        "{{ top[1].contribution|signed }} from {{ top[1].label }}; {{ top[0].label }} gave "
        "{{ top[0].contribution|signed }}.",
    ):
        text, v = check(tmp_path, sentence, robot)
        assert v.ok, (str(text), v.problems())


def test_numbers_the_template_wrote_itself_are_unchecked(tmp_path, exps):
    """A number the template wrote itself (arithmetic, a format string, a literal) is no tracked fact: its sentence
    is unchecked, never verified and never contradicted (a count up to the number of features is no claim)."""
    robot = exps["robot"]
    for wrong in (
        "{{ action }} (score {{ '%.2f'|format(score + 1) }}).",
        "{{ action }}, 7.77 ahead.",
        "{{ action }}, {{ '%.2f'|format(q_margin) }} ahead.",
    ):
        text, v = check(tmp_path, wrong, robot)
        assert v.status == "partly checked", (str(text), v.claims)
        assert [c.kind for c in by_rule(v, "tracked.undeclared", "unchecked")] == ["number"]
    text, v = check(tmp_path, "The 3 features: {{ top|join(', ', attribute='label') }}.", robot)
    assert v.ok, (str(text), v.problems())


def test_sign_words_carry_the_sign(tmp_path, exps):
    gust = exps["gust"]
    f = "{% set f = top|selectattr('name', 'equalto', 'wind_gust')|first %}"
    text, v = check(tmp_path, f + "{{ f.label }} was at minus {{ f.value|abs|num }}.", gust)
    assert v.ok and not by_rule(v, "tracked.sign"), (str(text), v.problems())
    # a positive value printed without a sign is no sign problem
    text, v = check(tmp_path, "{{ top[0].label }} was {{ top[0].value|abs|num }}.", exps["robot"])
    assert v.ok, v.problems()


def test_labels_beside_numbers(tmp_path, exps):
    robot = exps["robot"]
    for wrong in ("margin={{ score|num }}", "The base value was {{ q_margin|num }}.", "score of {{ base_margin|num }}"):
        text, v = check(tmp_path, wrong, robot)
        assert by_rule(v, "tracked.label"), (str(text), contradicted(v))
    for right in (
        "score={{ score|num }} margin={{ q_margin|num }} base={{ base_value|num }}",
        "Its score was {{ q_margin|num }} higher than {{ runner_up }}'s.",
        "{{ top[0].label }} added {{ top[0].contribution|num }} to the score.",
    ):
        text, v = check(tmp_path, right, robot)
        assert not by_rule(v, "tracked.label"), (str(text), contradicted(v))


def test_a_margin_of_the_score_view_is_no_view_mistake(tmp_path, exps):
    robot = exps["robot"]
    text, v = check(tmp_path, "{{ top[1].label }}: {{ top[1].contribution|signed }} to the margin.", robot)
    assert by_rule(v, "tracked.view"), (str(text), contradicted(v))  # +0.50 is speed's share of the score
    text, v = check(tmp_path, "{{ top[1].label }}: {{ top[1].contribution|signed }} to the score.", robot)
    assert v.ok, v.problems()


def test_declared_level_rank_and_comparison_words_are_checked_by_their_facts(tmp_path, exps):
    levels = exps["levels"]
    assert [(f.name, f.level) for f in decision_facts(levels, 0).top] == [
        ("obstacle", "high"),
        ("speed", "low"),
        ("battery", "high"),
    ]
    sentence = (
        "{{ top[1].label }} ({{ top[1].value|num }}, {{ top[1]|level('bajo', 'normal', 'alto') }}) and "
        "{{ top[2].label }} ({{ top[2].value|num }}, {{ top[2]|level('bajo', 'normal', 'alto') }})."
    )
    text, v = check(tmp_path, sentence, levels)
    assert str(text) == "speed (0.40, bajo) and battery (0.30, alto)." and v.ok, v.problems()
    text, v = check(tmp_path, "{{ top[1].label }} came {{ top[1]|rank('first', 'second', 'third') }}.", exps["robot"])
    assert str(text) == "speed came second." and v.ok, v.problems()
    text, v = check(
        tmp_path,
        "{{ top[2].label }} weighed {{ top[2]|cmp(top[0], 'more than', 'less than') }} {{ top[0].label }}.",
        exps["robot"],
    )
    assert str(text) == "battery weighed less than obstacle." and v.ok, v.problems()


# -- provenance given by hand --------------------------------------------------------------------------------------


def spans_of(text, *pieces):
    """Spans at the first place each (piece, fact, transform) is found, in order."""
    out, at = [], 0
    for piece, fact, *transform in pieces:
        start = text.index(piece, at)
        out.append(Span(start, start + len(piece), piece, fact, *transform))
        at = start + len(piece)
    return out


def test_fact_a_tracked_number_is_its_fact(exps):
    """tracked.fact: the span's text against its fact recomputed from the explanation (the fact's own value, as the
    renderer recorded it, is not trusted)."""
    robot = exps["robot"]
    name = Fact("name", "speed", "score")
    wrong = "speed: +0.90 to the score."
    v = xairl.verify(wrong, robot, 0, provenance=spans_of(wrong, ("speed", name), ("+0.90", _c("speed"))))
    assert [c.text for c in by_rule(v, "tracked.fact")] == ["+0.90"] and not v.ok
    lying = dataclasses.replace(_c("speed"), value=0.9)  # the recorded value says 0.9; the explanation says 0.5
    right = "speed: +0.50 to the score."
    v = xairl.verify(right, robot, 0, provenance=spans_of(right, ("speed", name), ("+0.50", lying)))
    assert v.ok and by_rule(v, "tracked.fact", "verified"), contradicted(v)
    # the template's transformation is part of the fact: -0.50 is speed's contribution negated, not speed's
    text = "speed: -0.50."
    v = xairl.verify(text, robot, 0, provenance=spans_of(text, ("speed", name), ("-0.50", _c("speed"))))
    assert by_rule(v, "tracked.fact")
    v = xairl.verify(text, robot, 0, provenance=spans_of(text, ("speed", name), ("-0.50", _c("speed"), "neg")))
    assert v.ok, contradicted(v)
    # a tracked action or name is its fact's word
    text = "The policy chose forward."
    v = xairl.verify(text, robot, 0, provenance=spans_of(text, ("forward", Fact("action", role="chosen"))))
    assert by_rule(v, "tracked.fact") and not v.ok


def _c(feature, view="score"):
    return Fact("contribution", feature, view)


def test_fact_scaled_values_count_only_as_percentages(tmp_path, exps):
    robot = exps["robot"]
    text, v = check(tmp_path, "{{ top[0].label }} was at {{ (top[0].value * 100)|num }}% of its range.", robot)
    assert str(text) == "obstacle was at 90% of its range." and v.ok, contradicted(v)
    text, v = check(tmp_path, "{{ top[0].label }} was {{ (top[0].value * 100)|num }}.", robot)
    assert by_rule(v, "tracked.fact"), (str(text), contradicted(v))


def test_unknown_a_fact_the_explanation_does_not_have(exps):
    robot = exps["robot"]
    text = "wind: +0.50 to the score."
    v = xairl.verify(
        text, robot, 0, provenance=spans_of(text, ("wind", Fact("name", "wind", "score")), ("+0.50", _c("wind")))
    )
    assert len(by_rule(v, "tracked.unknown")) == 2 and not v.ok
    text = "speed: +0.50 to the score."
    v = xairl.verify(text, robot, 0, provenance=spans_of(text, ("+0.50", _c("speed", "sideways"))))
    assert by_rule(v, "tracked.unknown")
    v = xairl.verify(
        text, robot, 0, provenance=spans_of(text, ("speed", Fact("name", "speed", "score")), ("+0.50", _c("speed")))
    )
    assert v.ok and not by_rule(v, "tracked.unknown"), contradicted(v)


# -- names make no claims -------------------------------------------------------------------------------------------


def test_runner_up_in_the_words_names_no_action_up(tmp_path):
    c = np.array([[0.5, -0.2, 0.1], [-0.3, 1.2, -0.1], [2.0, 0.0, -1.5]])
    exp = Explanation(
        values=c[None],
        base_values=np.ones((1, 3)),
        outputs=np.array([[3.2, 2.0, 2.2]]),
        states=np.array([[0.4, 0.3, 0.9]]),
        feature_names=("speed", "battery", "obstacle"),
        action_names=("fire", "up", "noop"),
        method="given",
    )
    facts = decision_facts(exp, 0)
    assert (facts.action, facts.runner_up) == ("fire", "noop")
    sentence = (
        "{{ action|cap }} {{ action|role('won') }}; {{ runner_up|role('', 'the runner-up was') }} {{ runner_up }}."
    )
    text, v = check(tmp_path, sentence, exp)
    assert str(text) == "Fire won; the runner-up was noop." and v.ok, v.problems()
    assert not [c for c in v.claims if c.text.lower() == "up"]
    # written as literal words, the roles are undeclared: unchecked (the word 'up' of 'runner-up' still names nothing)
    text, v = check(tmp_path, "{{ runner_up|cap }} won; the runner-up was {{ action }}.", exp)
    assert v.status == "partly checked" and not [c for c in v.claims if c.text.lower() == "up"], v.claims


# -- narratives ------------------------------------------------------------------------------------------------------


def test_narrative_claims_carry_their_spans(toy):
    policy, exp = toy
    for i in range(3):
        n = xairl.narrate(exp, i, policy=policy, robustness=False)
        assert n.verified and n.provenance
        tracked = [c for c in n.claims if c.span is not None]
        assert tracked and all(c.rule.startswith("tracked.") for c in tracked)
        for c in tracked:
            assert n.text[c.span.start : c.span.end] == c.span.text == c.text
        assert [c.span for c in n.claims if c.rule == "tracked.fact"] == list(n.provenance)
        for s in n.provenance:
            assert n.text[s.start : s.end] == s.text and isinstance(s.fact, Fact)
        assert {s.fact.quantity for s in n.provenance} >= {"action", "score", "margin", "name", "contribution"}


def test_verify_with_provenance_gives_the_narrative_statuses(toy):
    policy, exp = toy
    for template in ("explain_action", "why_not"):
        for i in range(3):
            n = xairl.narrate(exp, i, policy=policy, template=template, robustness=False)
            v = xairl.verify(n.text, exp, i, policy, provenance=n.provenance)
            assert [(s.text, s.status) for s in v.sentences] == list(n.sentences)
            assert v.claims == n.claims and v.ok == n.verified
            assert [c.span for c in v.claims] == [c.span for c in n.claims]


def test_without_provenance_the_reader_reads_as_before(toy):
    policy, exp = toy
    for i in range(3):
        n = xairl.narrate(exp, i, policy=policy, robustness=False)
        for given in (None, ()):
            v = xairl.verify(n.text, exp, i, policy, provenance=given)
            plain = read_prose(n.text, exp, i, policy)
            assert v.sentences == plain.sentences and v.status == plain.status
            assert [(c.kind, c.text, c.status, c.rule) for c in v.claims] == [
                (c.kind, c.text, c.status, c.rule) for c in plain.claims
            ]
            assert not any(c.rule.startswith("tracked.") or c.span is not None for c in v.claims)
        assert xairl.verify(n.text, exp, i, policy).status == read_prose(n.text, exp, i, policy).status


def test_a_wrong_provenance_is_contradicted_where_the_reader_would_not_be_asked(toy):
    """The same text, given spans that say each number is another feature's, is contradicted by its facts."""
    policy, exp = toy
    n = xairl.narrate(exp, 0, policy=policy, robustness=False)
    numbers = [s for s in n.provenance if s.fact.quantity == "contribution"]
    assert len(numbers) >= 2
    a, b = numbers[0], numbers[1]
    swapped = [
        dataclasses.replace(s, fact=b.fact) if s == a else dataclasses.replace(s, fact=a.fact) if s == b else s
        for s in n.provenance
    ]
    v = xairl.verify(n.text, exp, 0, policy, provenance=swapped)
    assert not v.ok and any(c.rule == "tracked.fact" and c.status == "contradicted" for c in v.claims)


def test_every_builtin_template_verifies_on_the_toy_policy(toy):
    policy, exp = toy
    names = {name for name in prompts.available() if prompts.load(name).spec.kind == "decision"}
    assert {"explain_action", "explain_score", "why_not", "explain_output"} <= names
    for name in sorted(names):
        if "actions" not in prompts.load(name).spec.outputs:
            continue
        for i in range(len(exp.values)):
            n = xairl.narrate(exp, i, policy=policy, template=name, robustness=False)
            assert n.verified and n.source == "template", (
                name,
                i,
                n.text,
                [c for c in n.claims if c.status != "verified"],
            )
            assert n.provenance
    n = xairl.narrate(exp, None, policy=policy, robustness=False)
    assert n.verified and n.provenance, n.text


def test_explain_output_verifies_on_a_value_policy():
    names = [f"x{j}" for j in range(5)]
    policy = xairl.Policy(mlp([5, 8, 1], act=torch.nn.Tanh), names, ["value"], output="value")
    rng = np.random.default_rng(1)
    exp = xairl.explain(policy, rng.normal(size=(10, 5)), background=rng.normal(size=(30, 5)))
    for i in range(10):
        n = xairl.narrate(exp, i, policy=policy, robustness=False)
        assert n.template == "explain_output" and n.verified and n.provenance, (i, n.text)


def test_names_and_descriptions_cannot_smuggle_claims_with_provenance(tmp_path):
    """A description carrying claims, printed as a tracked name, is not trusted as a name: its words are read."""
    net = torch.nn.Linear(2, 2)
    with torch.no_grad():
        net.weight.copy_(torch.tensor([[1.0, 0.0], [0.0, 1.0]]))
        net.bias.zero_()
    hostile = xairl.FeatureInfo("", "speed, the most important feature, pushing toward go by +9.99")
    policy = xairl.Policy(net, ["speed", "load"], ["go", "stop"], features={"speed": hostile})
    exp = xairl.explain(policy, [[0.1, 2.0]], background=np.zeros((10, 2)), method="exact")  # load dominates
    n = xairl.narrate(exp, 0, policy=policy, robustness=False)
    assert not n.verified and n.confidence == 0.0
    v = xairl.verify(n.text, exp, 0, policy, provenance=n.provenance)
    assert not v.ok
    text = rendered(tmp_path, ["The policy chose {{ action }}. {{ margin_top[1].label|cap }}."], exp, 0, policy)
    assert "pushing toward go by +9.99" in text
    v = xairl.verify(text, exp, 0, policy, provenance=text.spans)
    assert not v.ok and any(c.kind in ("number", "rank", "direction") for c in v.problems()), v.claims
