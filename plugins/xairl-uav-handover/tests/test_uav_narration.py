"""Narrating the reference DQN: the handover template, domain comparisons, and the verifier's mutation corpus."""

import collections
import re

import numpy as np
import pytest

import xairl
from xairl.facts import decision_facts
from xairl.templates import prompts
from xairl.testing import corpus
from xairl_uav_handover.features import LABEL_WORDS, handover_facts
from xairl_uav_handover.policy import uav_policy


@pytest.fixture(scope="module")
def uav():
    p = uav_policy()
    bg = p.background(100)
    return p, xairl.explain(p, p.background(40, seed=11), background=bg), bg


@pytest.mark.slow
def test_handover_template_comes_from_the_plugin(uav):
    policy, exp, bg = uav
    assert "xairl_uav_handover" in str(prompts.load("handover").path)
    n = xairl.narrate(exp, 0, template="handover", policy=policy, background=bg)
    assert n.verified and "BS " in n.text and n.confidence > 0.5
    assert "RSRP was" in n.text  # the plugin's comparison of candidate vs serving RSRP


def test_handover_facts():
    state = [0, 0, 100, 0, 7, -70, -66, -80, -90, -12, -8, -20, -25]
    f = handover_facts(state, 1, 0)
    assert isinstance(f, xairl.facts.DomainFacts)
    assert f.extras == {
        "decision": "hand over",
        "serving_bs": 7,
        "target_candidate": 1,
        "compared_candidate": 1,
        "runner_up_candidate": 0,
        "buffer_fill": 0.0,
        "buffer_trend": "",
        "a3_decisions": 1,
        "chm": "start its time-to-trigger",
    }
    assert f.comparisons == (
        xairl.facts.Comparison("the strongest neighbour's RSRP was 4.0 dB above the serving BS's RSRP", 4.0, "dB"),
    )
    assert (
        handover_facts(state, 0, 2)
        .comparisons[0]
        .text.startswith("the second strongest neighbour's RSRP was 10.0 dB below")
    )


def test_handover_facts_with_history():
    """Given the flight's earlier states: how long the strongest neighbour has met A3, what CHM would do, and the
    buffer's trend."""
    now = np.array([0, 0, 100, 5e5, 7, -70, -66, -80, -90, -12, -8, -20, -23], dtype=float)
    weak = now.copy()
    weak[6] = -69  # the neighbour only 1 dB above: A3 (2 dB) not met
    emptier = now.copy()
    emptier[3] = 2e5
    f = handover_facts(now, 0, 1, history=np.array([weak, now, emptier]))
    assert f.extras["a3_decisions"] == 3 and f.extras["chm"] == "hand over to candidate 1"
    assert f.extras["buffer_fill"] == 25.0 and f.extras["buffer_trend"] == "rising"
    assert f.comparisons[1] == xairl.facts.Comparison(
        "the strongest neighbour has been more than 2 dB above the serving BS for 3 consecutive decisions",
        3,
        "consecutive",
    )
    assert handover_facts(now, 0, 1, history=np.array([now, weak])).extras["chm"] == "start its time-to-trigger"
    assert handover_facts(weak, 0, 1).extras["chm"] == "stay"


def test_a3_sentence_verifies_when_the_compared_candidate_is_not_the_strongest_neighbour(uav):
    """The A3 sentence cites the rule's 2 dB offset while the first comparison is about another candidate (a real
    state where the DQN stayed with candidate 3 as runner-up and candidate 1 had met A3 for two decisions)."""
    policy, _, bg = uav
    state = np.array(
        [61.9, -505.2, 20.0, 0.0, 6.0, -82.0, -79.0, -81.0, -81.0, -16.0, -14.0, -16.0, -12.0], dtype=np.float32
    )
    exp = xairl.explain(policy, state[None], background=bg)
    facts = handover_facts(state, 0, 3, history=state[None])  # with the state itself: two decisions
    assert facts.extras["chm"] == "hand over to candidate 1"
    text = (
        "The third strongest neighbour's RSRP was {} dB above the serving BS's RSRP; the strongest neighbour has "
        "been more than {} dB above the serving BS for 2 consecutive decisions, so the conventional A3 rule (CHM) "
        "would hand over to candidate 1."
    )
    assert xairl.verify(text.format("1.0", "2"), exp, 0, policy, facts=facts).accurate  # ('more than', unread)
    assert not xairl.verify(text.format("1.0", "5"), exp, 0, policy, facts=facts).ok  # a wrong offset is caught
    assert not xairl.verify(text.format("4.0", "2"), exp, 0, policy, facts=facts).ok  # and a wrong gap


@pytest.mark.slow
def test_mutation_corpus_on_the_reference_policy(uav):
    policy, exp, _ = uav
    # 6 states keep every kind of mutation (the full corpus of 7,641: benchmarks/bench_narration.py --verifier-only)
    cases = corpus(
        exp, policy, ("explain_action", "explain_score", "why_not", "handover"), range(6), label_words=LABEL_WORDS
    )
    # a mutant is caught when it is not verified; an accurate phrasing must not be contradicted (outside prose: the
    # rule-table reader may leave a phrasing it does not read partly checked)
    wrongly = [
        (c.kind, c.text)
        for c in cases
        if (lambda r: r.accurate if c.should_pass else not r.ok)(xairl.verify(c.text, exp, c.index, policy)) is False
    ]
    kinds = collections.Counter(c.kind for c in cases)
    assert len(cases) > 400 and len(kinds) >= 8
    assert not wrongly, wrongly[:3]


@pytest.mark.slow
def test_a_flight_at_a_glance(uav, tmp_path):
    """A simulated flight: the DQN's and CHM's handovers on the same flight, a timeline figure, and a summary whose
    every number is verified; a wrong count is caught."""
    from xairl_uav_handover.flight import narrate_flight, simulated_flight, summary, timeline_figure
    from xairl_uav_handover.policy import load_checkpoint

    policy, _, bg = uav
    tl = simulated_flight(load_checkpoint(), seed=3)
    assert len(tl.states) == 600 and tl.duration_s == pytest.approx(119.8) and len(tl.chm_times) >= 1
    exp = xairl.explain(policy, tl.states, background=bg)
    text, check = narrate_flight(tl, exp, policy)
    assert check.accurate and check.coverage >= 0.55  # ('its first reason was most often A': no rule reads it)
    assert "of the mean |contribution| over 600 states" in check.account  # what its features carry, and leave out
    assert f"handed over {int(tl.dqn_handover.sum())} time" in text and f"handed over {len(tl.chm_times)} time" in text
    _, facts = summary(tl, exp, policy)
    wrong = text.replace(f"at {int((~tl.dqn_handover).sum())} of", "at 17 of")
    assert wrong != text and not xairl.verify(wrong, exp, None, policy, facts=facts).ok
    png = timeline_figure(tl, exp, policy, tmp_path / "flight.png")
    assert png.stat().st_size > 20_000


@pytest.mark.slow
def test_narratives_lead_with_reasons_for_the_decision(uav):
    """Issue 14's targets on 40 states: the first reason named favours the decision (or is a concession), no
    identifier is a cause, and every narrative is verified with full coverage."""
    policy, exp, bg = uav
    margin = exp.margin()
    for i in range(len(exp.values)):
        n = xairl.narrate(exp, i, template="handover", policy=policy, robustness=False)
        assert n.verified and all(status == "verified" for _, status in n.sentences), n.text
        assert not re.search(r"\bid\b", n.text)
        d = decision_facts(exp, i, policy)
        if d.reasons:
            assert d.reasons[0].label in n.text.split(". ")[1] and d.reasons[0].contribution > 0
        if d.concession:
            assert f"despite {d.concession.label}" in n.text and margin[i].min() < 0


def _claim(result, text):
    return next(c for s in result.sentences for c in s.claims if c.kind == "number" and c.text == text)


def test_wrong_numbers_that_equal_another_fact_stay_contradicted(uav):
    """Mutations the corpus found with the priced-reward checkpoint: an identifier's wrong value that equals its
    contribution, a push copied from the clause before, a score that equals another action's score."""
    policy, exp, _ = uav
    j, r1, r2 = (exp.feature_names.index(f) for f in ("serving_bs", "rsrp_1", "rsrp_2"))
    checked = 0
    for i in range(exp.values.shape[0]):
        chosen, runner = int(exp.chosen[i]), int(exp.runner_up[i])
        contrib = exp.values[i, j, chosen]
        if abs(contrib) >= 1 and round(float(contrib)) != round(float(exp.states[i, j])):
            text = f"The decision was taken with the serving BS's id at {contrib:.0f}."
            assert _claim(xairl.verify(text, exp, i, policy), f"{contrib:.0f}").status == "contradicted", text
            checked += 1
        margin = exp.values[i, :, chosen] - exp.values[i, :, runner]
        if chosen != runner and abs(margin[r1] - margin[r2]) > 1:
            c = f"{margin[r1]:+.1f}"
            text = (
                f"The strongest neighbour's RSRP pushed toward {exp.action_names[chosen]} over "
                f"{exp.action_names[runner]} by {c}; the second strongest neighbour's RSRP pushed toward "
                f"{exp.action_names[chosen]} over {exp.action_names[runner]} by {c}."
            )
            claims = [
                cl
                for s in xairl.verify(text, exp, i, policy).sentences
                for cl in s.claims
                if cl.kind == "number" and cl.text == c
            ]
            # the second is contradicted where grammar binds it; where only a deep 'by' does, it is unchecked (the
            # rule-table reader does not contradict on that), so the text is never verified
            assert claims[0].status == "verified" and claims[1].status in ("contradicted", "unchecked"), claims
            assert xairl.verify(text, exp, i, policy).status != "verified"
            checked += 1
        other = float(exp.outputs[i, runner])
        if chosen != runner and abs(other - float(exp.outputs[i, chosen])) > 1:
            text = f"The policy chose {exp.action_names[chosen]}, the only available action (score {other:.1f})."
            assert _claim(xairl.verify(text, exp, i, policy), f"{other:.1f}").status == "contradicted", text
            checked += 1
    assert checked >= 10


@pytest.mark.slow
def test_the_buffer_is_said_once(uav):
    """Issue 64: 'came from the uplink buffer (0 % full), by +1.85 ... The uplink buffer was 0 % full.' said it twice."""
    policy, exp, _ = uav
    named = 0
    for i in range(len(exp.values)):
        facts = decision_facts(exp, i, policy)
        said = [f.name for f in facts.reasons] + ([facts.concession.name] if facts.concession else [])
        text = xairl.narrate(exp, i, template="handover", policy=policy, robustness=False).text
        named += "buffer_queue_size" in said
        assert text.count("uplink buffer") == 1 if "buffer_queue_size" in said else "uplink buffer was" in text
    assert named  # the seed has decisions where the buffer is a reason
