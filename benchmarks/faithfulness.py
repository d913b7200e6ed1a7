"""Faithfulness of deep_shap to exact Shapley values on a registered policy with <= 16 features (exact is ground
truth); default: the reference plugin's uav-dqn (13 features) when installed, else the toy.

Per state, for the chosen action: Spearman correlation of the two feature rankings, agreement of the top feature,
overlap of the top 3, and max |difference|.
Run: .venv/bin/python benchmarks/faithfulness.py [--states 100] [--policy NAME]
"""

import argparse

import numpy as np

import xairl
import xairl.registry.plugins


def spearman(a, b):
    ra, rb = np.argsort(np.argsort(a)), np.argsort(np.argsort(b))
    return float(np.corrcoef(ra, rb)[0, 1])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--states", type=int, default=100)
    ap.add_argument("--policy", default=None, help="registered policy (default uav-dqn if installed, else toy)")
    args = ap.parse_args()
    n = args.states
    name = args.policy or ("uav-dqn" if "uav-dqn" in xairl.registry.plugins.registry("policy").names() else "toy")
    p = xairl.get_policy(name)
    bg, x = p.background(50, seed=1), p.background(n, seed=3)
    deep = xairl.explain(p, x, background=bg, method="deep_shap")
    # 100 states x 2^13 x 50 rows is over exact's default limit (max_evaluations): a benchmark raises it knowingly
    exact = xairl.explain(p, x, background=bg, method="exact", options={"max_evaluations": 10**10})
    d, e = deep.for_chosen(), exact.for_chosen()
    rho = [spearman(np.abs(d[i]), np.abs(e[i])) for i in range(n)]
    rho_signed = [spearman(d[i], e[i]) for i in range(n)]
    top1 = np.mean([np.argmax(np.abs(d[i])) == np.argmax(np.abs(e[i])) for i in range(n)])
    top3 = np.mean([len(set(np.argsort(-np.abs(d[i]))[:3]) & set(np.argsort(-np.abs(e[i]))[:3])) / 3 for i in range(n)])
    glob = spearman(np.abs(d).mean(0), np.abs(e).mean(0))
    print(
        f"{name}, {n} states, 50 background, chosen action: Spearman of |contribution| rankings median "
        f"{np.median(rho):.3f} (mean {np.mean(rho):.3f}, min {np.min(rho):.3f}); signed values median "
        f"{np.median(rho_signed):.3f}; same top feature {100 * top1:.0f} %; top-3 overlap {100 * top3:.0f} %; "
        f"global importance ranking Spearman {glob:.3f}; max |deep_shap - exact| {np.abs(d - e).max():.3f} "
        f"(mean |exact| {np.abs(e).mean():.3f})"
    )


if __name__ == "__main__":
    main()
