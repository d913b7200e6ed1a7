"""The DiCE benchmark's parts (its cases and scoring, tests/counterfactual_scoring.py; the script itself,
benchmarks/bench_counterfactual.py): the classifier DiCE sees takes exactly the policy's actions, the scoring re-runs
the policy (an answer that does not flip is counted invalid), and a quick run of the script on the toy policy (only
with dice-ml installed: the `bench` extra)."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import xairl
from tests import counterfactual_scoring as bench


@pytest.fixture(scope="module")
def case():
    return bench.toy_case(12)


def test_the_classifier_takes_the_policy_s_action(case):
    clf = bench.ChosenActionClassifier(case.policy)
    x = np.concatenate([case.states, case.background[:50]])
    np.testing.assert_array_equal(clf.predict(x), case.policy.act(x))
    np.testing.assert_allclose(clf.predict_proba(x).sum(axis=1), 1.0)
    assert (case.target != case.chosen).all()


def test_scoring_reruns_the_policy(case):
    """A brute-force flip (walk one feature until the target action wins) is valid; the state itself, given back as
    its own counterfactual, is answered but invalid; no answer is not counted."""
    found = []
    for s, t in zip(case.states, case.target):
        steps = s + np.linspace(-6, 6, 241)[:, None] * np.eye(len(s))[:, None, :]  # (features, steps, features)
        hits = steps.reshape(-1, len(s))[case.policy.act(steps.reshape(-1, len(s))) == t]
        found.append(hits[np.abs(hits - s).sum(axis=1).argmin()] if len(hits) else None)
    walked = bench.score(case, bench.Answers("walk", found, 1.0))
    assert walked.answered.sum() >= 6 and walked.valid[walked.answered].all()
    assert (walked.changed[walked.answered] == 1).all()
    same = bench.score(case, bench.Answers("same", list(case.states), 1.0))
    assert same.answered.all() and not same.valid.any() and (same.changed == 0).all() and (same.distance == 0).all()


def test_the_measures_are_xairl_s_own(case):
    """Measured here, xairl's own answers have exactly the distances, changes and action xairl reports."""
    results = xairl.counterfactual(case.policy, case.states, index=None, background=case.background)
    found = [None if r.best is None else np.asarray(r.best.state, np.float64) for r in results]
    s = bench.score(case, bench.Answers("xairl", found, 1.0))
    assert s.answered.sum() >= 10 and s.valid[s.answered].all()
    for k, r in enumerate(results):
        if r.best is not None:
            assert s.changed[k] == len(r.best.changes)
            np.testing.assert_allclose([s.distance[k], s.scaled[k]], [r.best.distance, r.best.distance_scaled])
            assert r.best.action == case.policy.action_names[case.target[k]]


@pytest.mark.slow
def test_quick_run_against_dice():
    pytest.importorskip("dice_ml")
    script = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_counterfactual.py"
    res = subprocess.run(
        [sys.executable, str(script), "--quick", "--policy", "toy", "--methods", "genetic"],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert res.returncode == 0, res.stderr[-2000:]
    assert "dice-genetic" in res.stdout
