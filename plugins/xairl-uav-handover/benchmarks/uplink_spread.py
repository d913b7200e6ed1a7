"""Does the buffer's first place depend on how much cells differ in uplink interference? Cells differ most by whether
they hold an aerial UE (uplink.py), so one DQN is trained per share of aerial UEs (radio.aerial_ue_ratio; TR 36.777's
cases 0, 0.67, 7.1, 25, 50 %; the simulator uses 0.67 %), then the buffer's rank by mean |contribution|
to the margin over the runner-up and to the chosen action's score (deep_shap) on the DQN's own decision states of
held-out flights.

Run: .venv/bin/python plugins/xairl-uav-handover/benchmarks/uplink_spread.py [--ratios 0.0067 0] [--episodes 40]
     [--states 400] [--demonstrations N]   (about 2 minutes of training per ratio on 2 cores; docs/uav-reference.md's
     figures of 2026-12-02 were measured on the retired +-9 dB spread, before issue 53)
"""

import argparse
import shutil
import tempfile
from pathlib import Path

import numpy as np

import xairl
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.features import FEATURES
from xairl_uav_handover.policy import background_states, dqn_decision_states, load_checkpoint, uav_policy
from xairl_uav_handover.train import TrainConfig, train_checkpoint


def ranks(ckpt, n_states: int, seed: int = 0) -> tuple[int, int, list[str]]:
    """(the buffer's rank by margin, by chosen score, the top 3 by margin), ranks counted from 1."""
    exp = xairl.explain(
        uav_policy(ckpt),
        dqn_decision_states(ckpt, n_states, seed),
        background=background_states(100, seed=seed + 7, config=ckpt.sim_config),
    )
    by_margin = [FEATURES[j] for j in np.argsort(-np.abs(exp.margin()).mean(axis=0))]
    by_score = [FEATURES[j] for j in np.argsort(-np.abs(exp.for_chosen()).mean(axis=0))]
    return by_margin.index("buffer_queue_size") + 1, by_score.index("buffer_queue_size") + 1, by_margin[:3]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--ratios", type=float, nargs="+", default=[0.0067, 0.0])
    ap.add_argument("--episodes", type=int, default=40)
    ap.add_argument("--states", type=int, default=400)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument(
        "--demonstrations",
        type=int,
        default=TrainConfig().demonstrations,
        help="episodes of the RSRQ rule's flights to learn from (0: a plain DQN)",
    )
    args = ap.parse_args()
    folder = Path(tempfile.mkdtemp())  # the checkpoints of this run; removed at the end
    print(f"{'aerial UEs':>10} {'buffer rank (margin)':>21} {'(chosen score)':>15}  top 3 by margin")
    for ratio in args.ratios:
        data = SimConfig().model_dump()
        data["radio"]["aerial_ue_ratio"] = ratio
        path = folder / f"ratio{ratio:g}.safetensors"
        tc = TrainConfig(episodes=args.episodes, seed=args.seed, demonstrations=args.demonstrations)
        train_checkpoint(tc, SimConfig.model_validate(data), str(path), progress=False)
        by_margin, by_score, top = ranks(load_checkpoint(path), args.states, args.seed)
        print(f"{ratio:>10g} {by_margin:>21} {by_score:>15}  {', '.join(top)}")
    shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
