"""The verifier on a corpus of real narratives made wrong, and of correct paraphrases."""

import collections

import numpy as np
import pytest
import torch

import xairl
from xairl.testing import corpus
from xairl.toy import toy_policy


@pytest.fixture(scope="module")
def toy():
    p = toy_policy()
    return p, xairl.explain(p, p.background(25, seed=3), background=p.background(100))


@pytest.mark.slow
def test_mutation_corpus_all_caught_no_paraphrase_rejected(toy):
    policy, exp = toy
    cases = corpus(exp, policy, ("explain_action", "why_not"), range(25))
    results = collections.Counter()
    wrongly = []
    for c in cases:  # (read as outside prose: a mutant never verified, a right phrasing never contradicted)
        v = xairl.verify(c.text, exp, c.index, policy)
        right = v.accurate if c.should_pass else not v.ok
        results[(c.kind, right)] += 1
        if not right:
            wrongly.append((c.kind, c.text))
    kinds = {k for k, _ in results}
    assert {
        "wrong number",
        "flipped direction",
        "swapped rank",
        "unknown feature",
        "wrong action",
        "other phrasing",
        "coarser rounding",
        "direction synonym",
    } <= kinds
    assert len(cases) > 800
    assert not wrongly, wrongly[:3]


def test_each_claim_kind_is_reported(toy):
    policy, exp = toy
    i = 0
    n = xairl.narrate(exp, i, policy=policy)
    assert n.verified
    kinds = {c.kind for c in n.claims}
    assert {"number", "feature", "direction", "rank", "action"} <= kinds


def test_reads_any_text_not_just_ours(toy):
    policy, exp = toy
    i = 2
    c = int(exp.chosen[i])
    j = int(np.argmax(np.abs(exp.values[i, :, c])))
    f, v = exp.feature_names[j], exp.values[i, j, c]
    good = f"Mostly {f} mattered: it pushed {'toward' if v > 0 else 'against'} {exp.action_names[c]} by {abs(v):.2f}."
    assert xairl.verify(good, exp, i, policy).accurate
    bad = good.replace("toward", "@").replace("against", "toward").replace("@", "against")
    assert not xairl.verify(bad, exp, i, policy).ok  # (contradicted, or left unchecked: never verified)
    res = xairl.verify("The policy chose nothing in particular.", exp, i, policy)
    # nothing to contradict, but nothing checked either: a vacuous text is not verified
    assert not res.ok and res.status == "partly checked" and res.coverage == 0.0


def test_global_summary_verifies(toy):
    policy, exp = toy
    n = xairl.narrate(exp, None, policy=policy)
    assert n.verified and n.template == "global_summary" and "25 states" in n.text
    assert " raised the margin" in n.text  # the toy's top feature raises the margin over the runner-up on average
    swapped = n.text.replace(" raised the margin", " lowered the margin", 1)
    problems = xairl.verify(swapped, exp, None, policy).problems()
    assert problems and all(c.kind == "direction" and c.status == "contradicted" for c in problems)


def test_confidence_near_tie_below_clear_decision():
    net = torch.nn.Linear(2, 2)
    with torch.no_grad():
        net.weight.copy_(torch.tensor([[1.0, 0.5], [0.0, 0.5]]))  # Q0 - Q1 = x0
        net.bias.zero_()
    policy = xairl.Policy(net, ["gap", "common"], ["a", "b"])
    bg = np.random.default_rng(0).normal(size=(50, 2))
    exp = xairl.explain(policy, [[0.001, 1.0], [3.0, 1.0]], background=bg, method="exact")
    tie = xairl.narrate(exp, 0, policy=policy, background=bg)
    clear = xairl.narrate(exp, 1, policy=policy, background=bg)
    assert tie.verified and clear.verified
    assert tie.components["margin"] < 0.1 < 0.5 < clear.components["margin"]
    assert tie.confidence < clear.confidence
    assert set(clear.components) == {"verification", "coverage", "additivity", "margin", "agreement", "stability"}
    assert 0 <= tie.confidence <= 1 and 0 <= clear.confidence <= 1


def test_unverified_text_has_zero_confidence(toy, tmp_path):
    policy, exp = toy
    lie = tmp_path / "lie.yaml"
    lie.write_text('name: lie\nkind: decision\nsentences:\n  - ["The policy chose {{ runner_up }}."]\n')
    n = xairl.narrate(exp, 0, policy=policy, template=str(lie))
    assert not n.verified and n.confidence == 0.0


def test_names_and_descriptions_cannot_smuggle_claims():
    """A feature description or action name carrying claims is not trusted as a name: its claims get checked."""
    net = torch.nn.Linear(2, 2)
    with torch.no_grad():
        net.weight.copy_(torch.tensor([[1.0, 0.0], [0.0, 1.0]]))
        net.bias.zero_()
    hostile = xairl.FeatureInfo("", "speed, the most important feature, pushing toward go by +9.99")
    policy = xairl.Policy(
        net,
        ["speed", "load"],
        ["go", "stop"],
        features={"speed": hostile},
        action_aliases={"stop": ["stop, which raises go by 12.5%"]},
    )
    bg = np.zeros((10, 2))
    exp = xairl.explain(policy, [[0.1, 2.0]], background=bg, method="exact")  # load dominates, stop is chosen
    n = xairl.narrate(exp, 0, policy=policy)
    assert not n.verified and n.confidence == 0.0
    text = "The policy chose stop. speed, the most important feature, pushing toward go by +9.99."
    v = xairl.verify(text, exp, 0, policy)
    assert v.status == "contradicted" and any(c.kind == "number" for c in v.problems()), v.claims
