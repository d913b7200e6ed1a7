"""Narrating the reference DQN: the handover template, domain comparisons, and the verifier's mutation corpus."""
import collections

import pytest

import xairl
from xairl import prompts
from xairl.testing import corpus
from xairl_uav_handover.features import LABEL_WORDS, handover_facts
from xairl_uav_handover.policy import uav_policy


@pytest.fixture(scope="module")
def uav():
    p = uav_policy()
    bg = p.background(100)
    return p, xairl.explain(p, p.background(40, seed=11), background=bg), bg


def test_handover_template_comes_from_the_plugin(uav):
    policy, exp, bg = uav
    assert "xairl_uav_handover" in str(prompts.load("handover").path)
    n = xairl.narrate(exp, 0, template="handover", policy=policy, background=bg)
    assert n.verified and "BS " in n.text and n.confidence > 0.5
    assert "RSRP was" in n.text  # the plugin's comparison of candidate vs serving RSRP


def test_handover_facts():
    state = [0, 0, 100, 0, 7, -70, -66, -80, -90, -12, -8, -20, -25]
    f = handover_facts(state, 1, 0)
    assert isinstance(f, xairl.DomainFacts)
    assert f.extras == {"decision": "hand over", "serving_bs": 7, "target_candidate": 1, "compared_candidate": 1}
    assert f.comparisons == (xairl.Comparison("the strongest neighbour's RSRP was 4.0 dB above the serving BS's "
                                              "RSRP", 4.0, "dB"),)
    assert handover_facts(state, 0, 2).comparisons[0].text.startswith("the second strongest neighbour's RSRP "
                                                                      "was 10.0 dB below")


def test_mutation_corpus_on_the_reference_policy(uav):
    policy, exp, _ = uav
    cases = corpus(exp, policy, ("explain_action", "why_not", "handover"), range(40), label_words=LABEL_WORDS)
    wrongly = [(c.kind, c.text) for c in cases if xairl.verify(c.text, exp, c.index, policy).ok != c.should_pass]
    kinds = collections.Counter(c.kind for c in cases)
    assert len(cases) > 2500 and len(kinds) >= 8
    assert not wrongly, wrongly[:3]
