"""deep_shap on image policies vs shap.DeepExplainer and captum DeepLiftShap, and the conformance table.

1. Speed on SB3's NatureCNN (Atari frames (4, 84, 84), 6 actions): 5 states x 10 background and 100 x 100, all
   actions; median of repeats; ratios against shap and captum. Goal (issue 12): >= 10x shap. The "gradient floor"
   column is the time deep_shap spends in what no exact method can skip (a backward pass per output and pair):
   shap's time over it bounds what any exact DeepSHAP can gain on this machine.
2. Conformance: max |xairl - shap| and |xairl - captum| and the additivity gap on every network of shap's own
   DeepExplainer tests (rebuilt in tests/deep_models.py), NatureCNN, and dict / multi-input networks.
Run: .venv/bin/python benchmarks/bench_cnn.py [--sizes 5x10,100x100] [--repeats 3] [--skip-table]
(100 x 100 takes ~2.5 min: ~1 min xairl, ~1.5 min shap)
"""

import argparse
import os
import sys
import time

import numpy as np
import torch

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))
import xairl  # noqa: E402
from tests.deep_models import NAMES, build, captum_values, shap_values  # noqa: E402


def timed(fn, repeats):
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return float(np.median(times)), out


def speed(sizes, repeats):
    import shap
    from captum.attr import DeepLiftShap

    print(
        "| network | states x background | xairl deep_shap | shap | captum | vs shap | vs captum | max diff to shap | "
        "gradient floor | most any exact method gains over shap |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for n, b in sizes:
        policy, x, bg, (xt, bt) = build("nature_cnn", n_states=n, n_background=b)
        t_ours, e = timed(lambda: xairl.explain(policy, x, background=bg, method="deep_shap"), repeats)
        floor = gradient_floor(policy, x, bg)
        net = policy.module
        t_shap, sv = timed(lambda: shap.DeepExplainer(net, bt).shap_values(xt, check_additivity=False), 1)
        # captum expands every state x baseline pair and keeps its hooks' tensors: at 100 x 100 frames it was
        # OOM-killed at 24 GB here even in chunks of 5 states, so it runs up to 1,000 pairs only
        t_cap = float("nan")
        if n * b <= 1000:
            dl = DeepLiftShap(net)
            t_cap, _ = timed(lambda: [dl.attribute(xt, baselines=bt, target=a) for a in range(policy.n_actions)], 1)
        diff = np.abs(e.values - np.asarray(sv).reshape(n, -1, policy.n_actions)).max()
        print(
            f"| NatureCNN 4x84x84, 6 actions | {n} x {b} | {t_ours:.2f} s | {t_shap:.2f} s | {t_cap:.2f} s | "
            f"**{t_shap / t_ours:.1f}x** | {t_cap / t_ours:.1f}x | {diff:.1e} | {floor:.2f} s | {t_shap / floor:.1f}x |".replace(
                "nan s", "not run (memory)"
            ).replace("nanx", "-"),
            flush=True,
        )


def gradient_floor(policy, x, bg) -> float:
    """Seconds deep_shap spends in the work no exact DeepSHAP can skip: the backward passes, one per output through
    the network for every (state, background) pair (the multipliers differ per pair), timed inside one deep_shap run
    (timings on this machine vary by tens of percent from run to run, so the floor is taken from the same run).
    shap's time over it bounds what any exact implementation can gain here."""
    grad, spent = torch.autograd.grad, [0.0]

    def timed_grad(*args, **kwargs):
        t0 = time.perf_counter()
        try:
            return grad(*args, **kwargs)
        finally:
            spent[0] += time.perf_counter() - t0

    torch.autograd.grad = timed_grad
    try:
        xairl.explain(policy, x, background=bg, method="deep_shap")
    finally:
        torch.autograd.grad = grad
    return spent[0]


def table():
    print("\n| network | features | outputs | additivity gap | max diff to shap | max diff to captum |")
    print("|---|---|---|---|---|---|")
    for name in NAMES:
        policy, x, bg, inputs = build(name)
        e = xairl.explain(policy, x, background=bg, method="deep_shap")
        s = np.abs(e.values - shap_values(policy, inputs)).max()
        try:
            c = f"{np.abs(e.values - captum_values(policy, x, bg)).max():.1e}"
        except RuntimeError as exc:  # captum refuses an input the network does not use
            c = f"captum refuses ({str(exc).split('.')[0]})"
        print(
            f"| {name} | {policy.n_features} | {policy.n_actions} | {e.additivity_gap.max():.1e} | {s:.1e} | {c} |",
            flush=True,
        )


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", default="5x10,100x100")
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--skip-table", action="store_true")
    args = ap.parse_args()
    torch.set_num_threads(int(os.environ.get("OMP_NUM_THREADS", torch.get_num_threads())))
    print(f"torch {torch.__version__}, {torch.get_num_threads()} threads, CPU")
    speed([tuple(int(v) for v in s.split("x")) for s in args.sizes.split(",")], args.repeats)
    if not args.skip_table:
        table()


if __name__ == "__main__":
    import warnings

    warnings.filterwarnings("ignore")
    main()
