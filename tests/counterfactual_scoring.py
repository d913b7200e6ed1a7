"""The counterfactual benchmark's cases and scoring (``benchmarks/bench_counterfactual.py`` runs DiCE and xairl on
them; ``tests/test_bench_counterfactual.py`` holds the scoring to its word): the states of a policy with their runner-up,
the room each search has, and the measures of an answer, re-run through the policy."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import xairl

SEED = 0


@dataclass(frozen=True)
class Case:
    """One policy's benchmark: the states searched, the background, the ranges and the targets."""

    name: str
    policy: xairl.Policy
    states: np.ndarray  # (n, n_features) float64
    background: np.ndarray
    units: object  # xairl's units of change (xairl.counterfactuals.bounds.Units): the features a search may change
    columns: np.ndarray  # the flat column of each unit
    low: np.ndarray  # (n, units): where each unit of each state may move, the same for both searches
    high: np.ndarray
    fixed: tuple[str, ...]  # features no search may change
    chosen: np.ndarray  # the action the policy took in each state
    target: np.ndarray  # its runner-up: the action each search must reach


class ChosenActionClassifier:
    """The policy as a scikit-learn-like classifier of the action it takes (for DiCE's 'sklearn' backend)."""

    def __init__(self, policy: xairl.Policy):
        self.policy = policy
        self.classes_ = np.arange(policy.n_actions)

    def predict_proba(self, frame) -> np.ndarray:
        x = np.asarray(frame, dtype=np.float64)
        scores = np.where(self.policy.available(x), self.policy.scores(x), -np.inf)
        scores = scores - scores.max(axis=1, keepdims=True)
        e = np.exp(scores)
        return e / e.sum(axis=1, keepdims=True)

    def predict(self, frame) -> np.ndarray:
        return self.predict_proba(frame).argmax(axis=1)


def runner_up(policy: xairl.Policy, states: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(chosen, runner-up, has one): the best and second-best available actions; one forward pass."""
    scores = np.where(policy.available(states), policy.scores(states), -np.inf)
    ranked = np.argsort(-scores, axis=1, kind="stable")
    has = np.isfinite(scores[np.arange(len(states)), ranked[:, 1]]) if scores.shape[1] > 1 else np.zeros(len(states))
    return ranked[:, 0], ranked[:, 1], has.astype(bool)


def make_case(name: str, policy: xairl.Policy, states: np.ndarray, background: np.ndarray) -> Case:
    """The states that have a runner-up, with xairl's own ranges (:mod:`xairl.counterfactuals.bounds`: declared
    bounds, else the background's 1st-99th percentile widened to the state's value; immutables, identifiers and
    categoricals fixed), so that DiCE gets exactly the room xairl's search has."""
    from xairl.counterfactuals.bounds import units as units_of

    states, background = np.asarray(states, np.float64), np.asarray(background, np.float64)
    chosen, target, keep = runner_up(policy, states)  # a state with one available action has no runner-up
    states, chosen, target = states[keep], chosen[keep], target[keep]
    units = units_of(policy, background, None)
    if any(len(c) != 1 for c in units.columns):
        raise ValueError("the benchmark wraps flat policies only (a unit is one column)")
    columns = np.array([c[0] for c in units.columns], dtype=int)
    low, high = units.ranges(units.values(states))
    fixed = tuple(f for j, f in enumerate(policy.feature_names) if j not in set(columns.tolist()))
    return Case(name, policy, states, background, units, columns, low, high, fixed, chosen, target)


def uav_case(n: int) -> Case:
    policy = xairl.get_policy("uav-dqn")  # through the plugin's entry point (the core's benchmarks import no plugin)
    return make_case("uav-dqn", policy, policy.background(n, seed=SEED + 1), policy.background(1000, seed=SEED))


def toy_case(n: int) -> Case:
    from xairl.toy import toy_background, toy_policy

    return make_case("toy", toy_policy(), toy_background(n, seed=SEED + 1), toy_background(1000, seed=SEED))


@dataclass
class Answers:
    """What one method returned: per state a counterfactual state or None, the seconds it took in all, and how many
    states ran out of time."""

    method: str
    states: list[np.ndarray | None]
    seconds: float
    timed_out: int = 0


@dataclass
class Scores:
    """Per state of one method: answered, valid (re-run: the policy takes the target), feasible (the policy's
    ``feasible`` accepts it: the UAV's RSRQ within what its RSRP allows), features changed, distances."""

    answered: np.ndarray
    valid: np.ndarray
    feasible: np.ndarray
    changed: np.ndarray
    distance: np.ndarray
    scaled: np.ndarray


def score(case: Case, answers: Answers) -> Scores:
    """Re-run the policy on every answer (one batch) and measure it against its state with xairl's own measures
    (the units' background quantiles and interquartile ranges)."""
    answered = np.array([a is not None for a in answers.states])
    cf = np.array([a if a is not None else s for a, s in zip(answers.states, case.states)])
    valid = answered & (case.policy.act(cf) == case.target)
    feasible = np.ones(len(cf), bool) if case.policy.feasible is None else np.asarray(case.policy.feasible(cf), bool)
    # any column, fixed ones included; 1e-6 relative: DiCE's genetic method rounds unchanged features (up to 5e-7 m)
    moved = np.abs(cf - case.states) > 1e-6 * (1 + np.abs(case.states))
    u = case.units
    before, after = u.values(case.states), u.values(cf)
    units = np.broadcast_to(np.arange(u.n), before.shape)
    dq = np.abs(u.quantile(after, units) - u.quantile(before, units))
    on = moved[:, case.columns]
    return Scores(
        answered,
        valid,
        answered & feasible,
        moved.sum(axis=1),
        np.where(on, dq, 0.0).sum(axis=1),
        np.where(on, np.abs(after - before) / u.scale(), 0.0).sum(axis=1),
    )
