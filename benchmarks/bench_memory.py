"""Peak resident memory of deep_shap on 100k states x 100 background states (reference DQN). Goal: <= 2 GB.

Each measurement runs in a fresh process; 'baseline' is the same process doing everything except the attribution.
Run: .venv/bin/python benchmarks/bench_memory.py [--states 100000]
"""
import argparse
import subprocess
import sys

CODE = """
import resource, time, numpy as np, xairl
from xairl_uav_handover.policy import uav_policy
p = uav_policy(); bg = p.background(100, seed=1)
x = np.repeat(p.background(1000, seed=2), {rep}, axis=0)
t = time.perf_counter()
if {run}:
    e = xairl.explain(p, x, background=bg, method="deep_shap")
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, time.perf_counter() - t)
"""


def peak(states: int, run: bool):
    out = subprocess.run([sys.executable, "-c", CODE.format(rep=states // 1000, run=run)], capture_output=True,
                         text=True, check=True).stdout.split()
    return float(out[0]), float(out[1])


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--states", type=int, default=100_000)
    n = ap.parse_args().states
    base, _ = peak(n, False)
    mem, secs = peak(n, True)
    print(f"deep_shap, {n} states x 100 background, 4 actions: peak RSS {mem:.0f} MB (process without the "
          f"attribution: {base:.0f} MB; attribution adds {mem - base:.0f} MB) in {secs:.1f} s; goal 2048 MB: "
          f"{mem / 2048:.2f} of it")
