"""The paper's SHAP findings re-measured on the reference DQN(s): the buffer's rank, position's rank, and the
importance of each candidate cell (its RSRP and RSRQ together), by mean |contribution| to the margin over the
runner-up and to the chosen action's score (deep_shap), on the DQN's own decision states of held-out simulated
flights and on real UKM states.

Run: .venv/bin/python plugins/xairl-uav-handover/benchmarks/findings.py --checkpoints A.safetensors ...
     [--states 400] [--real ../shared/data/ukm-uav-lte] [--json OUT]   (about a minute per checkpoint)
"""

import argparse
import json

import numpy as np

from xairl_uav_handover.evaluate import importance, ranked
from xairl_uav_handover.exports import load_folder
from xairl_uav_handover.features import GROUPS, N_CANDIDATES
from xairl_uav_handover.policy import dqn_decision_states, load_checkpoint
from xairl_uav_handover.real_data import walk

#: position as one group (as the paper's Figure 2 reads it); every other feature alone
POSITION = {"position": GROUPS["position"]}
#: each candidate cell's two measurements together, beside the buffer and position
CELLS = {
    "position": GROUPS["position"],
    **{f"cell_{k}": (f"rsrp_{k}", f"rsrq_{k}") for k in range(N_CANDIDATES)},
}


def real_states(folder: str, cfg, n: int, seed: int = 0) -> np.ndarray:
    """``n`` states drawn evenly from every real flight's walk."""
    flights, _ = load_folder(folder)
    states = np.concatenate([walk(f, cfg).states for f in flights])
    rng = np.random.default_rng(seed)
    return states[np.sort(rng.choice(len(states), size=min(n, len(states)), replace=False))]


def measure(ckpt, states: np.ndarray) -> dict:
    """Ranks (from 1) of the buffer and position, and the cells' shares of importance, in both views."""
    out = {}
    features = importance(ckpt, states, groups=POSITION)
    cells = importance(ckpt, states, groups=CELLS)
    for view in ("margin", "score"):
        order = ranked(features, view)
        share = cells[view] / cells[view].sum()
        out[view] = {
            "buffer_rank": order.index("buffer_queue_size") + 1,
            "position_rank": order.index("position") + 1,
            "top3": order[:3],
            "group_share": {str(n): round(float(s), 3) for n, s in zip(cells["names"], share)},
        }
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--checkpoints", nargs="+", default=[None], help="DQN checkpoints (default: the committed one)")
    ap.add_argument("--states", type=int, default=400, help="states explained per dataset")
    ap.add_argument("--real", default=None, help="a folder of real UKM flight exports")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", default=None, help="also write the results here")
    args = ap.parse_args()
    results = []
    for path in args.checkpoints:
        ckpt = load_checkpoint(path)
        data = {"simulated": dqn_decision_states(ckpt, args.states, args.seed)}
        if args.real:
            data["real"] = real_states(args.real, ckpt.sim_config, args.states, args.seed)
        for name, states in data.items():
            row = {"checkpoint": str(ckpt.path), "states": name, **measure(ckpt, states)}
            results.append(row)
            for view in ("margin", "score"):
                r = row[view]
                shares = ", ".join(f"{k} {v:.2f}" for k, v in r["group_share"].items())
                print(
                    f"{ckpt.path.name:<28} {name:<9} {view:<6} buffer {r['buffer_rank']:>2}  position "
                    f"{r['position_rank']:>2}  top 3: {', '.join(r['top3'])}  | shares: {shares}"
                )
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(results, fh, indent=1)


if __name__ == "__main__":
    main()
