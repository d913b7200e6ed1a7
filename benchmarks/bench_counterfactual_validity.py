"""Counterfactuals (issue 56): validity, reach and time per decision of :func:`xairl.counterfactual`.

On the reference plugin's trained DQN (``uav-dqn``, its committed checkpoint, through the plugin's entry point):
``--n`` decisions of the plugin's sampler (simulated UAVs 10 s into a flight, seed 1; the background 200 of seed 0);
the targets the
runner-up (the default) and any other action. On each policy kind: a flat MLP, a dict observation, image regions of a
small CNN, a continuous action with a Threshold, a value with a Threshold (seeded networks, standard-normal states).

Reported per row: decisions searched; *valid*: the share of returned counterfactuals that, re-run through the policy
(one batch of all of them, apart from the search), take the stated action (or cross the threshold), are feasible,
keep the immutables and stay within the ranges (the goal: 100 %); *reach*: the share of decisions with a
counterfactual of at most 2 changes within the bounds; *1 change*: the share of those that need only one; *time*: the
batched call (explanation included) divided by the decisions, and one decision asked alone (``index=k``), the median
over ``--single`` decisions. Goals: valid 100 %, <= 1 s per decision for an MLP on 2 cores.

Run: OMP_NUM_THREADS=2 .venv/bin/python benchmarks/bench_counterfactual_validity.py [--n 1000] [--single 20]
"""

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import torch

import xairl
from xairl import Threshold
from xairl.counterfactuals.bounds import units as mutable_units

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from conftest import mlp, small_cnn  # noqa: E402  (the tests' seeded networks)


def validity(policy, states, results, target) -> tuple[int, int]:
    """(valid, returned): every returned counterfactual re-run in one batch, apart from the search."""
    found = [(r, cf) for r in results for cf in r.found]
    if not found:
        return 0, 0
    x = np.stack([cf.state for _, cf in found])
    scores = policy.scores(x)
    if policy.output == "actions":
        acted = policy.act(x)
        ok = np.array([policy.action_names[a] == cf.action != r.chosen for a, (r, cf) in zip(acted, found)])
    else:
        j = policy.action_names.index(target.output) if isinstance(target.output, str) else target.output
        ok = scores[:, j] > target.above if target.above is not None else scores[:, j] < target.below
    if policy.feasible is not None:
        ok &= policy.feasible(x)
    names = set(mutable_units(policy, states[:2], None).names)
    for k, (r, cf) in enumerate(found):
        moved = {policy.feature_names[j] for j in np.flatnonzero(cf.state != states[r.index])}
        stated = {c.feature for c in cf.changes}
        regions = policy.observation.regions()
        allowed = set().union(*(regions[f] if f in regions else [policy.feature_names.index(f)] for f in stated))
        ok[k] &= stated <= names and {policy.feature_names.index(f) for f in moved} <= allowed
        for c in cf.changes:
            info = policy.features.get(c.feature)
            if info is not None and info.bounds is not None:
                ok[k] &= info.bounds[0] <= c.after <= info.bounds[1]
    return int(ok.sum()), len(found)


def row(name, policy, states, bg, target=None, single=20, **kwargs):
    t = time.perf_counter()
    results = xairl.counterfactual(policy, states, index=None, target=target, background=bg, **kwargs)
    batched = (time.perf_counter() - t) / len(states)
    times = []
    for k in range(min(single, len(states))):
        t = time.perf_counter()
        xairl.counterfactual(policy, states, index=k, target=target, background=bg, **kwargs)
        times.append(time.perf_counter() - t)
    valid, returned = validity(policy, policy.check_states(states), results, target)
    reached = [r for r in results if r.reachable]
    one = sum(len(r.best.changes) == 1 for r in reached)
    return (
        f"{name:<34} {len(states):>6} {100 * valid / max(returned, 1):>8.1f}% {returned:>6} "
        f"{100 * len(reached) / len(states):>6.1f}% {100 * one / max(len(reached), 1):>8.1f}% "
        f"{1000 * batched:>9.1f} {1000 * np.median(times) if times else float('nan'):>9.1f}"
    )


def uav_rows(n, single):
    policy = xairl.get_policy("uav-dqn")  # through the plugin's entry point, as a user reaches it
    states, bg = policy.background(n, seed=1), policy.background(200, seed=0)
    yield row("uav-dqn, runner-up", policy, states, bg, single=single)
    yield row("uav-dqn, any other action", policy, states, bg, "any", single=single)


def kind_rows(n, single):
    rng = np.random.default_rng(0)
    x, bg = rng.normal(size=(n, 8)).astype(np.float32), rng.normal(size=(200, 8)).astype(np.float32)
    flat = xairl.Policy(mlp([8, 64, 64, 4]), feature_names=[f"f{i}" for i in range(8)])
    yield row("flat MLP 8-64-64-4, runner-up", flat, x, bg, single=single)

    net = mlp([8, 64, 3], seed=1)

    class Cat(torch.nn.Module):
        def forward(self, obs):
            return net(torch.cat([obs["pos"], obs["vel"]], dim=1))

    d = xairl.Policy(Cat(), observation={"pos": (4,), "vel": (4,)})
    yield row("dict observation, runner-up", d, x, bg, single=single)
    cnn, frames = small_cnn()
    img_bg = np.concatenate([frames * k for k in np.linspace(0.1, 1.5, 8)]).astype(np.float32)
    yield row("image regions (small CNN), any", cnn, frames, img_bg, "any", single=min(single, 3))
    cont = xairl.Policy(
        torch.nn.Sequential(mlp([8, 64, 2], seed=2), torch.nn.Tanh()),
        feature_names=[f"f{i}" for i in range(8)],
        action_names=["steer", "throttle"],
        output="continuous",
    )
    s = float(np.median(cont.scores(x)[:, 0]))
    yield row(f"continuous, steer above median {s:.2f}", cont, x, bg, Threshold("steer", above=s), single=single)
    value = xairl.Policy(mlp([8, 64, 1], seed=3), feature_names=[f"f{i}" for i in range(8)], output="value")
    v = float(np.median(value.scores(x)))
    yield row(f"value, below median {v:.2f}", value, x, bg, Threshold("value", below=v), single=single)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=1000, help="UAV decisions (and flat states per policy kind)")
    ap.add_argument("--kinds-n", type=int, default=200, help="states per policy kind")
    ap.add_argument("--single", type=int, default=20, help="decisions also asked one at a time")
    args = ap.parse_args()
    torch.set_num_threads(2)
    print(f"torch threads {torch.get_num_threads()}")
    head = f"{'policy, target':<34} {'states':>6} {'valid':>9} {'found':>6} {'reach':>7} {'1 change':>9}"
    print(head + f" {'ms/dec':>9} {'ms alone':>9}")
    for line in (*uav_rows(args.n, args.single), *kind_rows(args.kinds_n, args.single)):
        print(line, flush=True)


if __name__ == "__main__":
    main()
