"""The reference DQN reproduced in one command: one DQN per training seed (the simulator's default reward, the
paper's; a plain DQN as TrainConfig's defaults say, or learning from the RSRQ rule with --demonstrations N), each on
Table I with bootstrap 95 % intervals against CHM and SA-MRO on the same held-out flights, the issue's targets 1-4
checked per seed (benchmarks/table_one.py), and the rank of buffer_queue_size by mean |contribution| to the margin
and to the chosen score (deep_shap) on each DQN's own decision states. With --real DIR (the UKM flights), also the
open-loop new handover proposals per minute on the real flights against the live network's handovers (target 5:
at most 2x), the buffer's ranks on real states and the Spearman correlation of the features' mean |margin
contribution| between simulated and real states (target 6: buffer in the top 2, Spearman >= 0.6). Training takes
about 3 minutes per seed on 2 cores; the committed checkpoint is seed 0 of this command (`xairl uav train --seed 0`
writes the same).

Run: .venv/bin/python plugins/xairl-uav-handover/benchmarks/reproduce.py [--seeds 0 1 2] [--episodes 40]
     [--flights 200] [--eval-seeds 0] [--states 400] [--real DIR] [--out-dir DIR] [--json OUT]
     [--demonstrations N] [--reward w_lost=2 w_pingpong=80 ...]   trains with these RewardConfig weights
     [--memory]   trains the DQN with memory (issue 55) instead of the snapshot DQN
or:  ... reproduce.py --checkpoints A.safetensors B.safetensors ...   measures existing checkpoints
"""

import argparse
import json
import tempfile
from pathlib import Path

import numpy as np
from scipy.stats import spearmanr
from table_one import print_targets, targets

from xairl_uav_handover.baselines import CHM, SAMRO
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.evaluate import importance, ranked
from xairl_uav_handover.memory import controller, walk_states
from xairl_uav_handover.policy import dqn_decision_states, load_checkpoint, memory_of
from xairl_uav_handover.table import flights, format_paper, format_rows, pooled_seeds, with_intervals
from xairl_uav_handover.train import TrainConfig, train_checkpoint


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser()
    ap.add_argument("--checkpoints", nargs="+", default=None, help="measure these instead of training")
    ap.add_argument("--seeds", nargs="+", type=int, default=[0, 1, 2], help="training seeds")
    ap.add_argument("--episodes", type=int, default=40, help="training episodes per seed")
    ap.add_argument("--out-dir", default=None, help="keep the trained checkpoints here (default: a temp dir)")
    ap.add_argument("--flights", type=int, default=200, help="held-out flights per evaluation seed")
    ap.add_argument("--eval-seeds", type=int, nargs="+", default=[0])
    ap.add_argument("--states", type=int, default=400, help="decision states explained for the feature ranks")
    ap.add_argument("--real", default=None, help="a folder of real UKM flight exports (targets 5 and 6)")
    ap.add_argument("--json", default=None, help="also write the per-seed results here")
    ap.add_argument(
        "--demonstrations",
        type=int,
        default=TrainConfig().demonstrations,
        help="episodes of the RSRQ rule's flights to learn from (0: a plain DQN)",
    )
    ap.add_argument(
        "--reward",
        nargs="+",
        default=[],
        metavar="KEY=VALUE",
        help="train with these reward weights (RewardConfig) instead of the defaults",
    )
    ap.add_argument(
        "--memory",
        action="store_true",
        help="train the DQN with memory (memory.py: the last 1 s and the times on the cell and since the handover)",
    )
    return ap


def _seed_figures(ckpt, res: dict, name: str, walks, n_states: int, n: int):
    """One DQN's targets met (Table I's against CHM; on real flights, targets 5 and 6b), its feature rankings by
    mean |contribution| (simulated and real, margin and score) and the buffer's rank in each."""
    imp = {"simulated": importance(ckpt, dqn_decision_states(ckpt, n_states, 0))}  # (with memory: per signal)
    met = [(label, bool(ok), detail) for label, ok, detail in targets({"CHM": res["CHM"], "DQN": res[name]}, n)]
    if walks:
        imp["real"], target5 = real_figures(ckpt, walks, n_states)
        rho = float(spearmanr(imp["simulated"]["margin"], imp["real"]["margin"]).statistic)
        met += [target5, ("6b. Spearman sim vs real (margin) >= 0.6", bool(rho >= 0.6), f"{rho:.2f}")]
    ranks = {f"{data} {view}": ranked(views, view) for data, views in imp.items() for view in ("margin", "score")}
    buffer = {k: r.index("buffer_queue_size") + 1 for k, r in ranks.items()}
    met.append(("6a. buffer in the top 2 everywhere", bool(max(buffer.values()) <= 2), str(buffer)))
    return met, ranks, buffer


def main():
    args = _parser().parse_args()
    folder = Path(args.out_dir or tempfile.mkdtemp(prefix="xairl-reproduce-"))
    folder.mkdir(parents=True, exist_ok=True)
    paths = args.checkpoints
    if not paths:
        paths = [str(folder / f"seed{seed}.safetensors") for seed in args.seeds]
        for seed, path in zip(args.seeds, paths):
            tc = TrainConfig(episodes=args.episodes, seed=seed, demonstrations=args.demonstrations, memory=args.memory)
            seconds = train_checkpoint(tc, with_reward(args.reward), path, progress=False)
            print(f"seed {seed}: trained in {seconds} s -> {path}")
    ckpts = [load_checkpoint(p) for p in paths]
    cfg = ckpts[0].sim_config
    if any(c.sim_config != cfg for c in ckpts[1:]):
        raise SystemExit(
            "the checkpoints were trained on different simulator settings; compare them one at a time "
            "(CHM, SA-MRO and the real walks use one setting)"
        )
    walks = real_walks(args.real, cfg) if args.real else None
    n = args.flights * len(args.eval_seeds)
    res = {
        c.name: with_intervals(flights(c, cfg, args.flights, args.eval_seeds))
        for c in (CHM(), CHM(decision_every=cfg.decision_every), SAMRO())
    }
    per_seed, runs = [], []
    for k, (path, ckpt) in enumerate(zip(paths, ckpts)):
        name = f"DQN seed {ckpt.meta.get('seed')}" if not args.checkpoints else f"DQN {k + 1}: {Path(path).stem}"
        runs.append(flights(controller(ckpt), ckpt.sim_config, args.flights, args.eval_seeds))
        res[name] = with_intervals(runs[-1])
        met, ranks, buffer = _seed_figures(ckpt, res, name, walks, args.states, n)
        per_seed.append(
            {
                "checkpoint": path,
                "name": name,
                "train_seconds": ckpt.meta.get("train_seconds"),
                "targets": met,
                "rankings": ranks,
                "buffer_rank": buffer,
            }
        )
    print(
        f"Table I: {args.flights} held-out flights x evaluation seeds {args.eval_seeds}; value [bootstrap 95 % "
        f"interval]; reward: {cfg.reward}"
    )
    if len(runs) > 1:  # intervals over training seeds, then flights
        pooled, groups = pooled_seeds(runs)
        res[f"DQN, {len(runs)} seeds"] = with_intervals(pooled, groups=groups)
    print(format_rows(res))
    print(format_paper(res))
    for s in per_seed:
        print(
            f"\n{s['name']} ({s['train_seconds']} s of training): "
            f"{sum(ok for _, ok, _ in s['targets'])} of {len(s['targets'])} targets met; first four by the margin "
            f"on simulated states: {', '.join(s['rankings']['simulated margin'][:4])}"
        )
        print_targets(s["targets"])
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"table": res, "seeds": per_seed}, fh, indent=1)


def with_reward(pairs: list[str]) -> SimConfig:
    """The default simulator with the reward weights ``KEY=VALUE`` changed (an unknown key is RewardConfig's
    error); the flights, CHM and SA-MRO do not depend on the reward, so every DQN still meets them on one setting."""
    data = SimConfig().model_dump()
    try:
        data["reward"].update({k: float(v) for k, v in (p.split("=", 1) for p in pairs)})
    except ValueError:
        raise SystemExit(f"--reward takes KEY=VALUE pairs of numbers, e.g. w_lost=2; got {' '.join(pairs)}") from None
    return SimConfig.model_validate(data)


def real_walks(folder: str, cfg) -> list:
    """The real flights as the live network flew them (real_data.walk)."""
    from xairl_uav_handover.exports import load_folder
    from xairl_uav_handover.real_data import walk

    return [walk(f, cfg) for f in load_folder(folder)[0]]


def real_sample(walks: list, n: int, ckpt=None) -> np.ndarray:
    """``n`` of the walks' states, drawn uniformly (seeded), in their order (a DQN with memory's: its windows)."""
    memory = ckpt is not None and memory_of(ckpt.meta)
    states = np.concatenate([walk_states(w, ckpt.sim_config) if memory else w.states for w in walks])
    return states[np.sort(np.random.default_rng(0).choice(len(states), size=min(n, len(states)), replace=False))]


def real_figures(ckpt, walks: list, n_states: int) -> tuple[dict, tuple[str, bool, str]]:
    """(importance on a sample of the real states, target 5: new proposals per minute <= 2 x the network's rate)."""
    from xairl_uav_handover.calibration import agreement_rows

    dqn = agreement_rows(walks, ckpt, ckpt.sim_config)[0]
    return importance(ckpt, real_sample(walks, n_states, ckpt)), (
        "5. real: new proposals <= 2 x the network's rate",
        bool(dqn.new_proposals_per_min <= 2 * dqn.network_per_min),
        f"{dqn.new_proposals_per_min:.2f} vs 2 x {dqn.network_per_min:.2f} per minute",
    )


if __name__ == "__main__":
    main()
