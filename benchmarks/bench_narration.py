"""The verifier on wrong versions of our own narratives: each sentence made wrong in one way (a mutation), and
correct paraphrases. 100 % of mutations caught, 0 correct paraphrases rejected. The corpus covers the policy (two
seeds) and the toy (two seeds). The local language model's figures are benchmarks/bench_lm.py's.
Run: .venv/bin/python benchmarks/bench_narration.py [--policy toy] [--template explain_action] [--states 150]
     [--label-words W,W]
The reference plugin's figures: --policy uav-dqn --template handover --label-words BS,candidate
"""

import argparse
import time

import xairl
from xairl.testing import corpus


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--states", type=int, default=150)
    ap.add_argument("--policy", default="toy", help="a registered policy")
    ap.add_argument("--template", default="explain_action")
    ap.add_argument("--label-words", default="", help="words followed by an identifier in the policy's narratives")
    ap.add_argument("--verifier-only", action="store_true", help="(the default; kept for old command lines)")
    args = ap.parse_args()
    label_words = tuple(w for w in args.label_words.split(",") if w)
    verifier_corpus(args.policy, args.template, label_words, args.states)


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
