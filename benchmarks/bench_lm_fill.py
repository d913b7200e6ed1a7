"""local_lm's fill mode (issue 52, "Done when" item 3): how often its words are accepted on the first try, how long a
narrative takes, and the accepted texts with their facts beside them, for a check by hand.

For each policy (the toy policy with ``explain_action``, the reference UAV policy ``uav-dqn`` with ``handover``) and
``--states`` decisions: ``xairl.narrate(..., narrator="local_lm")`` in its default mode (fill), warm. A narrative is
accepted on the first try when its source is ``local_lm`` and ``extras["tries"] == 1``; accepted at all when its
source is ``local_lm``; otherwise the template was shown. An accepted text may keep the template's words in some or
all of its sentences (the model copied them, or its rewording of them was refused); the sentences it reworded are
counted apart. ``--out`` writes a Markdown file with every accepted text,
the template's text and the decision's facts (the action, the scores, every feature's value and contribution in the
margin view), which is what a person checks the words against.

Run (about 5 minutes on 2 cores; nothing is downloaded):
    HF_HUB_OFFLINE=1 OMP_NUM_THREADS=2 .venv/bin/python benchmarks/bench_lm_fill.py [--states 20] [--threads 2]
        [--out /tmp/lm_fill.md]
"""

import argparse
import os
import statistics
import time

os.environ.setdefault("HF_HUB_OFFLINE", "1")
os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")

import xairl  # noqa: E402

POLICIES = (("toy", "explain_action"), ("uav-dqn", "handover"))


def facts_table(exp, i, policy) -> str:
    """The decision's facts as a person checks the words against them."""
    f = xairl.facts.decision_facts(exp, i, policy, k=len(exp.feature_names))
    rows = [
        f"- chosen **{f.action}** (score {f.score:.4g}), runner-up **{f.runner_up}** (score "
        f"{f.runner_up_score:.4g}), margin {f.q_margin:.4g}, base margin {f.base_margin:.4g}"
    ]
    rows += [
        f"- {g.label}: value {g.value_text or g.value}, level {g.level_text or g.level}, to the margin "
        f"{g.contribution:+.4g} (rank {g.rank})"
        for g in f.margin_top
    ]
    rows += [f"- {c.text}" for c in f.comparisons]
    return "\n".join(rows)


def run(name: str, template: str, states: int, threads: int) -> tuple[dict, list[str]]:
    policy = xairl.get_policy(name)
    exp = xairl.explain(policy, policy.background(states, seed=7), background=policy.background(60))
    options = {"threads": threads}
    xairl.narrate(exp, 0, narrator="local_lm", policy=policy, template=template, options=options, robustness=False)
    first = accepted = 0
    times, tries, pages, sentences, whole = [], [], [], [0, 0], 0
    for i in range(states):
        t = time.perf_counter()
        n = xairl.narrate(
            exp, i, narrator="local_lm", policy=policy, template=template, options=options, robustness=False
        )
        times.append(time.perf_counter() - t)
        ours = n.source == "local_lm"
        accepted += ours
        first += ours and n.extras["tries"] == 1
        tries.append(n.extras["tries"])
        done, kept, total = n.extras.get("reworded", (0, 0, 0))
        sentences[0] += done if ours else 0
        sentences[1] += total
        whole += ours and n.extras["tries"] == 1 and kept == total  # no sentence fell back to the template's words
        if ours:
            plain = xairl.narrate(exp, i, policy=policy, template=template, robustness=False).text
            pages.append(
                f"### {name}, decision {i} (try {n.extras['tries']})\n\n**local_lm (fill):** {n.text}\n\n"
                f"**template:** {plain}\n\n**facts:**\n\n{facts_table(exp, i, policy)}\n"
            )
    row = {
        "policy": name,
        "template": template,
        "states": states,
        "first_try": first,
        "accepted": accepted,
        "median_s": statistics.median(times),
        "p90_s": sorted(times)[int(0.9 * (len(times) - 1))],
        "mean_tries": statistics.mean(tries),
        "first_try_every_sentence": whole,
        "sentences_reworded": sentences[0],
        "sentences": sentences[1],
    }
    return row, pages


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--states", type=int, default=20)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--policies", default=",".join(f"{p}:{t}" for p, t in POLICIES))
    ap.add_argument("--out", default="/tmp/lm_fill.md")
    args = ap.parse_args()
    pages = []
    print(f"{'policy':10s} {'template':16s} {'first try':>10s} {'accepted':>9s} {'median s':>9s} {'p90 s':>7s} tries")
    for spec in args.policies.split(","):
        name, template = spec.split(":")
        row, more = run(name, template, args.states, args.threads)
        pages += more
        print(
            f"{name:10s} {template:16s} {row['first_try']:>4d}/{row['states']:<5d} {row['accepted']:>4d}/"
            f"{row['states']:<4d} {row['median_s']:9.2f} {row['p90_s']:7.2f} {row['mean_tries']:.2f}  "
            f"{row['sentences_reworded']}/{row['sentences']} sentences reworded (the others kept the template's "
            f"words); first try with every sentence accepted from the model: {row['first_try_every_sentence']}"
        )
    with open(args.out, "w") as fh:
        fh.write("# local_lm fill: accepted texts with their facts\n\n" + "\n".join(pages))
    print(f"accepted texts with their facts: {args.out}")


if __name__ == "__main__":
    main()
