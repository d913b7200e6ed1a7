"""Counterfactuals said in words (issue 56): the fact, its sentence in the built-in templates, and the check that
re-runs the policy on the stated change. Every correct rendering is verified; every mutation (a threshold on the wrong
side of the line, by a margin or one written digit across, another action, another feature, a wrong 'it was' value, the
other direction word, a wrong margin, a change left out) is contradicted; on a linear policy whose lines are known,
the toy MLP and the UAV DQN. The counterfactuals are found here by brute force (a dense grid over each feature's
range, refined on a second grid), independent of the search."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import torch

import xairl
from tests.counterfactual_cases import CAP, answer, at, caught_by_the_rerun, corpus, linear_policy, one_change, said
from xairl import FeatureInfo, InputError, Policy
from xairl.counterfactual_facts import counterfactual_fact
from xairl.counterfactuals import Counterfactuals
from xairl.toy import toy_policy


@pytest.fixture(scope="module")
def linear():
    p = linear_policy()
    states = np.array(
        [[160, -90], [120, -95], [180, -85], [30, -70], [20, -110], [100, -100], [60, -80], [190, -118]],
        dtype=np.float32,
    )
    bg = np.random.default_rng(0).uniform([0, -120], [CAP, -60], size=(64, 2)).astype(np.float32)
    return p, states, xairl.explain(p, states, background=bg, method="exact"), bg


def test_the_lines_found_are_the_known_ones(linear):
    """The brute force finds the analytic line: load at 20 x (-0.2 signal - 16), signal at -(0.05 load + 16) / 0.2."""
    p, states, _, _ = linear
    for (j, inside, after), (load, signal) in zip(one_change(p, states, {0: (0, CAP), 1: (-140, -40)}), states):
        line = 20 * (-0.2 * signal - 16) if j == 0 else -(0.05 * load + 16) / 0.2
        assert min(inside, after) <= line + 1e-3 and line - 1e-3 <= max(inside, after)


def test_values_are_written_away_from_the_line(linear):
    """A line at 20 % full is said 'below 19.9 % full' for a search that stopped at 19.9995 %, and that is the
    value re-run; a template that rounds it back to 20 % states a tie, which keeps stay: contradicted."""
    p, states, exp, _ = linear
    fact = counterfactual_fact(exp, 0, p, answer(p, states, 0, {0: 40 - 1e-3}))
    c = fact.changes[0]
    assert (c.direction, c.after_text, c.value_text, fact.action) == ("below", "19.9 % full", "80 % full", "go")
    assert c.after == pytest.approx(39.8) and fact.margin == pytest.approx(0.01, abs=1e-4)
    text, status, _ = said(exp, 0, p, fact)
    assert status == "verified" and "Had the queue been below 19.9 % full (it was 80 % full)" in text
    rounded = replace(fact, changes=(replace(c, after_text=f"{round(c.after_fill):.0f} % full"),))
    text, status, _ = said(exp, 0, p, rounded)
    assert "below 20 % full" in text and status == "contradicted"
    across = replace(fact, changes=(at(p, c, 41.0),))  # docs/customising-prompts.md's example of the rule
    text, status, _ = said(exp, 0, p, across, alone=True)
    assert text == (
        "Had the queue been below 20.5 % full (it was 80 % full), the policy would have chosen go (margin 0.01)."
    )
    assert status == "contradicted"


@pytest.mark.slow
def test_corpus_on_the_linear_policy(linear):
    p, states, exp, _ = linear
    found = one_change(p, states, {0: (0, CAP), 1: (-140, -40)})
    facts = {i: counterfactual_fact(exp, i, p, answer(p, states, i, {j: a})) for i, (j, _, a) in enumerate(found)}
    lines = {i: (inside,) for i, (_, inside, _) in enumerate(found)}
    # two changes together: neither alone flips state 0 (stay 8 vs go 2), both do (stay 5 vs go 5.2)
    two = counterfactual_fact(exp, 0, p, answer(p, states, 0, {0: 100.0, 1: -106.0}))
    assert [c.after_text for c in two.changes] == ["50 % full", "-106 dBm"] and two.action == "go"
    facts[len(states)] = two
    exp2 = xairl.explain(p, np.vstack([states, states[:1]]), background=linear[3], method="exact")
    n_ok, counts, rerun = corpus(p, exp2, np.vstack([states, states[:1]]), facts, lines)
    caught_by_the_rerun("linear", n_ok, counts, rerun)
    assert n_ok == len(states) + 1 and counts["a change left out"] == 1
    assert counts["threshold just across"] == len(states) and counts["threshold by a margin"] == len(states)
    assert sum(counts.values()) >= 50


@pytest.mark.slow
def test_corpus_on_the_toy_policy():
    p = toy_policy()
    bg, states = p.background(64), p.background(12, seed=5)
    exp = xairl.explain(p, states, background=bg, method="exact")
    found = one_change(p, states, {j: (-3.0, 3.0) for j in range(len(p.feature_names))})
    facts, lines = {}, {}
    for i, hit in enumerate(found):
        if hit is not None:
            facts[i] = counterfactual_fact(exp, i, p, answer(p, states, i, {hit[0]: hit[2]}))
            lines[i] = (hit[1],)
    assert len(facts) >= 8 and all(f is not None for f in facts.values())
    n_ok, counts, rerun = corpus(p, exp, states, facts, lines)
    caught_by_the_rerun("toy", n_ok, counts, rerun)
    assert sum(counts.values()) >= 100 and rerun["wrong feature and its value"] >= 10


@pytest.mark.slow
def test_corpus_on_the_uav_dqn():
    """The handover template's sentence on the real DQN: 'the DQN would have chosen to hand over to candidate 2'."""
    uav = pytest.importorskip("xairl_uav_handover.policy")
    p = uav.uav_policy()
    bg, states = p.background(64), p.background(24, seed=11)
    exp = xairl.explain(p, states, background=bg)
    cap = p.features["buffer_queue_size"].capacity  # (its real capacity, 15.2e6 bits: every fill it can have)
    cols = {"buffer_queue_size": (0.0, cap), **{f"rsrp_{k}": (-140.0, -44.0) for k in range(4)}}
    found = one_change(p, states, {p.feature_names.index(f): r for f, r in cols.items()})
    facts, lines = {}, {}
    for i, hit in enumerate(found):
        if hit is not None and len(facts) < 6:
            facts[i] = counterfactual_fact(exp, i, p, answer(p, states, i, {hit[0]: hit[2]}))
            lines[i] = (hit[1],)
    facts = {i: f for i, f in facts.items() if f is not None}
    assert len(facts) >= 4
    text = said(exp, next(iter(facts)), p, next(iter(facts.values())), "handover")[0]
    assert "the DQN would have chosen to " in text
    n_ok, counts, rerun = corpus(p, exp, states, facts, lines, "handover")
    caught_by_the_rerun("uav", n_ok, counts, rerun)
    assert sum(counts.values()) >= 40 and rerun["wrong feature and its value"] >= 5


def test_without_the_policy_the_sentence_is_unchecked(linear):
    p, states, exp, _ = linear
    fact = counterfactual_fact(exp, 0, p, answer(p, states, 0, {0: 39.0}))
    _, status, v = said(exp, 0, p, fact, check_policy=None)
    assert status == "unchecked"
    assert all(c.status == "unchecked" for c in v.claims if c.rule == "tracked.counterfactual")
    wrong = replace(fact, action="stay")
    assert said(exp, 0, p, wrong, check_policy=None)[1] == "unchecked"  # never verified, and not checked either


def test_narrate_with_a_counterfactual(linear):
    p, states, exp, bg = linear
    n = xairl.narrate(exp, 0, policy=p, background=bg, counterfactual=answer(p, states, 0, {0: 39.0}), robustness=False)
    assert n.verified and n.sentences[-1] == (
        "Had the queue been below 19.5 % full (it was 80 % full), the policy would have chosen go (margin 0.05).",
        "verified",
    )
    assert "Had " not in xairl.narrate(exp, 0, policy=p, robustness=False).text  # not asked: not said
    none = Counterfactuals(0, "stay", "go", (), "no change of at most 2 features within the bounds flips it")
    n = xairl.narrate(exp, 0, policy=p, counterfactual=none, robustness=False)
    assert n.text == xairl.narrate(exp, 0, policy=p, robustness=False).text  # a search's miss: no sentence
    with pytest.raises(InputError, match="needs the policy"):
        xairl.narrate(exp, 0, counterfactual=True, robustness=False)
    with pytest.raises(InputError, match="of state 0, not 1"):
        xairl.narrate(exp, 1, policy=p, counterfactual=none, robustness=False)


def test_the_action_mask_is_honoured(linear):
    """go is unavailable below -130 dBm: 'below -135 dBm, go' holds for the bare network, not for the policy."""
    p, states, exp, _ = linear
    masked = replace(p, action_mask=lambda x: np.stack([np.ones(len(x), bool), x[:, 1] >= -130], axis=1))
    assert counterfactual_fact(exp, 0, masked, answer(p, states, 0, {1: -135.0})) is None  # refused, not said
    fact = counterfactual_fact(exp, 0, p, answer(p, states, 0, {1: -135.0}))
    assert said(exp, 0, p, fact, alone=True)[1] == "verified"
    text, status, _ = said(exp, 0, masked, fact, alone=True)
    assert "below -135 dBm (it was -90 dBm), the policy would have chosen go" in text and status == "contradicted"


def test_a_category_is_said_by_its_label():
    """weather is a category: 'Had the weather been storm (it was calm)'; 'windy' does not flip it."""
    lin = torch.nn.Linear(2, 2)
    with torch.no_grad():
        lin.weight.copy_(torch.tensor([[0.05, 0.0], [0.0, 2.0]]))
        lin.bias.zero_()
    info = {"load": FeatureInfo("kbit", "the queue"), "weather": FeatureInfo(description="the weather", categories=("calm", "windy", "storm"))}  # fmt: skip
    p = Policy(lin, ["load", "weather"], ["stay", "go"], features=info)
    states = np.array([[60.0, 0.0], [20.0, 1.0]], dtype=np.float32)
    exp = xairl.explain(p, states, background=np.array([[0, 0], [100, 2], [50, 1]], dtype=np.float32), method="exact")
    fact = counterfactual_fact(exp, 0, p, answer(p, states, 0, {1: 2.0}))
    text, status, _ = said(exp, 0, p, fact, alone=True)
    assert (text, status) == (
        "Had the weather been storm (it was calm), the policy would have chosen go (margin 1).",
        "verified",
    )
    c = fact.changes[0]
    for wrong in (replace(c, after=1.0, after_text="windy"), replace(c, value_text="windy")):
        assert said(exp, 0, p, replace(fact, changes=(wrong,)), alone=True)[1] == "contradicted"


def test_a_batch_answer_gives_each_decision_its_own(linear):
    p, states, exp, _ = linear
    batch = (answer(p, states, 0, {0: 39.0}), answer(p, states, 1, {0: 20.0}))
    n = xairl.narrate(exp, 1, policy=p, counterfactual=batch, robustness=False)
    assert n.sentences[-1][1] == "verified" and "(it was 60 % full)" in n.sentences[-1][0]
    with pytest.raises(InputError, match="no answer for state 2"):
        xairl.narrate(exp, 2, policy=p, counterfactual=batch, robustness=False)


def test_a_capacity_end_has_no_direction_word_and_no_change_is_not_said(linear):
    """A queue filled to its capacity is 'been 100 % full', never 'above 100 % full'; a change the digits written do
    not show ('10 % full (it was 10 % full)') is left out of the sentence and of the re-run."""
    p, states, exp, _ = linear
    fact = counterfactual_fact(exp, 4, p, answer(p, states, 4, {0: CAP}))
    assert said(exp, 4, p, fact, alone=True)[:2] == (
        "Had the queue been 100 % full (it was 10 % full), the policy would have chosen stay (margin 4).",
        "verified",
    )
    assert fact.changes[0].direction == "" and fact.changes[0].after_text == "100 % full"
    fact = counterfactual_fact(exp, 4, p, answer(p, states, 4, {0: 20.0, 1: -60.0}))
    assert [c.name for c in fact.changes] == ["signal"] and fact.changes[0].after_text == "-60 dBm"
    assert said(exp, 4, p, fact, alone=True)[1] == "verified"


def test_the_words_name_the_action_the_policy_takes_as_written():
    """A search's answer whose action is not the one the policy takes with the values as written (a line that bends
    toward a third action) is said with the action the policy does take there."""
    p = toy_policy()
    states = p.background(6, seed=5)
    exp = xairl.explain(p, states, background=p.background(32), method="exact")
    i, (j, _, after) = next((i, h) for i, h in enumerate(one_change(p, states, {0: (-3.0, 3.0)})) if h is not None)
    right = answer(p, states, i, {j: after})
    third = next(a for a in p.action_names if a not in (right.chosen, right.found[0].action))
    wrong = replace(right, found=(replace(right.found[0], action=third),))
    fact = counterfactual_fact(exp, i, p, wrong)
    assert fact.action == right.found[0].action != third and said(exp, i, p, fact, alone=True)[1] == "verified"


@pytest.mark.slow
def test_narrate_searches_when_asked(linear):
    """counterfactual=True runs the search (xairl.counterfactual) and says its answer; every said one verified."""
    p, states, exp, bg = linear
    for i in range(len(states)):
        n = xairl.narrate(exp, i, policy=p, background=bg, counterfactual=True, robustness=False)
        assert n.verified and n.sentences[-1][1] == "verified", n.text
    toy = toy_policy()
    bg, states = toy.background(64), toy.background(8, seed=2)
    exp = xairl.explain(toy, states, background=bg)
    for i in range(len(states)):
        n = xairl.narrate(exp, i, policy=toy, background=bg, counterfactual=True, robustness=False)
        assert n.verified and n.sentences[-1][1] == "verified" and n.sentences[-1][0].startswith("Had "), n.text
