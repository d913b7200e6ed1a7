"""The Ray engine against the local engine on this machine (issue 28): the same 8-64-64-4 MLP x 100 background.

1. deep_shap on N states: wall time of the local streaming engine (torch on all cores) and of Ray with 2 workers
   (one core each, Ray's start-up included); target: Ray <= 1.5 x local. Values compared bit for bit.
2. kernel_shap on M states: Ray with 1 worker and with 2 workers; the speed-up per added worker (target: close to 2
   on 2 cores), and the local engine beside them.

Run: .venv/bin/python benchmarks/bench_ray.py [--states 200000] [--kernel-states 1000]
(the issue's figures: --states 1000000 --kernel-states 10000; about 40 minutes on 2 cores)
"""
import argparse
import tempfile
import time
from pathlib import Path

import numpy as np
from fleet_mlp import make_policy
from xairl.scale import explain_on_ray
from xairl.stream import explain_to_parquet, read_parquet


def timed(fn, *args, **kwargs) -> float:
    t = time.perf_counter()
    fn(*args, **kwargs)
    return time.perf_counter() - t


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--states", type=int, default=200_000)
    ap.add_argument("--kernel-states", type=int, default=1_000, help="0: skip the kernel_shap part")
    ap.add_argument("--chunk-size", type=int, default=50_000)
    args = ap.parse_args()
    policy = make_policy()
    rng = np.random.default_rng(0)
    bg = rng.normal(size=(100, 8)).astype(np.float32)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        np.save(tmp / "s.npy", rng.normal(size=(args.states, 8)).astype(np.float32))
        local = timed(explain_to_parquet, policy, tmp / "s.npy", tmp / "local", background=bg,
                      chunk_size=args.chunk_size, progress=False)
        ray = timed(explain_on_ray, policy, tmp / "s.npy", tmp / "ray", background=bg, chunk_size=args.chunk_size,
                    workers=2)
        same = np.array_equal(read_parquet(tmp / "local" / "explanations.parquet").values,
                              read_parquet(tmp / "ray" / "explanations.parquet").values)
        print(f"deep_shap, {args.states} states: local {local:.1f} s ({args.states / local:,.0f} states/s), Ray with 2 "
              f"workers {ray:.1f} s ({args.states / ray:,.0f} states/s); Ray / local = {ray / local:.2f} (target <= "
              f"1.5); values identical: {same}")
        m = args.kernel_states
        if not m:
            return
        np.save(tmp / "k.npy", rng.normal(size=(m, 8)).astype(np.float32))
        chunk = max(1, m // 8)  # enough chunks to keep 2 workers busy
        one = timed(explain_on_ray, policy, tmp / "k.npy", tmp / "k1", background=bg, method="kernel_shap",
                    chunk_size=chunk, workers=1)
        two = timed(explain_on_ray, policy, tmp / "k.npy", tmp / "k2", background=bg, method="kernel_shap",
                    chunk_size=chunk, workers=2)
        here = timed(explain_to_parquet, policy, tmp / "k.npy", tmp / "k0", background=bg, method="kernel_shap",
                     chunk_size=chunk, progress=False)
        print(f"kernel_shap, {m} states: Ray 1 worker {one:.1f} s, 2 workers {two:.1f} s: speed-up per added worker "
              f"{one / two:.2f}x (ideal 2.00 on 2 cores); local engine {here:.1f} s")


if __name__ == "__main__":
    main()
