"""Narration of the reference UAV DQN: LM verification rate, fallback share, latency, verifier catch rate.

Goals (issue 4): warm latency <= 1.5 s per narrative and cold start <= 5 s on 2 cores; 100 % of mutations caught,
0 correct paraphrases rejected.
Run: .venv/bin/python benchmarks/bench_narration.py [--states 200] [--rewrite-states 50] [--verifier-only]
"""
import argparse
import os
import platform
import subprocess
import sys
import time

import numpy as np

import xairl
from xairl.testing import corpus
from xairl_uav_handover.policy import uav_policy

COLD = ("import time; t = time.perf_counter(); import xairl; from xairl_uav_handover.policy import uav_policy; "
        "p = uav_policy(); e = xairl.explain(p, p.background(1, seed=5), background=p.background(50)); "
        "n = xairl.narrate(e, 0, narrator='local_lm', policy=p); print(time.perf_counter() - t, n.verified)")


def run_mode(exp, policy, mode, n_states, template):
    times, first_try, fallback = [], 0, 0
    for i in range(n_states):
        t0 = time.perf_counter()
        n = xairl.narrate(exp, i, narrator="local_lm", policy=policy, template=template, options={"mode": mode})
        times.append(time.perf_counter() - t0)
        first_try += n.source == "local_lm"
        fallback += n.source.startswith("template (fallback")
        assert n.verified, n
    return np.array(times), first_try, fallback


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--states", type=int, default=200)
    ap.add_argument("--rewrite-states", type=int, default=50)
    ap.add_argument("--template", default="handover")
    ap.add_argument("--verifier-only", action="store_true", help="only the verifier's mutation corpus")
    args = ap.parse_args()
    if args.verifier_only:
        return verifier_corpus(args.states)
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores; policy uav-dqn; template {args.template}")
    policy = uav_policy()
    exp = xairl.explain(policy, policy.background(args.states, seed=21), background=policy.background(100))
    xairl.narrate(exp, 0, narrator="local_lm", policy=policy)  # converts the model once (not timed as cold start)
    cold = subprocess.run([sys.executable, "-c", COLD], capture_output=True, text=True, check=True).stdout.split()
    print(f"cold start (new process: imports, model load from the cached copy, one narrative): {float(cold[0]):.2f} s"
          f" (goal 5 s: {float(cold[0]) / 5:.2f} of it)")
    for mode, n in (("choose", args.states), ("rewrite", args.rewrite_states)):
        t, ok, fb = run_mode(exp, policy, mode, n, args.template)
        print(f"local_lm mode={mode:<8} states {n:>4}: verified on first try {100 * ok / n:5.1f} %, fallback "
              f"{100 * fb / n:5.1f} %, warm latency median {np.median(t):.2f} s, p90 {np.percentile(t, 90):.2f} s "
              f"(goal 1.5 s: {np.median(t) / 1.5:.2f} of it)")
    verifier_corpus(min(args.states, 150))


def verifier_corpus(n_states: int) -> None:
    """Mutations and paraphrases of real narratives: reference DQN (two seeds) and the toy policy (two seeds)."""
    from xairl.toy import toy_policy

    caught = wrong = rejected = right = 0
    t0 = time.perf_counter()
    for policy, seed in ((uav_policy(), 21), (uav_policy(), 5), (toy_policy(), 3), (toy_policy(), 8)):
        exp = xairl.explain(policy, policy.background(n_states, seed=seed), background=policy.background(100))
        names = ("explain_action", "why_not") + (("handover",) if policy.name == "uav-dqn" else ())
        for c in corpus(exp, policy, names, range(n_states)):
            ok = xairl.verify(c.text, exp, c.index, policy).ok
            if c.should_pass:
                right, rejected = right + 1, rejected + (not ok)
            else:
                wrong, caught = wrong + 1, caught + (not ok)
    print(f"verifier: {caught}/{wrong} mutations caught ({100 * caught / wrong:.2f} %), {rejected}/{right} correct "
          f"paraphrases rejected; {1000 * (time.perf_counter() - t0) / (wrong + right):.1f} ms/text")

if __name__ == "__main__":
    main()
