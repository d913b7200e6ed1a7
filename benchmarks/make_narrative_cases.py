"""Write the explanations the held-out narrative corpus talks about: ``benchmarks/data/narratives/cases.json``.

Eight single-state explanations per domain (``tests/narrative_domains.py``): the house-price regressor and the
credit-default classifier explained with exact Shapley values against 100 background rows, the UAV handover DQN
(its committed checkpoint, states it met in flight, half of them handovers) and the toy policy with deep_shap.
Cases 0-3 of each domain are the dev split, 4-7 the test split; the split was fixed before any narrative was
written or any verifier change was made. Run once; the corpus refers to the stored numbers, not to a re-run.

    .venv/bin/python benchmarks/make_narrative_cases.py
"""
from __future__ import annotations

import json
import pathlib
import sys

import numpy as np
import torch

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
import xairl  # noqa: E402
from tests import narrative_domains as domains  # noqa: E402

OUT = pathlib.Path(__file__).parent / "data" / "narratives" / "cases.json"


def _explanations(domain: str) -> xairl.Explanation:
    if domain in domains.SPECS:
        policy = domains.policy(domain, domains.fitted(domain))
        states = domains.sample(domain, 8, seed=11)
        return xairl.explain(policy, states, background=domains.sample(domain, 100, seed=1), method="exact")
    policy = domains.policy(domain)
    if domain == "uav":
        from xairl_uav_handover.policy import dqn_decision_states, load_checkpoint

        pool = dqn_decision_states(load_checkpoint(), 4000, seed=5)  # the DQN hands over in ~0.3 %
        acts = policy.act(pool)
        states = np.concatenate([pool[acts != 0][:4], pool[acts == 0][:4]])
    else:
        states = policy.background(8, seed=21)
    return xairl.explain(policy, states, background=policy.background(100, seed=0))


def main() -> None:
    torch.set_num_threads(1)
    cases = []
    for domain in domains.DOMAINS:
        exp = _explanations(domain)
        for i in range(len(exp.values)):
            one = xairl.Explanation(**{**exp.__dict__, "values": exp.values[i:i + 1],
                                       "base_values": exp.base_values[i:i + 1], "outputs": exp.outputs[i:i + 1],
                                       "states": exp.states[i:i + 1],
                                       "available": None if exp.available is None else exp.available[i:i + 1]})
            cases.append({"id": f"{domain}-{i}", "domain": domain, "split": "dev" if i < 4 else "test",
                          "explanation": json.loads(one.to_json())})
    OUT.write_text(json.dumps(cases, indent=1) + "\n")
    print(f"wrote {len(cases)} cases to {OUT}")


if __name__ == "__main__":
    main()
