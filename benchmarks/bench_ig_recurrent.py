"""Integrated Gradients (and KernelSHAP, DeepSHAP) against exact Shapley values on recurrent Q-networks (issue 55).

A CleanRL-style Q-network over the last k = 4 observations of 4 signals, as a GRU, an LSTM, and an MLP over the same
window for comparison: 16 features, so exact (2^16 coalitions per state) is the ground truth. Each network is first
fitted for a few hundred steps to a synthetic Q-function with thresholds, trends and products of signals (a network
at its random initialisation is nearly linear, which flatters IG). Windows are AR(1) walks, correlated in time as
observations are.

IG integrates gradients along one path from the background mean; exact Shapley averages over every coalition of the
background; a recurrent network multiplies its inputs by gates that themselves depend on the inputs, so the two can
differ more than on an MLP. DeepSHAP refuses GRU and LSTM layers (UnsupportedModelError) rather than give wrong
numbers. This prints, per network, the error relative to the exact values' scale on the margin view (chosen action
minus runner-up): max |method - exact| / max |exact|, the mean of the same per state, the same on contributions summed
per signal over the 4 steps, how often the top feature agrees, and the seconds each method took.

Run: OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_ig_recurrent.py [--states 30] [--background 20] [--seeds 3]
"""

import argparse
import platform
import time

import numpy as np
import torch

import xairl
from xairl.errors import UnsupportedModelError

K, S, A, HIDDEN = 4, 4, 4, 32  # steps, signals, actions, hidden units
NAMES = [f"{s}_t-{K - 1 - t}" for t in range(K) for s in ("rsrp", "rsrq", "load", "speed")]  # time-major
METHODS = ("integrated_gradients", "kernel_shap", "deep_shap")


class RecurrentQ(torch.nn.Module):
    """(batch, k, signals) -> Q-values (batch, actions) from the last hidden state."""

    def __init__(self, cell: str):
        super().__init__()
        self.rnn = {"gru": torch.nn.GRU, "lstm": torch.nn.LSTM}[cell](S, HIDDEN, batch_first=True)
        self.head = torch.nn.Sequential(torch.nn.Linear(HIDDEN, 64), torch.nn.ReLU(), torch.nn.Linear(64, A))

    def forward(self, x):
        return self.head(self.rnn(x)[0][:, -1])


def network(kind: str, seed: int) -> torch.nn.Module:
    torch.manual_seed(seed)
    if kind == "mlp":
        return torch.nn.Sequential(
            torch.nn.Flatten(), torch.nn.Linear(K * S, 64), torch.nn.ReLU(), torch.nn.Linear(64, 64), torch.nn.ReLU(),
            torch.nn.Linear(64, A),
        )  # fmt: skip
    return RecurrentQ(kind)


def windows(rng, n: int) -> np.ndarray:
    """AR(1) walks: each signal's step t is 0.8 of step t-1 plus noise, unit variance throughout."""
    x = np.empty((n, K, S), dtype=np.float32)
    x[:, 0] = rng.normal(size=(n, S))
    for t in range(1, K):
        x[:, t] = 0.8 * x[:, t - 1] + 0.6 * rng.normal(size=(n, S))
    return x


def target(x: torch.Tensor) -> torch.Tensor:
    """A Q-function with a threshold, a gated trend, a rectified mean and a product of signals."""
    last, first = x[:, -1], x[:, 0]
    return torch.stack(
        [
            torch.tanh(2 * last[:, 0]) + 0.5 * last[:, 1],
            (last[:, 1] - first[:, 1]) * (last[:, 2] > 0),
            torch.relu(x[:, :, 3].mean(dim=1)) - 0.5 * last[:, 0].abs(),
            last[:, 2] * last[:, 3],
        ],
        dim=1,
    )


def fit(net: torch.nn.Module, seed: int, steps: int) -> float:
    """A few hundred Adam steps on fresh windows; returns the final mean squared error."""
    rng = np.random.default_rng(1000 + seed)
    opt = torch.optim.Adam(net.parameters(), lr=3e-3)
    net.train()
    loss = torch.tensor(float("nan"))  # 0 steps: the network at its random initialisation
    for _ in range(steps):
        x = torch.as_tensor(windows(rng, 256))
        loss = torch.nn.functional.mse_loss(net(x), target(x))
        opt.zero_grad()
        loss.backward()
        opt.step()
    return loss.item()


def compare(kind: str, seed: int, n: int, m: int, steps: int) -> dict:
    net = network(kind, seed)
    mse = fit(net, seed, steps)
    policy = xairl.Policy(net.eval(), feature_names=NAMES, action_names=[f"a{i}" for i in range(A)], observation=(K, S))
    rng = np.random.default_rng(seed)
    bg, x = windows(rng, m), windows(rng, n)
    t = time.perf_counter()
    truth = xairl.explain(policy, x, background=bg, method="exact", options={"max_evaluations": 10**10}).margin()
    out = {"exact": time.perf_counter() - t, "mse": mse}
    for method in METHODS:
        t = time.perf_counter()
        try:
            got = xairl.explain(policy, x, background=bg, method=method).margin()
        except UnsupportedModelError:
            out[method] = None  # deep_shap: GRU and LSTM layers are refused, not approximated
            continue
        out[method] = errors(got, truth) + (time.perf_counter() - t,)
    return out


def errors(got: np.ndarray, truth: np.ndarray) -> tuple:
    """Largest and mean-per-state error over max |exact|, the same per signal (summed over the k steps), top-1."""
    per_signal = lambda v: v.reshape(len(v), K, S).sum(axis=1)  # noqa: E731 (time-major columns)
    g, e = per_signal(got), per_signal(truth)
    return (
        float(np.abs(got - truth).max() / np.abs(truth).max()),
        float(np.mean(np.abs(got - truth).max(axis=1) / np.abs(truth).max(axis=1))),
        float(np.abs(g - e).max() / np.abs(e).max()),
        float(np.mean(np.abs(got).argmax(1) == np.abs(truth).argmax(1))),
    )


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--states", type=int, default=30)
    ap.add_argument("--background", type=int, default=20)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--fit-steps", type=int, default=400)
    args = ap.parse_args()
    print(
        f"{platform.processor() or platform.machine()}, torch {torch.__version__}, {torch.get_num_threads()} thread(s)"
    )
    print(
        f"Q-networks over k={K} steps x {S} signals (16 features; GRU/LSTM {HIDDEN} units + 64-unit head, MLP "
        f"16-64-64-4), fitted {args.fit_steps} steps; {args.states} states x {args.background} background, "
        f"{args.seeds} seeds; margin (chosen - runner-up); error relative to max |exact|; kernel_shap nsamples auto"
    )
    head = f"{'network':<8} {'method':<21} {'max rel. error':>14} {'mean per state':>14} {'per signal':>10}"
    print(f"{head} {'same top':>8} {'seconds':>8}")
    for kind in ("gru", "lstm", "mlp"):
        runs = [compare(kind, s, args.states, args.background, args.fit_steps) for s in range(args.seeds)]
        print(
            f"{kind:<8} {'exact (reference)':<21} {'':>14} {'':>14} {'':>10} {'':>8} {sum(r['exact'] for r in runs):>8.1f}"
        )
        for method in METHODS:
            if any(r[method] is None for r in runs):
                print(f"{kind:<8} {method:<21} refused (UnsupportedModelError)")
                continue
            worst = max(r[method][0] for r in runs)
            mean, sig = np.mean([r[method][1] for r in runs]), max(r[method][2] for r in runs)
            top, secs = np.mean([r[method][3] for r in runs]), sum(r[method][4] for r in runs)
            print(f"{kind:<8} {method:<21} {worst:>14.3f} {mean:>14.3f} {sig:>10.3f} {100 * top:>7.0f}% {secs:>8.1f}")
        if args.fit_steps == 0:
            continue
        mses = ", ".join(f"{r['mse']:.3f}" for r in runs)
        print(f"{kind:<8} fit: final mean squared error {mses} (variance of the target per action 0.35-1.0)")


if __name__ == "__main__":
    main()
