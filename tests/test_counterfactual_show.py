"""Where counterfactuals show (issue 56): the notebook card and repr, the CLI's lines (and its one-line errors), the
report's cards and its per-feature single-flip table, and the review page, each checked against the search's own
answer and a re-run of the policy."""

import json
import re

import numpy as np
import pytest

import xairl
from tests.conftest import one_line_error, run
from xairl.counterfactuals.show import summary
from xairl.explanations.display import counterfactual_text
from xairl.outputs.feedback import FeedbackStore
from xairl.outputs.report import ReportContent, ReportRequest, write_report
from xairl.outputs.report_counterfactuals import flip_rows
from xairl.outputs.review import page
from xairl.registry import plugins
from xairl.toy import toy_policy


@pytest.fixture(scope="module")
def uav():
    from xairl_uav_handover.policy import dqn_decision_states, load_checkpoint, uav_policy

    ckpt = load_checkpoint(None)
    policy = uav_policy(ckpt)
    return policy, dqn_decision_states(ckpt, 12, seed=1), policy.background(100, seed=7)


@pytest.mark.slow
def test_notebook_card_names_the_change_and_the_new_action(uav):
    policy, states, bg = uav
    found = xairl.counterfactual(policy, states, index=None, background=bg)
    hit = next(r for r in found if r.reachable)
    cf = hit.best
    again = policy.action_names[policy.act(cf.state[None])[0]]
    assert again == cf.action != hit.chosen  # what the card states is what the policy does
    card = hit._repr_html_()
    assert "What would have changed it" in card and cf.action in card
    for c in cf.changes:
        assert c.feature in card
    line = repr(hit)
    assert "\n" not in line and len(line) < 400 and cf.changes[0].feature in line and cf.action in line
    miss = next((r for r in found if not r.reachable), None)
    if miss is not None:
        assert "None found" in miss._repr_html_() and miss.reason in repr(miss)


@pytest.mark.slow
def test_summary_writes_values_as_the_narratives_do(uav):
    from xairl.outputs.report_counterfactuals import writer

    policy, states, bg = uav
    found = xairl.counterfactual(policy, states, index=None, background=bg, features=["rsrp_0"], target="any")
    hit = next(r for r in found if r.reachable)
    d = summary(hit, writer(policy))
    change = d["found"][0]["changes"][0]
    assert (
        change["feature"] == "rsrp_0"
        and change["before_text"].endswith(" dBm")
        and change["after_text"].endswith(" dBm")
    )
    assert writer(policy)("buffer_queue_size", 7.6e6) == "50 % full"
    assert json.loads(json.dumps(d)) == d  # travels in the evidence as JSON


def test_cli_prints_each_decisions_counterfactual(capsys):
    rc, out, err = run(capsys, "explain", "--n", "3", "--counterfactual", "--max-changes", "1")
    assert rc == 0, err
    assert out.count("what would have changed it") == 3
    policy = toy_policy()
    states = policy.background(3, seed=1)  # the CLI's sampled states (--seed 0: seed + 1)
    ref = xairl.counterfactual(policy, states, index=None, max_changes=1, background=policy.background(100, seed=0))
    for r in ref:
        if r.reachable:
            assert f"{r.best.changes[0].feature} " in out and f": {r.best.action} (margin" in out
        else:
            assert "none found within the bounds (a grid search: " in out and "unreachable" not in out
    rc, out, err = run(capsys, "explain", "--n", "2", "--counterfactual-target", "2", "--format", "jsonl")
    assert rc == 0 and {json.loads(line)["counterfactual"]["target"] for line in out.splitlines()} == {
        policy.action_names[2]
    }  # (an action's index, as the docs say)
    rc, out, err = run(capsys, "explain", "--n", "2", "--counterfactual-target", "any", "--format", "jsonl")
    assert rc == 0 and all(
        json.loads(line)["counterfactual"]["target"] == "any other action" for line in out.splitlines()
    )


def _rerun_printed(policy, states, shown: dict) -> list[str]:
    """The action the policy takes on state ``shown['index']`` with each shown counterfactual's values *as printed*
    (its ``after_text``: a number, in % of the capacity where it says so), one batch."""
    rows = []
    for one in shown["found"]:
        x = states[shown["index"]].astype(float).copy()
        for c in one["changes"]:
            info = policy.features.get(c["feature"])
            v = float(re.match(r"-?[\d.]+(?:e-?\d+)?", c["after_text"]).group())
            x[policy.feature_names.index(c["feature"])] = v * info.capacity / 100 if "%" in c["after_text"] else v
        rows.append(x)
    return [policy.action_names[a] for a in policy.act(np.array(rows))] if rows else []


@pytest.mark.slow
def test_the_cli_shows_values_that_flip_as_printed(capsys, monkeypatch, uav):
    """Review 56b, finding 2: every value the CLI prints, re-run as printed, gives the action it prints (the UAV DQN,
    whose lines the search's raw values sit within a rounding step of); a bare answer's card (no policy) rounds them
    away from the state and says they were not re-run so."""
    policy, _, bg = uav
    monkeypatch.setenv(plugins.LOAD_ENV, "uav-handover")
    rc, out, err = run(capsys, "explain", "--policy", "uav-dqn", "--n", "12", "--counterfactual", "--format", "jsonl")
    assert rc == 0, err
    states = policy.background(12, seed=1)  # the CLI's sampled states (--seed 0: seed + 1)
    shown = [json.loads(line)["counterfactual"] for line in out.splitlines()]
    assert sum(len(s["found"]) for s in shown) >= 4 and all(s["as_written"] for s in shown)
    for s in shown:
        assert _rerun_printed(policy, states, s) == [one["action"] for one in s["found"]], s
    raw = next(r for r in xairl.counterfactual(policy, states, index=None, background=bg) if r.reachable)
    for cf, one in zip(raw.found, summary(raw)["found"]):  # (no policy: rounded away from the state, past the line)
        for c, printed in zip(cf.changes, one["changes"]):
            assert abs(printed["after"] - c.before) >= abs(c.after - c.before) and c.before == printed["before"]
    card = raw._repr_html_()
    assert "just past the line" in card and "as shown" not in card


def test_cli_bad_target_or_max_changes_is_one_line(capsys):
    rc, _, err = run(capsys, "explain", "--n", "2", "--counterfactual-target", "fly")
    one_line_error(rc, err, "fly", "any")
    rc, _, err = run(capsys, "explain", "--n", "2", "--counterfactual", "--max-changes", "3")
    one_line_error(rc, err, "--max-changes")


@pytest.mark.slow
def test_report_cards_and_the_single_flip_table(tmp_path):
    policy = toy_policy()
    bg = policy.background(60)
    states = policy.background(40, seed=3)
    req = ReportRequest(out=tmp_path, n_narrated=3, robustness=False, progress=False, records=False)
    path = write_report(req, ReportContent(title="t", policy=policy, background=bg, datasets=[("s", states)]))
    text = path.read_text()
    assert text.count("What would have changed it") == 3 and "Distance to another action" in text
    # each card's narrative says it too, as its last sentence, marked as the verifier found it
    assert 1 <= text.count("the policy would have chosen") <= 3 and "No change of at most" not in text
    exp = xairl.explain(policy, states, background=bg)
    _, header, rows, sentence = flip_rows(policy, exp, bg)
    shares = {r[0]: r[1::2] for r in rows}  # per chosen action: 'share % (count)', then the median change

    def counts(label):
        return np.array([int(c.split("(")[1].rstrip(")")) for c in shares[label]])

    decided = np.array([int(c) for c in shares["decisions"]])
    assert (counts("some single feature") + counts("no single feature") == decided).all()
    assert decided.sum() == len(states) and len(header) == 1 + 2 * len(decided)
    # a feature's count is what a search of that feature alone finds (to any other action)
    f = rows[0][0]
    alone = xairl.counterfactual(policy, states, index=None, features=[f], max_changes=1, target="any", background=bg)
    assert counts(f).sum() == sum(r.reachable for r in alone) > 0
    assert (counts(f) <= counts("some single feature")).all()
    assert f in sentence or "No decision" in sentence


def _toy_decision(n: int, seed: int):
    """(policy, background, explanation, every state's counterfactuals, the first decision with one)."""
    policy = toy_policy()
    bg = policy.background(50)
    states = policy.background(n, seed=seed)
    exp = xairl.explain(policy, states, background=bg)
    found = xairl.counterfactual(policy, states, index=None, background=bg, explanation=exp)
    return policy, bg, exp, found, next(k for k, r in enumerate(found) if r.reachable)


def test_review_page_shows_the_counterfactual_beside_the_narrative(tmp_path):
    policy, bg, exp, found, i = _toy_decision(4, 4)
    store = FeedbackStore(tmp_path / "fb.sqlite")
    n = xairl.narrate(exp, i, policy=policy, background=bg, robustness=False)
    n.evidence["counterfactual"] = summary(found[i])
    store.record(n, policy=policy)
    html = page(store, "t")
    assert "What would have changed it" in html and found[i].best.action in html
    assert found[i].best.changes[0].feature in html.split("What would have changed it")[1]


def test_a_narratives_counterfactual_sentence_shows_in_its_card():
    policy, bg, exp, found, i = _toy_decision(6, 5)
    n = xairl.narrate(exp, i, policy=policy, background=bg, robustness=False, counterfactual=found[i])
    last, status = n.sentences[-1]
    assert last.startswith("Had ") and found[i].best.action in last and status == "verified"
    assert f"<span class='s verified' title='verified'>{last.split(' (')[0]}" in n._repr_html_()


def test_the_single_flip_table_of_a_window_policy_takes_its_background_as_windows():
    import torch

    from tests.conftest import mlp

    policy = xairl.Policy(
        torch.nn.Sequential(torch.nn.Flatten(), mlp([12, 16, 3])), feature_names=list("abc"), window=4
    )
    rng = np.random.default_rng(0)
    states, bg = rng.normal(size=(20, 4, 3)).astype(np.float32), rng.normal(size=(60, 4, 3)).astype(np.float32)
    exp = xairl.explain(policy, states, background=bg)
    _, _, rows, _ = flip_rows(policy, exp, bg)
    # the newest step's slots (a past slot changed alone is a history the present cannot have: issue 64)
    assert {r[0] for r in rows[:-3]} == {f"{s}[t]" for s in "abc"}
    assert sum(int(c) for c in rows[-1][1::2]) == 20


def test_a_threshold_card_shows_the_new_output_and_a_miss_is_said_as_one():
    """Review 56b, finding 6: a threshold's card shows the output's value after the change (re-run here); a search's
    miss reads 'none found within the bounds (a grid search: ...)', never 'unreachable' next to 'no proof'."""
    import torch

    lin = torch.nn.Linear(2, 1)
    with torch.no_grad():
        lin.weight.copy_(torch.tensor([[1.0, 0.5]]))
        lin.bias.zero_()
    p = xairl.Policy(lin, ["a", "b"], ["steer"], output="continuous")
    states = np.array([[0.2, 0.2]], np.float32)
    bg = np.random.default_rng(0).uniform(-1, 1, (64, 2)).astype(np.float32)
    r = xairl.counterfactual(p, states, index=0, background=bg, target=xairl.Threshold("steer", above=0.6))
    out = float(p.scores(r.best.state[None].astype(np.float32))[0, 0])
    card = r._repr_html_()
    assert "then its output" in card and f"steer = {out:.3g}" in card and out > 0.6
    miss = xairl.counterfactual(p, states, index=0, background=bg, target=xairl.Threshold("steer", above=50.0))
    lines = counterfactual_text(summary(miss))
    assert lines[0].startswith("none found within the bounds (a grid search: ") and "no proof" not in lines[0]
    assert "None found within the bounds (a grid search: " in miss._repr_html_()
