"""A number bound by position alone is a guess: when the words or the parse show that it states another fact of the
explanation, it is unchecked, not wrong (rules ``number.elsewhere`` and ``parse.said-of-other``); each rule's
example is outside prose (the held-out tuning voices), and each has a wrong twin that stays contradicted."""

import numpy as np
import pytest

import xairl
from xairl.narrators.verify import rules


def _air():
    """Next-day PM2.5 (µg/m³): the average forecast 22.0, this one 53.0."""
    names = ("precip_mm_24h", "wind_speed_ms", "pm2_5_lag1", "traffic_index")
    contrib = np.array([2.2, 6.9, 14.7, 7.2])
    return xairl.Explanation(
        values=contrib.reshape(1, -1, 1),
        base_values=np.array([[22.0]]),
        outputs=np.array([[22.0 + contrib.sum()]]),
        states=np.array([[0.0, 0.8, 48.2, 2.4]]),
        feature_names=names,
        action_names=("pm2_5",),
        method="given",
        output="value",
    )


def _numbers(text):
    return [c for c in xairl.verify(text, _air(), 0).claims if c.kind == "number"]


@pytest.mark.parametrize(
    "number,status,rule",
    [
        ("53", "unchecked", "number.elsewhere"),  # the forecast itself, after a name it is not about
        ("35", "contradicted", "number.name-before"),  # no fact at all: wrong wherever it is bound
    ],
)
def test_a_decision_level_number_after_a_name_is_not_that_names(number, status, rule):
    text = f"Tomorrow's PM2.5 forecast with 0 mm of rain is {number} µg/m³."
    claim = next(c for c in _numbers(text) if c.text.startswith(number))
    assert (claim.status, claim.rule) == (status, rule), claim


@pytest.mark.parametrize("number,status", [("14.7", "unchecked"), ("11.3", "contradicted")])
def test_a_number_said_of_a_noun_that_names_nothing(number, status):
    """'yesterday's reading' is pm2_5_lag1 in words the vocabulary lacks: its exact contribution is unchecked (the
    reading may mean it), a number no feature holds stays contradicted."""
    text = f"Heavy traffic adds about 7.2, and yesterday's high reading adds {number}."
    claim = next(c for c in _numbers(text) if c.text == number)
    assert claim.status == status, claim
    if status == "unchecked":
        assert claim.rule == "parse.said-of-other" and "pm2_5_lag1" in claim.detail


@pytest.mark.parametrize(
    "text,status",
    [
        ("pred=53.0 base=22.0 pm2_5_lag1=+14.7 run_id=7781 latency_ms=42", "verified"),  # the run's record: no claim
        ("pred=53.0 base=22.0 pm2_5_lag1=+14.7 humidity_pct=+3.1", "contradicted"),  # a push of no feature
    ],
)
def test_a_log_field_is_no_invented_feature(text, status):
    assert xairl.verify(text, _air(), 0).status == status


def test_a_name_that_only_qualifies_another_noun_is_not_what_a_rank_is_about():
    """'the wind queue' is a queue (no feature of this explanation), not the wind: its rank is unchecked; said of
    the wind itself, the wrong rank is contradicted; a question asserts nothing."""

    def rank(text):
        return next(c for c in xairl.verify(text, _air(), 0).claims if c.kind == "rank")

    assert rank("The main reason is the wind queue at the junction.").status == "unchecked"
    assert rank("The main reason is the wind.").status == "contradicted"
    assert xairl.verify("Is the wind the main reason?", _air(), 0).accurate


@pytest.mark.parametrize(
    "text,status",
    [
        ("The season adds -1.0.", "verified"),  # the signed amount says the way
        ("The season adds a small penalty of about 1.", "verified"),  # so does a noun of loss
        ("The season adds about 1.", "contradicted"),  # a plain 'adds' raises: the season lowered it
        ("Traffic adds a small penalty of about 7.", "contradicted"),  # traffic raised it
    ],
)
def test_what_an_amount_verb_adds_says_its_way(text, status):
    assert xairl.verify(text, rules.example("air"), 0).status == status  # (the season: -1.0)


@pytest.mark.parametrize(
    "text,status",
    [
        ("With the traffic heavy, the forecast is pushed up by the wind.", "verified"),  # said of the agent
        ("With the season cold, the forecast is pushed up by the wind.", "verified"),  # not of the name before
        ("With the traffic heavy, the forecast is pushed down by the wind.", "contradicted"),
    ],
)
def test_a_passive_direction_is_said_of_its_agent(text, status):
    assert xairl.verify(text, rules.example("air"), 0).status == status


@pytest.mark.parametrize(
    "text,status",
    [
        ("The lag-one reading's pm2_5_lag1 effect is roughly twice that of traffic (14.7 vs 7.2).", "verified"),
        ("The lag-one reading's pm2_5_lag1 effect is roughly twice that of traffic (7.2 vs 14.7).", "contradicted"),
    ],
)
def test_a_bracket_of_two_numbers_pairs_with_the_two_names_in_order(text, status):
    assert xairl.verify(text, rules.example("air"), 0).status == status
