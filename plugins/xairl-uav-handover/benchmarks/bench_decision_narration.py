"""Issue 14's targets on the reference policy: narratives true to the decision, in an operator's terms.

On N simulated decision states (the DQN's own held-out flights, each with its flight history) and N real ones
(samples of the UKM flights, with theirs), narrated with the plugin's ``handover`` template and the built-in
``explain_action``, it counts:

- opposing lead: the first feature the text names (found by the verifier's own name finder) pushes against the
  decision (its contribution to the margin over the runner-up is negative) and the sentence is not a concession
  ('despite');
- identifier as cause: a sentence names an identifier feature (the serving BS's id) with a direction word;
- level words against the range: a feature with a capacity or thresholds described with a level word its value
  contradicts (e.g. 'heavily loaded' below 75 % of capacity, 'weak signal' above -100 dBm);
- not verified, and coverage below 1.

The old chosen-score view (``explain_score``) is measured the same way for comparison.

    .venv/bin/python plugins/xairl-uav-handover/benchmarks/bench_decision_narration.py [--n 500]
"""

from __future__ import annotations

import argparse
import re
import time
from pathlib import Path

import numpy as np

import xairl
from xairl_uav_handover.env import HandoverVecEnv
from xairl_uav_handover.policy import background_states, greedy, load_checkpoint, uav_policy

REAL = Path(__file__).resolve().parents[4] / "shared" / "data" / "ukm-uav-lte" / "raw"
DIRECTION = re.compile(r"\b(push\w*|favou?r\w*|toward|against|raised?|lowered?)\b", re.IGNORECASE)


def simulated(ckpt, n: int, seed: int = 0):
    """(states, history per state) from held-out flights the DQN flies itself."""
    env = HandoverVecEnv(ckpt.sim_config, n_flights=32)
    obs, _ = env.reset(seed=3_000_000 + seed)
    seen, ended = [], False
    while not ended:
        seen.append(obs)
        obs, _, _, truncated, _ = env.step(greedy(ckpt.net, obs, ckpt.sim_config))
        ended = bool(truncated.all())
    traj = np.stack(seen, axis=1)  # (flights, T, features)
    rng = np.random.default_rng(seed)
    picks = [(int(rng.integers(len(traj))), int(rng.integers(1, traj.shape[1]))) for _ in range(n)]
    return np.array([traj[f, t] for f, t in picks]), [traj[f, max(0, t - 10) : t] for f, t in picks]


def real(ckpt, n: int, seed: int = 0):
    from xairl_uav_handover.exports import load_folder
    from xairl_uav_handover.real_data import walk

    flights, _ = load_folder(REAL)
    walks = [walk(f, ckpt.sim_config, seed=seed).states for f in flights]
    rng = np.random.default_rng(seed)
    picks = []
    for _ in range(n):
        w = walks[int(rng.integers(len(walks)))]
        picks.append((w, int(rng.integers(1, len(w)))))
    return np.array([w[t] for w, t in picks]), [w[max(0, t - 10) : t] for w, t in picks]


def measure(policy, exp, histories, template: str) -> dict:
    margin = exp.margin()
    names = exp.feature_names
    idx = {f: j for j, f in enumerate(names)}
    groups = policy.reason_groups
    out = dict(
        opposing_lead=0,
        identifier_cause=0,
        level_contradicts_range=0,
        not_verified=0,
        partial_coverage=0,
        n=len(histories),
    )
    for i, hist in enumerate(histories):
        n = xairl.narrate(exp, i, template=template, policy=policy, robustness=False, history=hist)
        out["not_verified"] += not n.verified  # checked with the facts the hook stated from the history
        out["partial_coverage"] += any(status == "unchecked" for _, status in n.sentences)
        first = True
        for sentence in xairl.verify(n.text, exp, i, policy).sentences:
            text = sentence.text  # the features it names unambiguously, in order: the verifier's name mentions
            feats = [c.detail for c in sentence.claims if c.rule == "names.mention" and " / " not in c.detail]
            if first and feats and exp.chosen[i] != exp.runner_up[i]:
                key = feats[0]
                cols = [idx[f] for f in groups.get(key, (key,))]
                if margin[i, cols].sum() < 0 and "despite" not in text.lower():
                    out["opposing_lead"] += 1
                first = False
            for f in feats:
                info = policy.features.get(f)
                if info is not None and info.kind == "identifier" and DIRECTION.search(text):
                    out["identifier_cause"] += 1
        for f, info in policy.features.items():
            if info.kind != "numeric" or (info.capacity is None and info.thresholds is None):
                continue
            label = info.description or f
            value = float(exp.states[i, idx[f]])
            truth = xairl.facts.value_level(value, info, None)[0]
            for word, lvl in ((info.low, "low"), (info.high, "high")):
                if re.search(re.escape(label) + r"\s*\([^)]*\b" + re.escape(word), n.text) and truth != lvl:
                    out["level_contradicts_range"] += 1
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=500)
    args = ap.parse_args()
    ckpt = load_checkpoint()
    policy = uav_policy(ckpt)
    bg = background_states(100, seed=7, config=ckpt.sim_config)
    sets = [("simulated", *simulated(ckpt, args.n))]
    if REAL.is_dir():
        sets.append(("real", *real(ckpt, args.n)))
    print(
        f"{'states':<10}{'template':<16}{'n':>5}{'opposing lead':>15}{'id as cause':>13}{'level vs range':>16}"
        f"{'not verified':>14}{'coverage<1':>12}{'s':>7}"
    )
    for label, states, hist in sets:
        exp = xairl.explain(policy, states, background=bg)
        for template in ("handover", "explain_action", "explain_score"):
            t0 = time.time()
            r = measure(policy, exp, hist, template)
            print(
                f"{label:<10}{template:<16}{r['n']:>5}{r['opposing_lead']:>15}{r['identifier_cause']:>13}"
                f"{r['level_contradicts_range']:>16}{r['not_verified']:>14}{r['partial_coverage']:>12}"
                f"{time.time() - t0:>7.1f}"
            )


if __name__ == "__main__":
    main()
