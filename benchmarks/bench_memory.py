"""Peak resident memory of deep_shap on 100k states x 100 background states. Goal: <= 2 GB.

The policy is a registered one (default: the reference plugin's uav-dqn when installed, else the toy).
Each measurement runs in a fresh process; 'baseline' is the same process doing everything except the attribution.
Run: .venv/bin/python benchmarks/bench_memory.py [--states 100000] [--policy NAME]
"""

import argparse
import subprocess
import sys

CODE = """
import resource, time, numpy as np, xairl
p = xairl.get_policy({policy!r}); bg = p.background(100, seed=1)
x = np.repeat(p.background(1000, seed=2), {rep}, axis=0)
t = time.perf_counter()
if {run}:
    e = xairl.explain(p, x, background=bg, method="deep_shap")
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, time.perf_counter() - t)
"""


def peak(states: int, run: bool, policy: str):
    out = subprocess.run(
        [sys.executable, "-c", CODE.format(rep=states // 1000, run=run, policy=policy)],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    return float(out[0]), float(out[1])


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--states", type=int, default=100_000)
    ap.add_argument("--policy", default=None, help="registered policy (default uav-dqn if installed, else toy)")
    args = ap.parse_args()
    import xairl.registry.plugins

    name = args.policy or ("uav-dqn" if "uav-dqn" in xairl.registry.plugins.registry("policy").names() else "toy")
    n = args.states
    base, _ = peak(n, False, name)
    mem, secs = peak(n, True, name)
    print(
        f"deep_shap on {name}, {n} states x 100 background, all actions: peak RSS {mem:.0f} MB (process without the "
        f"attribution: {base:.0f} MB; attribution adds {mem - base:.0f} MB) in {secs:.1f} s; goal 2048 MB: "
        f"{mem / 2048:.2f} of it"
    )
