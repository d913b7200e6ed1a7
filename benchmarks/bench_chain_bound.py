"""How fast deep_shap on the fleet MLP (8-64-64-4, 100 background states) could be on this machine: the part of its
time spent in the two matrix products of the backward sweep, and the ceiling they set (issue 28's 50,000 states/s).

On one torch thread it times: xairl.explain on N states; the rescale multipliers alone (chain_multipliers, the
batches the attributor uses); the two matrix products alone at the same sizes. The ceiling is N / (products' time)
x cores: what the path would reach if every other step were free and the cores scaled perfectly.

Run: .venv/bin/python benchmarks/bench_chain_bound.py [--states 50000] [--cores 2]
"""

import argparse
import time

import numpy as np
import torch
from fleet_mlp import make_policy

import xairl
from xairl.attributors.deep_shap import _only_child, chain, chain_multipliers


def timed(fn) -> float:
    t = time.perf_counter()
    fn()
    return time.perf_counter() - t


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--states", type=int, default=50_000)
    ap.add_argument("--cores", type=int, default=2)
    args = ap.parse_args()
    torch.set_num_threads(1)
    policy, n, b = make_policy(), args.states, 100
    rng = np.random.default_rng(0)
    x, bg = rng.normal(size=(n, 8)).astype(np.float32), rng.normal(size=(b, 8)).astype(np.float32)
    layers = chain(_only_child(policy, x[:1]))
    a, width = policy.n_actions, max(getattr(layer, "out_features", 0) for layer in layers)
    per = max(1, 2**20 // (a * width) // b)  # the attributor's batch (deep_shap._attribute_chain)
    xt, bt = torch.as_tensor(x), torch.as_tensor(bg)
    total = timed(lambda: xairl.explain(policy, x, background=bg))
    mult = timed(lambda: [chain_multipliers(layers, xt[s : s + per], bt) for s in range(0, n, per)])
    rows, w2, w1 = torch.randn(per * b * a, 64), torch.randn(64, 64), torch.randn(64, 8)
    gemm = timed(lambda: [(rows @ w2) @ w1 for _ in range(0, n, per)])
    flops = 2 * n * b * a * (64 * 64 + 64 * 8)
    print(
        f"one thread, {n} states: explain {total:.2f} s ({n / total:,.0f} states/s); multipliers {mult:.2f} s; the "
        f"two matrix products alone {gemm:.2f} s ({flops / gemm / 1e9:.0f} GFLOP/s, {gemm / mult:.0%} of the "
        f"multipliers' time)"
    )
    ceiling = n / gemm * args.cores
    print(
        f"ceiling on {args.cores} cores, every other step free: {ceiling:,.0f} states/s = {ceiling / 50_000:.2f} x "
        "the 50,000 states/s target"
    )


if __name__ == "__main__":
    main()
