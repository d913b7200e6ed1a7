"""The calibrated reproduction over several training seeds: Table I (mean and spread over seeds), the buffer's use,
and the rank of buffer_queue_size by mean |contribution to the margin| (deep_shap) on the DQN's own decision states.

Targets (issue 11): CHM > SA-MRO > DQN in handovers; DQN handovers <= 0.2 x CHM; buffer non-empty in >= 30 % of
simulated decision states; buffer_queue_size in the top 2 features for every seed.
Run: .venv/bin/python plugins/xairl-uav-handover/benchmarks/reproduce.py [--seeds 0 1 2] [--episodes 40]
     [--flights 200] [--states 400] [--json OUT]      trains one DQN per seed (the simulator's defaults), then measures
or:  ... reproduce.py --checkpoints A.safetensors B.safetensors C.safetensors   measures existing checkpoints
"""
import argparse
import json
import tempfile
from pathlib import Path

import numpy as np
from xairl_uav_handover.baselines import CHM, SAMRO
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.evaluate import margin_ranking, run_flights, summarise
from xairl_uav_handover.policy import DQNController, load_checkpoint
from xairl_uav_handover.train import TrainConfig, train_checkpoint

KEYS = ("handovers_median", "handovers_mean", "pingpong_pct_median", "pingpong_pct_pooled", "pingpong_pct_mean",
        "service_availability_pct_mean", "lost_data_kbit_mean", "mean_buffer_kbit_mean", "buffer_nonempty_pct_mean")


def train_seeds(seeds: list[int], episodes: int, folder: Path) -> list[str]:
    """One checkpoint per training seed, as ``xairl uav train --episodes E --seed S`` writes it."""
    paths = [str(folder / f"seed{seed}.safetensors") for seed in seeds]
    for seed, path in zip(seeds, paths):
        train_checkpoint(TrainConfig(episodes=episodes, seed=seed), SimConfig(), path, progress=False)
    return paths


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--checkpoints", nargs="+", default=None, help="measure these instead of training")
    ap.add_argument("--seeds", nargs="+", type=int, default=[0, 1, 2], help="training seeds")
    ap.add_argument("--episodes", type=int, default=40, help="training episodes per seed")
    ap.add_argument("--out-dir", default=None, help="keep the trained checkpoints here (default: a temp dir)")
    ap.add_argument("--flights", type=int, default=200)
    ap.add_argument("--states", type=int, default=400)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", default=None, help="also write the per-seed results here")
    args = ap.parse_args()
    folder = Path(args.out_dir or tempfile.mkdtemp(prefix="xairl-reproduce-"))
    folder.mkdir(parents=True, exist_ok=True)
    paths = args.checkpoints or train_seeds(args.seeds, args.episodes, folder)
    per_seed = []
    for path in paths:
        ckpt = load_checkpoint(path)
        flown = {c.name: run_flights(c, ckpt.sim_config, args.flights, args.seed)
                 for c in (CHM(), SAMRO(), DQNController(ckpt.net))}
        rows = {name: summarise(m) for name, m in flown.items()}
        ranking = margin_ranking(ckpt, args.states, args.seed)
        dqn_ho = max(flown["DQN"]["handovers"].sum(), 1)  # shares of the DQN's handovers by the buffer before them
        nonempty, full = (float(flown["DQN"][k].sum() / dqn_ho) for k in ("handovers_buffer_nonempty",
                                                                           "handovers_buffer_full"))
        per_seed.append({"checkpoint": path, "train_seed": ckpt.meta.get("seed"), "rows": rows,
                         "handovers_with_buffer_nonempty": nonempty, "handovers_with_buffer_full": full,
                         "margin_ranking": ranking, "buffer_rank": ranking.index("buffer_queue_size") + 1,
                         "train_seconds": ckpt.meta.get("train_seconds")})
        print(f"{path}: seed {ckpt.meta.get('seed')}, trained in {ckpt.meta.get('train_seconds')} s; "
              f"DQN {rows['DQN']['handovers_median']:.1f} HO (CHM {rows['CHM']['handovers_median']:.1f}, SA-MRO "
              f"{rows['SA-MRO']['handovers_median']:.1f}); buffer rank {per_seed[-1]['buffer_rank']}: "
              f"{', '.join(ranking[:4])}; DQN handovers with the buffer non-empty {100 * nonempty:.1f} %, full "
              f"{100 * full:.1f} %")
    print(f"\nTable I over {len(per_seed)} training seeds, {args.flights} held-out flights each (mean +- std over seeds)")
    print(f"{'policy':<8}" + "".join(f"{k.replace('_mean', '').replace('_pct', ' %'):>24}" for k in KEYS))
    for name in ("CHM", "SA-MRO", "DQN"):
        vals = np.array([[s["rows"][name][k] for k in KEYS] for s in per_seed])
        print(f"{name:<8}" + "".join(f"{m:>16.2f} +- {sd:<5.2f}" for m, sd in zip(vals.mean(0), vals.std(0))))
    ratio = [s["rows"]["DQN"]["handovers_median"] / max(s["rows"]["CHM"]["handovers_median"], 1) for s in per_seed]
    mean_ratio = [s["rows"]["DQN"]["handovers_mean"] / max(s["rows"]["CHM"]["handovers_mean"], 1e-9) for s in per_seed]
    print(f"DQN / CHM median handovers per seed: {', '.join(f'{r:.2f}' for r in ratio)} (target <= 0.2); by mean "
          f"handovers per flight: {', '.join(f'{r:.2f}' for r in mean_ratio)}; buffer rank per seed: "
          f"{[s['buffer_rank'] for s in per_seed]} (target <= 2)")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(per_seed, fh, indent=2)


if __name__ == "__main__":
    main()
