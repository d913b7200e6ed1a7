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
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", default="uav-dqn.safetensors", help="checkpoint path (metadata holds the configs)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(run=run_train)
    p = sub.add_parser("evaluate", help="CHM, SA-MRO and the DQN on the same held-out flights (Table I)")
    p.add_argument("--flights", type=int, default=100, help="held-out flights")
    p.add_argument("--seed", type=int, default=0, help="seed of the held-out flights")
    p.add_argument("--duration", type=float, default=None, help="seconds per flight")
    p.add_argument("--min-stay", type=float, default=None, help="ping-pong window in seconds (default 1)")
    p.add_argument("--checkpoint", default=None, help="DQN checkpoint (default: the plugin's pretrained one)")
    p.add_argument("--json", action="store_true", help="print the table as JSON, keys per policy")
    p.set_defaults(run=run_evaluate)


def _sim_config(base, duration=None, min_stay=None):
    from pydantic import ValidationError
    from xairl import InputError, validation_message

    from .config import SimConfig

    data = (base or SimConfig()).model_dump()
    if duration is not None:
        data["flight"]["duration_s"] = duration
    if min_stay is not None:
        data["handover"]["min_time_of_stay_s"] = min_stay
    try:
        return SimConfig.model_validate(data)
    except ValidationError as exc:
        raise InputError(validation_message(exc, "UAV simulator settings")) from None


def run_train(args) -> int:
    from xairl import InputError

    from .train import TrainConfig, train_checkpoint

    if args.episodes < 1 or args.flights < 1:
        raise InputError("--episodes and --flights must be at least 1.")
    tc = TrainConfig(episodes=args.episodes, n_flights=args.flights, seed=args.seed)
    seconds = train_checkpoint(tc, _sim_config(None, args.duration), args.out, progress=not args.no_progress)
    print(f"trained {args.episodes} episodes in {seconds} s; wrote {args.out}")
    return 0


def run_evaluate(args) -> int:
    from xairl import InputError

    from .baselines import CHM, SAMRO
    from .evaluate import format_table, table_one
    from .policy import DQNController, load_checkpoint

    if args.flights < 1:
        raise InputError("--flights must be at least 1.")
    ckpt = load_checkpoint(args.checkpoint)
    cfg = _sim_config(ckpt.sim_config, args.duration, args.min_stay)
    rows = table_one([CHM(), SAMRO(), DQNController(ckpt.net)], cfg, args.flights, args.seed)
    if args.json:
        print(json.dumps({"flights": args.flights, "seed": args.seed,
                          "min_time_of_stay_s": cfg.handover.min_time_of_stay_s, "policies": rows}, indent=2))
    else:
        print(format_table(rows, cfg, args.flights))
    return 0
