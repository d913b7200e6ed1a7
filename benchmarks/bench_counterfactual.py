"""xairl's counterfactual search against DiCE's model-agnostic methods (issue 56).

The same states of two policies: the UAV handover DQN (``uav-dqn``, the plugin's committed checkpoint, through its
entry point; the states and the background 1,000 others drawn by its sampler: simulated UAVs 10 s into a flight) and
the toy policy (``xairl.toy.toy_policy()``, standard-normal states). For each state the question is the same: which change of the state makes the policy
choose its runner-up (the second-best available action) instead of the action it took?

DiCE (``dice-ml``) explains classifiers, so each policy is wrapped as a classifier of the chosen action: its
``predict_proba`` is a softmax of the policy's scores with unavailable actions at probability 0, so that its argmax
is exactly the action the policy takes; the label DiCE flips is "the chosen action", ``desired_class`` the runner-up's
index (DiCE's multiclass validity: the argmax of the probabilities is the desired class). Both searches get the same
room, xairl's own (:mod:`xairl.counterfactuals.bounds`): each feature within its declared ``FeatureInfo.bounds``,
else the background's 1st-99th percentile widened to the state's value (DiCE's ``permitted_range``, per state), and
the features xairl never changes (immutables, identifiers, categoricals) left out of DiCE's ``features_to_vary``.
What neither range can say, the UAV's coupling of each RSRQ to the RSRPs (the policy's ``feasible``), xairl's search
enforces and DiCE cannot be told: it is reported. DiCE has no limit on the number of features changed (xairl's
``max_changes=2``): its counts are as they come. One counterfactual is asked of each (``total_CFs=1``, ``n=1``), with
DiCE's other settings at their defaults; a DiCE query is stopped after ``--limit`` seconds (its genetic method draws
random states until enough have the desired class, with no limit of its own).

Every returned counterfactual is re-run through the policy here. Per policy and method it prints: the share of states
answered; among the answers, valid (the policy, re-run, takes the runner-up), feasible, features changed (mean and
share <= 2), the distance (sum over the changed features of |quantile after - quantile before| in the background)
and the scaled one (sum of |delta| / interquartile range), xairl's ``Counterfactual.distance`` and
``distance_scaled`` measured by xairl's own units; seconds per state (wall clock, one process, all states of the
policy); queries out of time; and "usable", the share of all states with a valid, feasible answer of at most two
changes. A second table compares each DiCE method with xairl on the states where both returned a valid answer, and
counts xairl's misses: states where DiCE's answer is one xairl could have given (valid, feasible, at most two
changes) and xairl found none.

    .venv/bin/python benchmarks/bench_counterfactual.py [--states 200] [--quick] [--policy uav toy] [--methods ...]
        [--limit 10] [--cache DIR]

200 states of each take about 25 minutes on 2 cores, most of it DiCE's k-d tree on the toy policy (its default
post-hoc sparsity walks each feature back in steps of the data's decimal precision, up to 10,000 single-row forward
passes).

dice-ml is an optional extra (``pip install xairl[bench]``); without it the benchmark says so and exits 0.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import pathlib
import platform
import random
import signal
import sys
import time
from importlib.metadata import version

import numpy as np
import torch

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
import xairl  # noqa: E402
from tests.counterfactual_scoring import (  # noqa: E402
    SEED,
    Answers,
    Case,
    ChosenActionClassifier,
    Scores,
    score,
    toy_case,
    uav_case,
)

DICE_METHODS = ("random", "genetic", "kdtree")


class OutOfTime(Exception):
    pass


_FIRED: list[bool] = [False]  # the alarm's own flag: the policy may wrap the exception raised inside its forward pass


def _alarm(signum, frame):
    _FIRED[0] = True
    raise OutOfTime


def dice_answers(case: Case, method: str, limit: float = 10.0, cache: str | None = None) -> Answers:
    """DiCE's first counterfactual per state (one query per call: each state has its own desired class), each query
    stopped after ``limit`` seconds (DiCE's genetic search draws random states until enough of them have the
    desired class, without a limit); with ``cache``, answers are kept in that folder and reused for the same states,
    ranges and targets."""
    path = cache and os.path.join(cache, f"{case.name}-{method}-{len(case.states)}-{limit:g}.npz")
    if path and os.path.exists(path):
        saved = np.load(path)
        if all(np.array_equal(saved[k], getattr(case, k)) for k in ("states", "low", "high", "columns", "target")):
            rows = [None if np.isnan(r).all() else r for r in saved["found"]]
            return Answers(f"dice-{method}", rows, float(saved["seconds"]), int(saved["timed_out"]))
    answers = _run_dice(case, method, limit)
    if path:
        os.makedirs(cache, exist_ok=True)
        found = np.array([np.full(case.states.shape[1], np.nan) if a is None else a for a in answers.states])
        np.savez(
            path,
            states=case.states,
            low=case.low,
            high=case.high,
            columns=case.columns,
            target=case.target,
            found=found,
            seconds=answers.seconds,
            timed_out=answers.timed_out,
        )
    return answers


def _run_dice(case: Case, method: str, limit: float) -> Answers:
    import dice_ml
    import pandas as pd

    # columns renamed: DiCE's k-d tree writes a column 'distance' of its own over the toy's feature 'distance'
    names = [f"f{j}" for j in range(case.states.shape[1])]
    frame = pd.DataFrame(case.background, columns=names)
    frame["action"] = ChosenActionClassifier(case.policy).predict(case.background)
    data = dice_ml.Data(dataframe=frame, continuous_features=names, outcome_name="action")
    model = dice_ml.Model(model=ChosenActionClassifier(case.policy), backend="sklearn", model_type="classifier")
    explainer = dice_ml.Dice(data, model, method=method)
    vary = [names[c] for c in case.columns]
    random.seed(SEED)
    np.random.seed(SEED)
    extra = {"random_seed": SEED} if method == "random" else {}
    found: list[np.ndarray | None] = []
    timed_out, start = 0, time.perf_counter()
    previous = signal.signal(signal.SIGALRM, _alarm)
    try:
        for i in range(len(case.states)):
            query = pd.DataFrame(case.states[i : i + 1], columns=names)
            permitted = {f: [float(case.low[i, u]), float(case.high[i, u])] for u, f in enumerate(vary)}
            _FIRED[0] = False
            signal.setitimer(signal.ITIMER_REAL, limit)
            try:
                found.append(_one_dice(explainer, query, int(case.target[i]), vary, permitted, extra))
            except OutOfTime:
                found.append(None)
            finally:
                signal.setitimer(signal.ITIMER_REAL, 0)
            if _FIRED[0]:
                found[-1], timed_out = None, timed_out + 1
    finally:
        signal.signal(signal.SIGALRM, previous)
    return Answers(f"dice-{method}", found, time.perf_counter() - start, timed_out)


def _one_dice(explainer, query, target: int, vary, permitted, extra) -> np.ndarray | None:
    """One DiCE query; None when it returns nothing (DiCE raises when no counterfactual is found)."""
    try:
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):  # its chatter, bars
            out = explainer.generate_counterfactuals(
                query, total_CFs=1, desired_class=target, features_to_vary=vary, permitted_range=permitted, **extra
            )
    except OutOfTime:
        raise
    except Exception as err:  # noqa: BLE001 (DiCE's 'no counterfactual found' is an exception of its own)
        if "no counterfactuals found" not in str(err).lower() and not _FIRED[0]:
            print(f"  dice: {type(err).__name__}: {str(err)[:120]}")
        return None
    ex = out.cf_examples_list[0]
    cfs = ex.final_cfs_df_sparse if ex.final_cfs_df_sparse is not None else ex.final_cfs_df
    if cfs is None or len(cfs) == 0:
        return None
    return cfs[list(query.columns)].to_numpy(np.float64)[0]


def xairl_answers(case: Case) -> Answers:
    """xairl's best counterfactual per state, all states in one call (the search batches its forward passes)."""
    start = time.perf_counter()
    answers = xairl.counterfactual(case.policy, case.states, index=None, max_changes=2, background=case.background)
    seconds = time.perf_counter() - start
    found = [None if a.best is None else np.asarray(a.best.state, np.float64) for a in answers]
    return Answers("xairl", found, seconds)


HEAD = f"{'policy':<9}{'method':<15}{'states':>7}{'answered':>10}{'valid':>8}{'feasible':>10}{'changed':>9}{'<=2':>7}"
HEAD += f"{'distance':>10}{'scaled':>8}{'s/state':>9}{'timeouts':>10}{'usable':>8}"


def row(case: Case, answers: Answers, s: Scores) -> str:
    n, a = len(case.states), s.answered
    mean = (lambda v: float(v[a].mean())) if a.any() else (lambda v: float("nan"))
    validity = float(s.valid[a].mean()) if a.any() else float("nan")
    return (
        f"{case.name:<9}{answers.method:<15}{n:>7}{a.mean():>10.0%}{validity:>8.1%}{mean(s.feasible):>10.1%}{mean(s.changed):>9.2f}"
        f"{(mean(s.changed <= 2)):>7.0%}{mean(s.distance):>10.3f}{mean(s.scaled):>8.2f}{answers.seconds / n:>9.3f}"
        f"{answers.timed_out:>10}{(s.valid & s.feasible & (s.changed <= 2)).mean():>8.0%}"
    )


def paired(case: Case, ours: Scores, theirs: Scores, method: str) -> str:
    """xairl and one DiCE method on the states where both returned a valid counterfactual."""
    both = ours.valid & theirs.valid
    # a search miss of xairl's: DiCE's answer is one xairl could have given (valid, feasible, <= 2 changes)
    missed = int((theirs.valid & theirs.feasible & (theirs.changed <= 2) & ~ours.answered).sum())
    if not both.any():
        return f"{case.name:<9}{method:<15} no state where both are valid; xairl missed {missed}"
    c = f"{ours.changed[both].mean():.2f} vs {theirs.changed[both].mean():.2f}"
    d = f"{ours.distance[both].mean():.3f} vs {theirs.distance[both].mean():.3f}"
    sc = f"{ours.scaled[both].mean():.2f} vs {theirs.scaled[both].mean():.2f}"
    fewer = float((ours.changed[both] < theirs.changed[both]).mean())
    nearer = float((ours.distance[both] < theirs.distance[both]).mean())
    return (
        f"{case.name:<9}{method:<15}{int(both.sum()):>6}  changed {c} (xairl fewer {fewer:.0%}), distance {d} "
        f"(xairl nearer {nearer:.0%}), scaled {sc}; xairl missed {missed}"
    )


def run(case: Case, methods: tuple[str, ...], limit: float, cache: str | None) -> None:
    print(f"{case.name}: {len(case.states)} states with a runner-up; fixed: {', '.join(case.fixed) or 'none'}")
    ours = xairl_answers(case)
    results = [(ours, score(case, ours))]
    for method in methods:
        answers = dice_answers(case, method, limit, cache)
        results.append((answers, score(case, answers)))
    print(HEAD)
    for answers, s in results:
        print(row(case, answers, s))
    print("paired, on states where both are valid (xairl vs DiCE):")
    for answers, s in results[1:]:
        print(paired(case, results[0][1], s, answers.method))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--states", type=int, default=200, help="states per policy (default 200)")
    ap.add_argument("--quick", action="store_true", help="a smoke run: 10 states per policy")
    ap.add_argument("--policy", nargs="+", choices=("uav", "toy"), default=["uav", "toy"])
    ap.add_argument("--methods", nargs="+", choices=DICE_METHODS, default=list(DICE_METHODS))
    ap.add_argument("--limit", type=float, default=10.0, help="seconds a DiCE query may take (default 10)")
    ap.add_argument("--cache", help="a folder to keep DiCE's answers in and reuse them for the same states")
    args = ap.parse_args(argv)
    try:
        import dice_ml  # noqa: F401
    except ImportError:
        print("bench_counterfactual: dice-ml is not installed; pip install xairl[bench] to compare with DiCE.")
        return 0
    n = 10 if args.quick else args.states
    print(
        f"machine: {platform.machine()}, {os.cpu_count()} cores (load {os.getloadavg()[0]:.1f}), torch "
        f"{torch.get_num_threads()} thread(s); dice-ml {version('dice-ml')}; DiCE limit {args.limit:g} s per query"
    )
    for name in args.policy:
        if name == "uav":
            try:
                case = uav_case(n)
            except xairl.InputError:
                print("uav: the xairl-uav-handover plugin is not installed; skipped.")
                continue
        else:
            case = toy_case(n)
        run(case, tuple(args.methods), args.limit, args.cache)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
