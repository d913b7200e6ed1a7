"""Write the explanations the held-out narrative corpus talks about: ``benchmarks/data/narratives/cases.json``.

Eight single-state explanations per domain (``tests/narrative_domains.py``): the house-price regressor and the
credit-default classifier explained with exact Shapley values against 100 background rows, the UAV handover DQN
(its committed checkpoint, states it met in flight, half of them handovers) and the toy policy with deep_shap.
Cases 0-3 of each domain are the dev split, 4-7 the test split; the split was fixed before any narrative was
written or any verifier change was made. Run once; the corpus refers to the stored numbers, not to a re-run.

    .venv/bin/python benchmarks/make_narrative_cases.py --write
    .venv/bin/python benchmarks/make_narrative_cases.py --stay-cases   # voices/dev-qa-shorthand-lists/cases.json: two UAV 'stay' dev cases
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
    if domain == "uav":  # through the plugin registry: the core imports no plugin. cases.json was written from
        # states the DQN visited on simulated flights (it hands over in ~0.3 % of them); it stays as written, and a
        # new run draws from the policy's own sampler
        policy = xairl.get_policy("uav-dqn")
        pool = policy.background(4000, seed=5)
        acts = policy.act(pool)
        states = np.concatenate([pool[acts != 0][:4], pool[acts == 0][:4]])
    else:
        policy = domains.policy(domain)
        states = policy.background(8, seed=21)
    return xairl.explain(policy, states, background=policy.background(100, seed=0))


def _one(exp: xairl.Explanation, i: int) -> dict:
    one = xairl.Explanation(
        **{
            **exp.__dict__,
            "values": exp.values[i : i + 1],
            "base_values": exp.base_values[i : i + 1],
            "outputs": exp.outputs[i : i + 1],
            "states": exp.states[i : i + 1],
            "available": None if exp.available is None else exp.available[i : i + 1],
        }
    )
    return json.loads(one.to_json())


def _dev2_cases() -> list[dict]:
    """Two more UAV cases for the dev-qa-shorthand-lists narratives, both 'stay' (the dev split's UAV cases are all handovers), from
    another pool of states than the frozen cases: the registered policy's own sampler (``voices/dev-qa-shorthand-lists/cases.json`` was
    written from states the DQN visited on simulated flights; it stays as written)."""
    policy = xairl.get_policy("uav-dqn")  # through the plugin registry: the core imports no plugin
    pool = policy.background(400, seed=17)
    states = pool[policy.act(pool) == 0][:2]
    exp = xairl.explain(policy, states, background=policy.background(100, seed=0))
    return [{"id": f"uav-stay-{i}", "domain": "uav", "split": "dev", "explanation": _one(exp, i)} for i in range(2)]


def main() -> None:
    torch.set_num_threads(1)
    if not {"--write", "--stay-cases"} & set(sys.argv[1:]):  # the corpus is frozen: never rewritten by accident
        sys.exit(
            f"{OUT} is the frozen corpus the narratives speak of; --write rewrites it, --stay-cases writes the two "
            "UAV 'stay' cases (--help is this line)"
        )
    if "--stay-cases" in sys.argv:  # added after the freeze: new dev cases only, cases.json is left as it is
        out = OUT.parent / "voices" / "dev-qa-shorthand-lists" / "cases.json"
        out.write_text(json.dumps(_dev2_cases(), indent=1) + "\n")
        print(f"wrote {out}")
        return
    cases = []
    for domain in domains.DOMAINS:
        exp = _explanations(domain)
        for i in range(len(exp.values)):
            cases.append(
                {
                    "id": f"{domain}-{i}",
                    "domain": domain,
                    "split": "dev" if i < 4 else "test",
                    "explanation": _one(exp, i),
                }
            )
    OUT.write_text(json.dumps(cases, indent=1) + "\n")
    print(f"wrote {len(cases)} cases to {OUT}")


if __name__ == "__main__":
    main()
