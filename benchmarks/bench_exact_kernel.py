"""Cost of exact (all 2^F coalitions) and kernel_shap (shap, nsamples auto) vs the number of features F.

Run: .venv/bin/python benchmarks/bench_exact_kernel.py
"""

import time

import numpy as np
import torch

import xairl


def main():
    print(f"{'F':>3}{'exact s/state':>15}{'kernel s/state':>16}{'max|exact-kernel|':>19}")
    for f in (4, 8, 12, 16):
        torch.manual_seed(f)
        net = torch.nn.Sequential(
            torch.nn.Linear(f, 32), torch.nn.ReLU(), torch.nn.Linear(32, 32), torch.nn.ReLU(), torch.nn.Linear(32, 4)
        ).eval()
        p = xairl.Policy(net, [f"f{i}" for i in range(f)], list("abcd"))
        r = np.random.default_rng(f)
        x, bg = r.normal(size=(4, f)), r.normal(size=(50, f))
        t0 = time.perf_counter()
        ex = xairl.explain(p, x, background=bg, method="exact").values
        t1 = time.perf_counter()
        ks = xairl.explain(p, x, background=bg, method="kernel_shap").values
        t2 = time.perf_counter()
        print(f"{f:>3}{(t1 - t0) / 4:>15.3f}{(t2 - t1) / 4:>16.3f}{np.abs(ex - ks).max():>19.1e}")


if __name__ == "__main__":
    main()
