"""Narration of a registered policy: LM verification rate, fallback share, latency, verifier catch rate.

Goals (issue 4): warm latency <= 1.5 s per narrative and cold start <= 5 s on 2 cores; 100 % of mutations caught,
0 correct paraphrases rejected. The verifier corpus covers the policy (two seeds) and the toy (two seeds).
Run: .venv/bin/python benchmarks/bench_narration.py [--policy toy] [--template explain_action] [--states 200]
     [--rewrite-states 50] [--verifier-only] [--label-words W,W]
The reference plugin's figures: --policy uav-dqn --template handover --label-words BS,candidate
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

COLD = (
    "import time; t = time.perf_counter(); import xairl; p = xairl.get_policy({policy!r}); "
    "e = xairl.explain(p, p.background(1, seed=5), background=p.background(50)); "
    "n = xairl.narrate(e, 0, narrator='local_lm', policy=p); print(time.perf_counter() - t, n.verified)"
)


def run_mode(exp, policy, mode, n_states, template):
    """Latencies, first-try verified count, fallbacks, and the coverage of the model's own text (the share of its
    sentences with a checked claim, whether it was shown or rejected)."""
    times, first_try, fallback, coverage = [], 0, 0, []
    for i in range(n_states):
        t0 = time.perf_counter()
        n = xairl.narrate(exp, i, narrator="local_lm", policy=policy, template=template, options={"mode": mode})
        times.append(time.perf_counter() - t0)
        first_try += n.source == "local_lm"
        fallback += n.source.startswith("template (fallback")
        own = n.text if n.source == "local_lm" else n.rejected
        if own is not None:
            coverage.append(xairl.verify(own, exp, i, policy).coverage)
        assert n.verified, n
    return np.array(times), first_try, fallback, np.array(coverage)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--states", type=int, default=200)
    ap.add_argument("--rewrite-states", type=int, default=50)
    ap.add_argument("--policy", default="toy", help="a registered policy")
    ap.add_argument("--template", default="explain_action")
    ap.add_argument("--label-words", default="", help="words followed by an identifier in the policy's narratives")
    ap.add_argument("--verifier-only", action="store_true", help="only the verifier's mutation corpus")
    args = ap.parse_args()
    label_words = tuple(w for w in args.label_words.split(",") if w)
    if args.verifier_only:
        return verifier_corpus(args.policy, args.template, label_words, args.states)
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores; policy {args.policy}; template {args.template}")
    policy = xairl.get_policy(args.policy)
    exp = xairl.explain(policy, policy.background(args.states, seed=21), background=policy.background(100))
    xairl.narrate(exp, 0, narrator="local_lm", policy=policy)  # converts the model once (not timed as cold start)
    cold = subprocess.run(
        [sys.executable, "-c", COLD.format(policy=args.policy)], capture_output=True, text=True, check=True
    ).stdout.split()
    print(
        f"cold start (new process: imports, model load from the cached copy, one narrative): {float(cold[0]):.2f} s"
        f" (goal 5 s: {float(cold[0]) / 5:.2f} of it)"
    )
    for mode, n in (("choose", args.states), ("rewrite", args.rewrite_states)):
        t, ok, fb, cov = run_mode(exp, policy, mode, n, args.template)
        print(
            f"local_lm mode={mode:<8} states {n:>4}: verified on first try {100 * ok / n:5.1f} %, fallback "
            f"{100 * fb / n:5.1f} %, coverage of the model's text mean {cov.mean() if len(cov) else 0:.2f} "
            f"(full in {100 * np.mean(cov == 1) if len(cov) else 0:.0f} %), warm latency median {np.median(t):.2f} s, "
            f"p90 {np.percentile(t, 90):.2f} s (goal 1.5 s: {np.median(t) / 1.5:.2f} of it)"
        )
    verifier_corpus(args.policy, args.template, label_words, min(args.states, 150))


def verifier_corpus(name: str, template: str, label_words: tuple[str, ...], n_states: int) -> None:
    """Mutations and paraphrases of real narratives: the policy (two seeds) and the toy policy (two seeds)."""
    caught = wrong = rejected = right = 0
    t0 = time.perf_counter()
    runs = [(name, 21, template), (name, 5, template), ("toy", 3, "explain_action"), ("toy", 8, "explain_action")]
    for policy_name, seed, tpl in runs:
        policy = xairl.get_policy(policy_name)
        exp = xairl.explain(policy, policy.background(n_states, seed=seed), background=policy.background(100))
        names = tuple(dict.fromkeys(("explain_action", "why_not", tpl)))
        words = label_words if policy_name == name else ()
        for c in corpus(exp, policy, names, range(n_states), label_words=words):
            ok = xairl.verify(c.text, exp, c.index, policy).ok
            if c.should_pass:
                right, rejected = right + 1, rejected + (not ok)
            else:
                wrong, caught = wrong + 1, caught + (not ok)
    print(
        f"verifier: {caught}/{wrong} mutations caught ({100 * caught / wrong:.2f} %), {rejected}/{right} correct "
        f"paraphrases rejected; {1000 * (time.perf_counter() - t0) / (wrong + right):.1f} ms/text"
    )


if __name__ == "__main__":
    main()
