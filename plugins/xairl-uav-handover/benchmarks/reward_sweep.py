"""Rewards that price what operators pay for: train one DQN per weight set and seed, then Table I with intervals
against CHM and SA-MRO and the targets of the issue "A reference DQN that beats the A3 rule on what operators pay
for" (benchmarks/table_one.py), per weight set.

A weight set is w_lost,w_rsrq,w_handover,w_pingpong (per Mbit lost, per decision below the RSRQ threshold, per
handover, per handover back to the previous BS within 5 s); the other weights are the simulator's defaults. Training
takes about 2 minutes per set and seed on 2 cores (40 episodes of 64 flights).
Run: .venv/bin/python plugins/xairl-uav-handover/benchmarks/reward_sweep.py [--sets 1,3,30,80 0.5,2,30,60 ...]
     [--seeds 0] [--episodes 40] [--flights 100] [--eval-seeds 0] [--keep DIR] [--demonstrations N]
The sweeps in docs/uav-reference.md dated before 2026-12-03 evening trained plain DQNs: --demonstrations 0.
"""

import argparse
import tempfile
from pathlib import Path

from table_one import targets

from xairl_uav_handover.baselines import CHM, SAMRO
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.memory import MemoryDQNController
from xairl_uav_handover.policy import DQNController, load_checkpoint
from xairl_uav_handover.table import flights, format_rows, with_intervals
from xairl_uav_handover.train import TrainConfig, train_checkpoint


def config(weights: str) -> SimConfig:
    w_lost, w_rsrq, w_handover, w_pingpong = (float(x) for x in weights.split(","))
    data = SimConfig().model_dump()
    data["reward"].update(w_lost=w_lost, w_rsrq=w_rsrq, w_handover=w_handover, w_pingpong=w_pingpong)
    return SimConfig.model_validate(data)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument(
        "--sets",
        nargs="+",
        default=["1,3,30,80"],
        help="w_lost,w_rsrq,w_handover,w_pingpong per set (default: the best set found so far)",
    )
    ap.add_argument("--seeds", type=int, nargs="+", default=[0], help="training seeds")
    ap.add_argument("--episodes", type=int, default=40)
    ap.add_argument("--flights", type=int, default=100, help="held-out flights per evaluation seed")
    ap.add_argument("--eval-seeds", type=int, nargs="+", default=[0])
    ap.add_argument("--keep", default=None, help="folder for the checkpoints (default: a temporary one)")
    ap.add_argument(
        "--demonstrations",
        type=int,
        default=TrainConfig().demonstrations,
        help="episodes of the RSRQ rule's flights to learn from (0: a plain DQN)",
    )
    ap.add_argument(
        "--memory",
        choices=["off", "on", "both"],
        default="off",
        help="on: the DQN with memory (memory.py: the last 1 s and the times); both: each set with and without",
    )
    args = ap.parse_args()
    folder = Path(args.keep or tempfile.mkdtemp())
    folder.mkdir(parents=True, exist_ok=True)
    cfg = SimConfig()
    res = {c.name: with_intervals(flights(c, cfg, args.flights, args.eval_seeds)) for c in (CHM(), SAMRO())}
    memories = {"off": [False], "on": [True], "both": [False, True]}[args.memory]
    for weights in args.sets:
        for seed in args.seeds:
            for memory in memories:
                name = f"{weights} s{seed}{' mem' if memory else ''}"
                path = folder / f"w{weights.replace(',', '_')}_seed{seed}{'_mem' if memory else ''}.safetensors"
                tc = TrainConfig(episodes=args.episodes, seed=seed, demonstrations=args.demonstrations, memory=memory)
                seconds = train_checkpoint(tc, config(weights), str(path), progress=False)
                net = load_checkpoint(path).net
                controller = MemoryDQNController(net) if memory else DQNController(net)
                res[name] = with_intervals(flights(controller, cfg, args.flights, args.eval_seeds))
                print(f"{name}: trained in {seconds:.0f} s", flush=True)
    print(f"w_lost,w_rsrq,w_handover,w_pingpong per column; {args.flights} held-out flights x {args.eval_seeds}")
    print(format_rows(res))
    for name in [k for k in res if k not in ("CHM", "SA-MRO")]:
        pooled = args.flights * len(args.eval_seeds)
        met = [label for label, ok, _ in targets({"CHM": res["CHM"], "DQN": res[name]}, pooled) if ok]
        print(f"{name}: {len(met)} of 9 targets met ({'; '.join(m.split('.')[0] for m in met)})")


if __name__ == "__main__":
    main()
