"""Decision narration: reasons for the margin first with the strongest opposing one as a concession, feature kinds
(identifier, group, capacity, thresholds), level words, coverage in the confidence, evidence."""

from dataclasses import replace

import numpy as np
import pytest
import torch

import xairl
from xairl.errors import InputError
from xairl.explanations.evidence import card_html, evidence
from xairl.facts import decision_facts, value_level


def _policy(**features):
    """Q(a) - Q(b) = 2*speed - 3*load + 0.5*(x + y) + 0*cell; load has a capacity, cell is an identifier."""
    net = torch.nn.Linear(5, 2)
    with torch.no_grad():
        net.weight.copy_(torch.tensor([[2.0, -3.0, 0.5, 0.5, 1.0], [0.0, 0.0, 0.0, 0.0, 1.0]]))
        net.bias.zero_()
    info = {
        "speed": xairl.FeatureInfo("m/s", "the speed", thresholds=(1.0, 5.0)),
        "load": xairl.FeatureInfo("bit", "the queue", "lightly loaded", "heavily loaded", capacity=100.0),
        "cell": xairl.FeatureInfo("", "the cell id", kind="identifier"),
        "position": xairl.FeatureInfo("", "the position", kind="group"),
    } | features
    return xairl.Policy(
        net, ["speed", "load", "x", "y", "cell"], ["go", "wait"], features=info, groups={"position": ("x", "y")}
    )


@pytest.fixture(scope="module")
def case():
    p = _policy()
    bg = np.zeros((20, 5))
    bg[:, 4] = np.arange(20)  # cell ids vary; everything else is 0 in the background
    # go wins by 2*3 - 3*0.5 + 0.5*(1 + 1) = 5.5: speed for it (+6), load against it (-1.5), position for it (+1)
    exp = xairl.explain(p, [[3.0, 0.5, 1.0, 1.0, 7.0]], background=bg, method="exact")
    return p, exp


def test_reasons_favour_the_decision_and_the_concession_opposes_it(case):
    p, exp = case
    d = decision_facts(exp, 0, p)
    assert d.action == "go" and d.runner_up == "wait"
    assert [f.name for f in d.reasons] == ["speed", "position"]  # the group is one reason
    assert d.reasons[1].contribution == pytest.approx(1.0) and d.reasons[1].value_text == ""
    assert d.concession.name == "load" and d.concession.contribution == pytest.approx(-1.5)
    assert [f.name for f in d.identifiers] == ["cell"] and d.identifiers[0].value_text == "7"
    assert "cell" not in [f.name for f in d.top + d.margin_top + d.reasons]
    text = xairl.narrate(exp, 0, policy=p, robustness=False).text
    assert text.index("the speed") < text.index("despite the queue")
    assert "the cell id at 7" in text and "pushed" not in text.split("the cell id")[1][:20]


def test_level_words_come_from_capacity_and_thresholds_not_degenerate_quartiles(case):
    p, exp = case
    load = p.features["load"]
    assert value_level(50.0, load, None) == ("typical", "moderate")
    assert value_level(80.0, load, None)[1] == "heavily loaded" and value_level(10.0, load, None)[1] == "lightly loaded"
    assert value_level(80.0, load, (0.0, 100.0))[1] == "heavily loaded"  # the range wins over quartiles
    assert value_level(8.6, xairl.FeatureInfo(), (0.0, 0.0)) == ("unknown", "")  # degenerate background: no word
    assert value_level(8.6, xairl.FeatureInfo(), (0.0, 5.0))[0] == "high"
    f = {x.name: x for x in decision_facts(exp, 0, p).top}
    assert f["load"].fill == pytest.approx(0.5) and f["load"].value_text == "0.50 % full"
    assert f["speed"].level_text == "moderate"


def test_the_verifier_checks_each_view_against_its_own_quantity(case):
    p, exp = case
    ok = "The policy chose go over wait. The biggest push toward go over wait came from the speed, by +6.00."
    assert xairl.verify(ok, exp, 0, p).accurate  # (outside prose: nothing false, whatever is left unread)
    # the speed's contribution to go's own score is also +6 here, so use the position (+1 to the margin)
    assert xairl.verify("The position favoured go over wait by +1.00.", exp, 0, p).accurate
    assert not xairl.verify("The position favoured go over wait by +3.00.", exp, 0, p).ok
    assert not xairl.verify("The biggest push toward go over wait came from the queue.", exp, 0, p).ok
    assert xairl.verify("The queue was 0.5 % full.", exp, 0, p).ok
    assert not xairl.verify("The queue was 50 % full.", exp, 0, p).ok


def test_bad_feature_kinds_are_refused():
    with pytest.raises(InputError, match="kind 'label' is unknown"):
        xairl.FeatureInfo(kind="label")
    with pytest.raises(InputError, match="capacity must be a positive number"):
        xairl.FeatureInfo(capacity=0)
    with pytest.raises(InputError, match="thresholds must be"):
        xairl.FeatureInfo(thresholds=(5, 1))
    with pytest.raises(InputError, match="'place' is not in groups"):
        _policy(place=xairl.FeatureInfo(kind="group"))
    assert xairl.FeatureInfo(categories=("a", "b")).kind == "categorical"


def test_the_chosen_score_view_stays_available(case):
    p, exp = case
    n = xairl.narrate(exp, 0, policy=p, template="explain_score", robustness=False)
    assert n.verified and "go's score" in n.text


def test_history_reaches_a_hook_that_takes_it(case):
    p, exp = case
    seen = []

    def hook(state, chosen, runner_up, history=None):
        seen.append(None if history is None else history.shape)
        steps = 0 if history is None else len(history)
        return xairl.facts.DomainFacts(
            comparisons=(xairl.facts.Comparison(f"it has gone for {steps} steps", steps, "steps"),)
        )

    hooked = replace(p, facts_hook=hook)  # a Policy is frozen: a changed one is a new one
    n = xairl.narrate(exp, 0, policy=hooked, robustness=False, history=np.zeros((4, 5)))
    assert seen[0] == (4, 5) and "gone for 4 steps" in n.text and n.verified
    plain = replace(p, facts_hook=lambda state, chosen, runner_up: xairl.facts.DomainFacts())  # called without history
    assert xairl.narrate(exp, 0, policy=plain, robustness=False, history=np.zeros((4, 5))).verified


def test_coverage_is_the_share_of_claims_checked_and_evidence_marks_sentences(case):
    """The confidence's coverage is the verifier's: the share of the text's claims checked. A sentence that states
    nothing neither counts nor blocks; a number left unchecked makes the text partly checked, with no confidence."""
    from xairl.narrators.confidence import confidence

    p, exp = case
    n = xairl.narrate(exp, 0, policy=p, robustness=False)
    assert n.components["coverage"] == n.coverage and (n.status == "verified" or n.confidence == 0.0)

    def check(more: str):
        v = xairl.verify(n.text + more, exp, 0, p, provenance=n.provenance)
        return v, *confidence(exp, 0, v.ok, xairl.NarrationOptions(policy=p), coverage=v.coverage)

    v, same, comp = check(" It felt right. Nobody objected.")
    assert [s.status for s in v.sentences][-2:] == ["none", "none"]
    assert (v.status, v.coverage, comp["coverage"]) == (n.status, n.coverage, n.coverage) and same == n.confidence
    v, lower, comp = check(" The rest came to 731.")  # a number that is no fact of it
    assert v.status == "partly checked" and lower == 0.0 and comp["coverage"] == v.coverage < n.coverage
    assert [c.text for c in v.claims if c.status == "unchecked"][-1:] == ["731"]
    ev = evidence(exp, n)
    assert ev["target"] == "margin of go over wait" and ev["features"][0]["name"] == "speed"
    assert ev["output"] == pytest.approx(5.5)
    card = card_html(n.text, ev)
    assert "wf-bar up" in card and "wf-bar down" in card and card.count("class='s verified'") == len(n.sentences)


def test_declared_groups_are_narrated_as_one_without_a_group_description():
    """Issue 64: ``Policy(groups=)`` alone changes the words: the position is one reason, not x and y. A group whose
    members are each described keeps their words (a figure's group); one sharing a member with a group before it is
    not narrated."""
    p = _policy()
    plain = xairl.Policy(p.module, p.feature_names, p.action_names, groups={"position": ("x", "y"), "xs": ("x",)})
    assert plain.reason_groups == {"position": ("x", "y")}
    figures = replace(
        plain, groups={"motion": ("speed", "load")}, features={f: p.features[f] for f in ("speed", "load")}
    )
    assert figures.reason_groups == {}  # each member has words of its own: they keep them
    exp = xairl.explain(plain, [[3.0, 0.5, 1.0, 1.0, 7.0]], background=np.zeros((20, 5)), method="exact")
    d = decision_facts(exp, 0, plain)
    assert [f.name for f in d.reasons] == ["speed", "position"]  # x and y are one reason: 0.5 * (1 + 1)
    assert d.reasons[1].contribution == pytest.approx(1.0)
    n = xairl.narrate(exp, 0, policy=plain, robustness=False)
    assert n.verified and "position" in n.text.lower() and "nan" not in n.text, n.text
    assert not {"x", "y"} & set(n.text.replace(".", " ").replace(",", " ").split()), n.text
    assert xairl.verify("The position favoured action_0 over action_1 by +1.00.", exp, 0, plain).accurate
    assert not xairl.verify("The position favoured action_0 over action_1 by +3.00.", exp, 0, plain).ok
