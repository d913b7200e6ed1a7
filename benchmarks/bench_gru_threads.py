"""The memory doc's GRU (4 signals x 4 steps, 32 units) explained and narrated, timed: issue 64's "a GRU narration takes
35 s" and "one state took 37 s with torch's 2 threads and 7.4 s with one". Attributions now run a small network on
one torch thread (xairl.policies.network.torch_threads); run this with torch's default threads (no OMP_NUM_THREADS) on the
code before and after to compare.

Run: env -u OMP_NUM_THREADS .venv/bin/python benchmarks/bench_gru_threads.py [--background 20]
"""

import argparse
import time

import numpy as np
import torch

import xairl

SIGNALS = ["cart_position", "cart_velocity", "pole_angle", "pole_velocity"]


class GRUQ(torch.nn.Module):
    def __init__(self):
        super().__init__()
        self.gru = torch.nn.GRU(len(SIGNALS), 32, batch_first=True)
        self.head = torch.nn.Linear(32, 2)

    def forward(self, window):
        return self.head(self.gru(window)[0][:, -1])


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--background", type=int, default=20)
    args = ap.parse_args()
    torch.manual_seed(0)
    policy = xairl.Policy(GRUQ(), SIGNALS, ["left", "right"], window=4)
    rng = np.random.default_rng(0)
    states, bg = rng.normal(size=(3, 4, 4)) * 0.1, rng.normal(size=(args.background, 4, 4)) * 0.1
    warm = xairl.explain(policy, states[:1], background=bg[:5], method="kernel_shap", options={"nsamples": 50})
    xairl.narrate(warm, 0, policy=policy, robustness=False)  # shap's import and the verifier's pipeline, unclocked
    print(f"torch threads outside attributions: {torch.get_num_threads()}")
    for method, options in (("kernel_shap", {"nsamples": 600}), ("exact", {})):
        t0 = time.perf_counter()
        exp = xairl.explain(policy, states[:1], background=bg, method=method, options=options)
        t1 = time.perf_counter()
        n = xairl.narrate(exp, 0, policy=policy, background=bg)  # with robustness: three more explanations
        t2 = time.perf_counter()
        print(f"{method}: explain one state {t1 - t0:.1f} s, its narration {t2 - t1:.1f} s (verified {n.verified})")


if __name__ == "__main__":
    main()
