"""What exact's default limit (ExactOptions.max_evaluations, 2^24 network evaluations) costs on a few Q-networks over
a 16-feature window (4 steps x 4 signals): one state against 256 background rows, exactly the limit's worth. Each
network runs in its own process so that its peak resident memory is its own.

Run: OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_exact_limit.py
"""

import argparse
import resource
import subprocess
import sys
import time

import numpy as np
import torch

import xairl
from xairl.attributors.exact import MAX_EVALUATIONS, Exact

NETS = ("mlp 16-32-32-4", "mlp 16-120-84-4", "mlp 16-256-256-4", "gru 64", "lstm 64")


class Recurrent(torch.nn.Module):
    def __init__(self, cell: str, hidden: int):
        super().__init__()
        self.rnn = {"gru": torch.nn.GRU, "lstm": torch.nn.LSTM}[cell](4, hidden, batch_first=True)
        self.head = torch.nn.Linear(hidden, 4)

    def forward(self, x):
        return self.head(self.rnn(x)[0][:, -1])


def build(name: str) -> torch.nn.Module:
    torch.manual_seed(0)
    kind, size = name.split()
    if kind != "mlp":
        return Recurrent(kind, int(size))
    sizes = [int(s) for s in size.split("-")]
    layers = [torch.nn.Flatten()]
    for i, (a, b) in enumerate(zip(sizes[:-1], sizes[1:])):
        layers += [torch.nn.Linear(a, b)] + [torch.nn.ReLU()] * (i < len(sizes) - 2)
    return torch.nn.Sequential(*layers)


def one(name: str) -> None:
    policy = xairl.Policy(build(name).eval(), feature_names=[f"f{i}" for i in range(16)], observation=(4, 4))
    r = np.random.default_rng(0)
    x, bg = r.normal(size=(1, 16)).astype(np.float32), r.normal(size=(256, 16)).astype(np.float32)
    cost = Exact().cost(policy, 1, 256)
    t = time.perf_counter()
    xairl.explain(policy, x, background=bg, method="exact")
    dt = time.perf_counter() - t
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e3
    print(
        f"{name:<18} {cost.evaluations:>12,} {dt:>8.1f} {cost.evaluations / dt / 1e6:>8.2f} {cost.bytes / 1e6:>12.1f} "
        f"{peak:>10.0f}",
        flush=True,
    )


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--net", choices=NETS)
    args = ap.parse_args()
    if args.net:
        return one(args.net)
    print(
        f"torch {torch.__version__}, {torch.get_num_threads()} thread(s); default max_evaluations {MAX_EVALUATIONS:,}"
    )
    print(f"{'network':<18} {'evaluations':>12} {'seconds':>8} {'M rows/s':>8} {'batches MB':>12} {'peak MB':>10}")
    for name in NETS:
        subprocess.run([sys.executable, __file__, "--net", name], check=True)


if __name__ == "__main__":
    main()
