"""``xairl uav train`` and ``xairl uav evaluate``. Light at import: torch loads inside the commands."""

from __future__ import annotations

import argparse
import json


def configure(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="uav_command", metavar="COMMAND", required=True)
    p = sub.add_parser("train", help="train the handover DQN and write a safetensors checkpoint")
    p.add_argument("--episodes", type=int, default=40, help="training episodes (each flies --flights flights)")
    p.add_argument("--flights", type=int, default=64, help="flights simulated in parallel per episode")
    p.add_argument("--duration", type=float, default=None, help="seconds per flight (default: the sim config's)")
    p.add_argument(
        "--demonstrations",
        type=int,
        default=None,
        help="episodes of the RSRQ rule's flights to learn from (DQfD); default 0: a plain DQN, as in the paper",
    )
    p.add_argument(
        "--pretrain-updates",
        type=int,
        default=None,
        help="gradient steps on the demonstrations alone before the DQN flies (default: TrainConfig's 3000)",
    )
    p.add_argument(
        "--eps-start",
        type=float,
        default=None,
        help="exploration at the start (default: 0.2 with "
        "demonstrations, as the pretrained network already acts like the rule; 1 without)",
    )
    p.add_argument(
        "--reward",
        choices=("paper", "priced"),
        default="paper",
        help="the paper's reward (default), or the operator-priced one that also prices lost data and ping-pongs",
    )
    p.add_argument(
        "--standardise-states",
        type=int,
        default=None,
        help="flights simulated for the statistics that standardise the network's inputs (default: 2048)",
    )
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", default="uav-dqn.safetensors", help="checkpoint path (metadata holds the configs)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(run=run_train)
    p = sub.add_parser(
        "evaluate",
        help="CHM, SA-MRO and the DQN on the same held-out flights: Table I, each figure "
        "with its bootstrap 95 %% interval",
    )
    p.add_argument("--flights", type=int, default=100, help="held-out flights per evaluation seed")
    p.add_argument(
        "--seeds", type=int, nargs="+", default=[0], help="evaluation seeds, distinct and >= 0 (their flights pooled)"
    )
    p.add_argument("--duration", type=float, default=None, help="seconds per flight")
    p.add_argument("--checkpoint", default=None, help="DQN checkpoint (default: the plugin's pretrained one)")
    p.add_argument(
        "--json", action="store_true", help="print the table as JSON: per policy, per figure, [value, low, high]"
    )
    p.set_defaults(run=run_evaluate)


def _sim_config(base, duration=None):
    from pydantic import ValidationError

    import xairl
    from xairl import InputError

    from .config import SimConfig

    data = (base or SimConfig()).model_dump()
    if duration is not None:
        data["flight"]["duration_s"] = duration
    try:
        return SimConfig.model_validate(data)
    except ValidationError as exc:
        raise InputError(xairl.plugin.validation_message(exc, "UAV simulator settings")) from None


#: TrainConfig's fields that ``xairl uav train`` sets, by their flags
_TRAIN_FLAGS = {
    "episodes": "--episodes",
    "n_flights": "--flights",
    "seed": "--seed",
    "demonstrations": "--demonstrations",
    "pretrain_updates": "--pretrain-updates",
    "eps_start": "--eps-start",
    "standardise_states": "--standardise-states",
}


def run_train(args) -> int:
    import re

    from pydantic import ValidationError

    import xairl
    from xairl import InputError

    from .train import TrainConfig, train_checkpoint

    if args.episodes < 1 or args.flights < 1:
        raise InputError("--episodes and --flights must be at least 1.")
    given = {field: getattr(args, flag[2:].replace("-", "_")) for field, flag in _TRAIN_FLAGS.items()}
    try:
        tc = TrainConfig.model_validate({k: v for k, v in given.items() if v is not None})
    except ValidationError as exc:  # named by the flags the user typed
        message = xairl.plugin.validation_message(exc, "training settings")
        raise InputError(
            re.sub(r"\b(" + "|".join(_TRAIN_FLAGS) + r")\b", lambda m: _TRAIN_FLAGS[m.group(1)], message)
        ) from None
    from .config import PRICED_REWARD, SimConfig

    base = SimConfig.model_validate({"reward": PRICED_REWARD}) if args.reward == "priced" else None
    seconds = train_checkpoint(tc, _sim_config(base, args.duration), args.out, progress=not args.no_progress)
    print(f"trained {args.episodes} episodes in {seconds} s; wrote {args.out}")
    return 0


def run_evaluate(args) -> int:
    from xairl import InputError

    from .baselines import CHM, SAMRO
    from .policy import DQNController, load_checkpoint
    from .table import flights, format_paper, format_rows, verdict, with_intervals

    if args.flights < 1:
        raise InputError("--flights must be at least 1.")
    if min(args.seeds) < 0 or len(set(args.seeds)) < len(args.seeds):
        raise InputError(
            f"--seeds must be distinct and at least 0 (the same flights twice would narrow the "
            f"intervals falsely), got {' '.join(map(str, args.seeds))}."
        )
    ckpt = load_checkpoint(args.checkpoint)
    cfg = _sim_config(ckpt.sim_config, args.duration)
    res = {
        c.name: with_intervals(flights(c, cfg, args.flights, args.seeds))
        for c in (CHM(), CHM(decision_every=ckpt.sim_config.decision_every), SAMRO(), DQNController(ckpt.net))
    }
    if args.json:
        print(json.dumps({"flights": args.flights, "seeds": args.seeds, "policies": res}, indent=2))
    else:
        print(
            f"Table I: {args.flights} held-out flights of {cfg.flight.duration_s:g} s x evaluation seeds "
            f"{args.seeds}, value [bootstrap 95 % interval]; a ping-pong is a handover back to the previous BS "
            f"within the window its row names\n{format_rows(res, cfg.handover.min_time_of_stay_s)}\n{format_paper(res)}\n"
            f"{verdict(res, min_stay_s=cfg.handover.min_time_of_stay_s)}"
        )
    return 0
