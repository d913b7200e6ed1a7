"""Counterfactuals of many decisions in one call (issue 64): the peak resident memory of
``xairl.counterfactual(toy, states, index=None)`` over ``--n`` toy states (the search takes the decisions
:data:`xairl.counterfactuals.search.CHUNK` at a time, so the peak does not grow with ``--n``; every decision's pair
grids at once took about 1.15 MB a decision: 6,000 states ran out of memory). Goal: 20,000 states within 2 GB.

Run: OMP_NUM_THREADS=1 /usr/bin/time -v .venv/bin/python benchmarks/bench_counterfactual_memory.py --n 20000
"""

import argparse
import resource
import time

import xairl
from xairl.toy import toy_policy


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=20_000, help="toy states searched in one call")
    n = ap.parse_args().n
    policy = toy_policy()
    states, background = policy.background(n, seed=1), policy.background(200, seed=0)
    t0 = time.time()
    found = xairl.counterfactual(policy, states, index=None, background=background)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # kB on Linux
    print(f"{n} states, {sum(r.reachable for r in found)} reachable, {time.time() - t0:.0f} s, peak RSS {peak:.0f} MB")


if __name__ == "__main__":
    main()
