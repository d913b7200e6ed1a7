"""Does the confidence score order narratives usefully? (issue 14)

On states of each registered policy named with ``--policy`` (default: the toy policy and, when its plugin is
installed, the UAV reference DQN), drawn from the policy's own sampler, for each state: the verified ``explain_action`` narrative;
the same text with one number made wrong (contradicted); the same text padded with sentences nobody can check (low
coverage). It prints the mean confidence of each kind, the share of pairs ordered right (AUC: a fully checked true
text above its contradicted / low-coverage twin), and how confidence follows the decision's clarity: the mean
confidence of the nearest-tie quarter of decisions against the clearest quarter, and their Spearman correlation.

    .venv/bin/python benchmarks/bench_confidence.py [--n 200] [--robustness] [--policy NAME ...]
"""

from __future__ import annotations

import argparse
import re

import numpy as np
from scipy.stats import spearmanr

import xairl
from xairl.narrators.confidence import confidence

VAGUE = " The situation looked delicate. Operators should keep an eye on this kind of state."


def _wrong_number(text: str) -> str:
    m = re.search(r"by ([+-]?)(\d+\.\d+)", text)
    return text[: m.start(2)] + f"{float(m.group(2)) * 3 + 1:.2f}" + text[m.end(2) :] if m else text + " It scored 999."


def auc(hi: list[float], lo: list[float]) -> float:
    return float(np.mean([(a > b) + 0.5 * (a == b) for a, b in zip(hi, lo)]))


def run(label: str, policy, states, bg, robustness: bool) -> None:
    exp = xairl.explain(policy, states, background=bg)
    how = xairl.NarrationOptions(policy=policy, background=bg, robustness=robustness)
    true, wrong, vague, margins = [], [], [], []
    for i in range(len(states)):
        n = xairl.narrate(exp, i, narration=how)
        true.append(n.confidence)
        for text, out in ((_wrong_number(n.text), wrong), (n.text + VAGUE, vague)):
            v = xairl.verify(text, exp, i, policy)
            out.append(confidence(exp, i, v.ok, how, coverage=v.coverage)[0])
        c, r = exp.chosen[i], exp.runner_up[i]
        margins.append(float(exp.outputs[i, c] - exp.outputs[i, r]))
    margins, true = np.array(margins), np.array(true)
    q1, q3 = np.quantile(margins, [0.25, 0.75])
    rho = spearmanr(margins, true).statistic
    print(
        f"{label:<8}{len(states):>5}{np.mean(true):>10.3f}{np.mean(wrong):>13.3f}{np.mean(vague):>13.3f}"
        f"{auc(true, wrong):>11.2f}{auc(true, vague):>11.2f}{true[margins <= q1].mean():>12.3f}"
        f"{true[margins >= q3].mean():>10.3f}{rho:>8.2f}"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--robustness", action="store_true", help="include agreement and stability (slower)")
    ap.add_argument("--policy", action="append", help="a registered policy (repeatable; default: toy, uav-dqn)")
    args = ap.parse_args()
    print(
        f"{'policy':<8}{'n':>5}{'true text':>10}{'contradicted':>13}{'low coverage':>13}{'AUC t>c':>11}"
        f"{'AUC t>low':>11}{'near ties':>12}{'clearest':>10}{'rho':>8}"
    )
    for name in args.policy or ["toy", "uav-dqn"]:
        try:
            policy = xairl.get_policy(name)  # through the plugin registry: the core imports no plugin
        except xairl.plugin.UnknownNameError:
            print(f"{name}: not installed, skipped")
            continue
        run(name, policy, policy.background(args.n, seed=11), policy.background(100, seed=7), args.robustness)


if __name__ == "__main__":
    main()
