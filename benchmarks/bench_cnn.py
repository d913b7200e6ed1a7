"""deep_shap on image policies vs shap.DeepExplainer and captum DeepLiftShap, and the conformance table.

1. Speed on SB3's NatureCNN (Atari frames (4, 84, 84), 6 actions): 5 states x 10 background and 100 x 100, all
   actions; median of repeats; ratios against shap and captum. Goal (issue 12): >= 10x shap. The "gradient floor"
   column times what no exact method can skip (a plain backward pass per output and pair, no forward, no rules):
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

    print("| network | states x background | xairl deep_shap | shap | captum | vs shap | vs captum | max diff to shap | "
          "gradient floor | most any exact method gains over shap |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for n, b in sizes:
        policy, x, bg, (xt, bt) = build("nature_cnn", n_states=n, n_background=b)
        t_ours, e = timed(lambda: xairl.explain(policy, x, background=bg, method="deep_shap"), repeats)
        net = policy.module
        t_shap, sv = timed(lambda: shap.DeepExplainer(net, bt).shap_values(xt, check_additivity=False), 1)
        # captum expands every state x baseline pair and keeps its hooks' tensors: at 100 x 100 frames it was
        # OOM-killed at 24 GB here even in chunks of 5 states, so it runs up to 1,000 pairs only
        t_cap = float("nan")
        if n * b <= 1000:
            dl = DeepLiftShap(net)
            t_cap, _ = timed(lambda: [dl.attribute(xt, baselines=bt, target=a) for a in range(policy.n_actions)], 1)
        diff = np.abs(e.values - np.asarray(sv).reshape(n, -1, policy.n_actions)).max()
        floor = gradient_floor(policy, x, b)
        print(f"| NatureCNN 4x84x84, 6 actions | {n} x {b} | {t_ours:.2f} s | {t_shap:.2f} s | {t_cap:.2f} s | "
              f"**{t_shap / t_ours:.1f}x** | {t_cap / t_ours:.1f}x | {diff:.1e} | {floor:.2f} s | {t_shap / floor:.1f}x |"
              .replace("nan s", "not run (memory)").replace("nanx", "-"), flush=True)


def gradient_floor(policy, x, b: int) -> float:
    """Seconds for the work no exact DeepSHAP can skip: one plain backward pass per output through the network for
    every (state, background) pair (the multipliers differ per pair), with the forward pass and every DeepLIFT rule
    left out. shap's time over this is the most any exact implementation can gain on this machine."""
    net = policy.network
    flags = [p.requires_grad for p in net.parameters()]
    for p in net.parameters():
        p.requires_grad_(False)
    try:
        total = 0.0
        for s in range(0, len(x), max(1, 1000 // b)):  # the pairs in chunks of about 1,000 rows, as deep_shap does
            rows = torch.as_tensor(x[s:s + max(1, 1000 // b)]).repeat_interleave(b, 0).requires_grad_(True)
            out = net(rows)
            t0 = time.perf_counter()
            for j in range(out.shape[1]):
                torch.autograd.grad(out[:, j].sum(), rows, retain_graph=j + 1 < out.shape[1])
            total += time.perf_counter() - t0
        return total
    finally:
        for p, f in zip(net.parameters(), flags):
            p.requires_grad_(f)


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
        print(f"| {name} | {policy.n_features} | {policy.n_actions} | {e.additivity_gap.max():.1e} | {s:.1e} | {c} |",
              flush=True)


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
