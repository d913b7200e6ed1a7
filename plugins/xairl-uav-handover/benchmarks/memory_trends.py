"""Does the DQN with memory act on trends? Of its handovers on held-out flights (and, with --real, proposed on the
real flights), the share it would not take if it could not look back (memory.on_trends: the same network on the
window with every step set to the newest one), and why: for those decisions, which signals' past and which steps of
the window drove the margin (deep_shap, by signal and by step; the past is every step but the newest).

Run: .venv/bin/python plugins/xairl-uav-handover/benchmarks/memory_trends.py --checkpoint PATH [--flights 64]
     [--real ../shared/data/ukm-uav-lte]
"""

import argparse

import numpy as np

import xairl
from xairl_uav_handover.features import SIGNALS
from xairl_uav_handover.memory import on_trends, walk_states
from xairl_uav_handover.policy import dqn_decision_states, greedy, load_checkpoint, memory_of, uav_policy


def why(ckpt, states: np.ndarray, label: str) -> None:
    """The share of handovers taken on trends among ``states``, and what drove those (margin, deep_shap)."""
    cfg = ckpt.sim_config
    took = greedy(ckpt.net, states, cfg) > 0
    trend = on_trends(ckpt.net, states, cfg)
    print(
        f"\n{label}: {int(took.sum())} handovers among {len(states)} decision states; {int(trend.sum())} "
        f"({100 * trend.sum() / max(took.sum(), 1):.1f} %) would not be taken without the past"
    )
    if not trend.any():
        return
    policy = uav_policy(ckpt)
    exp = xairl.explain(policy, states[trend][:200], background=policy.background(100, seed=7))
    steps = np.abs(exp.by_step().margin()).mean(axis=0)
    print(
        "  mean |margin contribution| per step: "
        + ", ".join(f"{s} {v:.3f}" for s, v in zip(exp.by_step().feature_names, steps))
    )
    past = exp.margin().reshape(len(exp.margin()), -1, len(SIGNALS))[:, :-1].sum(axis=1)  # each signal's past
    order = np.argsort(-np.abs(past).mean(axis=0))[:5]
    print(
        "  signals whose past pushed most (mean |contribution of steps t-4..t-1| to the margin; mean signed): "
        + "; ".join(f"{SIGNALS[j]} {np.abs(past[:, j]).mean():.3f} ({past[:, j].mean():+.3f})" for j in order)
    )


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--checkpoint", required=True)
    ap.add_argument("--flights", type=int, default=64, help="held-out flights the DQN flies itself")
    ap.add_argument("--real", default=None, help="a folder of real UKM flight exports")
    args = ap.parse_args()
    ckpt = load_checkpoint(args.checkpoint)
    if not memory_of(ckpt.meta):
        raise SystemExit(f"{args.checkpoint} is a snapshot DQN; give a checkpoint trained with memory")
    why(ckpt, dqn_decision_states(ckpt, 10**9, seed=0, n_flights=args.flights), f"simulated ({args.flights} flights)")
    if args.real:
        from xairl_uav_handover.exports import load_folder
        from xairl_uav_handover.real_data import walk

        flights = load_folder(args.real)[0]
        states = np.concatenate([walk_states(walk(f, ckpt.sim_config), ckpt.sim_config) for f in flights])
        why(ckpt, states, f"real ({len(flights)} flights, open loop)")


if __name__ == "__main__":
    main()
