"""What a two-threshold rule reaches on the targets of Table I: where the handovers/RSRQ/availability frontier lies,
so that a DQN's figures can be read against the best simple policy and not only against CHM.

The rule (``baselines.RSRQRule``) stays unless the serving cell's reported RSRQ is below ``threshold_db`` while the
buffer holds data, or the buffer is at least ``full_share`` of its size; then it hands over to the measured candidate
with the best RSRQ, if that one is at least ``margin_db`` better than the serving cell. It sees the DQN's 13 inputs
and acts at the DQN's decision period. One rule per combination of the values given.

Run: .venv/bin/python plugins/xairl-uav-handover/benchmarks/rule_frontier.py [--flights 100] [--seeds 0]
     [--thresholds -14 -10] [--margins 2 3] [--full-shares 0.5]
"""

import argparse
import itertools

from table_one import print_targets, targets

from xairl_uav_handover.baselines import CHM, RSRQRule
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.table import flights, format_rows, with_intervals


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--flights", type=int, default=100, help="held-out flights per evaluation seed")
    ap.add_argument("--seeds", type=int, nargs="+", default=[0], help="evaluation seeds (flights pooled)")
    ap.add_argument("--thresholds", type=float, nargs="+", default=[-14.0], help="serving RSRQ triggers (dB)")
    ap.add_argument(
        "--margins", type=float, nargs="+", default=[2.0, 3.0], help="how much better the target's RSRQ must be (dB)"
    )
    ap.add_argument("--full-shares", type=float, nargs="+", default=[0.5], help="buffer share that triggers")
    args = ap.parse_args()
    cfg = SimConfig()
    res = {"CHM": with_intervals(flights(CHM(), cfg, args.flights, args.seeds))}
    for spec in itertools.product(args.thresholds, args.margins, args.full_shares):
        rule = RSRQRule(*spec)
        res[rule.name] = with_intervals(flights(rule, cfg, args.flights, args.seeds))
    print(f"{args.flights} held-out flights x evaluation seeds {args.seeds}")
    print(format_rows(res))
    for name in [k for k in res if k != "CHM"]:
        met = targets({"CHM": res["CHM"], "DQN": res[name]}, args.flights * len(args.seeds))
        print(f"\n{name}: {sum(ok for _, ok, _ in met)} of 9 simulated targets")
        print_targets(met)


if __name__ == "__main__":
    main()
