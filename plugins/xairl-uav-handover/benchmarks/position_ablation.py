"""Why position does not rank second, as the paper's Figure 2 has it: the committed DQN against a DQN trained with
its position hidden (x, y, z reported as 0; the same reward, training seed and budget).

If the DQN without position does as well on Table I, its position tells it nothing that the signal and the buffer
do not: position acts through the RSRP and RSRQ it sets (path loss, line of sight, shadowing), which the state
already holds.

Prints, for both DQNs: the rank of the position group (x, y, z summed per state) and of the buffer by mean
|contribution to the margin| on their own simulated decision states (and on real states with --real), with the top
four; Table I of CHM and both DQNs on the same held-out flights; and the rows where the two DQNs differ beyond the
intervals.

Run: .venv/bin/python plugins/xairl-uav-handover/benchmarks/position_ablation.py [--flights 200] [--eval-seeds 0]
     [--real DIR] [--states 400]            (about 3 minutes on 2 cores: one training run of 40 episodes)
"""

import argparse
import tempfile
from pathlib import Path

import numpy as np
from reproduce import real_sample, real_walks

from xairl_uav_handover.baselines import CHM
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.evaluate import importance, ranked
from xairl_uav_handover.features import GROUPS
from xairl_uav_handover.policy import DQNController, dqn_decision_states, load_checkpoint
from xairl_uav_handover.table import flights, format_rows, verdict, with_intervals
from xairl_uav_handover.train import TrainConfig, train_checkpoint


def ranks(ckpt, states: np.ndarray) -> str:
    """The position group's and the buffer's rank by mean |contribution to the margin|, and the top four."""
    imp = importance(ckpt, states, groups={"position": GROUPS["position"]})
    order = ranked(imp)
    return (
        f"position {order.index('position') + 1} of {len(order)}, buffer {order.index('buffer_queue_size') + 1}"
        f" (top four: {', '.join(order[:4])})"
    )


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--flights", type=int, default=200)
    ap.add_argument("--eval-seeds", type=int, nargs="+", default=[0])
    ap.add_argument("--states", type=int, default=400)
    ap.add_argument("--real", default=None, help="a folder of real UKM flight exports")
    args = ap.parse_args()
    committed = load_checkpoint()
    data = committed.sim_config.model_dump()
    data["observation"]["position_hidden"] = True
    hidden_cfg = SimConfig.model_validate(data)
    path = Path(tempfile.mkdtemp()) / "no-position.safetensors"
    tc = TrainConfig.of_checkpoint(committed.meta)
    train_checkpoint(tc, hidden_cfg, str(path), progress=False)
    blind = load_checkpoint(path)
    dqns = {"DQN": committed, "DQN without position": blind}
    for name, ckpt in dqns.items():
        print(f"{name}, simulated decision states: {ranks(ckpt, dqn_decision_states(ckpt, args.states, 0))}")
        if args.real:
            real = real_sample(real_walks(args.real, ckpt.sim_config), args.states)
            print(f"{name}, real states: {ranks(ckpt, real)}")
    res = {"CHM": with_intervals(flights(CHM(), committed.sim_config, args.flights, args.eval_seeds))}
    for name, ckpt in dqns.items():
        res[name] = with_intervals(flights(DQNController(ckpt.net), ckpt.sim_config, args.flights, args.eval_seeds))
    print(
        f"\nTable I: {args.flights} held-out flights x evaluation seeds {args.eval_seeds}, value [bootstrap 95 % "
        "interval]\n" + format_rows(res)
    )
    for a, b in (("DQN without position", "DQN"), ("DQN", "DQN without position")):
        print(verdict(res, a, b))


if __name__ == "__main__":
    main()
