"""Table I as an operator reads it: CHM, SA-MRO and the DQN on the same held-out flights, every figure with its
bootstrap 95 % interval (xairl_uav_handover.table), and the targets of the issue "A reference DQN that beats the
A3 rule on what operators pay for" checked one by one.

Run: .venv/bin/python plugins/xairl-uav-handover/benchmarks/table_one.py [--flights 200] [--seeds 0 1 2]
     [--calibrated]   (every policy on the network calibrated to the real flights, network_check.CALIBRATED)
     [--checkpoint PATH ...]   (default: the committed checkpoint; several: one DQN column each, and one pooled
    column whose intervals resample training seeds, then flights)
Each per-flight figure as mean and median; the paper's medians beside ours (table.format_paper).
"""

import argparse
import json

from xairl_uav_handover.baselines import CHM, SAMRO
from xairl_uav_handover.network_check import calibrated
from xairl_uav_handover.policy import DQNController, load_checkpoint
from xairl_uav_handover.table import flights, format_paper, format_rows, pooled_seeds, with_intervals


def targets(res: dict, n_flights: int) -> list[tuple[str, bool, str]]:
    """(target, met, the figures compared) for targets 1-4 (value against value; the intervals are in the table)."""
    c, d = res["CHM"], res["DQN"]
    v = {k: x[0] for k, x in d.items()}
    w = {k: x[0] for k, x in c.items()}
    return [
        (
            "1. handovers <= 0.5 x CHM",
            v["handovers"] <= 0.5 * w["handovers"],
            f"{v['handovers']:.2f} vs 0.5 x {w['handovers']:.2f}",
        ),
        (
            "2a. ping-pongs per flight-minute <= CHM",
            v["pp_per_min"] <= w["pp_per_min"],
            f"{v['pp_per_min']:.3f} vs {w['pp_per_min']:.3f}",
        ),
        (
            "2b. at most 1 flight in 200 with > 5 ping-pongs",
            v["pp_over_5"] <= 0.5,
            f"{v['pp_over_5']:.2f} % of {n_flights} flights",
        ),
        (
            "3a. lost data <= CHM + 1 %",
            v["lost_mbit"] <= 1.01 * w["lost_mbit"],
            f"{v['lost_mbit']:.1f} vs {w['lost_mbit']:.1f} Mbit",
        ),
        (
            "3b. availability mean >= CHM - 0.1 point",
            v["availability"] >= w["availability"] - 0.1,
            f"{v['availability']:.2f} vs {w['availability']:.2f} %",
        ),
        (
            "3c. availability worst 5 % >= CHM's",
            v["availability_worst5"] >= w["availability_worst5"],
            f"{v['availability_worst5']:.2f} vs {w['availability_worst5']:.2f} %",
        ),
        (
            "3d. RSRQ violation time <= CHM + 2 points",
            v["rsrq_violation"] <= w["rsrq_violation"] + 2,
            f"{v['rsrq_violation']:.2f} vs {w['rsrq_violation']:.2f} %",
        ),
        ("4a. handovers with a full buffer <= 50 %", v["ho_full"] <= 50, f"{v['ho_full']:.1f} %"),
        ("4b. handovers with an empty buffer <= 5 %", v["ho_empty"] <= 5, f"{v['ho_empty']:.1f} %"),
    ]


def print_targets(met: list[tuple[str, bool, str]]) -> None:
    """One line per target: met or NOT met, and the figures compared."""
    for label, ok, detail in met:
        print(f"  {'met' if ok else 'NOT met':<8} {label:<50} {detail}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--flights", type=int, default=200, help="held-out flights per evaluation seed")
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2], help="evaluation seeds (flights pooled)")
    ap.add_argument("--checkpoint", nargs="+", default=[None], help="DQN checkpoints (default: the committed one)")
    ap.add_argument("--json", default=None, help="also write the figures here")
    ap.add_argument("--calibrated", action="store_true", help="on network_check.CALIBRATED's network (issue 67)")
    args = ap.parse_args()
    ckpts = [load_checkpoint(p) for p in args.checkpoint]
    cfg = calibrated(ckpts[0].sim_config) if args.calibrated else ckpts[0].sim_config
    n = args.flights * len(args.seeds)
    res = {
        c.name: with_intervals(flights(c, cfg, args.flights, args.seeds))
        for c in (CHM(), CHM(decision_every=cfg.decision_every), SAMRO())
    }
    runs = [flights(DQNController(ckpt.net), cfg, args.flights, args.seeds) for ckpt in ckpts]
    for k, run in enumerate(runs):
        res["DQN" if len(ckpts) == 1 else f"DQN {k}"] = with_intervals(run)
    if len(runs) > 1:  # intervals over training seeds and flights
        pooled, groups = pooled_seeds(runs)
        res[f"DQN, {len(runs)} seeds"] = with_intervals(pooled, groups=groups)
    f = cfg.flight
    print(
        f"Table I: {args.flights} held-out flights of {f.duration_s:g} s x evaluation seeds {args.seeds} ({n} "
        f"flights per policy); value [bootstrap 95 % interval]; reward of the DQN: {ckpts[0].sim_config.reward}"
    )
    print(format_rows(res))
    print(format_paper(res))
    for name in [k for k in res if k.startswith("DQN") and "seeds" not in k]:
        print(f"\ntargets, {name}:")
        print_targets(targets({"CHM": res["CHM"], "DQN": res[name]}, n))
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(res, fh, indent=1)


if __name__ == "__main__":
    main()
