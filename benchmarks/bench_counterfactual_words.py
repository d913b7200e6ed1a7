"""Counterfactuals said in words (issue 56, done-when 1 and 3): on many decisions of a registered policy, the search's
answer (xairl.counterfactual, batched), the fact said by the template's last sentence, and two checks of every
sentence: the verifier's (its re-run of the stated change) and an independent one here (the policy run, in one batch,
on every state with the changes as the fact writes them). Reports how many were said, verified, contradicted, left
unsaid (no candidate flips, and keeps the state feasible, as written) or unreachable (not said: a search's miss is
no proof that no change flips it).

Run: .venv/bin/python benchmarks/bench_counterfactual_words.py [--policy toy] [--template explain_action]
     [--states 1000] [--max-changes 2]
The reference plugin: --policy uav-dqn --template handover
"""

import argparse
import collections
import time
from dataclasses import replace

import numpy as np

import xairl
from xairl.counterfactual_facts import counterfactual_fact
from xairl.facts import decision_facts
from xairl.narrators.base import first_phrasings
from xairl.templates import prompts
from xairl.templates.tracking import track_decision
from xairl.verification import verify


def last_sentence(name: str):
    """The template with its last sentence only (the counterfactual's)."""
    tpl = prompts.load(name)
    return replace(tpl, spec=tpl.spec.model_copy(update={"sentences": tpl.spec.sentences[-1:]}), lines=tpl.lines[-1:])


def independent(policy, exp, facts: dict) -> int:
    """How many said facts flip the decision to their stated action when the policy runs their written changes."""
    idx = [i for i, f in facts.items() if f.reachable]
    rows = np.array(exp.states[idx], dtype=float)
    for r, i in enumerate(idx):
        for c in facts[i].changes:
            rows[r, policy.feature_names.index(c.name)] = c.after
    taken = policy.act(rows)
    return sum(policy.action_names[a] == facts[i].action != facts[i].chosen for a, i in zip(taken, idx))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--policy", default="toy")
    ap.add_argument("--template", default="explain_action")
    ap.add_argument("--states", type=int, default=1000)
    ap.add_argument("--max-changes", type=int, default=2)
    ap.add_argument("--narrate", type=int, default=50, help="whole narratives, narrate(counterfactual=True)")
    a = ap.parse_args()
    policy = xairl.get_policy(a.policy)
    bg, states = policy.background(200), policy.background(a.states, seed=3)
    exp = xairl.explain(policy, states, background=bg)
    t0 = time.perf_counter()
    found = xairl.counterfactual(
        policy, states, index=None, background=bg, explanation=exp, max_changes=a.max_changes, n=3
    )
    t_search, t0 = time.perf_counter() - t0, time.perf_counter()
    tpl, counts, facts = last_sentence(a.template), collections.Counter(), {}
    for i, answer in enumerate(found):
        fact = counterfactual_fact(exp, i, policy, answer, a.max_changes)
        if fact is None:
            counts["found, not said (no candidate flips and stays feasible as written)"] += 1
            continue
        if not fact.reachable:
            counts["unreachable: not said"] += 1
            continue
        facts[i] = fact
        context = track_decision(replace(decision_facts(exp, i, policy, 3), counterfactual=fact).context())
        text = first_phrasings(tpl.render_variants(context))
        status = verify(text, exp, i, policy, provenance=text.spans).sentences[-1].status
        counts[f"said: {status}"] += 1
        counts[f"features changed: {len(fact.changes)}"] += 1
    t_words = time.perf_counter() - t0
    print(f"{a.policy}, {a.states} decisions, template {a.template}, max_changes {a.max_changes}")
    for k, v in sorted(counts.items()):
        print(f"  {k}: {v}")
    said = sum(f.reachable for f in facts.values())
    print(
        f"  said and flipping when re-run here (independent of the verifier): {independent(policy, exp, facts)}/{said}"
    )
    print(
        f"  search {1000 * t_search / a.states:.1f} ms per decision; fact, words and check {1000 * t_words / a.states:.1f} ms"
    )
    told, t0, m = collections.Counter(), time.perf_counter(), min(a.narrate, a.states)
    for i in range(m):
        n = xairl.narrate(
            exp, i, template=a.template, policy=policy, background=bg, counterfactual=True, robustness=False
        )
        said = [st for text, st in n.sentences if text.startswith("Had ")]
        told[f"verified {n.verified}, counterfactual sentence {said[0] if said else 'none'}"] += 1
    each = (time.perf_counter() - t0) / max(1, m)
    print(f"  {m} whole narratives, counterfactual=True: {dict(told)}; {each:.2f} s each (robustness=False)")


if __name__ == "__main__":
    main()
