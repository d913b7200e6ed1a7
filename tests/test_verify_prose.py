"""The verifier on prose it did not write: each pipeline step on its own, the held-out corpus, bad input."""

import json
import pathlib
from dataclasses import replace

import numpy as np
import pytest
import torch

import xairl
from benchmarks.bench_verifier import explanation_from_tuples, load_corpus, run, shapstories_case
from tests import narrative_domains as domains
from tests.work_budget import calls
from xairl.narrators.verify.book import clean_surface
from xairl.narrators.verify.names import find_mentions
from xairl.narrators.verify.numbers import find_numbers, matches, normalise
from xairl.narrators.verify.vocabulary import vocabulary


@pytest.mark.parametrize(
    "text,value,unit,hedge",
    [
        ("22,5 dB", 22.5, 0.1, ""),
        ("0,098", 0.098, 0.001, ""),
        ("USD 39 960", 39960, 10, ""),
        ("between $500 and", 500, 100, "at_least"),
        ("minus 1.37", -1.37, 0.01, ""),
        ("$12,757.84", 12757.84, 0.01, ""),
        (".9", 0.9, 0.1, ""),
        ("about $12,000", 12000, 1000, "approx"),
        ("262KB", 262, 1, ""),
        ("-4330.84", -4330.84, 0.01, ""),
        ("~$21k", 21000, 1000, "approx"),
        ("nearly 2 dB", 2, 1, "below"),
        ("1.2e-3", 0.0012, 1e-4, ""),
        ("five thousand dollars", 5000, 1000, ""),
        ("up to 31.1", 31.1, 0.1, "at_most"),
        ("the positives add up to 31.1", 31.1, 0.1, ""),  # a sum, not a bound
    ],
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
    assert xairl.verify("The narrow gill size raises the prediction by 0.11.", exp, 0).ok
    bad = xairl.verify("The broad gill size raises the prediction by 0.11.", exp, 0)
    assert [c.kind for c in bad.problems()] == ["category"]
    assert not xairl.verify("odor: none, which adds 0.15.", exp, 0).ok
    assert xairl.verify("odor: foul, which adds 0.15.", exp, 0).ok


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
        assert xairl.verify(good, exp, 0).ok, good
    for bad in (
        "Odor decreases the prediction.",
        "Cap diameter pushes the prediction up.",
        "Odor does not increase the prediction.",
        "The SHAP value of odor is 0.51.",
    ):
        assert not xairl.verify(bad, exp, 0).ok, bad


def test_lists_ranks_and_magnitude():
    exp = _exp()
    assert xairl.verify("Odor and gill size raise it by 0.15 and 0.11, respectively.", exp, 0).ok
    assert not xairl.verify("Odor and gill size raise it by 0.11 and 0.15, respectively.", exp, 0).ok
    assert xairl.verify("The top two features were odor and gill size.", exp, 0).ok
    assert not xairl.verify("The top two features were odor and cap diameter.", exp, 0).ok
    assert xairl.verify("Odor was the most important feature, followed by gill size.", exp, 0).ok
    assert not xairl.verify("Gill size was the most important feature.", exp, 0).ok
    assert not xairl.verify("Odor barely matters.", exp, 0).ok


def test_sentence_status_and_coverage():
    exp = _exp()
    res = xairl.verify("Odor raises the prediction by 0.15. Mushrooms are fascinating. Nature is big.", exp, 0)
    assert [s.status for s in res.sentences] == ["verified", "unchecked", "unchecked"]
    assert res.coverage == pytest.approx(1 / 3) and not res.ok and res.status == "unchecked"
    invented = xairl.verify("The stem height raises the prediction by 0.2.", exp, 0)
    assert invented.status == "contradicted"


def test_a_direction_said_by_taking_a_feature_away():
    assert _status("If it were not for its odor, the prediction would be much lower.") == "verified"
    assert _status("Had the odor not been foul, the prediction would likely be lower.") == "verified"
    assert _status("Without the cap diameter, the prediction would be higher.") == "verified"
    assert _status("If it were not for its odor, the prediction would be much higher.") == "contradicted"
    assert _status("Without the cap diameter, the prediction would be lower.") == "contradicted"
    assert _status("Had the odor been different, the prediction would be lower.") == "unchecked"  # another value


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


def test_table_cells_are_items_and_an_unnamed_feature_is_not_wrong():
    """A row of 'label number' cells (or cells after '||'): each is an item, so a cell whose label the vocabulary lacks ('lag reading')
    does not lend its numbers to the name of the cell before; a field's name and its value stay one item. A number
    bound by position that states an unnamed feature's exact fact is unchecked; one that states no fact, or measures
    a fact noun of the name before it, stays contradicted."""
    from xairl.narrators.verify import rules

    air = rules.example("air")

    def numbers(text):
        return [(c.text, c.status) for c in xairl.verify(text, air, 0).claims if c.kind == "number"]

    row = numbers("traffic 2.4 +7.2 | lag reading 48.2 +14.7 | wind 0.8 +6.9")
    assert [s for _, s in row] == ["verified", "verified", "unchecked", "verified", "verified", "verified"]  # (+14.7:
    # the one feature whose push it is)
    assert ("+9.9", "contradicted") in numbers("traffic 2.4 +7.2 | wind 0.8 +9.9")
    assert numbers("Top factors | traffic = 2.4 | +7.2 || wind 0.8 m/s | +6.9 || sheltered site | +3.3")[-1] == (
        "+3.3",
        "unchecked",
    )  # (not the wind's)
    assert numbers("Feature: traffic_index | value: 2.4 | SHAP: +7.2") == [("2.4", "verified"), ("+7.2", "verified")]
    assert numbers("Traffic is heavy, with yesterday's level at 14.7.") == [("14.7", "unchecked")]
    assert numbers("Traffic is heavy, with yesterday's level at 12.3.") == [("12.3", "contradicted")]
    assert numbers("Traffic is heavy, with an increase of 14.7.") == [("14.7", "contradicted")]


def test_an_invented_feature_needs_the_parse_to_agree():
    """The words before a direction word propose an invented feature; the parse must find a subject of the word's
    verb that names nothing: not the model itself after an opener, not a participle's missing subject."""
    from xairl.narrators.verify import rules

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
    "text,accurate",
    [
        ("pm2_5_lag1 48.2 +14.7 and traffic 2.4 +7.2 dominate.", True),  # the top two
        ("Precip 0 +2.2 and wind 0.8 +6.9 dominate.", False),
        ("The season is the main thing holding the forecast down.", True),  # the largest negative
        ("The road is the main thing holding the forecast down.", False),
    ],
)
def test_ranks_of_several_names_and_of_one_side(text, accurate):
    from xairl.narrators.verify import rules

    result = xairl.verify(text, rules.example("air"), 0)
    assert result.accurate == accurate, [(c.status, c.text, c.detail) for c in result.claims]
    assert all("\0" not in c.text for c in result.claims)  # the names as written, not masked


@pytest.mark.parametrize(
    "text,accurate",
    [
        ("Claims on this policy are expected to cost around $1,560.", True),  # the output's own word: no push, but
        ("Claims on this policy are expected to cost around $2,600.", False),  # the output (1,563)
        ("Students like her drop out more often, so the model adds about 4.4 points.", True),
        ("Her age, 44, works in your favour by roughly $88.", True),  # whose favour: the reader's, unsaid
        ("Her age does the heaviest lifting.", True),  # an idiom of size, not of way
        ("Her age raises the expected cost by roughly $88.", False),
        ("Her age pushes the cost up.", False),  # the output named as the verb's object: still a push
        ("The evening enrolment lowers the dropout probability.", False),
        ("The risk factors add 21.9 points in total.", True),  # a sum in the explanation's own points
        ("The risk factors add 25.9 points in total.", False),
    ],
)
def test_the_outputs_own_words_idioms_and_totals(text, accurate):
    from benchmarks.bench_verifier import one_output

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
    assert result.accurate == accurate, [(c.status, c.text, c.detail) for c in result.claims]


@pytest.mark.parametrize(
    "text,accurate",
    [
        ("About 7.2 of that comes from the traffic, and 6.9 from the wind.", True),  # where a push comes from
        ("About 7.2 of that comes from the traffic, and 4.9 from the wind.", False),
        ("The traffic is about one and a half times the wind.", True),  # 'one': a ratio word, no value
    ],
)
def test_where_a_push_comes_from(text, accurate):
    from xairl.narrators.verify import rules

    result = xairl.verify(text, rules.example("air"), 0)
    assert result.accurate == accurate, [(c.status, c.text, c.detail) for c in result.claims]


def test_a_plus_sign_marks_a_push_not_the_output():
    """'made the forecast higher (+2.2)' of a thing the vocabulary lacks: the one feature whose push it is, not the
    forecast (52.1); a push no feature has is left unchecked (whose it is is unsaid), not read as the forecast."""
    from xairl.narrators.verify import rules

    def number(text):
        return [(c.status, c.detail) for c in xairl.verify(text, rules.example("air"), 0).claims if c.kind == "number"]

    assert number("Calm air, which on its own made the forecast higher (+2.2).") == [
        ("verified", "precip_mm_24h's contribution (the only one it matches)")
    ]
    assert number("Calm air, which on its own made the forecast higher (+3.3).")[0][0] == "unchecked"


def test_a_sum_of_probabilities_in_points():
    from benchmarks.bench_verifier import one_output

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
    assert not xairl.verify(
        "The contract and tenure together pull the estimate down by around 35 points.", churn, 0
    ).accurate


@pytest.mark.parametrize(
    "text,accurate",
    [
        ("Reviewed: traffic (+7.2), dry soil (+0.1), 31.5 °C (+2.2).", True),  # each '(x), ' starts a list's item
        ("Reviewed: traffic (+7.2), wind (+6.1).", False),
        ("22.0 baseline, 52.1 predicted.", True),
        ("22.0 baseline, 48.1 predicted.", False),
        ("The model starts from an average forecast of 22.0.", True),
        ("Traffic plus the junction make up 9.9.", True),  # a sum over a thing the vocabulary lacks: unchecked
        ("Traffic and wind together add 19.9.", False),
    ],
)
def test_list_items_outputs_named_after_and_sums_with_unknown_members(text, accurate):
    from xairl.narrators.verify import rules

    result = xairl.verify(text, rules.example("air"), 0)
    assert result.accurate == accurate, [(c.status, c.text, c.detail) for c in result.claims]


def test_one_word_of_a_long_name_is_no_sure_binding():
    """'bill $109.9 +.097': 'bill' is one word of price_increase_last_bill_pct, and both numbers are the monthly
    charge's exactly: unchecked, not wrong; a number that is no fact after that word stays contradicted."""
    from benchmarks.bench_verifier import one_output

    exp = one_output(["price_increase_last_bill_pct", "MonthlyCharges"], [12, 109.9], [0.141, 0.097], 0.4, "churn")

    def numbers(text):
        return [(c.text, c.status) for c in xairl.verify(text, exp, 0).claims if c.kind == "number"]

    assert numbers("bill $109.9 +.097") == [("$109.9", "unchecked"), ("+.097", "unchecked")]
    assert ("+.099", "contradicted") in numbers("bill $109.9 +.099")


def test_a_heading_before_a_colon_is_no_invented_feature():
    from benchmarks.bench_verifier import one_output

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
    from xairl.narrators.verify import rules

    air = rules.example("air")

    def numbers(text):
        return [(c.text, c.status, c.detail) for c in xairl.verify(text, air, 0).claims if c.kind == "number"]

    assert [s for _, s, _ in numbers("pm2_5_lag1 +14.7 traffic_index +7.2")] == ["verified", "verified"]
    wrong = numbers("the base of 22.0 wind -6.9 traffic +7.2")[1]
    assert wrong[1] == "contradicted" and "wind_speed_ms" in wrong[2]


@pytest.mark.parametrize(
    "text,status",
    [
        ("Traffic explains another 24%.", "verified"),  # 7.2 of the 30.1 net change
        ("Traffic explains another 34%.", "contradicted"),
        ("The precip effect is roughly 32% of the wind effect.", "verified"),  # 2.2 / 6.9
        ("The precip effect is roughly 60% of the wind effect.", "contradicted"),
        ("The wind effect is about 3 times the precip effect.", "verified"),
        ("The wind effect is about 5 times the precip effect.", "contradicted"),
        ("Wind and traffic together add 14.1, about 47% of it.", "verified"),  # 14.1 of 30.1
        ("Wind and traffic together add 14.1, about 67% of it.", "contradicted"),
        ("The three wind-and-traffic factors (wind, traffic and precip) add up.", "verified"),  # a count, no claim
    ],
)
def test_shares_ratios_and_counts_of_factors(text, status):
    """A percentage of the net change, a ratio to another named feature ('% of', 'times'), the share of a sum, and a
    count of the factors a sentence lists (no claim)."""
    from xairl.narrators.verify import rules

    result = xairl.verify(text, rules.example("air"), 0)
    got = "contradicted" if not result.accurate else "verified"
    assert got == status, [(c.status, c.text, c.detail) for c in result.claims]


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
    assert res.status in ("verified", "contradicted", "unchecked")
    assert work < 1_000_000


@pytest.fixture(scope="module")
def corpus():
    return run(load_corpus(), {d: domains.policy(d) for d in domains.DOMAINS})


def test_held_out_corpus_agreement(corpus):
    """Regression guard at the measured figures (benchmarks/bench_verifier.py reports them per domain and kind)."""
    floors = (
        ("dev", 0.98),
        ("dev2", 0.95),
        ("dev3", 0.93),
        ("dev4", 0.95),
        ("dev5", 0.93),
        ("dev6", 0.97),
        ("dev7", 0.97),
        ("dev8", 0.9),
        ("dev9", 0.97),
        ("dev10", 0.97),
        ("dev11", 0.94),
        ("dev12", 0.94),
        ("dev13", 0.95),
        ("dev14", 0.93),
        ("dev15", 0.92),
        ("dev16", 0.95),
        ("dev17", 0.9),
        ("dev18", 0.88),
        ("dev19", 0.95),
        ("dev20", 0.93),
        ("dev21", 0.88),  # (dev21: an invented "uplink SINR" given another
        # feature's exact +4.4 now reads as that feature in words the vocabulary lacks: unchecked)
        ("test", 0.93),
        ("test2", 0.85),
    )
    for split, floor in floors:
        part = [it for it in corpus if it["split"] == split]
        agree = sum(it["ok"] == it["accurate"] for it in part) / len(part)
        assert agree >= floor, (split, agree)
    assert len(corpus) >= 300 and len({it["domain"] for it in corpus}) == 4


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
    assert xairl.verify(f"The agent chose {chosen}, which could save time.", exp, 0, policy).ok
    assert xairl.verify(f"The agent chose {other}, which could save time.", exp, 0, policy).status == "contradicted"
    res = xairl.verify(f"Without the wind, the agent would have chosen {other}.", exp, 0, policy)
    assert res.status == "unchecked"  # what did not happen is not a claim about the decision


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


def test_options_weighed_against_each_other():
    """'favoured turning by x' weighs turning against the runner-up (the margin's contribution holds as well as the
    score's); '(Q 3.10)' after an action is that action's score; a signed number after '<feature> argued for
    <action>' is the feature's contribution; 'the strongest argument for <runner-up>' ranks among the reasons
    against the decision. Cases of the dev split (dev5's voices)."""

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
    """dev6's voices: 'beat staying by x' and 'the handover's lead of x' are the margin whatever is named before;
    'pulled in opposite directions' is no direction word."""
    # uav-1: the handover led staying by 0.63; uav-3: by 3.88, the serving RSRQ's share of it +24.5
    assert _on_case("Handing over beat staying by 0.63.", "uav-1").status == "verified"
    assert _on_case("Handing over beat staying by 6.3.", "uav-1").status == "contradicted"
    lead = "At -27.2 dB the serving RSRQ alone contributes +24.5 to the handover's lead of {} over staying."
    assert _on_case(lead.format(3.9), "uav-3").status == "verified"
    assert _on_case(lead.format(5.9), "uav-3").status == "contradicted"
    # toy-2: wind +5.31 and speed -5.48 in turn's lead over recharging
    assert _on_case("Wind and speed pulled in opposite directions.", "toy-2").status == "unchecked"


def test_dev7_voices():
    """Each rule tuned on dev7, on its own case: 'the big one' is a pronoun; 'edged out B (2.52) by x' is the margin;
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


def test_comparisons_between_features():
    """dev9's voices: 'A mattered more than B', chained through 'which', 'A and B both ... more than C', 'less than',
    'about as much as', 'outweighs'; a comparison with no feature after 'than' is no claim."""
    assert (
        _status("Odor mattered more than gill size, which in turn mattered more than the cap diameter.") == "verified"
    )
    assert _status("Gill size mattered more than odor.") == "contradicted"
    assert _status("Odor and gill size both mattered more than the cap diameter.") == "verified"
    assert _status("The cap diameter lowers it less than odor raises it.") == "verified"
    near = _exp(contrib=(0.13, 0.15, -0.05))  # within 25 % of each other
    assert xairl.verify("Gill size pushes it up by about as much as odor.", near, 0).status == "verified"
    assert _status("The cap diameter pushes it down by about as much as odor pushes it up.") == "contradicted"
    assert _status("Odor outweighs gill size.") == "verified" and _status("Gill size outweighs odor.") == "contradicted"
    assert [c for c in xairl.verify("Odor adds more than 0.1.", _exp(), 0).claims if c.kind == "rank"] == []


def test_a_name_first_is_not_a_hypothetical_had():
    """'Odor had the largest effect' starts with a name, then 'had': what happened, not 'Had it been ...'."""
    exp = _exp()
    assert xairl.verify("Odor had the largest effect.", exp, 0).status == "verified"
    assert xairl.verify("Gill size had the largest effect.", exp, 0).status == "contradicted"


def test_a_direction_belongs_to_the_list_of_names_nearest_it():
    assert _status("With a gill size of 1, the cap diameter lowers the prediction.") == "verified"
    assert _status("Odor (0) and gill size (1) both raise the prediction.") == "verified"
    assert _status("Odor, gill size and the cap diameter raise the prediction.") == "contradicted"


def test_dev10_number_formats():
    """Spaced thousands at a sentence's end, a range, percentage points that are not a share."""
    assert [n.value for n in find_numbers("USD 31 370. Then 12 140, 3")] == [31370, 12140, 3]
    assert find_numbers("between $500 and $1,000")[1].hedge == "at_most"
    assert find_numbers("~14 pts")[0].points and not find_numbers("14 %")[0].points


#: (case, text, status): each rule tuned on dev8 and dev10, with a right and a wrong figure on its own corpus case
ON_CASES = [
    # uav-1: the serving BS id counts -1.37 in the margin (+0.22 for the handover's own score): either view
    ("uav-1", "Serving BS id 14 counted slightly against the handover (minus 1.37).", "verified"),
    ("uav-1", "Serving BS id 14 counted slightly against the handover (minus 2.37).", "contradicted"),
    # a feature's '+x for <action>' is its push in either view (the serving RSRQ: +22.02 in the margin)
    ("uav-0", "The serving RSRQ (-22.5 dB) was worth +22.0 for the handover.", "verified"),
    ("uav-0", "The serving RSRQ (-22.5 dB) was worth +12.0 for the handover.", "contradicted"),
    ("toy-2", "Obstacle barely affected the turn score (-0.09).", "verified"),
    ("toy-2", "Obstacle barely affected the turn score (-0.19).", "contradicted"),
    # 'the strongest reason' ranks among the reasons for the decision (toy-3: battery +1.46, distance -2.15)
    ("toy-3", "Turn won over forward; battery was the strongest reason.", "verified"),
    ("toy-3", "Turn won over forward; distance was the strongest reason.", "contradicted"),
    ("uav-3", "Q-value gap: 3.88 in favour of handing over to candidate 1.", "verified"),
    ("housing-2", "The fair kitchen chipped away $23,750; everything else was positive except the lot.", "verified"),
    (
        "housing-2",
        "The fair kitchen chipped away $23,750; everything else was positive except the garage.",
        "contradicted",
    ),
    ("toy-0", "Low speed was worth +7.61 to recharging, almost four times what obstacle added (+2.05).", "verified"),
    # a range is two bounds (the lot: -715)
    ("housing-1", "The lot takes off somewhere between $500 and $1,000.", "verified"),
    ("housing-1", "The lot takes off somewhere between $800 and $1,000.", "contradicted"),
    # points are not a share (credit-3: the history lowers the risk by 4.4 points, 13 % of the total)
    ("credit-3", "A 20-year credit history lowers the risk by ~4 pts.", "verified"),
    ("credit-3", "A 20-year credit history lowers the risk by ~14 pts.", "contradicted"),
    # an acronym of a three-word name
    ("credit-3", "DTI of 60 % adds 0.11 to the predicted probability.", "verified"),
    ("credit-3", "DTI of 60 % lowers the predicted probability.", "contradicted"),
    ("uav-1", "The serving RSRQ adds about 12 to the margin, roughly 1.3x candidate 1's RSRP.", "verified"),
    ("housing-2", "The 2010 construction year takes 17.8K off the estimate.", "contradicted"),
    # toy-2: turning chosen over recharging; '+5.48' given to recharging is speed's -5.48 in that margin
    ("toy-2", "Speed (-1.70) gives recharging +5.48.", "verified"),
    ("toy-2", "Speed (-1.70) gives recharging +4.48.", "contradicted"),
    # dev13: 'from x to y' is the baseline and the prediction; 'a 12-point drop' is in percentage points
    ("credit-0", "The applicant's features move the predicted default risk from 34.1 % to 43.0 %.", "verified"),
    ("credit-0", "The applicant's features move the predicted default risk from 34.1 % to 53.0 %.", "contradicted"),
    ("housing-3", "The price falls from an average of $230,061 to $195,878.", "verified"),
    ("credit-0", "Retirement brings a 12-point drop in the default probability.", "verified"),
    ("credit-0", "Retirement brings a 19-point drop in the default probability.", "contradicted"),
    # dev14: a feature's typical value is checked against the background's quartiles (credit age 36 / 48 / 62.25:
    # Tukey's fences at -3.4 and 101.6); the output's average is the baseline
    (
        "credit-0",
        "The applicant's age of 28, younger than the typical borrower of about 48, raised the risk.",
        "verified",
    ),
    (
        "credit-0",
        "The applicant's age of 28, younger than the typical borrower of about 110, raised the risk.",
        "contradicted",
    ),
    ("housing-1", "The model estimated this house at $316,107, above the average sale price of $230,061.", "verified"),
    (
        "housing-1",
        "The model estimated this house at $316,107, above the average sale price of $250,061.",
        "contradicted",
    ),
    ("housing-1", "Overall, size and quality drove the price far above the baseline of $230,061.", "verified"),
    # 'on the positive side' and 'the lower quartile' are places, not pushes
    ("credit-0", "On the positive side, the loan purpose (home improvement) slightly lowered the risk.", "verified"),
    ("toy-1", "The distance of -0.80, close to the lower quartile, added about 1.03 to the turn score.", "verified"),
    ("credit-0", "Overall, this leads to a 43% predicted probability of default.", "verified"),
    ("credit-0", "Overall, this leads to a 53% predicted probability of default.", "contradicted"),
    # 'A and B outweighed C': together (credit-0: age 0.081 + ratio 0.067 against retirement's 0.123)
    ("credit-0", "The applicant's age and debt-to-income ratio outweighed retirement.", "verified"),
    ("credit-0", "The applicant's age and debt-to-income ratio both outweighed retirement.", "contradicted"),
    # dev15: net effects are the change from the baseline; '>' chains and 'A first, then B' rank; shares add up
    ("credit-0", "Net effect of the eight features: +0.089 (0.341 -> 0.430).", "verified"),
    ("credit-0", "Net effect of the eight features: +0.129 (0.341 -> 0.430).", "contradicted"),
    ("housing-1", "Net uplift over the base value: +$86,046, of which +$39,963 from living area.", "verified"),
    ("housing-1", "Net uplift over the base value: +$96,046, of which +$39,963 from living area.", "contradicted"),
    ("credit-0", "|phi| ranking: employment > age > DTI > credit history.", "verified"),
    ("credit-0", "|phi| ranking: age > employment > DTI > credit history.", "contradicted"),
    ("uav-0", "Margin drivers: RSRQ_0 first (+22.0), then RSRP_1 (+11.0).", "verified"),
    ("uav-0", "Margin drivers: RSRP_1 first (+11.0), then RSRQ_0 (+22.0).", "contradicted"),
    ("credit-0", "Age and employment together carry about 46 % of the total attribution.", "verified"),
    ("credit-0", "Age and employment together carry about 66 % of the total attribution.", "contradicted"),
    ("credit-2", "p(default) = 0.14 vs base 0.34.", "verified"),
    ("credit-0", "Retirement alone offsets most of the push from age and debt, taking 12.3 pp off.", "verified"),
    # an elliptical 'A for <chosen action> (+x)' weighs the options: either view (toy-3: battery +1.46 in the margin)
    ("toy-3", "Distance argues for forward (-2.15 in the margin); battery for turn (+1.46).", "verified"),
    ("toy-3", "Distance argues for forward (-2.15 in the margin); battery for turn (+2.46).", "contradicted"),
    # a list's next item named by a word the vocabulary lacks is not the previous item's
    ("housing-3", "Kitchen (Fa) -23.6k, living area 1,270 sq ft -12.1k, year 1945 -9.5k.", "verified"),
    ("uav-1", "Candidate 1's RSRP, which was -83.6 dBm, added 6.8 to the margin.", "contradicted"),
    # dev16: lists. A numbered item ranks its name; 'in order of size: A, B' and 'largest first: A, B' rank the list
    ("housing-1", "1. Living area (2,112 sq ft): +$39,963\n2. Overall quality (10): +$31,370", "verified"),
    ("housing-1", "1. Overall quality (10): +$31,370\n2. Living area (2,112 sq ft): +$39,963", "contradicted"),
    ("credit-1", "Risk 38 %. In order of size: debt-to-income, employment, credit history.", "verified"),
    ("credit-1", "Risk 38 %. In order of size: credit history, debt-to-income, employment.", "contradicted"),
    ("uav-2", "Largest first: candidate 1 RSRQ (+14.6), serving RSRQ (+10.6), serving RSRP (+7.1).", "verified"),
    ("uav-2", "Largest first: serving RSRQ (+10.6), candidate 1 RSRQ (+14.6), serving RSRP (+7.1).", "contradicted"),
    # 'Runner-up: X' names the runner-up; a name's digit is not the start of a number ('RSRQ (-3.2 dB)')
    ("toy-1", "Chosen: turn (6.27). Runner-up: recharge (3.88).", "verified"),
    ("toy-1", "Chosen: turn (6.27). Runner-up: forward (3.88).", "contradicted"),
    ("uav-2", "For the handover: candidate 1 RSRQ (-3.2 dB), serving RSRQ (-17.0 dB).", "verified"),
    # a signed number right after its name is its own, whatever another feature's value; 'below base by x'
    ("toy-1", "Pushing turn up: speed +1.71, battery +1.70.", "contradicted"),
    ("housing-3", "Below base by $34,184. Negatives: kitchen (Fa) -23.6k; CollgCr -5.8k.", "verified"),
    ("housing-3", "Below base by $44,184. Negatives: kitchen (Fa) -23.6k; CollgCr -5.8k.", "contradicted"),
    # a list item named by something that is no feature
    ("housing-3", "Negatives: kitchen (Fa) -23.6k; roof condition -12.1k; CollgCr -5.8k.", "contradicted"),
    ("housing-3", "Net: -34.2k. Kitchen (Fa) -23.6k; CollgCr -5.8k.", "verified"),
    # dev17: everyday hedges; a participle after a comma says what the clause's subject does; 'to about x' after a
    # motion verb is where the output ends; a number in points is never a value, and a sentence in points counts its
    # bare numbers in points too
    ("housing-0", "The estimate lands north of $298k, a bit over $68k above the average house.", "verified"),
    ("housing-0", "The estimate lands north of $318k, a bit over $88k above the average house.", "contradicted"),
    ("housing-1", "The lot barely registers: it takes off just shy of $1,000.", "verified"),
    ("housing-1", "Living area alone is worth upwards of $59k here.", "contradicted"),
    ("credit-0", "Being retired shaves off something like 12 points.", "verified"),
    ("credit-0", "Retirement alone offsets most of the push from age and debt, taking 12.3 pp off.", "verified"),
    ("credit-2", "Everything else drags it well below the 34 % base, to about 14 %.", "verified"),
    ("credit-2", "Everything else drags it well below the 34 % base, to about 24 %.", "contradicted"),
    (
        "credit-1",
        "The low debt ratio takes the risk down by close to 10 points, the salaried job by a bit under 9.",
        "verified",
    ),
    (
        "credit-1",
        "The low debt ratio takes the risk down by close to 10 points, the salaried job by a bit under 5.",
        "contradicted",
    ),
    ("uav-1", "Candidate 1's RSRQ takes a good 9 points off the handover's margin.", "contradicted"),
    ("uav-0", "The handover wins by a whisker, about 0.14.", "verified"),
    ("uav-0", "The handover wins by a whisker, about 1.4.", "contradicted"),
    ("toy-3", "Forward comes out ahead of turn by roughly 1.5.", "contradicted"),
    # dev18: plain language. 'N in 100' is a percentage; "it's worth $x" is the prediction (not a pair list with
    # 'the usual $y'); 'about average (33%)' may be the prediction; 'lower than it would be' is a claim, 'lower than
    # average' is not; 'It turned, helped by X' is X's push toward the choice; ', though,' is an aside
    (
        "credit-0",
        "Your chance of default is put at 43 in 100, compared with 34 in 100 for a typical applicant.",
        "verified",
    ),
    (
        "credit-0",
        "Your chance of default is put at 53 in 100, compared with 34 in 100 for a typical applicant.",
        "contradicted",
    ),
    (
        "housing-1",
        "Big house, top quality, good area: that's why it's worth about $316k instead of the usual $230k.",
        "verified",
    ),
    (
        "housing-1",
        "Big house, top quality, good area: that's why it's worth about $416k instead of the usual $230k.",
        "contradicted",
    ),
    ("credit-3", "Your risk is about average (33%).", "verified"),
    (
        "credit-0",
        "Mostly because you're retired, the risk is lower than it would be; your age pushes it back up.",
        "verified",
    ),
    ("credit-0", "Because of your age, the risk is lower than it would be.", "contradicted"),
    ("toy-1", "It turned, helped by the wind.", "verified"),
    ("toy-1", "It turned, helped by the low battery.", "contradicted"),
    ("credit-1", "Your salaried job brings the risk down. Your low debt, though, pushes it up.", "contradicted"),
    ("toy-0", "It went to recharge because it was barely moving.", "verified"),
    ("toy-0", "It went to turn because it was barely moving.", "contradicted"),
    # dev19: long reports. 'overall' is an adverb, not overall_quality; 'it' names what came before; 'the 8.32-point
    # lead' is the margin; 'two inputs dominate: A ..., B ...' ranks them top two
    (
        "housing-2",
        "The one real weakness is the kitchen. Rated fair, it takes $23,750 off, the third-largest effect overall.",
        "verified",
    ),
    ("toy-0", "Speed is worth 5.56 of the 8.32-point lead.", "verified"),
    ("toy-0", "Speed is worth 5.56 of the 9.32-point lead.", "contradicted"),
    (
        "toy-2",
        "Two inputs dominate the comparison with recharging: wind favours turning by 5.31 and speed favours "
        "recharging by 5.48.",
        "verified",
    ),
    (
        "toy-2",
        "Two inputs dominate the comparison with recharging: wind favours turning by 5.31 and the obstacle by 1.50.",
        "contradicted",
    ),
    # 'of the three' counts the things compared, it is no claim (a rewrite of the local LM)
    ("uav-1", "Candidate 1's RSRP (-83.6 dBm) was the strongest of the three neighbours.", "verified"),
    # dev21: engineers' notes. 'the deciding input', 'largest margin term' rank; 'Q_recharge' is an action's score
    ("uav-1", "Handover to neighbour 1. The deciding input was candidate 1's RSRP.", "verified"),
    ("uav-1", "Handover to neighbour 1. The deciding input was the serving RSRP.", "contradicted"),
    ("toy-3", "t=3: TURN (4.07) vs FWD (2.52). Largest margin term: distance (-2.15).", "verified"),
    ("toy-3", "t=3: TURN (4.07) vs FWD (2.52). Largest margin term: battery (+1.46).", "contradicted"),
    ("toy-0", "Driver: speed -1.79 sigma (+7.61 on Q_recharge).", "verified"),
    ("toy-0", "Driver: speed -1.79 sigma (+7.61 on Q_charging).", "contradicted"),
    # dev20: a colleague writing in a second language
    ("credit-0", "Employment (retired) is making the risk more low, of 0.12 approximately.", "verified"),
    ("credit-0", "Employment (retired) is making the risk more high, of 0.12 approximately.", "contradicted"),
    ("credit-1", "Debt-to-income of 0,24 decrease risk for 0,098; salaried employment decrease for 0,086.", "verified"),
    ("credit-1", "Debt-to-income of 0,24 decrease risk for 0,198.", "contradicted"),
    # ranks among one sign (credit-2: employment +0.128 first overall, the ratio -0.127 first of those lowering it)
    ("credit-2", "The biggest factor working against default was the low debt-to-income ratio.", "verified"),
    ("credit-2", "The biggest factor working against default was the 26-year credit history.", "contradicted"),
    (
        "credit-3",
        "The ratio raised the risk most; salaried employment was the strongest factor pulling the other way.",
        "verified",
    ),
    (
        "credit-3",
        "The ratio raised the risk most; the credit history was the strongest factor pulling the other way.",
        "contradicted",
    ),
    ("housing-1", "The house sits in Somerst, one of the pricier neighbourhoods, adding about $14,200.", "verified"),
    # a coordinated clause's own subject that is no feature
    (
        "housing-3",
        "The fair kitchen lowered the price by about $23,600, and the lack of a finished basement cost "
        "another $12,000.",
        "contradicted",
    ),
]


@pytest.mark.parametrize("case,text,status", ON_CASES)
def test_phrasings_on_corpus_cases(case, text, status):
    assert _on_case(text, case).status == status


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


OUTSIDE = [
    # fifa-105: goals 0 (-0.20), corners 7 (+0.04), attempts 13 (+0.02), on target 1 (-0.015); a plural name in the
    # singular, the head of a compound and the object of 'on' belong to the name before them
    ("fifa", 105, "The team took 7 corner kicks, which slightly boosted their probability.", "verified"),
    ("fifa", 105, "The team took 7 corner kicks, which slightly lowered their probability.", "contradicted"),
    ("fifa", 105, "Their 13 attempts on goal, close to the average of 12.33, added a little.", "verified"),
    ("fifa", 105, "Their 13 attempts on goal, close to the average of 12.33, lowered it slightly.", "contradicted"),
    ("fifa", 105, "The team took 7 corners.", "verified"),
    ("fifa", 105, "The team took 9 corners.", "contradicted"),
    # a typical value by habit; a side word whose object is the classifier's lower class
    (
        "fifa",
        105,
        "Failing to score (the average team typically scores around 1.3 goals) hurt the team most.",
        "verified",
    ),
    ("fifa", 96, 'The lack of corners and fewer attempts tipped the prediction toward "no."', "verified"),
    ("fifa", 96, 'The four goals tipped the prediction toward "no."', "contradicted"),
    # student-375: failures 0 (+0.12; quartiles 0 / 0 / 0), goout 2 (+0.05), absences 2 (+0.03), Mjob other (-0.01)
    (
        "student",
        375,
        "Going out with friends moderately often (2 out of 5, below the average of ~3) also helped.",
        "verified",
    ),
    ("student", 375, "Fewer absences than average (2 vs. ~5.75) further supported the prediction.", "verified"),
    ("student", 375, "Fewer absences than average (3 vs. ~5.75) further supported the prediction.", "contradicted"),
    ("student", 375, "Fewer absences than average (2 vs. ~25) further supported the prediction.", "contradicted"),
    ("student", 375, "No past class failures (0 compared to the average of ~0.36) strongly boosted it.", "verified"),
    (
        "student",
        375,
        "Unlike 95% of their peers, the student had no past class failures, which boosted the odds.",
        "verified",
    ),
    # a description's legend is not needed to name the feature ('weekly study time (1: <2 hours, ...)')
    ("student", 221, "Their weekly study time (3, compared to the average of ~2) helped.", "verified"),
    ("student", 221, "Their weekly study time (3, compared to the average of ~2) lowered the odds.", "contradicted"),
    # a plain label ('other') only next to its feature, and not after a negation
    ("student", 300, "The student's mother's job wasn't in the 'other' category, which added a little.", "verified"),
    ("student", 375, "The mother's job (other) was the only minor detractor.", "verified"),
    ("student", 300, "The mother's job (other) added a little.", "contradicted"),
    (
        "student",
        82,
        "Like the other students, this one had no past class failures, which boosted the prediction.",
        "verified",
    ),
    # a rank over a list counts the items the verifier does not know too
    (
        "student",
        261,
        "The student's low absences, no failures, and balanced social life were the key drivers.",
        "verified",
    ),
    ("student", 261, "The student's low absences and no failures were the key drivers.", "contradicted"),
    # diabetes-725 (Pima): age 38 (+0.08), pedigree 0.236 (-0.07), BMI 39.4 (+0.05), glucose 112 (-0.02); the
    # output's word 'diabetes' is not a part of 'DiabetesPedigreeFunction', 'outcome 1' is a class
    ("diabetes", 725, "The model predicted a 32% probability of diabetes (outcome 1).", "verified"),
    ("diabetes", 725, "The model predicted a 42% probability of diabetes (outcome 1).", "contradicted"),
    (
        "diabetes",
        725,
        "While age and BMI pushed the prediction toward diabetes, low genetic predisposition and "
        "relatively lower glucose levels outweighed these risks.",
        "verified",
    ),
    ("diabetes", 725, "Age and BMI pushed the prediction away from diabetes.", "contradicted"),
    (
        "diabetes",
        725,
        "Their below-average Diabetes Pedigree Function score (0.236 vs. 0.469) reduced the probability.",
        "verified",
    ),
    # diabetes-210: glucose 81 (-0.20), age 25 (-0.08), BMI 27.7 (-0.04), pregnancies 2 (-0.02)
    (
        "diabetes",
        210,
        "A BMI of 27.7, while slightly elevated, was still lower than average and contributed modestly "
        "to lowering the risk.",
        "verified",
    ),
    (
        "diabetes",
        210,
        "A BMI of 27.7, while slightly elevated, was still lower than average and contributed modestly "
        "to raising the risk.",
        "contradicted",
    ),
    # a rank said of several features at once: together against all the others
    (
        "diabetes",
        490,
        "Overall, the combination of favorable glucose, age, and insulin levels dominated the prediction.",
        "verified",
    ),
    ("diabetes", 490, "Overall, the combination of insulin and BMI dominated the prediction.", "contradicted"),
    # stroke (Kaggle columns): 'the patient' in 'age of the patient' names no feature; a one-hot column is a label
    ("stroke", 243, "The most influential factor was the patient's high average glucose level (247.51).", "verified"),
    ("stroke", 243, "The most influential factor was the patient's age (68 years).", "contradicted"),
    ("stroke", 2819, "Being a child (work_type_children) slightly lowered the risk.", "verified"),
    ("stroke", 2819, "Being in private work (work_type_Private) slightly lowered the risk.", "contradicted"),
    # a label after 'compared to' is no claim about this patient; 'a positive prediction' is a class
    ("stroke", 5029, "Having never smoked slightly reduced the risk compared to smokers.", "verified"),
    ("stroke", 5029, "Being a smoker slightly reduced the risk.", "contradicted"),
    ("stroke", 237, "Age and glucose raised the risk, though not enough for a positive prediction.", "verified"),
    # what might seem or would be: no claim
    (
        "stroke",
        242,
        "The high BMI (42.4) might intuitively suggest increased risk, but it slightly lowered it.",
        "verified",
    ),
    (
        "stroke",
        15,
        "Other factors were not severe enough to make age a dominant predictor; age lowered the risk.",
        "verified",
    ),
    # South German Credit (good-credit probability): a number of the meaning of a code in the description's legend
    # (status 4 = '200 DM or more', savings 3 = '100 to 500 DM')
    ("credit", 175, "Having a checking account balance above 200 DM strongly increased the likelihood.", "verified"),
    ("credit", 175, "Having a checking account balance below 0 DM strongly increased the likelihood.", "contradicted"),
    (
        "credit",
        175,
        "Their savings account balance (between 100 and 500 DM) further reinforced the prediction.",
        "verified",
    ),
    ("credit", 175, "Their savings account balance (over 1000 DM) further reinforced the prediction.", "contradicted"),
    ("credit", 124, "Another key factor was their long employment duration (over 7 years).", "verified"),
    ("credit", 124, "The key factor was their long employment duration (over 7 years).", "contradicted"),
    ("credit", 675, "The loan duration of 6 months was much shorter than average (21 months).", "verified"),
    ("credit", 675, "The loan duration of 6 months was much shorter than average (91 months).", "contradicted"),
    # a good outcome's 'risk' is its inverse framing; 'raised concerns', 'this negative impact', 'balanced X against
    # Y' and a 'because' clause's subject claim no direction of a feature; 'added to the negative outlook' lowers
    ("credit", 571, "The loan amount of 9,055 DM raised concerns; the purpose slightly reduced risk.", "verified"),
    (
        "credit",
        319,
        "However, this negative impact was partially offset by the customer's status (value: 4), which "
        "boosted the prediction.",
        "verified",
    ),
    (
        "credit",
        700,
        "The prediction balanced the customer's financial gaps against their strong savings, which boosted it.",
        "verified",
    ),
    ("credit", 990, "Having no savings account (value 1) added to the negative outlook.", "verified"),
    ("credit", 990, "Being unemployed (value 1) added to the positive outlook.", "contradicted"),
    (
        "credit",
        319,
        "Other installment plans (value: 1) slightly lowered the probability, because existing debt "
        "obligations increase repayment risk.",
        "verified",
    ),
    # other LLMs' narratives of the same cases (baseline_narratives_best.json): 'this boost' refers back; a risk
    # output's 'risk' is the output itself; counting nouns and 'type 2' are no values; ', as ...' gives a reason
    (
        "fifa",
        69,
        "However, this boost was offset by the team having only 1 corner kick, which significantly reduced "
        "the probability.",
        "verified",
    ),
    (
        "fifa",
        69,
        "However, this boost was offset by the team having only 1 corner kick, which significantly raised "
        "the probability.",
        "contradicted",
    ),
    ("diabetes", 66, "The patient's age of 38 also contributed positively to the risk.", "verified"),
    ("diabetes", 66, "The patient's age of 38 also contributed negatively to the risk.", "contradicted"),
    (
        "diabetes",
        66,
        "The glucose level of 109 lowered the probability, leaving a nearly equal split between the two outcomes.",
        "verified",
    ),
    (
        "diabetes",
        66,
        "The glucose level of 119 lowered the probability, leaving a nearly equal split between the two outcomes.",
        "contradicted",
    ),
    (
        "diabetes",
        66,
        "Next, the age of 38 raised the risk, as older age is generally associated with higher diabetes likelihood.",
        "verified",
    ),
    ("student", 300, "Going out with friends, rated 4 on a 5-point scale, reduced the probability.", "verified"),
    ("student", 300, "Going out with friends, rated 3 on a 5-point scale, reduced the probability.", "contradicted"),
    ("diabetes", 375, "The patient's age of 58 raised the risk of type 2 diabetes.", "verified"),
    ("diabetes", 375, "The patient's age of 48 raised the risk of type 2 diabetes.", "contradicted"),
    # 'the contributions from A and B dominated' is said of the two together
    ("diabetes", 490, "The strong protective contributions from low glucose and young age dominated.", "verified"),
    ("diabetes", 66, "The strong contributions from glucose and BMI dominated.", "contradicted"),
    # a gerund of a name's word and all the words of a description are vague mentions, not invented features; a
    # flag's one-word legend ('sex (1 = male)') names its value
    (
        "fifa",
        19,
        "Next, one goal gave a slight positive contribution, though scoring only once did not strongly boost "
        "the probability.",
        "verified",
    ),
    (
        "fifa",
        19,
        "Next, one goal gave a slight positive contribution, though the team's singing did not strongly "
        "boost the probability.",
        "contradicted",
    ),
    (
        "student",
        375,
        'However, the student\'s mother having a job categorized as "other" slightly reduced the probability.',
        "unchecked",
    ),
    ("student", 375, "However, the student's love of chess slightly reduced the probability.", "contradicted"),
    ("student", 246, "Finally, being male provided a slight positive contribution.", "verified"),
    ("student", 252, "Finally, being male provided a slight positive contribution.", "contradicted"),
    # the worst LLM's narratives (baseline_narratives_worst.json, FIFA, student, diabetes): 'driven by' of one output
    # says what mattered, not which way ('drives it up' does); ranks scoped to where the prediction went ('the
    # primary reasons for the model's prediction', 'the factors that led to ... a low probability')
    (
        "diabetes",
        668,
        "The prediction was largely driven by the patient's glucose level, which was lower than expected.",
        "verified",
    ),
    ("diabetes", 668, "The glucose level drives the probability up.", "contradicted"),
    (
        "fifa",
        84,
        "Their lack of goal scoring and limited attacking threat were the primary reasons for the model's prediction.",
        "verified",
    ),
    (
        "fifa",
        84,
        "Their corner kicks and limited attacking threat were the primary reasons for the model's prediction.",
        "contradicted",
    ),
    (
        "fifa",
        105,
        "The team's lack of goal scoring and relatively low number of shots on target were the primary "
        "factors that led to the model's prediction of a low probability.",
        "verified",
    ),
    (
        "fifa",
        105,
        "The team's lack of goal scoring and its seven corner kicks were the primary factors that led to "
        "the model's prediction of a low probability.",
        "contradicted",
    ),
    ("fifa", 118, "The goals led to a predicted probability of 66.00% for receiving the award.", "verified"),
    ("fifa", 118, "The goals led to a predicted probability of 76.00% for receiving the award.", "contradicted"),
    # 'which could be due to' gives a reason (no hypothetical); 'not effective in increasing' negates; 'the opposing
    # team', 'dominate the game', 'the negative contributions from other areas' claim nothing of a feature
    (
        "fifa",
        40,
        "The number of attempts also had a negative impact, which could be due to the team's inability to "
        "convert them.",
        "verified",
    ),
    (
        "fifa",
        40,
        "The number of attempts also had a positive impact, which could be due to the team's inability to "
        "convert them.",
        "contradicted",
    ),
    ("fifa", 40, "The team's corner kicks were not effective in increasing their chances.", "verified"),
    ("fifa", 105, "The team's corner kicks were not effective in increasing their chances.", "contradicted"),
    (
        "fifa",
        96,
        "Scoring four goals raised the probability, but not enough to outweigh the negative contributions "
        "from other areas.",
        "verified",
    ),
    (
        "fifa",
        56,
        "The 8 corner kicks put pressure on the opposing team's defense and raised the probability.",
        "verified",
    ),
    (
        "fifa",
        40,
        "The 3 corner kicks put pressure on the opposing team's defense and raised the probability.",
        "contradicted",
    ),
    ("fifa", 81, "The 719 passes suggest that the team was able to dominate the game.", "verified"),
    # 'A and B being the most significant', 'X and Y were the most important factors' with X unknown: top 2
    (
        "fifa",
        84,
        "The prediction was shaped by many factors, with the team's inability to score goals and convert "
        "attempts being the most significant.",
        "verified",
    ),
    (
        "fifa",
        40,
        "The prediction was shaped by many factors, with the team's inability to score goals and convert "
        "attempts being the most significant.",
        "contradicted",
    ),
    (
        "student",
        82,
        "The student's relatively low level of socializing and lack of past failures were likely the most "
        "important factors.",
        "verified",
    ),
    (
        "student",
        300,
        "The student's relatively high level of socializing and high number of absences were likely the "
        "most important factors.",
        "contradicted",
    ),
    # a label's stem takes inflections, not compounds ('coursework' is no 'course'); a label given after its
    # feature ("the mother's job, which is categorized as 'other'")
    (
        "student",
        252,
        "Having one past failure suggests that the student has struggled with their coursework, which "
        "lowered the probability.",
        "verified",
    ),
    (
        "student",
        82,
        'Additionally, the mother\'s job, which is categorized as "other", had a small positive contribution.',
        "contradicted",
    ),
    (
        "student",
        375,
        'Additionally, the mother\'s job, which is categorized as "other", had a small negative contribution.',
        "verified",
    ),
]


@pytest.mark.parametrize("dataset,index,text,status", OUTSIDE)
def test_phrasings_on_outside_cases(dataset, index, text, status):
    assert _outside(text, dataset, index).status == status


def _tuples(text):
    return explanation_from_tuples(text, output="price")


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
    assert xairl.verify("The house's location on a feeder street reduced the price by about $8,000.", exp).ok
    assert not xairl.verify("The house's location on a feeder street reduced the price by about $28,000.", exp).ok
    exp = _tuples(
        "(Original construction date, 1915.00, -17966.77), (Second floor square feet, 756.00, 10129.96), "
        "(Total square feet of basement area, 756.00, -8362.22), (Condition of sale, Abnorml, -6786.66)"
    )
    text = "The smaller basement area and abnormal sale condition reduce it by about $8,400 and $6,800, respectively."
    assert xairl.verify(text, exp).status == "verified"
    assert xairl.verify(text.replace("$6,800", "$9,800"), exp).status == "contradicted"
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
    assert xairl.verify(text, exp).status == "verified"
    assert xairl.verify(text.replace("decreases", "increases"), exp).status == "contradicted"
    text = "The Above ground living area square feet feature has a values of 1256.00 and a SHAP value of -12527.46."
    assert xairl.verify(text, exp).status == "verified"
    assert xairl.verify(text.replace("-12527.46", "-10743.76"), exp).status == "contradicted"  # another's
    text = "The Wood deck area in square feet feature has a values of 736.00 and a SHAP value of 9846.38."
    assert xairl.verify(text, exp).status == "verified"
    assert xairl.verify(text, replace(exp, values=-exp.values)).status == "contradicted"  # it is -9846.38
    assert xairl.verify(text.replace("a SHAP", "a negative SHAP"), replace(exp, values=-exp.values)).ok


def test_no_direction_in_an_adjective_an_appearance_or_an_aside():
    """'their lower efficiency' describes the subject; 'might seem positive' is an appearance; after '—likely' comes
    the writer's reasoning, whose names are not the subject of the claim before it."""
    text = "Despite attempting 9 shots (below the average of 12), their lower efficiency here also hurt their chances."
    assert _outside(text, "fifa", 11).status != "contradicted"
    text = "The team blocked 9 shots, which might seem positive defensively but hurt the team's chances."
    assert _outside(text, "fifa", 81).status == "verified"
    text = (
        "The most influential factor was the student's frequent outings, which slightly reduced the chance of "
        "passing—likely because socializing may detract from study time."
    )
    assert _outside(text, "student", 82).status != "contradicted"


def test_dev11_corrections():
    """Operators' corrections: a name after 'not', 'rather than', 'instead of' is not what the sentence says things
    of; 'would not worry' is an opinion, not a hypothetical; 'Q: Anything positive? A: ...' and 'A: a little, +1.77
    toward ...' name no unknown feature."""
    assert _status("It is not the cap diameter but the odor that raises the prediction most.") == "verified"
    assert _status("It is not the odor but the cap diameter that raises the prediction most.") == "contradicted"
    assert _status("Rather than the cap diameter, odor is what raises the prediction.") == "verified"
    tiny = _exp(contrib=(0.11, 0.15, -0.01))  # the cap diameter: 4 % of the total |contribution|
    assert xairl.verify("I would not worry about the cap diameter: its effect is negligible.", tiny, 0).ok
    assert _status("Had the odor not been foul, the prediction would be lower.") == "verified"  # still hypothetical
    assert _status("Q: Anything positive? A: odor, +0.15.") == "verified"
    assert (
        _on_case("Q: Did the buffer matter? A: a little, +1.77 toward the handover.", "uav-1").status != "contradicted"
    )


def test_sums_and_scoped_ranks():
    """dev12's voices: 'A and B together add x' is their sum (a list 'x and y' and 'most of the x above the baseline'
    are not); 'Among the positives, X is the largest' and 'Of the factors lowering it, X matters most' rank within
    that sign."""
    assert _status("Odor and gill size together add 0.26.") == "verified"
    assert _status("Odor and gill size together add 0.36.") == "contradicted"
    assert _status("Odor (+0.15) and the cap diameter (-0.05) together come to +0.10.") == "verified"
    assert _status("Odor and gill size together add 0.15 and 0.11, respectively.") == "verified"
    assert _status("Among the positives, odor is the largest.") == "verified"
    assert _status("Among the positives, gill size is the largest.") == "contradicted"
    assert _status("Of the factors lowering the prediction, the cap diameter matters most.") == "verified"


def test_a_qualifier_after_an_ambiguous_name_and_a_compound_modifier():
    """'the queue on the east approach' is queue_east (its words qualify an ambiguous 'queue' after it, and the
    'approach' of approach_speed inside it names nothing); 'the 19-vehicle queue' is a queue, not the emergency
    vehicle; a wrong number for the qualified queue stays contradicted."""
    from benchmarks.bench_verifier import one_output

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


def test_the_first_number_of_a_sentence_about_the_average_case_is_the_baseline():
    from benchmarks.bench_verifier import one_output

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


def test_abbreviations_in_feature_names_are_read_as_the_words_people_write():
    """'dist_to_charger_m' is 'the distance', 'battery_pct' 'the battery': a ranking in those words is checked."""
    from benchmarks.bench_verifier import one_output

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


def test_a_value_in_another_unit_of_the_one_its_name_ends_in():
    """'next_drop_dist_km' is 0.6: '600 m away' states it, '900 m' does not; 'wait_s' of 90 is '1.5 minutes'."""
    from benchmarks.bench_verifier import one_output

    exp = one_output(["next_drop_dist_km", "wait_s"], [0.6, 90], [1.15, -0.4], 3.1, "Q-value of continuing")

    def numbers(text):
        return [(c.text, c.status, c.detail) for c in xairl.verify(text, exp, 0).claims if c.kind == "number"]

    assert numbers("It kept going because the next drop is only 600 m away.") == [
        ("600", "verified", "next_drop_dist_km: value in m (not km)")
    ]
    assert numbers("It kept going because the next drop is only 900 m away.")[0][1] == "contradicted"
    assert numbers("The wait of 1.5 minutes counted against it.")[0][:2] == ("1.5", "verified")
    assert numbers("The next drop is 0.6 km away.")[0] == ("0.6", "verified", "next_drop_dist_km: value")


def test_a_period_that_is_the_window_of_a_features_name_is_no_claim():
    """'in the past twelve months' of prior_returns_12m is the name's window even where the words bind the number
    to customer_tenure_mo (71 months); a period no name holds is still checked."""
    from benchmarks.bench_verifier import one_output

    exp = one_output(["customer_tenure_mo", "prior_returns_12m"], [71, 0], [-2.3, -1.9], 14.0, "return probability")

    def numbers(text):
        return [(c.text, c.status) for c in xairl.verify(text, exp, 0).claims if c.kind == "number"]

    assert numbers("A customer of 71 months who returned nothing in the past twelve months.") == [("71", "verified")]
    assert numbers("A customer of 71 months who returned nothing in the past nine months.")[1] == (
        "nine",
        "contradicted",
    )


def test_fractions_state_a_probability_given_in_percent():
    """A dropout probability of 46.9 (%) from 18.4 with Q3_grade +9.6: 'p_dropout=0.469 ... (+0.096)' states it; a
    wrong fraction is caught; an output that is no probability does not read fractions as percentages."""
    from benchmarks.bench_verifier import one_output

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


def test_a_change_since_last_time_is_the_features_value_not_its_push():
    from benchmarks.bench_verifier import one_output

    exp = one_output(["gpa_trend", "units_failed"], [-0.4, 3], [3.1, 11.3], 18.4, "probability of dropping out")

    def numbers(text):
        return [(c.text, c.status, c.detail) for c in xairl.verify(text, exp, 0).claims if c.kind == "number"]

    assert numbers("A falling GPA trend, down 0.4 since last term, adds another 3.")[0] == (
        "0.4",
        "verified",
        "gpa_trend: value",
    )
    assert numbers("A falling GPA trend, down 0.9 since last term, adds another 3.")[0][1] == "contradicted"


def test_the_words_of_one_names_window_do_not_bind_a_number_to_another_name():
    """'in the last 90 days' spells num_support_calls_90d's window, not days_since_last_upgrade: the push after it
    is the support calls'."""
    from benchmarks.bench_verifier import one_output

    exp = one_output(
        ["num_support_calls_90d", "days_since_last_upgrade"], [7, 612], [0.133, 0.029], 0.26, "churn probability"
    )
    text = "The seven support calls logged in the last 90 days add roughly {} percentage points."
    found = [(c.text, c.status, c.detail) for c in xairl.verify(text.format(13), exp, 0).claims if c.kind == "number"]
    assert ("13 percentage points", "verified", "num_support_calls_90d: contribution (chosen)") in found
    assert not xairl.verify(text.format(3), exp, 0).ok


def test_this_rounds_readings_do_not_let_wrong_numbers_through():
    """Counterexamples a second review found for the readings above, each a wrong (or right) number that must keep
    its status."""
    from benchmarks.bench_verifier import one_output

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


def test_words_people_write_for_a_names_word():
    """'the charge' is battery_pct, 'the fever' temp_c (lexicon.SYNONYMS): their numbers are checked."""
    from benchmarks.bench_verifier import one_output

    exp = one_output(["battery_pct", "temp_c"], [76, 38.8], [0.92, 5.3], 3.1, "Q-value of continuing")

    def numbers(text):
        return [(c.text, c.status) for c in xairl.verify(text, exp, 0).claims if c.kind == "number"]

    assert numbers("The healthy 76% charge added about 0.92.") == [("76%", "verified"), ("0.92", "verified")]
    assert numbers("The healthy 76% charge added about 0.52.")[1] == ("0.52", "contradicted")
    assert numbers("The fever of 38.8 adds about 5.3.") == [("38.8", "verified"), ("5.3", "verified")]


def test_a_push_equal_only_to_a_decision_level_number_is_not_verified():
    """'piles on around 8 more' where the baseline is 8 and no feature pushes 8: not verified as 'a decision-level
    fact' (the words say it is a push)."""
    from benchmarks.bench_verifier import one_output

    exp = one_output(["lactate", "heart_rate"], [4.2, 118], [9.6, 4.1], 8.0, "sepsis risk")

    def numbers(text):
        return [(c.text, c.status) for c in xairl.verify(text, exp, 0).claims if c.kind == "number"]

    assert numbers("Lactate adds about 9.6.") == [("9.6", "verified")]
    assert ("8", "verified") not in numbers("Something else piles on around 8 more.")


def test_fronted_phrases_and_swaps():
    """'Beyond A and B, the C added ...': C is the subject (an invented feature here), not A and B; 'Beyond A, B
    lowered it' is said of B alone. Two numbers that cross (each name holding the other's, on two lines of a table)
    are contradicted, one number that states another named fact stays unclear. A side's sum that is the other side's
    is a sign error."""
    from xairl.narrators.verify import rules

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
    from benchmarks.bench_verifier import one_output

    exp = one_output(["hm_pr_min", "AvgWait5m"], [121, 41], [11.2, 0.26], 252.0, "finish time")
    vocab = vocabulary(exp, None, clean_surface)

    def said(text):
        return [m.keys for m in find_mentions(text, vocab)[0]]

    assert said("The others add 14.7 min; avg 3.2.") == []
    assert said("hm_pr_min adds 11.2 min, AvgWait5m 0.26.") == [("hm_pr_min",), ("AvgWait5m",)]
    assert said("The hm pr min adds 11.2.") == [("hm_pr_min",)]


def test_log_odds_given_as_a_probability_and_names_with_an_index_or_an_acronym():
    """A log-odds output and its baseline may be written as the probabilities they stand for; an index in square
    brackets ('forecast_price[+6h]') is part of a name, not a signed number; 'debt-to-income' is dti_ratio."""
    from benchmarks.bench_verifier import one_output

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


def test_a_span_of_time_names_no_feature():
    """'in the last two years' names no months_since_last_record: its 'two' is not that feature's value; the
    written-out acronym 'the antibiotics' still names abx_given_last_24h."""
    from benchmarks.bench_verifier import one_output

    exp = one_output(
        ["delinq_2yrs", "months_since_last_record", "abx_given_last_24h"], [1, 14, 1], [2.6, 0.4, -3.3], 12.0, "risk"
    )

    def claims(text):
        return [(c.text, c.status) for c in xairl.verify(text, exp, 0).claims if c.kind == "number"]

    assert ("two", "contradicted") not in claims("One delinquency in the last two years adds 2.6 points.")
    assert ("2.6 points", "verified") in claims("One delinquency in the last two years adds 2.6 points.")
    assert claims("The antibiotics take off about 3.3 points.") == [("3.3 points", "verified")]


def test_a_ratio_written_as_odds():
    """'outweighed B by roughly 1.5 to 1', 'two to one (x vs y)', '3:1': the ratio of the two sizes, checked; its
    numbers are no values (but 'fell from 3 to 1' states two)."""
    from xairl.narrators.verify.rules import example

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


def test_twice_the_size_of_and_more_than_twice_that_of():
    """'twice the size of B', 'three times that of B' state a ratio; 'more than twice that of B' at least about 2;
    a second comparison joined by 'and' keeps the first one's subject; the bracket after 'the B effect' pairs."""
    from xairl.narrators.verify.rules import example

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


FIRE = (
    ["month", "aspect", "days_since_rain", "campfire_ban", "wind_kmh"],
    ["August", "south-west", 15, "yes", 11],
    [1.9, 0.6, 2.2, -1.6, -0.8],
    4.0,
    "probability of ignition in %",
)
LOAN = (
    ["dti", "grade", "income", "term"],
    [28.0, "C", 52000, "60 months"],
    [0.9, 0.6, -0.2, 0.53],
    -2.1,
    "log-odds of default",
)  # prediction -0.27: 43 %; baseline 10.9 %
MED = (["fever", "cough", "age", "test_result"], ["yes", "no", 54, "negative"], [1.3, -0.4, 0.6, -0.9], 10.0, "risk")


@pytest.mark.parametrize(
    "case,text",
    [  # accurate sentences a second review wrote against this session's readings
        (FIRE, "Since June, the month term has grown; in August it added +1.9."),
        (FIRE, "The month (August, two months after June) added 1.9."),
        (FIRE, "Fifteen dry days since early July raised the risk by 2.2, and the month added 1.9."),
        (FIRE, "The month added 1.9, so fire crews will march in early."),
        (FIRE, "The aspect added 0.6: south-west slopes dry out faster than north-facing ones."),
        (FIRE, "The aspect added 0.6 while the wind, blowing from the north at 11 km/h, lowered risk by 0.8."),
        (FIRE, "It would need to drop by 2.2 points to reach the alert threshold."),
        (LOAN, "The baseline is about 11%."),
        (LOAN, "Up from a baseline of about 11%, the default probability is 43%."),
        (MED, "The negative test lowered the risk by 0.9, not the fever."),
        (MED, "The risk is high because of age, not fever alone."),
        (MED, "The patient is not without fever: +1.3."),
        (
            (["verification_status", "income"], ["Not Verified", 5], [0.4, 0.1], 1.0, "risk"),
            "Verified or not, the verification status added 0.4.",
        ),
        (
            (["verification_status", "income"], ["Verified", 5], [-0.4, 0.1], 1.0, "risk"),
            "An unverified income would raise the risk; here the verification status lowered it by 0.4.",
        ),
        (
            (
                ["user_segment", "parties_involved", "bedrooms", "category"],
                ["premium", 2, 3, "toys"],
                [0.3, 0.2, 1.2, -1.3],
                1.0,
                "sales",
            ),
            "In the US 3 of 10 applicants were flagged; par 3 golf aside, a 3 bed house; Cat 3 storms too.",
        ),
        ((["lag[-1]", "load_mw"], [48.5, 300], [-1.2, 0.8], 1.0, "load"), "The lag removed 1.2 [2]."),
    ],
)
def test_accurate_sentences_of_a_second_review_stay_accurate(case, text):
    from benchmarks.bench_verifier import one_output

    result = xairl.verify(text, one_output(*case), 0)
    assert result.accurate, [(c.rule, c.text, c.detail) for c in result.claims if c.status == "contradicted"]


def test_log_odds_are_no_percentages():
    """'The probability of default is 27%' of log-odds -0.27 (a probability of 43 %): contradicted."""
    from benchmarks.bench_verifier import one_output

    claims = xairl.verify("The probability of default is 27%.", one_output(*LOAN), 0).claims
    assert [c.status for c in claims if c.kind == "number"] == ["contradicted"]


def test_odds_of_a_larger_number_to_a_smaller_one():
    """'outweighs B by about 3 to 2' is a ratio of 1.5, checked; its numbers are no values; '2 to 3' is no odds."""
    from benchmarks.bench_verifier import one_output

    exp = one_output(["income", "late_payments"], [52000, 3], [1.46, -1.0], 3.0, "credit score")

    def claims(text):
        return [(c.rule, c.status) for c in xairl.verify(text, exp, 0).claims if c.kind != "feature"]

    assert claims("Income outweighs the late payments by about 3 to 2.") == [("rank.comparison", "verified")]
    assert claims("Income outweighs the late payments by about 5 to 2.") == [("rank.comparison", "contradicted")]


FIRE = (["wind_kmh", "humidity_pct", "crew_size"], [35, 20, 4], [1.5, 0.8, -0.6], 2.0, "fire risk")
GATE = (["queue_len", "eta_min"], [5, 12.0], [0.4, -0.2], 1.0, "Q-value of the action 'open gate 4'")
DAIRY = (["temp_c", "rain_mm", "lag[-1] yield (L)"], [31, 0, 30.5], [-1.4, 0.5, 2.1], 20.0, "milk yield")


@pytest.mark.parametrize(
    "case, text",
    [
        (FIRE, "If the wind had contributed nothing, the fire risk would be about 2.2."),
        (FIRE, "Had the crew size been removed (its -0.6), the risk would sit near 4.3."),
        (GATE, "Opening gate 4 scores 1.2, mostly for the queue (+0.4)."),
        (GATE, "Despite that, the Q-value ends above the baseline because of several positive terms."),
        (DAIRY, "pred=21.2 lag[-1]=+2.1 temp=-1.4"),
        (DAIRY, "The heat itself (-1.4) hurt more than twice as much as the rain (+0.5) helped."),
        (FIRE, "Most of the positive push (1.5 of 2.3) came from the wind."),
    ],
)
def test_counterfactuals_output_names_and_pushes_in_other_words_stay_accurate(case, text):
    """A removal said after the name ('if A had contributed nothing'), a number of the output's name ('gate 4'), an
    index in brackets ('lag[-1]'), a subject in other words with its push in brackets, 'positive terms' and 'most of
    the positive push' (no subject of their own)."""
    from benchmarks.bench_verifier import one_output

    result = xairl.verify(text, one_output(*case), 0)
    assert result.accurate, [(c.rule, c.text, c.detail) for c in result.claims if c.status == "contradicted"]


@pytest.mark.parametrize(
    "case, text",
    [
        (GATE, "If the queue had contributed nothing, the Q-value would be about 2.0."),
        (FIRE, "The drought index (+0.9) raised the risk."),
        (GATE, "Opening gate 4 scores 2.2."),
    ],
)
def test_their_near_misses_are_contradicted(case, text):
    """The same readings with a wrong counterfactual, an invented name whose bracketed number is no contribution, a
    wrong score beside the output's number."""
    from benchmarks.bench_verifier import one_output

    assert not xairl.verify(text, one_output(*case), 0).accurate


def test_an_opposite_of_the_label_is_a_wrong_category():
    """A label's opposite said in a sentence naming its feature, or its label's word in capitals ('outside the ECA'
    of 'inside_ECA'): contradicted; the label itself, or its opposite said beside it, is not."""
    from benchmarks.bench_verifier import one_output

    exp = one_output(["stage", "zone", "yield_lag"], ["early", "inside_ECA", 30.0], [2.4, -0.3, 1.1], 20.0, "yield")

    def accurate(text):
        return xairl.verify(text, exp, 0).accurate

    assert not accurate("Being in late lactation, she got a 2.4 boost from the stage feature.")
    assert not accurate("Because the ship is outside the ECA, the zone feature lowered it by 0.3.")
    assert accurate("Being in early lactation, she got a 2.4 boost from the stage feature.")
    assert accurate("Inside the ECA, the zone feature lowered it by 0.3.")
    assert accurate("Early lactation, not late, is what the stage term rewarded with 2.4.")
