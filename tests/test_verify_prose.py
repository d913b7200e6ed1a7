"""The verifier on prose it did not write: each pipeline step on its own, the held-out corpus, bad input.

The parametrised case lists live in benchmarks/data/verify_cases/*.yaml (loaded by tests/cases.py), one item per case."""

import json
import pathlib
from dataclasses import replace

import numpy as np
import pytest
import torch

import xairl
from tests import cases
from tests import narrative_domains as domains
from tests.narrative_corpus import VOICES, explanation_from_tuples, load_corpus, run, shapstories_case
from tests.work_budget import calls
from xairl.verification.prose.book import clean_surface
from xairl.verification.prose.names import find_mentions
from xairl.verification.prose.numbers import find_numbers, matches
from xairl.verification.prose.vocabulary import vocabulary
from xairl.verification.text import normalise


@pytest.mark.parametrize(
    "text,value,unit,hedge", cases.params("numbers", "numbers_as_people_write_them", ("text", "value", "unit", "hedge"))
)
def test_numbers_as_people_write_them(text, value, unit, hedge):
    n = find_numbers(normalise(text))[0]
    assert n.value == pytest.approx(value) and n.unit == pytest.approx(unit) and n.hedge == hedge


def test_hedges_widen_the_tolerance_as_documented():
    def num(t):
        return find_numbers(normalise(t))[0]

    assert matches(num("about $12,000"), 12757.84) and matches(num("around 800"), 812)
    assert matches(num("roughly 0.6"), 0.63) and matches(num("nearly 2 dB"), 1.8)
    assert not matches(num("about 5,000"), 12757.84) and not matches(num("12,000"), 13757)
    assert matches(num("6,157"), 6157.86)  # truncated
    assert not matches(num("nearly 2"), 2.8) and matches(num("less than $500"), -494)
    assert matches(num("3/10"), 0.3) and matches(num("3/10"), 3)
    assert matches(num("\u22124.3"), -4.3) and not matches(num("+4.3"), -4.3)


def _exp(
    names=("gill_size", "odor", "cap_diameter"),
    contrib=(0.11, 0.15, -0.05),
    states=(1, 0, 7.5),
    categories=None,
):
    if categories is None:
        categories = {"gill_size": ("broad", "narrow"), "odor": ("foul", "none")}
    c = np.array(contrib, float)
    return xairl.Explanation(
        values=c.reshape(1, -1, 1),
        base_values=np.array([[0.3]]),
        outputs=np.array([[0.3 + c.sum()]]),
        states=np.array([states], float),
        feature_names=tuple(names),
        action_names=("poisonous",),
        method="given",
        output="value",
        categories=categories,
    )


_CASES = {
    c["id"]: c
    for c in json.loads((pathlib.Path(__file__).parents[1] / "benchmarks/data/narratives/cases.json").read_text())
}


def _status(text):
    """The verdict on ``text`` against the mushroom explanation (odor +0.15, gill size +0.11, cap diameter -0.05)."""
    return xairl.verify(text, _exp(), 0).status


def _on_case(text, case):
    """``text`` verified against a corpus case, with its domain's policy."""
    exp = xairl.Explanation.from_json(json.dumps(_CASES[case]["explanation"]))
    return xairl.verify(text, exp, 0, domains.policy(case.split("-")[0]))


def test_name_variants_and_ambiguity():
    exp = _exp(names=("gill_size", "gill_color", "capDiameter"), categories=None)
    vocab = vocabulary(exp, None, clean_surface)
    for text in ("gill-size", "gill size", "GillSize", "gill_size"):
        (m,), _ = find_mentions(text, vocab)
        assert m.keys == ("gill_size",), text
    (m,), _ = find_mentions("the cap diameter", vocab)
    assert m.keys == ("capDiameter",)
    for text in ("GILL SIZE", "gıll ſize", "CAPDIAMETERS"):  # each name's regex runs only when its first word is there
        (m,), _ = find_mentions(text, vocab)
        assert m.keys[0] in ("gill_size", "capDiameter"), text
    (m,), _ = find_mentions("the gill", vocab)
    assert set(m.keys) == {"gill_size", "gill_color"}  # ambiguous, not guessed
    res = xairl.verify("The gill raised the prediction by 0.11.", exp, 0)  # true of gill_size only
    assert [c.status for c in res.claims if c.kind == "number"] == ["unchecked"]
    assert any("ambiguous" in c.detail for c in res.claims)
    assert xairl.verify("The gill lowered the prediction.", exp, 0).status == "contradicted"  # false of both


def test_categorical_values_are_checked():
    exp = _exp()
    assert xairl.verify("The narrow gill size raises the prediction by 0.11.", exp, 0).accurate
    bad = xairl.verify("The broad gill size raises the prediction by 0.11.", exp, 0)
    assert [c.kind for c in bad.problems()] == ["category"]
    assert not xairl.verify("odor: none, which adds 0.15.", exp, 0).ok
    assert xairl.verify("odor: foul, which adds 0.15.", exp, 0).accurate


def test_contribution_phrasing_single_output_and_directions():
    exp = _exp()
    for good in (
        "The SHAP value of odor is 0.15.",
        "Its odor has a contribution of 0.15.",
        "odor increases the prediction by about 0.15",
        "Cap diameter decreases the prediction.",
        "Cap diameter does not increase the prediction.",
        "Odor has a positive impact on the prediction.",
    ):
        assert xairl.verify(good, exp, 0).accurate, good
    for bad in (
        "Odor decreases the prediction.",
        "Cap diameter pushes the prediction up.",
        "Odor does not increase the prediction.",
        "The SHAP value of odor is 0.51.",
    ):
        assert not xairl.verify(bad, exp, 0).ok, bad


def test_lists_ranks_and_magnitude():
    exp = _exp()
    assert xairl.verify("Odor and gill size raise it by 0.15 and 0.11, respectively.", exp, 0).accurate
    assert not xairl.verify("Odor and gill size raise it by 0.11 and 0.15, respectively.", exp, 0).ok
    assert xairl.verify("The top two features were odor and gill size.", exp, 0).accurate
    assert not xairl.verify("The top two features were odor and cap diameter.", exp, 0).ok
    assert xairl.verify("Odor was the most important feature, followed by gill size.", exp, 0).accurate
    assert not xairl.verify("Gill size was the most important feature.", exp, 0).ok
    assert not xairl.verify("Odor barely matters.", exp, 0).ok


def test_sentence_status_and_coverage():
    exp = _exp()
    res = xairl.verify("Odor raises the prediction by 0.15. Mushrooms are fascinating. Nature is big.", exp, 0)
    assert [s.status for s in res.sentences] == ["verified", "none", "none"]  # (they state nothing)
    assert res.coverage == 1 and res.ok and res.status == "verified"
    res = xairl.verify("Odor raises the prediction by 0.15. Most of it comes from elsewhere.", exp, 0)
    assert [s.status for s in res.sentences] == ["verified", "unchecked"] and res.status == "partly checked"
    invented = xairl.verify("The stem height raises the prediction by 0.2.", exp, 0)
    assert invented.status == "partly checked"  # an invented subject: unchecked (the parse may err), never verified


def test_a_direction_said_by_taking_a_feature_away():
    assert _status("If it were not for its odor, the prediction would be much lower.") == "partly checked"
    assert _status("Had the odor not been foul, the prediction would likely be lower.") == "partly checked"
    assert _status("Without the cap diameter, the prediction would be higher.") == "partly checked"
    assert _status("If it were not for its odor, the prediction would be much higher.") == "partly checked"
    assert _status("Without the cap diameter, the prediction would be lower.") == "partly checked"
    assert _status("Had the odor been different, the prediction would be lower.") == "partly checked"  # another value


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 172): not read yet, or left unchecked where the old reader bound it",
)
def test_a_vague_subject_is_not_an_invented_feature():
    """Explingo's 'The house's small size decreases the house price prediction': no feature is named, but 'size' of
    the house is vague, not invented (unchecked); a noun of its own ('the swimming pool') is invented."""
    exp = _exp(names=("living_area_sqft", "overall_quality"), contrib=(-0.2, 0.1), states=(1256, 5), categories=None)
    for vague in (
        "The house's small size decreases the prediction.",
        "Its size of around 800 sq ft significantly decreased the prediction.",
    ):
        assert xairl.verify(vague, exp, 0).status == "unchecked", vague
    assert xairl.verify("The swimming pool decreases the prediction.", exp, 0).status == "contradicted"


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 186): not read yet, or left unchecked where the old reader bound it",
)
def test_a_number_bound_to_the_wrong_name_is_unchecked_not_wrong():
    """'by 0.15' binds to the nearest name (the cap diameter, -0.05), but it is odor's contribution exactly: the
    binding was a guess, so the number is left unchecked; a number that is no fact of a named feature, or a hedged
    one, is still contradicted."""
    exp = _exp()

    def number(text):
        return [c for c in xairl.verify(text, exp, 0).claims if c.kind == "number"][0]

    guessed = number("Odor beats the cap diameter by 0.15.")
    assert guessed.status == "unchecked" and "odor's contribution" in guessed.detail
    assert number("Odor beats the cap diameter by 0.35.").status == "contradicted"
    assert number("Odor beats the cap diameter by about 0.15.").status == "contradicted"


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 210): not read yet, or left unchecked where the old reader bound it",
)
def test_table_cells_are_items_and_an_unnamed_feature_is_not_wrong():
    """A row of 'label number' cells (or cells after '||'): each is an item, so a cell whose label the vocabulary lacks ('lag reading')
    does not lend its numbers to the name of the cell before; a field's name and its value stay one item. A number
    bound by position that states an unnamed feature's exact fact is unchecked; one that states no fact, or measures
    a fact noun of the name before it, stays contradicted."""
    from tests import rule_examples as rules

    air = rules.example("air")

    def numbers(text):
        return [(c.text, c.status) for c in xairl.verify(text, air, 0).claims if c.kind == "number"]

    row = xairl.verify("traffic 2.4 +7.2 | lag reading 48.2 +14.7 | wind 0.8 +6.9", air, 0)
    assert row.status == "partly checked"  # nothing bound across a cell; the unnamed cell's numbers unchecked
    assert xairl.verify("traffic 2.4 +7.2 | wind 0.8 +9.9", air, 0).status == "partly checked"  # +9.9 unread
    assert numbers("Top factors | traffic = 2.4 | +7.2 || wind 0.8 m/s | +6.9 || sheltered site | +3.3")[-1] == (
        "+3.3",
        "unchecked",
    )  # (not the wind's)
    assert numbers("Feature: traffic_index | value: 2.4 | SHAP: +7.2") == [("2.4", "verified"), ("+7.2", "verified")]
    assert numbers("Traffic is heavy, with yesterday's level at 14.7.") == [("14.7", "unchecked")]
    assert numbers("Traffic is heavy, with yesterday's level at 12.3.") == [("12.3", "contradicted")]
    assert numbers("Traffic is heavy, with an increase of 14.7.") == [("14.7", "contradicted")]


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 228): not read yet, or left unchecked where the old reader bound it",
)
def test_an_invented_feature_needs_the_parse_to_agree():
    """The words before a direction word propose an invented feature; the parse must find a subject of the word's
    verb that names nothing: not the model itself after an opener, not a participle's missing subject."""
    from tests import rule_examples as rules

    air = rules.example("air")

    def invented(text):
        return [c.text for c in xairl.verify(text, air, 0).claims if c.kind == "feature" and c.status == "contradicted"]

    assert invented("With 0 mm of rain in the last day, the model adds about 2.2.") == []
    assert invented("A pedestrian pressed the button at the crossing, costing about 0.7.") == []
    assert invented("The wet pavement reported by the weather feed lowered the forecast by 0.5.") == [
        "The wet pavement reported by the weather feed"
    ]
    assert invented("The depot's smoke added 0.5.") == ["The depot's smoke"]


@pytest.mark.parametrize(
    "text,status", cases.params("phrasings", "ranks_of_several_names_and_of_one_side", ("text", "status"))
)
def test_ranks_of_several_names_and_of_one_side(text, status):
    from tests import rule_examples as rules

    result = xairl.verify(text, rules.example("air"), 0)
    assert result.status == status, [(c.status, c.text, c.detail) for c in result.claims]
    assert all("\0" not in c.text for c in result.claims)  # the names as written, not masked


@pytest.mark.parametrize(
    "text,status", cases.params("phrasings", "outputs_own_words_idioms_and_totals", ("text", "status"))
)
def test_the_outputs_own_words_idioms_and_totals(text, status):
    from tests.narrative_corpus import one_output

    cost = one_output(["driver_age", "deductible_usd"], [44, 1000], [-88.0, -199.0], 1850.0, "expected claim cost")
    dropout = one_output(
        ["enrollment_type", "units_failed", "scholarship"],
        ["evening", 3, "yes"],
        [4.4, 17.5, -7.9],
        18.4,
        "probability that the student drops out",
    )
    exp = dropout if "points" in text or "drop" in text else cost
    result = xairl.verify(text, exp, 0)
    assert result.status == status, [(c.status, c.text, c.detail) for c in result.claims]


@pytest.mark.parametrize("text,status", cases.params("phrasings", "where_a_push_comes_from", ("text", "status")))
def test_where_a_push_comes_from(text, status):
    from tests import rule_examples as rules

    result = xairl.verify(text, rules.example("air"), 0)
    assert result.status == status, [(c.status, c.text, c.detail) for c in result.claims]


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 296): not read yet, or left unchecked where the old reader bound it",
)
def test_a_plus_sign_marks_a_push_not_the_output():
    """'made the forecast higher (+2.2)' of a thing the vocabulary lacks: the one feature whose push it is, not the
    forecast (52.1); a push no feature has is left unchecked (whose it is is unsaid), not read as the forecast."""
    from tests import rule_examples as rules

    def number(text):
        return [(c.status, c.detail) for c in xairl.verify(text, rules.example("air"), 0).claims if c.kind == "number"]

    assert number("Calm air, which on its own made the forecast higher (+2.2).") == [
        ("verified", "precip_mm_24h's contribution (the only one it matches)")
    ]
    assert number("Calm air, which on its own made the forecast higher (+3.3).")[0][0] == "unchecked"


def test_a_sum_of_probabilities_in_points():
    from tests.narrative_corpus import one_output

    churn = one_output(
        ["Contract", "tenure_months", "MonthlyCharges"],
        ["Two year", 58, 80.0],
        [-0.152, -0.094, 0.051],
        0.26,
        "churn probability",
    )
    assert xairl.verify(
        "The contract and tenure together pull the estimate down by around 25 points.", churn, 0
    ).accurate
    assert (  # (a sum of several features: unchecked, so the text is not verified)
        xairl.verify("The contract and tenure together pull the estimate down by around 35 points.", churn, 0).status
        == "partly checked"
    )


@pytest.mark.parametrize("text,status", cases.params("phrasings", "list_items_outputs_and_sums", ("text", "status")))
def test_list_items_outputs_named_after_and_sums_with_unknown_members(text, status):
    from tests import rule_examples as rules

    result = xairl.verify(text, rules.example("air"), 0)
    assert result.status == status, [(c.status, c.text, c.detail) for c in result.claims]


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 323): not read yet, or left unchecked where the old reader bound it",
)
def test_one_word_of_a_long_name_is_no_sure_binding():
    """'bill $109.9 +.097': 'bill' is one word of price_increase_last_bill_pct, and both numbers are the monthly
    charge's exactly: unchecked, not wrong; a number that is no fact after that word stays contradicted."""
    from tests.narrative_corpus import one_output

    exp = one_output(["price_increase_last_bill_pct", "MonthlyCharges"], [12, 109.9], [0.141, 0.097], 0.4, "churn")

    def numbers(text):
        return [(c.text, c.status) for c in xairl.verify(text, exp, 0).claims if c.kind == "number"]

    assert numbers("bill $109.9 +.097") == [("$109.9", "unchecked"), ("+.097", "unchecked")]
    assert ("+.099", "contradicted") in numbers("bill $109.9 +.099")


def test_a_heading_before_a_colon_is_no_invented_feature():
    from tests.narrative_corpus import one_output

    exp = one_output(["gpa", "scholarship"], [3.6, "yes"], [-7.0, -5.0], 18.0, "dropout risk")
    claims = xairl.verify(
        "Good news on Aisha: the model puts her dropout risk at just under 6%, against a cohort average of about 18%.",
        exp,
        0,
    ).claims
    assert not [c for c in claims if c.kind == "feature" and c.status == "contradicted"]


def test_a_signed_number_ends_the_item_before_the_next_name():
    """'pm2_5_lag1 +14.7 traffic_index +7.2': +14.7 is the lag's, not the traffic's that follows it; so is a field's
    value after '=' ('E[Q]=1.20 battery_pct=31'); a wrong one is contradicted as its own item's."""
    from tests import rule_examples as rules

    air = rules.example("air")

    def numbers(text):
        return [(c.text, c.status, c.detail) for c in xairl.verify(text, air, 0).claims if c.kind == "number"]

    assert [s for _, s, _ in numbers("pm2_5_lag1 +14.7 traffic_index +7.2")] == ["verified", "verified"]
    wrong = next(n for n in numbers("the base of 22.0 wind -6.9 traffic +7.2") if n[0] == "-6.9")
    assert wrong[1] == "contradicted" and "wind_speed_ms" in wrong[2]


@pytest.mark.parametrize(
    "text,status", cases.params("phrasings", "shares_ratios_and_counts_of_factors", ("text", "status"))
)
def test_shares_ratios_and_counts_of_factors(text, status):
    """A percentage of the net change, a ratio to another named feature ('% of', 'times'), the share of a sum, and a
    count of the factors a sentence lists (no claim)."""
    from tests import rule_examples as rules

    result = xairl.verify(text, rules.example("air"), 0)
    assert result.status == status, [(c.status, c.text, c.detail) for c in result.claims]


@pytest.mark.parametrize(
    "text",
    [
        "",
        " ",
        "x" * 1_000_000,
        "Die Geruchsnote erhöht die Vorhersage deutlich.",
        "odor adds 1.5e-1",
        "odor adds\u00a00.15 \u2212 wait",
        "\x00\x01",
    ],
)
def test_bad_input_gives_a_status_not_an_exception(text):
    """... after little work: counted in function calls, not seconds (~230,000 for the million characters, cut at
    200,000; the time is in benchmarks/bench_test_timings.py)."""
    res, work = calls(xairl.verify, text, _exp(), 0)
    assert res.status in ("verified", "contradicted", "partly checked")
    assert work < 1_000_000


@pytest.fixture(scope="module")
def corpus():
    return run(load_corpus(), {d: domains.policy(d) for d in domains.DOMAINS})


#: the measured shares of accurate texts contradicted (issue 65's target is 5 %; the held-out voices are above it)
HELD_OUT_CONTRADICTED, TUNING_CONTRADICTED = 0.08, 0.04


@pytest.mark.slow
def test_held_out_corpus_agreement(corpus):
    """Regression guard at the measured figures of issue 65 (benchmarks/bench_verifier.py reports them): per group,
    the share of accurate texts contradicted, and of texts with a labelled error fully verified."""
    held_out = {"test", *(v for v in VOICES if v.startswith("test-"))}
    for group, split, most_contradicted, most_verified in (
        ("held out", lambda it: it["split"] in held_out, HELD_OUT_CONTRADICTED, 0.03),
        ("tuning", lambda it: it["split"] not in held_out, TUNING_CONTRADICTED, 0.04),
    ):
        part = [it for it in corpus if split(it)]
        good = [it for it in part if it["accurate"]]
        bad = [it for it in part if not it["accurate"]]
        contradicted = sum(it["result"].status == "contradicted" for it in good) / len(good)
        verified = sum(it["result"].status == "verified" for it in bad) / len(bad)
        assert contradicted <= most_contradicted and verified <= most_verified, (group, contradicted, verified)
    assert len(corpus) >= 300 and len({it["domain"] for it in corpus}) == 4


@pytest.mark.slow
def test_exact_restatements_verify_in_every_domain():
    for case in _CASES.values():
        exp = xairl.Explanation.from_json(json.dumps(case["explanation"]))
        policy = domains.policy(case["domain"])
        a = int(exp.focus[0])
        for j, f in enumerate(exp.feature_names):
            text = f"The SHAP value of feature {f} is {exp.values[0, j, a]:.2f}."
            res = xairl.verify(text, exp, 0, policy)
            assert res.ok, (case["id"], text, res.problems())


def _signal_policy():
    """Three RSRQ features described the way a radio plugin describes them (serving cell, ranked neighbours)."""
    who = ("the serving BS", "the strongest neighbour", "the second strongest neighbour")
    features = {
        f"rsrq_{k}": xairl.FeatureInfo("dB", f"{w}'s RSRQ", aliases=(f"candidate {k}'s RSRQ",) if k else ())
        for k, w in enumerate(who)
    }
    net = torch.nn.Linear(3, 2)
    return xairl.Policy(net, list(features), ["stay", "handover"], features=features)


def test_qualifiers_narrow_an_ambiguous_name():
    policy = _signal_policy()
    exp = xairl.explain(
        policy, np.array([[-20.0, -10.0, -14.0]], np.float32), background=np.zeros((4, 3), np.float32), method="exact"
    )
    vocab = vocabulary(exp, policy, clean_surface)

    def keys(text):
        return [m.keys for m in find_mentions(text, vocab)[0] if m.kind == "feature"]

    assert keys("the serving cell's poor RSRQ") == [("rsrq_0",)]  # 'serving' belongs to rsrq_0 only
    assert keys("candidate 1's excellent RSRQ") == [("rsrq_1",)]
    assert keys("the strongest neighbour's weak RSRQ") == [("rsrq_1",)]  # not the *second* strongest
    assert keys("candidate 1's RSRQ and RSRQ") == [("rsrq_1",), ("rsrq_1",)]  # the qualifier carries over 'and'
    assert len(keys("its RSRQ")[0]) == 3  # no qualifying word: still ambiguous


def test_rounding_scale_words_and_truncation():
    def num(t):
        return find_numbers(normalise(t))[0]

    assert num("roughly 40 thousand dollars").value == 40_000
    assert matches(num("2.4"), 2.345)  # rounded twice: 2.345 -> 2.35 -> 2.4
    assert matches(num("0.43"), 0.4252) and not matches(num("0.42"), 0.4252)  # half-up, no slack beyond it
    assert matches(num("6,157"), 6157.86) and not matches(num("0.42"), 0.4299)  # truncation needs 3 digits


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 469): not read yet, or left unchecked where the old reader bound it",
)
def test_directions_people_write():
    exp = _exp(contrib=(0.11, -0.15, 0.05))

    def statuses(text):
        return [c.status for c in xairl.verify(text, exp, 0).claims if c.kind == "direction"]

    assert statuses("Everything but the odor raised the prediction.") == ["verified"]  # odor: the opposite
    assert statuses("Everything but the gill size raised the prediction.") == ["contradicted"]
    assert statuses("The odor helps (-0.15).") == []  # helps whom? no direction for a one-output model
    assert statuses("The odor works against the applicant.") == []
    res = xairl.verify("Had the odor been none, the prediction would have been much higher.", exp, 0)
    assert res.sentences[0].status == "unchecked" and not res.ok  # hypothetical: not a statement of what happened
    res = xairl.verify("The prediction is 0.31 above the baseline.", exp, 0)
    assert [c.status for c in res.claims if c.kind == "number"] == ["contradicted"]  # the change is 0.01


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 484): not read yet, or left unchecked where the old reader bound it",
)
def test_vague_names_are_not_invented_features():
    exp = _exp(names=("overall_quality", "kitchen_quality", "lot_area"), categories=None)
    res = xairl.verify("A quality rating of 10/10 adds 0.11.", exp, 0)
    assert not [c for c in res.claims if c.status == "contradicted"]  # 'quality': ambiguous, not unknown
    res = xairl.verify("The swimming pool adds 0.11.", exp, 0)
    assert [c.status for c in res.claims if c.kind == "feature"] == ["contradicted"]


def test_a_modal_in_a_relative_clause_keeps_the_claims_checked():
    from xairl.toy import toy_policy

    policy = toy_policy()
    exp = xairl.explain(policy, policy.background(1, seed=2), background=policy.background(50))
    chosen = exp.action_names[exp.chosen[0]]
    other = next(a for a in exp.action_names if a != chosen)
    assert xairl.verify(f"The agent chose {chosen}, which could save time.", exp, 0, policy).accurate
    assert xairl.verify(f"The agent chose {other}, which could save time.", exp, 0, policy).status == "partly checked"
    res = xairl.verify(f"Without the wind, the agent would have chosen {other}.", exp, 0, policy)
    assert res.status == "partly checked"  # what did not happen is not a claim about the decision


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 508): not read yet, or left unchecked where the old reader bound it",
)
def test_baseline_and_change_phrasings():
    exp = _exp(categories=None)  # prediction 0.51, baseline 0.30, change 0.21

    def numbers(text):
        return [c.status for c in xairl.verify(text, exp, 0).claims if c.kind == "number"]

    assert numbers("The prediction of 0.51 is well above the base value of 0.30.") == ["verified", "verified"]
    assert numbers("The prediction (0.51) exceeds the base rate (0.30) by 0.21.") == ["verified"] * 3
    assert numbers("The prediction (0.51) exceeds the base rate (0.30) by 0.31.")[-1] == "contradicted"
    # a value and a contribution in brackets after one name are that name's, not a list to pair with the names
    res = xairl.verify("Key factors raising it include odor (0, SHAP 0.15) and gill_size (1, SHAP 0.11).", exp, 0)
    assert res.ok and {c.status for c in res.claims} == {"verified"}


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 526): not read yet, or left unchecked where the old reader bound it",
)
def test_options_weighed_against_each_other():
    """'favoured turning by x' weighs turning against the runner-up (the margin's contribution holds as well as the
    score's); '(Q 3.10)' after an action is that action's score; a signed number after '<feature> argued for
    <action>' is the feature's contribution; 'the strongest argument for <runner-up>' ranks among the reasons
    against the decision. Cases of the dev split (dev-memo-log-arrows's voices)."""

    def ok(text, case):
        return _on_case(text, case).ok

    # toy-2: turn chosen over recharge; wind's contribution to the margin 5.31, speed's -5.48
    assert ok("Wind at 1.55 favoured turning by 5.31.", "toy-2")
    assert not ok("Wind at 1.55 favoured turning by 6.31.", "toy-2")
    assert ok("Speed argued strongly for recharging (\u22125.48).", "toy-2")
    assert not ok("Speed argued strongly for recharging (\u22124.48).", "toy-2")
    # toy-0: recharge (11.42) chosen over turn (3.10); battery is the only feature for turning (-0.05)
    assert ok("The agent chose recharge (Q 11.42) over turn (Q 3.10).", "toy-0")
    assert not ok("The agent chose recharge (Q 11.42) over turn (Q 4.10).", "toy-0")
    assert ok("The battery was the strongest argument for turning.", "toy-0")
    assert not ok("The speed was the strongest argument for turning.", "toy-0")


def test_the_lead_and_what_is_no_direction():
    """dev-lowercase-notes's voices: 'beat staying by x' and 'the handover's lead of x' are the margin whatever is named before;
    'pulled in opposite directions' is no direction word."""
    # uav-1: the handover led staying by 0.63; uav-3: by 3.88, the serving RSRQ's share of it +24.5
    assert _on_case("Handing over beat staying by 0.63.", "uav-1").status == "partly checked"
    assert _on_case("Handing over beat staying by 6.3.", "uav-1").status == "partly checked"
    lead = "At -27.2 dB the serving RSRQ alone contributes +24.5 to the handover's lead of {} over staying."
    assert _on_case(lead.format(3.9), "uav-3").status == "partly checked"
    assert _on_case(lead.format(5.9), "uav-3").status == "partly checked"
    # toy-2: wind +5.31 and speed -5.48 in turn's lead over recharging
    assert _on_case("Wind and speed pulled in opposite directions.", "toy-2").status == "partly checked"


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 558): not read yet, or left unchecked where the old reader bound it",
)
def test_dev7_voices():
    """Each rule tuned on dev-by-far-edged-out, on its own case: 'the big one' is a pronoun; 'edged out B (2.52) by x' is the margin;
    '0.341 base' the baseline; 'pull it down to x' the prediction; 'despite X, ...' is no subject of what follows;
    '2 Mbit' a value in bit; 'held it back from handing over' a direction; 'A outweighed B: list' gives the list to
    neither."""

    def claims(text, case):
        res = _on_case(text, case)
        return res.status, [c.status for c in res.claims if c.kind in ("number", "direction")]

    assert claims("The living area is the big one: forty thousand.", "housing-1")[1] == ["verified"]
    assert claims("Turning (4.07) edged out going forward (2.52) by 1.55.", "toy-3")[0] == "verified"
    assert claims("Turning (4.07) edged out going forward (2.52) by 0.55.", "toy-3")[0] == "contradicted"
    # credit-2: unemployed +0.128, prediction 0.142, base 0.341
    good = (
        "Despite being unemployed (+0.128), the risk is well below the 0.341 base: a low debt-to-income ratio "
        "(-0.127) pulls it down to {}."
    )
    assert claims(good.format(0.142), "credit-2")[0] == "verified"
    assert claims(good.format(0.242), "credit-2")[0] == "contradicted"
    # uav-1: the buffer holds 2 Mbit and favours the handover (+1.77 in the margin)
    assert claims("The full buffer (2 Mbit) nudged it toward the handover.", "uav-1")[0] == "verified"
    assert claims("The full buffer (3 Mbit) nudged it toward the handover.", "uav-1")[0] == "contradicted"
    assert claims("The full buffer held the UAV back from handing over.", "uav-1")[0] == "contradicted"
    listed = "Negative drivers outweighed positive ones: kitchen (-23.6k) and living area (-12.1k)."
    assert "contradicted" not in claims(listed, "housing-3")[1]


def test_signs_in_words():
    assert find_numbers("minus 1.37")[0].value == -1.37 and find_numbers("Negative 0.1")[0].sign == "-"


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 592): not read yet, or left unchecked where the old reader bound it",
)
def test_comparisons_between_features():
    """dev-comparisons-json's voices: 'A mattered more than B', chained through 'which', 'A and B both ... more than C', 'less than',
    'about as much as', 'outweighs'; a comparison with no feature after 'than' is no claim."""
    assert (
        _status("Odor mattered more than gill size, which in turn mattered more than the cap diameter.") == "verified"
    )
    assert _status("Gill size mattered more than odor.") == "contradicted"
    assert _status("Odor and gill size both mattered more than the cap diameter.") == "partly checked"
    assert _status("The cap diameter lowers it less than odor raises it.") == "verified"
    near = _exp(contrib=(0.13, 0.15, -0.05))  # within 25 % of each other
    assert xairl.verify("Gill size pushes it up by about as much as odor.", near, 0).status == "partly checked"
    assert _status("The cap diameter pushes it down by about as much as odor pushes it up.") == "partly checked"
    assert _status("Odor outweighs gill size.") == "verified" and _status("Gill size outweighs odor.") == "contradicted"
    assert [c for c in xairl.verify("Odor adds more than 0.1.", _exp(), 0).claims if c.kind == "rank"] == []


def test_a_name_first_is_not_a_hypothetical_had():
    """'Odor had the largest effect' starts with a name, then 'had': what happened, not 'Had it been ...'."""
    exp = _exp()
    assert xairl.verify("Odor had the largest effect.", exp, 0).status == "partly checked"
    assert xairl.verify("Gill size had the largest effect.", exp, 0).status == "partly checked"


def test_a_direction_belongs_to_the_list_of_names_nearest_it():
    assert _status("With a gill size of 1, the cap diameter lowers the prediction.") == "verified"
    assert _status("Odor (0) and gill size (1) both raise the prediction.") == "verified"
    assert _status("Odor, gill size and the cap diameter raise the prediction.") == "contradicted"


def test_dev10_number_formats():
    """Spaced thousands at a sentence's end, a range, percentage points that are not a share."""
    assert [n.value for n in find_numbers("USD 31 370. Then 12 140, 3")] == [31370, 12140, 3]
    assert find_numbers("between $500 and $1,000")[1].hedge == "at_most"
    assert find_numbers("~14 pts")[0].points and not find_numbers("14 %")[0].points


@pytest.mark.slow
@pytest.mark.parametrize(
    "case,text,status", cases.params("on_corpus_cases", "on_corpus_cases", ("case", "text", "status"))
)
def test_phrasings_on_corpus_cases(case, text, status):
    """Each rule tuned on dev-tutor-prose and dev-number-formats (and later dev splits), with a right and a wrong figure on its own corpus
    case (benchmarks/data/verify_cases/on_corpus_cases.yaml)."""
    assert _on_case(text, case).status == status


@pytest.mark.xfail(
    strict=True, reason="issue 65, the rule-table reader (line 630): precision: an accurate number contradicted"
)
def test_typical_value_between_band_and_fences_is_unchecked():
    """credit-0's age quartiles 36 / 48 / 62.25: 80 is neither typical nor past Tukey's fence (101.6)."""
    res = _on_case("The applicant's age of 28 is below the typical borrower's age of about 80.", "credit-0")
    typical = [c for c in res.claims if c.kind == "number" and c.text == "80"]
    assert [c.status for c in typical] == ["unchecked"], res.claims


def _outside(text, dataset, index):
    """``text`` against an outside case (FIFA match statistics and UCI student performance, named as in those data
    sets, with their data dictionaries' descriptions: benchmarks/data/narratives/outside/shapstories.yaml)."""
    _, exp, policy = shapstories_case(dataset, index)
    return xairl.verify(text, exp, 0, policy)


@pytest.mark.parametrize(
    "dataset,index,text,status", cases.params("outside", "outside", ("dataset", "index", "text", "status"))
)
def test_phrasings_on_outside_cases(dataset, index, text, status):
    """Sentences on outside cases: FIFA, UCI student, Pima diabetes, stroke, South German Credit
    (benchmarks/data/verify_cases/outside.yaml)."""
    assert _outside(text, dataset, index).status == status


def _tuples(text):
    return explanation_from_tuples(text, output="price")


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 677): not read yet, or left unchecked where the old reader bound it",
)
def test_names_that_are_phrases_and_coarse_amounts():
    """Feature names written as phrases ('Rates the overall condition of the house'): 'the house' names none of
    them; 'condition' means both names with the word ('conditions' too); two words of one name are one mention
    ('sale condition'); 'about $10,000' after 'increased the price by' is a contribution, unchecked when several
    round to it, never the prediction."""
    exp = _tuples(
        "(Refers to walkout or garden level walls, Gd, 17607.43), (Rates the overall condition of the house, "
        "8.00, 13038.14), (Second floor square feet, 0.00, -10142.29), (Proximity to various conditions, "
        "Feedr, -8251.83)"
    )
    assert xairl.verify("The house's location on a feeder street reduced the price by about $8,000.", exp).accurate
    assert not xairl.verify("The house's location on a feeder street reduced the price by about $28,000.", exp).ok
    exp = _tuples(
        "(Original construction date, 1915.00, -17966.77), (Second floor square feet, 756.00, 10129.96), "
        "(Total square feet of basement area, 756.00, -8362.22), (Condition of sale, Abnorml, -6786.66)"
    )
    text = "The smaller basement area and abnormal sale condition reduce it by about $8,400 and $6,800, respectively."
    assert xairl.verify(text, exp).status == "partly checked"
    assert xairl.verify(text.replace("$6,800", "$9,800"), exp).status == "partly checked"
    exp = _tuples(
        "(Rates the overall material and finish of the house, 8.00, 9655.79), (Original construction date, "
        "2000.00, 8192.46), (Second floor square feet, 1053.00, 18094.05)"
    )
    res = xairl.verify("The house's good condition (rated 8/10) increased the price by about $10,000.", exp)
    assert res.status == "unchecked", res.claims


def test_explingo_unaligned_voice_and_signed_restatements():
    """Explingo's dataset/unaligned_examples_1.json voice: 'The SHAP value says that the house price decreases
    because A is x, ...' says A lowered the price (a reporting clause and the output as subject name no invented
    feature); a restatement 'X has a value of v and a SHAP value of c' binds c to X, and an unsigned SHAP value is a
    positive one."""
    exp = _tuples(
        "(Above ground living area square feet, 1256.00, -12527.46), (Rates the overall material and finish "
        "of the house, 5.00, -10743.76), (Wood deck area in square feet, 736.00, 9846.38)"
    )
    text = (
        "The SHAP value says that the house price decreases because the above ground living area is 1256 sq ft "
        "and the material quality is rated 5."
    )
    assert xairl.verify(text, exp).status == "partly checked"
    assert xairl.verify(text.replace("decreases", "increases"), exp).status == "partly checked"
    text = "The Above ground living area square feet feature has a values of 1256.00 and a SHAP value of -12527.46."
    assert xairl.verify(text, exp).status == "verified"
    assert xairl.verify(text.replace("-12527.46", "-10743.76"), exp).status == "partly checked"  # another's
    text = "The Wood deck area in square feet feature has a values of 736.00 and a SHAP value of 9846.38."
    assert xairl.verify(text, exp).status == "verified"
    assert xairl.verify(text, replace(exp, values=-exp.values)).status == "partly checked"  # it is -9846.38
    assert xairl.verify(text.replace("a SHAP", "a negative SHAP"), replace(exp, values=-exp.values)).accurate


def test_no_direction_in_an_adjective_an_appearance_or_an_aside():
    """'their lower efficiency' describes the subject; 'might seem positive' is an appearance; after '—likely' comes
    the writer's reasoning, whose names are not the subject of the claim before it."""
    text = "Despite attempting 9 shots (below the average of 12), their lower efficiency here also hurt their chances."
    assert _outside(text, "fifa", 11).status != "contradicted"
    text = "The team blocked 9 shots, which might seem positive defensively but hurt the team's chances."
    assert _outside(text, "fifa", 81).status == "partly checked"
    text = (
        "The most influential factor was the student's frequent outings, which slightly reduced the chance of "
        "passing—likely because socializing may detract from study time."
    )
    assert _outside(text, "student", 82).status != "contradicted"


def test_dev11_corrections():
    """Operators' corrections: a name after 'not', 'rather than', 'instead of' is not what the sentence says things
    of; 'would not worry' is an opinion, not a hypothetical; 'Q: Anything positive? A: ...' and 'A: a little, +1.77
    toward ...' name no unknown feature."""
    assert _status("It is not the cap diameter but the odor that raises the prediction most.") == "partly checked"
    assert _status("It is not the odor but the cap diameter that raises the prediction most.") == "partly checked"
    assert _status("Rather than the cap diameter, odor is what raises the prediction.") == "partly checked"
    tiny = _exp(contrib=(0.11, 0.15, -0.01))  # the cap diameter: 4 % of the total |contribution|
    assert xairl.verify("I would not worry about the cap diameter: its effect is negligible.", tiny, 0).accurate
    assert (
        _status("Had the odor not been foul, the prediction would be lower.") == "partly checked"
    )  # still hypothetical
    assert _status("Q: Anything positive? A: odor, +0.15.") == "verified"
    assert (
        _on_case("Q: Did the buffer matter? A: a little, +1.77 toward the handover.", "uav-1").status != "contradicted"
    )


def test_sums_and_scoped_ranks():
    """dev-sums-shares's voices: 'A and B together add x' is their sum (a list 'x and y' and 'most of the x above the baseline'
    are not); 'Among the positives, X is the largest' and 'Of the factors lowering it, X matters most' rank within
    that sign."""
    assert _status("Odor and gill size together add 0.26.") == "partly checked"
    assert _status("Odor and gill size together add 0.36.") == "partly checked"
    assert _status("Odor (+0.15) and the cap diameter (-0.05) together come to +0.10.") == "partly checked"
    assert _status("Odor and gill size together add 0.15 and 0.11, respectively.") == "partly checked"
    assert _status("Among the positives, odor is the largest.") == "verified"
    assert _status("Among the positives, gill size is the largest.") == "contradicted"
    assert _status("Of the factors lowering the prediction, the cap diameter matters most.") == "partly checked"


def test_a_qualifier_after_an_ambiguous_name_and_a_compound_modifier():
    """'the queue on the east approach' is queue_east (its words qualify an ambiguous 'queue' after it, and the
    'approach' of approach_speed inside it names nothing); 'the 19-vehicle queue' is a queue, not the emergency
    vehicle; a wrong number for the qualified queue stays contradicted."""
    from tests.narrative_corpus import one_output

    exp = one_output(
        ["queue_east", "queue_north", "emergency_vehicle", "approach_speed_avg_kmh"],
        [19, 2, "none", 31.4],
        [4.06, 1.73, 0.05, -0.27],
        -13.85,
        "Q-value of switching",
    )

    def claims(text):
        return [
            (c.text, c.status, c.detail.split(":")[0]) for c in xairl.verify(text, exp, 0).claims if c.kind == "number"
        ]

    assert claims("The main reason is the 19-vehicle queue on the east approach, worth about +4.1.") == [
        ("19", "verified", "queue_east"),
        ("+4.1", "verified", "queue_east"),
    ]
    assert claims("The queue to the north adds 1.7.") == [("1.7", "verified", "queue_north")]
    assert claims("The queue on the north approach adds 4.1.")[0][1] == "contradicted"


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 782): not read yet, or left unchecked where the old reader bound it",
)
def test_the_first_number_of_a_sentence_about_the_average_case_is_the_baseline():
    from tests.narrative_corpus import one_output

    exp = one_output(["Q3_grade", "attendance_pct"], [54, 71], [9.6, 7.2], 18.4, "probability of dropping out")

    def numbers(text):
        return [(c.text, c.status, c.detail) for c in xairl.verify(text, exp, 0).claims if c.kind == "number"]

    assert numbers("On average, a student has about an 18% chance of dropping out.") == [
        ("18%", "verified", "the baseline is 18.4")
    ]
    assert numbers("On average, a student has about a 25% chance of dropping out.")[0][1] == "contradicted"
    assert numbers("For Marcus the model says about 35%.")[0][1] == "verified"
    assert numbers("On average, attendance at 71% adds about 7 points.")[0] == (
        "71%",
        "verified",
        "attendance_pct: value",
    )


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 809): not read yet, or left unchecked where the old reader bound it",
)
def test_abbreviations_in_feature_names_are_read_as_the_words_people_write():
    """'dist_to_charger_m' is 'the distance', 'battery_pct' 'the battery': a ranking in those words is checked."""
    from tests.narrative_corpus import one_output

    exp = one_output(
        ["dist_to_charger_m", "pending_orders", "battery_pct"],
        [4.2, 2, 46],
        [0.88, 0.67, 0.49],
        1.2,
        "Q-value of recharging",
    )

    def ranks(text):
        return [c.status for c in xairl.verify(text, exp, 0).claims if c.kind == "rank"]

    assert ranks("Ranking by magnitude: distance, pending orders, battery.") == ["verified"] * 3
    assert "contradicted" in ranks("Ranking by magnitude: pending orders, distance, battery.")
    assert [c.status for c in xairl.verify("The distance adds 0.5.", exp, 0).claims if c.kind == "number"] == [
        "contradicted"
    ]


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 828): not read yet, or left unchecked where the old reader bound it",
)
def test_a_value_in_another_unit_of_the_one_its_name_ends_in():
    """'next_drop_dist_km' is 0.6: '600 m away' states it, '900 m' does not; 'wait_s' of 90 is '1.5 minutes'."""
    from tests.narrative_corpus import one_output

    exp = one_output(["next_drop_dist_km", "wait_s"], [0.6, 90], [1.15, -0.4], 3.1, "Q-value of continuing")

    def numbers(text):
        return [(c.text, c.status, c.detail) for c in xairl.verify(text, exp, 0).claims if c.kind == "number"]

    assert numbers("It kept going because the next drop is only 600 m away.") == [
        ("600", "verified", "next_drop_dist_km: value in m (not km)")
    ]
    assert numbers("It kept going because the next drop is only 900 m away.")[0][1] == "contradicted"
    assert numbers("The wait of 1.5 minutes counted against it.")[0][:2] == ("1.5", "verified")
    assert numbers("The next drop is 0.6 km away.")[0] == ("0.6", "verified", "next_drop_dist_km: value")


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 844): not read yet, or left unchecked where the old reader bound it",
)
def test_a_period_that_is_the_window_of_a_features_name_is_no_claim():
    """'in the past twelve months' of prior_returns_12m is the name's window even where the words bind the number
    to customer_tenure_mo (71 months); a period no name holds is still checked."""
    from tests.narrative_corpus import one_output

    exp = one_output(["customer_tenure_mo", "prior_returns_12m"], [71, 0], [-2.3, -1.9], 14.0, "return probability")

    def numbers(text):
        return [(c.text, c.status) for c in xairl.verify(text, exp, 0).claims if c.kind == "number"]

    assert numbers("A customer of 71 months who returned nothing in the past twelve months.") == [("71", "verified")]
    assert numbers("A customer of 71 months who returned nothing in the past nine months.")[1] == (
        "nine",
        "contradicted",
    )


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 860): not read yet, or left unchecked where the old reader bound it",
)
def test_fractions_state_a_probability_given_in_percent():
    """A dropout probability of 46.9 (%) from 18.4 with Q3_grade +9.6: 'p_dropout=0.469 ... (+0.096)' states it; a
    wrong fraction is caught; an output that is no probability does not read fractions as percentages."""
    from tests.narrative_corpus import one_output

    exp = one_output(["Q3_grade", "attendance_pct"], [54, 71], [9.6, 18.9], 18.4, "probability of dropping out")

    def numbers(text, e=exp):
        return [(c.text, c.status) for c in xairl.verify(text, e, 0).claims if c.kind == "number"]

    assert numbers("p_dropout=0.469 base=0.184 Q3_grade=54(+0.096)") == [
        ("0.469", "verified"),
        ("0.184", "verified"),
        ("54", "verified"),
        ("+0.096", "verified"),
    ]
    assert ("+0.090", "contradicted") in numbers("p_dropout=0.469 base=0.184 Q3_grade=54(+0.090)")
    cost = one_output(["Q3_grade", "attendance_pct"], [54, 71], [9.6, 18.9], 18.4, "claim cost")
    assert ("+0.096", "verified") not in numbers("cost=46.9 base=18.4 Q3_grade=54(+0.096)", cost)


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 879): not read yet, or left unchecked where the old reader bound it",
)
def test_a_change_since_last_time_is_the_features_value_not_its_push():
    from tests.narrative_corpus import one_output

    exp = one_output(["gpa_trend", "units_failed"], [-0.4, 3], [3.1, 11.3], 18.4, "probability of dropping out")

    def numbers(text):
        return [(c.text, c.status, c.detail) for c in xairl.verify(text, exp, 0).claims if c.kind == "number"]

    assert numbers("A falling GPA trend, down 0.4 since last term, adds another 3.")[0] == (
        "0.4",
        "verified",
        "gpa_trend: value",
    )
    assert numbers("A falling GPA trend, down 0.9 since last term, adds another 3.")[0][1] == "contradicted"


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 897): not read yet, or left unchecked where the old reader bound it",
)
def test_the_words_of_one_names_window_do_not_bind_a_number_to_another_name():
    """'in the last 90 days' spells num_support_calls_90d's window, not days_since_last_upgrade: the push after it
    is the support calls'."""
    from tests.narrative_corpus import one_output

    exp = one_output(
        ["num_support_calls_90d", "days_since_last_upgrade"], [7, 612], [0.133, 0.029], 0.26, "churn probability"
    )
    text = "The seven support calls logged in the last 90 days add roughly {} percentage points."
    found = [(c.text, c.status, c.detail) for c in xairl.verify(text.format(13), exp, 0).claims if c.kind == "number"]
    assert ("13 percentage points", "verified", "num_support_calls_90d: contribution (chosen)") in found
    assert not xairl.verify(text.format(3), exp, 0).ok


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 914): not read yet, or left unchecked where the old reader bound it",
)
def test_this_rounds_readings_do_not_let_wrong_numbers_through():
    """Counterexamples a second review found for the readings above, each a wrong (or right) number that must keep
    its status."""
    from tests.narrative_corpus import one_output

    def status(text, exp):
        return [c.status for c in xairl.verify(text, exp, 0).claims if c.kind == "number"]

    dist = one_output(["dist_m", "wait_s"], [12.0, 90], [-0.3, 0.4], 1.0, "Q-value of recharging")
    assert status("Distance -0.3 means a lower score.", dist) == ["verified"]  # 'means' is no unit 'm'
    assert status("The wait of 2 minutes counted for it.", dist) != ["verified"]  # 90 s is no '2 minutes'
    drop = one_output(["next_drop_dist_km", "battery_pct"], [0.64, 46], [1.15, 0.49], 3.1, "Q-value of continuing")
    assert status("The distance raises the Q-value by 0.6 since it is short.", drop) == ["contradicted"]
    assert status("Battery 46, about 0.64 km to go.", drop) == ["verified", "verified"]  # its unit's one owner
    assert status("Battery 46, about 0.94 km to go.", drop)[1] != "verified"
    gpa = one_output(["gpa_trend", "units_failed"], [-0.4, 3], [3.1, 11.3], 18.4, "probability of dropping out")
    assert status("A GPA trend of -0.004 adds about 3.1 points.", gpa)[0] == "contradicted"
    speed = one_output(["speed", "gap"], [0.5, 12], [0.3, 0.2], 1.1, "Q-value of accelerate")
    assert status("speed=0.005(+0.003)", speed) != ["verified", "verified"]
    calls = one_output(
        ["support_calls_90d", "days_since_last_upgrade"], [7, 612], [0.13, 0.03], 0.26, "churn probability"
    )
    assert status("It has been 90 days since the last upgrade.", calls) == ["contradicted"]
    robots = one_output(["battery_pct", "charger_queue_len"], [46, 3], [0.5, -0.2], 1.0, "Q-value of recharging")
    assert not xairl.verify("Battery 46 and queue 9 robots waiting.", robots, 0).ok


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 937): not read yet, or left unchecked where the old reader bound it",
)
def test_words_people_write_for_a_names_word():
    """'the charge' is battery_pct, 'the fever' temp_c (lexicon.SYNONYMS): their numbers are checked."""
    from tests.narrative_corpus import one_output

    exp = one_output(["battery_pct", "temp_c"], [76, 38.8], [0.92, 5.3], 3.1, "Q-value of continuing")

    def numbers(text):
        return [(c.text, c.status) for c in xairl.verify(text, exp, 0).claims if c.kind == "number"]

    assert numbers("The healthy 76% charge added about 0.92.") == [("76%", "verified"), ("0.92", "verified")]
    assert numbers("The healthy 76% charge added about 0.52.")[1] == ("0.52", "contradicted")
    assert numbers("The fever of 38.8 adds about 5.3.") == [("38.8", "verified"), ("5.3", "verified")]


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 953): precision: a push equal to the baseline verified as the baseline",
)
def test_a_push_equal_only_to_a_decision_level_number_is_not_verified():
    """'piles on around 8 more' where the baseline is 8 and no feature pushes 8: not verified as 'a decision-level
    fact' (the words say it is a push)."""
    from tests.narrative_corpus import one_output

    exp = one_output(["lactate", "heart_rate"], [4.2, 118], [9.6, 4.1], 8.0, "sepsis risk")

    def numbers(text):
        return [(c.text, c.status) for c in xairl.verify(text, exp, 0).claims if c.kind == "number"]

    assert numbers("Lactate adds about 9.6.") == [("9.6", "verified")]
    assert ("8", "verified") not in numbers("Something else piles on around 8 more.")


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 968): not read yet, or left unchecked where the old reader bound it",
)
def test_fronted_phrases_and_swaps():
    """'Beyond A and B, the C added ...': C is the subject (an invented feature here), not A and B; 'Beyond A, B
    lowered it' is said of B alone. Two numbers that cross (each name holding the other's, on two lines of a table)
    are contradicted, one number that states another named fact stays unclear. A side's sum that is the other side's
    is a sign error."""
    from tests import rule_examples as rules

    air = rules.example("air")  # traffic_index +7.2, wind_speed_ms +6.9; positives 31.1, negatives -1.0

    def bad(text):
        return [(c.kind, c.text) for c in xairl.verify(text, air, 0).claims if c.status == "contradicted"]

    assert bad("Beyond traffic and the wind, the bus lane closure added roughly 0.09.") == [
        ("feature", "the bus lane closure")
    ]
    assert bad("Beyond traffic, the wind lowered it.") == [("direction", "lowered")]
    assert bad("- traffic 2.4 -> +6.9\n- wind 0.8 -> +7.2") == [("number", "+6.9"), ("number", "+7.2")]
    assert bad("- traffic 2.4 -> +7.2\n- wind 0.8 -> +6.9") == []
    assert bad("The wind was calm, which, with the traffic, added 7.2.") == []  # (unclear: which one is unsaid)
    assert bad("The negatives add up to 31.1.") == [("number", "31.1")]
    assert bad("The positives add up to 31.1 and the negatives to -1.0.") == []
    # accurate phrasings a second review found contradicted by the first version of these readings
    for text in (
        "Traffic outweighs wind with 7.2. Wind trails traffic with 6.9.",
        "Traffic, unlike wind, adds 7.2; wind, unlike traffic, adds 6.9.",
        "Even with the negatives, the contributions add up to about 30.",
        "Traffic and wind outweigh the season by a factor of 14.",
        "The road was set to 4 lanes.",
        "The road was listed as a minor factor.",
        "The season was flagged as a drag on the forecast.",
        "## How the Current Season Shapes the Forecast",
        "season: negative -1.0",
        "Traffic adds 7.2 extra risk.",
        "Wind is calm, which gives +6.9.",
        "Traffic gives a net increase of 7.2.",
        "Of the six factors traffic and wind together add 14.1.",
        "road traffic wind",
    ):
        assert bad(text) == [], text
    assert bad("Wind is smaller than traffic by a factor of 5.") == [("rank", "smaller than")]
    assert not [c for c in xairl.verify("road traffic wind", air, 0).claims if c.kind == "internal"]  # (a name
    # that qualified two others was removed twice: ValueError)


def test_a_unit_or_statistic_in_a_name_is_no_mention_on_its_own():
    """'14.7 min' names no hm_pr_min and 'avg 3.2' no AvgWait5m; the whole name, and a run of its words, still do."""
    from tests.narrative_corpus import one_output

    exp = one_output(["hm_pr_min", "AvgWait5m"], [121, 41], [11.2, 0.26], 252.0, "finish time")
    vocab = vocabulary(exp, None, clean_surface)

    def said(text):
        return [m.keys for m in find_mentions(text, vocab)[0]]

    assert said("The others add 14.7 min; avg 3.2.") == []
    assert said("hm_pr_min adds 11.2 min, AvgWait5m 0.26.") == [("hm_pr_min",), ("AvgWait5m",)]
    assert said("The hm pr min adds 11.2.") == [("hm_pr_min",)]


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 1032): not read yet, or left unchecked where the old reader bound it",
)
def test_log_odds_given_as_a_probability_and_names_with_an_index_or_an_acronym():
    """A log-odds output and its baseline may be written as the probabilities they stand for; an index in square
    brackets ('forecast_price[+6h]') is part of a name, not a signed number; 'debt-to-income' is dti_ratio."""
    from tests.narrative_corpus import one_output

    exp = one_output(
        ["dti_ratio", "forecast_price[+6h]", "FICO_score"],
        [0.41, 118.0, 648],
        [0.62, 0.56, 0.65],
        -2.1,
        "log-odds of default within 12 months",
    )  # prediction -0.27: a probability of 43.3 %

    def numbers(text):
        return [(c.text, c.status) for c in xairl.verify(text, exp, 0).claims if c.kind == "number"]

    said = "The log-odds rise from -2.10 at baseline to -0.27, which corresponds to a probability of roughly {}."
    assert numbers(said.format("43%"))[-1] == ("43%", "verified")
    assert numbers(said.format("60%"))[-1] == ("60%", "contradicted")
    assert numbers("From about 11% to about 43%.") == [("11%", "verified"), ("43%", "verified")]
    assert numbers("next=forecast_price[+6h](+0.56)") == [("+0.56", "verified")]
    assert numbers("next=forecast_price[+6h](+0.65)") == [("+0.65", "contradicted")]
    assert numbers("The debt-to-income ratio of 0.41 adds +0.62.") == [("0.41", "verified"), ("+0.62", "verified")]
    prob = one_output(["dti_ratio"], [0.41], [0.62], -2.1, "probability of default")  # not log-odds: no reading
    assert ("43%", "verified") not in [(c.text, c.status) for c in xairl.verify(said.format("43%"), prob, 0).claims]


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 1055): not read yet, or left unchecked where the old reader bound it",
)
def test_a_span_of_time_names_no_feature():
    """'in the last two years' names no months_since_last_record: its 'two' is not that feature's value; the
    written-out acronym 'the antibiotics' still names abx_given_last_24h."""
    from tests.narrative_corpus import one_output

    exp = one_output(
        ["delinq_2yrs", "months_since_last_record", "abx_given_last_24h"], [1, 14, 1], [2.6, 0.4, -3.3], 12.0, "risk"
    )

    def claims(text):
        return [(c.text, c.status) for c in xairl.verify(text, exp, 0).claims if c.kind == "number"]

    assert ("two", "contradicted") not in claims("One delinquency in the last two years adds 2.6 points.")
    assert ("2.6 points", "verified") in claims("One delinquency in the last two years adds 2.6 points.")
    assert claims("The antibiotics take off about 3.3 points.") == [("3.3 points", "verified")]


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 1069): not read yet, or left unchecked where the old reader bound it",
)
def test_a_ratio_written_as_odds():
    """'outweighed B by roughly 1.5 to 1', 'two to one (x vs y)', '3:1': the ratio of the two sizes, checked; its
    numbers are no values (but 'fell from 3 to 1' states two)."""
    from tests.rule_examples import example

    exp = example("air")  # traffic_index +7.2, wind_speed_ms +6.9: a ratio of 1.04

    def claims(text):
        return [(c.text, c.status) for c in xairl.verify(text, exp, 0).claims if c.kind != "feature"]

    assert claims("Traffic outweighed wind by roughly 1 to 1.") == [("outweighed", "verified")]
    assert claims("Traffic outweighed wind by roughly 3 to 1.") == [("outweighed", "contradicted")]
    assert claims("Traffic outweighs wind 1:1.") == [("outweighs", "verified")]
    assert claims("Traffic outweighs wind roughly one to one (7.2 vs 6.9).") == [
        ("7.2", "verified"),
        ("6.9", "verified"),
        ("outweighs", "verified"),
    ]
    assert ("outweighs", "contradicted") in claims("Traffic outweighs wind roughly two to one (7.2 vs 6.9).")
    assert [s for _, s in claims("Traffic fell from 3 to 1.")] == ["contradicted", "contradicted"]


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 1091): not read yet, or left unchecked where the old reader bound it",
)
def test_twice_the_size_of_and_more_than_twice_that_of():
    """'twice the size of B', 'three times that of B' state a ratio; 'more than twice that of B' at least about 2;
    a second comparison joined by 'and' keeps the first one's subject; the bracket after 'the B effect' pairs."""
    from tests.rule_examples import example

    exp = example("air")  # pm2_5_lag1 14.7, traffic_index 7.2, wind_speed_ms 6.9

    def ranks(text):
        return [c.status for c in xairl.verify(text, exp, 0).claims if c.rule == "rank.comparison"]

    assert ranks("The pm2_5_lag1 effect is roughly twice the size of the wind effect.") == ["verified"]
    assert ranks("The wind effect is roughly twice the size of the traffic effect.") == ["contradicted"]
    assert ranks("The pm2_5_lag1 effect is three times that of the wind.") == ["contradicted"]
    assert ranks("The pm2_5_lag1 effect is more than three times that of the wind.") == ["contradicted"]
    assert ranks("The pm2_5_lag1 effect is about 2 times that of traffic and twice that of the wind.") == [
        "verified",
        "verified",
    ]
    said = xairl.verify("The pm2_5_lag1 effect is roughly twice the size of the wind effect (6.9 vs 14.7).", exp, 0)
    assert [c.status for c in said.claims if c.kind == "number"] == ["contradicted", "contradicted"]


@pytest.mark.parametrize(
    "explanation,text,status",
    cases.params("second_review", "accurate_sentences", ("explanation", "text", "status")),
)
def test_accurate_sentences_of_a_second_review_stay_accurate(explanation, text, status):
    """Accurate sentences a second review wrote against this session's readings (second_review.yaml)."""
    from tests.narrative_corpus import one_output

    result = xairl.verify(text, one_output(**cases.explanation(explanation)), 0)
    assert result.status == status, [(c.rule, c.text, c.detail) for c in result.claims if c.status == "contradicted"]


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 1120): not read yet, or left unchecked where the old reader bound it",
)
def test_log_odds_are_no_percentages():
    """'The probability of default is 27%' of log-odds -0.27 (a probability of 43 %): contradicted."""
    from tests.narrative_corpus import one_output

    claims = xairl.verify("The probability of default is 27%.", one_output(**cases.explanation("loan")), 0).claims
    assert [c.status for c in claims if c.kind == "number"] == ["contradicted"]


@pytest.mark.xfail(
    strict=True,
    reason="issue 65, the rule-table reader (line 1132): not read yet, or left unchecked where the old reader bound it",
)
def test_odds_of_a_larger_number_to_a_smaller_one():
    """'outweighs B by about 3 to 2' is a ratio of 1.5, checked; its numbers are no values; '2 to 3' is no odds."""
    from tests.narrative_corpus import one_output

    exp = one_output(["income", "late_payments"], [52000, 3], [1.46, -1.0], 3.0, "credit score")

    def claims(text):
        return [(c.rule, c.status) for c in xairl.verify(text, exp, 0).claims if c.kind != "feature"]

    assert claims("Income outweighs the late payments by about 3 to 2.") == [("rank.comparison", "verified")]
    assert claims("Income outweighs the late payments by about 5 to 2.") == [("rank.comparison", "contradicted")]


@pytest.mark.parametrize(
    "explanation,text,status",
    cases.params("second_review", "counterfactuals_output_names_and_pushes", ("explanation", "text", "status")),
)
def test_counterfactuals_output_names_and_pushes_in_other_words_stay_accurate(explanation, text, status):
    """A removal said after the name ('if A had contributed nothing'), a number of the output's name ('gate 4'), an
    index in brackets ('lag[-1]'), a subject in other words with its push in brackets, 'positive terms' and 'most of
    the positive push' (no subject of their own)."""
    from tests.narrative_corpus import one_output

    result = xairl.verify(text, one_output(**cases.explanation(explanation)), 0)
    assert result.status == status, [(c.rule, c.text, c.detail) for c in result.claims if c.status == "contradicted"]


@pytest.mark.parametrize(
    "explanation,text,status", cases.params("second_review", "near_misses", ("explanation", "text", "status"))
)
def test_their_near_misses_are_contradicted(explanation, text, status):
    """The same readings with a wrong counterfactual, an invented name whose bracketed number is no contribution, a
    wrong score beside the output's number."""
    from tests.narrative_corpus import one_output

    assert xairl.verify(text, one_output(**cases.explanation(explanation)), 0).status == status


def test_an_opposite_of_the_label_is_a_wrong_category():
    """A label's opposite said in a sentence naming its feature, or its label's word in capitals ('outside the ECA'
    of 'inside_ECA'): contradicted; the label itself, or its opposite said beside it, is not."""
    from tests.narrative_corpus import one_output

    exp = one_output(["stage", "zone", "yield_lag"], ["early", "inside_ECA", 30.0], [2.4, -0.3, 1.1], 20.0, "yield")

    def accurate(text):
        return xairl.verify(text, exp, 0).accurate

    assert not accurate("Being in late lactation, she got a 2.4 boost from the stage feature.")
    assert not accurate("Because the ship is outside the ECA, the zone feature lowered it by 0.3.")
    assert accurate("Being in early lactation, she got a 2.4 boost from the stage feature.")
    assert accurate("Inside the ECA, the zone feature lowered it by 0.3.")
    assert accurate("Early lactation, not late, is what the stage term rewarded with 2.4.")


def _turn_over_recharge():
    """A discrete policy choosing turn (7.2) over recharge (5.66); on the margin battery +5.03, obstacle +2.0, wind
    -0.8 and speed -3.0 (the hardest push against turning)."""
    c = np.array([[-1.0, 2.0], [4.0, -1.03], [-0.3, 0.5], [2.5, 0.5]])
    base = np.array([2.0, 3.69])
    return xairl.Explanation(
        values=c[None],
        base_values=base[None],
        outputs=(base + c.sum(axis=0))[None],
        states=np.array([[0.4, 0.3, 0.9, 1.0]]),
        feature_names=("speed", "battery", "wind", "obstacle"),
        action_names=("turn", "recharge"),
        method="given",
    )


@pytest.mark.parametrize(
    "text,status",
    [
        ("The policy did not choose turn.", "contradicted"),
        ("It is false that the policy chose turn.", "partly checked"),
        ("Recharge had the higher score (5.66).", "contradicted"),
        ("Battery raised the margin by 5.03, and so did wind.", "partly checked"),
        ("The agent turned because of the speed.", "contradicted"),
        ("Every feature favoured turn.", "contradicted"),
        ("Every feature but speed favoured turn.", "partly checked"),  # (wind was against it too)
        # the true statements beside them
        ("The policy chose turn over recharge.", "verified"),
        ("The policy did not choose recharge.", "verified"),
        ("Battery raised the margin by 5.03.", "verified"),
        ("The agent turned because of the obstacle.", "verified"),
    ],
)
def test_false_sentences_of_a_hostile_round_are_never_verified(text, status):
    """Issue 65: each false sentence is contradicted (grammar binds it) or leaves its sentence unchecked (a claim no
    rule read: 'so did wind', a claim under 'it is false that'); appended to a verified text, it still keeps that
    text from being verified."""
    exp = _turn_over_recharge()
    assert xairl.verify(text, exp, 0).status == status
    if status != "verified":
        assert xairl.verify("The policy chose turn over recharge. " + text, exp, 0).status == status
        bad = [c for c in xairl.verify(text, exp, 0).claims if c.status != "verified"]
        assert bad and all(c.text for c in bad)  # the claim names the word it is about


def test_a_sentence_with_no_name_number_nor_claim_word_states_nothing():
    res = xairl.verify("The policy chose turn over recharge. That was the story of the day.", _turn_over_recharge(), 0)
    assert [s.status for s in res.sentences] == ["verified", "none"] and res.status == "verified"
    res = xairl.verify("The policy chose turn over recharge. Most of the push was upward.", _turn_over_recharge(), 0)
    assert [s.status for s in res.sentences] == ["verified", "unchecked"] and res.status == "partly checked"
