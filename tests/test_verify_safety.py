"""Two safety readings of the verifier for text from outside (issue 52): a negative feature value written without
its sign is a wrong value (``number.value-sign``), and a feature-like identifier that names nothing, given a push,
is an invented feature (``identifier.invented``). Read on real explanations: the toy policy's, as the template
narrates them, and a corpus case."""

import json
import pathlib
import re

import pytest

import xairl
from tests import narrative_domains as domains
from xairl.narrators.verify import rules
from xairl.toy import toy_policy

STATES = 25


@pytest.fixture(scope="module")
def toy():
    policy = toy_policy()
    exp = xairl.explain(policy, policy.background(STATES, seed=3), background=policy.background(100))
    return policy, exp, [xairl.narrate(exp, i, policy=policy).text for i in range(STATES)]


def _rules(text, exp, i, policy=None):
    result = xairl.verify(text, exp, i, policy)
    return result, {c.rule for c in result.claims if c.status == "contradicted"}


#: a value the template prints in brackets after its name, negative: '(-2.56)', '(-2.02, close)'
_NEGATIVE_VALUE = re.compile(r"\(-(\d+\.\d+)")


@pytest.mark.slow
def test_template_narratives_stay_accurate_and_a_dropped_sign_is_caught(toy):
    policy, exp, texts = toy
    dropped = said = 0
    for i, text in enumerate(texts):
        assert xairl.verify(text, exp, i, policy).accurate, text
        for m in _NEGATIVE_VALUE.finditer(text):
            unsigned = text[: m.start()] + "(" + m.group(1) + text[m.end() :]
            result, why = _rules(unsigned, exp, i, policy)
            assert not result.accurate and "number.value-sign" in why, unsigned
            dropped += 1
            worded = text[: m.start()] + "(" + m.group(1) + " below zero" + text[m.end() :]
            result, why = _rules(worded, exp, i, policy)
            assert result.accurate, (worded, [(c.text, c.detail) for c in result.claims if c.status == "contradicted"])
            said += 1
    assert dropped >= 10 and said == dropped  # (the 25 states hold a few dozen negative values)


@pytest.mark.parametrize(
    "text,accurate",
    [
        ("wind_gust (1.46) pushed toward turn_left by +0.10.", False),  # the case
        ("wind_gust (-1.46) pushed toward turn_left by +0.10.", True),
        ("The wind gust was 1.46.", False),
        ("The wind gust stood at about 1.5.", False),
        ("The wind gust fell to 1.46.", False),  # where it went: the value as written
        ("wind_gust=1.463", False),
        ("The wind gust was 1.46 below zero.", True),
        ("The wind gust was minus 1.46.", True),
        ("The wind gust was negative 1.46.", None),  # (the direction reader reads 'negative' as a push: below)
        ("The wind gust was negative, at 1.46.", None),
        ("The wind gust sat 1.46 standard deviations below the mean.", True),
        ("The wind gust, 1.46 lower than usual, pushed toward turn_left.", True),
        ("The wind gust was 1.46 m/s under the mean.", True),
        ("The wind gust sat below zero at 1.46.", True),
        ("The wind gust was under 2.", True),  # a bound below: true as written
        ("Altitude lowered turn_left's score by 0.3.", True),  # a contribution: its direction word judges it
        ("Altitude raised turn_left's score by 0.3.", False),
        ("Altitude (0.8) lowered turn_left's score by 0.3.", True),
    ],
)
def test_a_values_sign(text, accurate):
    """``accurate`` None: the value holds ('negative 1.46' carries its sign), though the direction reader, not
    this one, reads 'negative' as a push of the wind gust (whose contribution is positive) and contradicts that."""
    result = xairl.verify(text, rules.example("gust"), 0)
    said = [(c.status, c.rule, c.text, c.detail) for c in result.claims]
    if accurate is None:
        assert [c.status for c in result.claims if c.kind == "number"] == ["verified"], said
        return
    assert result.accurate == accurate, said
    if not accurate and "wind" in text.lower():
        assert "number.value-sign" in {c.rule for c in result.claims}


def test_a_value_that_rounds_to_zero_has_no_sign_to_drop():
    exp = rules.example("gust")
    near_zero = xairl.Explanation(
        values=exp.values,
        base_values=exp.base_values,
        outputs=exp.outputs,
        states=exp.states * [[0.002, 1, 1]],  # wind_gust -0.0029
        feature_names=exp.feature_names,
        action_names=exp.action_names,
        method="given",
    )
    assert xairl.verify("The wind gust was 0.00.", near_zero, 0).accurate
    assert xairl.verify("The wind gust was 0.003.", near_zero, 0).accurate is False  # three digits: it is -0.003


def test_a_corpus_case_with_negative_values():
    case = next(c for c in json.loads(_CASES.read_text()) if c["id"] == "toy-1")
    exp = xairl.Explanation.from_json(json.dumps(case["explanation"]))
    policy = domains.policy("toy")
    speed = float(exp.states[0, list(exp.feature_names).index("speed")])
    assert speed < -1
    written = f"{abs(speed):.2f}"
    assert xairl.verify(f"The speed was -{written}.", exp, 0, policy).accurate
    assert xairl.verify(f"The speed was {written} below zero.", exp, 0, policy).accurate
    result, why = _rules(f"The speed was {written}.", exp, 0, policy)
    assert not result.accurate and why == {"number.value-sign"}


_CASES = pathlib.Path(__file__).parents[1] / "benchmarks/data/narratives/cases.json"

INVENTED = (
    " The feature wind_speed contributed +0.50 toward this action.",  # the case
    " The feature humidity contributed +0.50 toward this action.",
    " Its windSpeed input, at the moment, pushed toward this action.",
    " The gimbal's sensor[7] reading contributed +0.2 as well.",
)


@pytest.mark.parametrize("sentence", INVENTED)
def test_an_invented_feature_appended_to_template_narratives_is_caught(toy, sentence):
    policy, exp, texts = toy
    caught = 0
    for i, text in enumerate(texts):
        result, why = _rules(text + sentence, exp, i, policy)
        caught += "identifier.invented" in why
        detail = next(c.detail for c in result.claims if c.rule == "identifier.invented")
        assert "battery" in detail and "wind" in detail  # which names exist
    assert caught == STATES


@pytest.mark.parametrize(
    "sentence",
    [
        " The weather contributed +0.50 toward this action.",  # plain words: no identifier
        " The battery_charge reading pushed toward this action.",  # a description's words
        " Computed with deep_shap; kernel_shap and integrated_gradients agree, within 0.01.",
        " The turn_left option was never on the table, at 0.0.",  # no action of the toy, but no feature-like claim
        " Not wind_speed but the wind itself pushed the choice, by a lot.",
        " See run_log_7 for the raw numbers; they total 25 states.",
        " The feature importance list is the same as before: 3 features matter.",
    ],
)
def test_no_invented_feature_where_none_is_said_to_push(toy, sentence):
    policy, exp, texts = toy
    for i, text in enumerate(texts[:5]):
        _, why = _rules(text + sentence, exp, i, policy)
        assert "identifier.invented" not in why, (sentence, why)


def test_an_invented_feature_in_the_examples_explanations():
    air = rules.example("air")

    def invented(text):
        return [c.text for c in xairl.verify(text, air, 0).claims if c.rule == "identifier.invented"]

    assert invented("The wind_speed reading, at the time, added +6.9.") == []  # part of wind_speed_ms
    assert invented("The humidity_pct reading, at the time, added +6.9.") == ["humidity_pct"]
    assert invented("The feature 'relative humidity' raised the forecast by 3.") == ["relative humidity"]
    assert invented("Traffic, not humidity_pct, raised the forecast by 7.2.") == []
    assert invented('{"eta_h": 19.7, "traffic_index": 2.4}') == []  # a record's field
    assert invented("a=EXTEND_NS Q=52.1 traffic_index +7.2") == []  # an action's code
