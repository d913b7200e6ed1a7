"""The account beside a verdict (issue 65): what the features a text names account for of the margin (the score, the
output, or over all states the mean |contribution|), and the features it leaves out with their sum."""

import re

import numpy as np
import pytest

import xairl
from xairl.templates.tracking import Fact, Span
from xairl.toy import toy_policy
from xairl.verification.account import account, features_named
from xairl.verification.result import Claim

#: the issue's report card: it names the buffer (+0.92) and one feature against; four more against are left out
CARD = {"buffer": 0.92, "rsrp_gap": -0.5, "load": -4.72, "speed": -4.56, "distance": -4.11, "cio": -1.36}


def _decision(contributions: dict, base=(20.0, 3.5), output="actions") -> xairl.Explanation:
    values = np.zeros((1, len(contributions), 2))
    values[0, :, 0] = list(contributions.values())
    base_values = np.array([base])
    return xairl.Explanation(
        values=values,
        base_values=base_values,
        outputs=base_values + values.sum(axis=1),
        states=np.ones((1, len(contributions))),
        feature_names=tuple(contributions),
        action_names=("stay", "hand over"),
        method="given",
        output=output,
    )


def _left_out(text: str) -> tuple[int, float, list[tuple[str, float]]]:
    """(how many, their sum, [(name, contribution)]) of the features a margin account says pushed against it."""
    m = re.search(r"(\d+) more features pushed against it, together ([-+][\d.]+): (.*)$", text)
    assert m, text
    listed = [(name, float(v)) for name, v in re.findall(r"(\w+) ([-+][\d.]+)", m.group(3))]
    return int(m.group(1)), float(m.group(2)), listed


def test_the_report_card_says_the_four_features_it_leaves_out_and_their_sum():
    """Coverage 1.00 said nothing of the four features against the choice that the card omits."""
    said = account(_decision(CARD), 0, {"buffer", "rsrp_gap"})
    assert said.startswith("its 2 features account for +0.42 of the margin "), said
    assert "(stay over hand over; base +16.5)" in said
    n, total, listed = _left_out(said)
    assert n == 4 and total == pytest.approx(-14.75, abs=0.06)
    assert listed == [("load", -4.72), ("speed", -4.56), ("distance", -4.11), ("cio", -1.36)]
    margin = float(re.search(r"of the margin ([-\d.]+)", said).group(1))
    assert margin == pytest.approx(16.5 + sum(CARD.values()), abs=0.01)  # base + every contribution


def test_a_text_that_names_every_feature_leaves_none_out_and_both_sides_are_said():
    assert account(_decision(CARD), 0, set(CARD)).endswith("; it leaves no feature out")
    said = account(_decision(CARD), 0, {"load"})
    assert "1 more feature pushed for it: buffer +0.92" in said and "4 more pushed against it, together " in said
    assert "and 1 more" not in said  # four against are listed in full
    said = account(_decision(CARD), 0, set())
    assert said.startswith("it names no feature behind the margin ")
    assert "5 pushed against it" in said and "and 1 more" in said  # the fifth is counted, not named


def test_a_score_a_value_and_the_global_view():
    said = account(_decision(CARD), 0, {"buffer"}, view="score")
    assert said.startswith("its 1 feature accounts for +0.92 of stay's score ") and "lowered it" in said
    value = _decision({"a": 0.3, "b": -0.2}, output="value")
    value = xairl.Explanation(
        values=value.values[:, :, :1],
        base_values=value.base_values[:, :1],
        outputs=value.outputs[:, :1],
        states=None,
        feature_names=("a", "b"),
        action_names=("risk",),
        method="given",
        output="value",
    )
    assert (
        account(value, 0, {"a"}) == "its 1 feature accounts for +0.3 of the output risk 20.1 (base +20); 1 more "
        "feature lowered it: b -0.2"
    )
    said = account(_decision(CARD), None, {"load", "speed"})
    assert said.startswith("its 2 features carry 57 % of the mean |contribution| over 1 state; 4 more features ")
    assert said.endswith("are left out, together 43 %: distance 25 %, cio 8 %, buffer 6 %, rsrp_gap 3 %")


def test_unknown_names_are_no_account_and_a_zero_contribution_pushed_neither_way():
    assert account(_decision(CARD), 0, {"weather"}) == ""
    said = account(_decision({"a": 1.0, "b": 0.0, "c": -0.5}), 0, {"a"})
    assert said.endswith("; 1 more feature pushed against it: c -0.5") and " b " not in said


def test_the_features_named_come_from_tracked_facts_and_from_the_prose_readers_names():
    span = Span(0, 4, "0.92", Fact("contribution", feature="buffer", view="margin"))
    claims = [
        Claim("number", "0.92", "verified", span=span),
        Claim("feature", "load", "verified", "load"),
        Claim("feature", "the gap", "verified", "rsrp_gap / cio"),  # a name the reader could not narrow down
    ]
    assert features_named(claims) >= {"buffer", "load", "rsrp_gap", "cio"}
    assert features_named([], [Span(0, 5, "speed", Fact("name", feature="speed"))]) == {"speed"}


def test_verify_and_narrate_give_the_account_of_their_text():
    """A narrative's account leaves out exactly the features its tracked values do not name, each with its
    contribution to the margin."""
    policy = toy_policy()
    exp = xairl.explain(policy, policy.background(1, seed=3), background=policy.background(40))
    n = xairl.narrate(exp, 0, policy=policy, robustness=False)
    named = {s.fact.feature for s in n.provenance if s.fact.feature in exp.feature_names}
    again = xairl.verify(n.text, exp, 0, policy, provenance=n.provenance)
    assert again.account == n.account and n.evidence["account"] == n.account
    margin = dict(zip(exp.feature_names, exp.margin()[0]))
    for f in set(exp.feature_names) - named:  # each one left out is listed with its contribution
        assert f"{f} {margin[f]:+.3g}" in n.account, n.account
    assert n.account.startswith(f"its {len(named)} feature")
