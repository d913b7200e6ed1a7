"""UAV-steps per second of the vectorised TR 36.777 simulator (goal: >= 200k/s on 2 cores), under CHM control,
stepped through the vectorised Gymnasium env as training and evaluation do.

Run: .venv/bin/python plugins/xairl-uav-handover/benchmarks/bench_simulator.py
"""

import os
import platform
import time

import numpy as np

from xairl_uav_handover.baselines import CHM
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.env import HandoverVecEnv

GOAL = 200_000


def rate(n_uavs: int, steps: int, repeats: int = 3) -> float:
    times = []
    for r in range(repeats):
        env = HandoverVecEnv(SimConfig(), n_flights=n_uavs, decision_every=1)
        env.reset(seed=r)
        chm = CHM()
        chm.reset(env)
        t0 = time.perf_counter()
        for _ in range(steps):
            env.step(chm(env))
        times.append(time.perf_counter() - t0)
    return n_uavs * steps / float(np.median(times))


if __name__ == "__main__":
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, numpy {np.__version__}")
    print(f"{'UAVs':>6} {'UAV-steps/s':>14} {'ratio to goal 200k/s':>22}")
    for k in (10, 100, 1000):
        r = rate(k, steps=500 if k <= 100 else 200)
        print(f"{k:>6} {r:>14,.0f} {r / GOAL:>21.2f}x")
