"""Calibration against the real UKM flights (issue 11): handovers per minute by altitude band (the live network,
CHM closed-loop on the real measurements, simulated CHM), the uplink's capacity and the buffer in simulation and on
real flights, and the share of real states outside the simulated training distribution (0.5-99.5 % per feature).

Targets: simulated / real CHM within 2x in every band; buffer full in < 20 % of real states; <= 5 % of real states
with any feature outside the simulated range.
Run: .venv/bin/python plugins/xairl-uav-handover/benchmarks/calibrate.py [--real DIR] [--checkpoint PATH]
     [--set observation.l3_filter_k=4 ...]   (overrides of the checkpoint's simulator settings)
     [--calibrated]   (network_check.CALIBRATED over the checkpoint's network, before --set)
     [--table]   (issue 67's calibration table instead, network_check.py: serving SINR, replayed failures, an A3
                  grid at the logs' cadence, ring convergence; fit and check halves; about 45 minutes at 5 rings)
"""

import argparse
import dataclasses
import json
import time
from pathlib import Path

import numpy as np

from xairl_uav_handover.baselines import CHM
from xairl_uav_handover.calibration import band_rows, link_loss_fit, outside, quantile_rows, rsrq_spread, split_flights
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.env import HandoverVecEnv
from xairl_uav_handover.exports import load_folder
from xairl_uav_handover.network_check import calibrated
from xairl_uav_handover.policy import dqn_decision_states, load_checkpoint
from xairl_uav_handover.real_data import chm_handovers, walk
from xairl_uav_handover.uplink import capacity_bps

ROOT = Path(__file__).resolve().parents[3]


def overridden(cfg: SimConfig, sets: list[str]) -> SimConfig:
    data = cfg.model_dump()
    for item in sets:
        key, value = item.split("=", 1)
        section, field = key.split(".")
        data[section][field] = json.loads(value)
    return SimConfig.model_validate(data)


def simulated_link(cfg: SimConfig, n: int = 100, seconds: float = 60.0, seed: int = 1):
    """Uplink capacity and queue under CHM, sampled once a second over ``n`` flights."""
    env = HandoverVecEnv(cfg, n, decision_every=1)
    env.reset(seed=seed)
    chm = CHM()
    chm.reset(env)
    caps, queues = [], []
    for i in range(int(seconds / cfg.flight.dt_s)):
        env.step(chm(env))
        if i % 25 == 0:
            caps.append(capacity_bps(cfg, env.sim.ul_sinr_db()))
            queues.append(env.sim.q.copy())
    return np.concatenate(caps), np.concatenate(queues)


def spread_report(cfg: SimConfig, walks, seed: int = 3) -> None:
    """The spread of RSRQ - RSRP over a state's candidates, simulated (CHM's flights, sampled once a second) against
    the real states, with a two-sample Kolmogorov-Smirnov test."""
    from scipy.stats import ks_2samp

    real = np.concatenate(
        [rsrq_spread(w.states, np.array([[k < len(c) for k in range(4)] for c in w.candidates])) for w in walks]
    )
    env = HandoverVecEnv(cfg, 100, decision_every=1)
    env.reset(seed=seed)
    chm, sim = CHM(), []
    chm.reset(env)
    for i in range(int(60 / cfg.flight.dt_s)):
        env.step(chm(env))
        if i % 25 == 24:
            sim.append(rsrq_spread(env.obs, env.candidates >= 0))
    sim = np.concatenate(sim)
    test = ks_2samp(sim, real)
    q = [25, 50, 75, 90, 99]
    print(
        f"spread of RSRQ - RSRP over a state's candidates (dB, 1 dB resolution; p{'/p'.join(map(str, q))}): "
        f"real {np.percentile(real, q)} ({len(real)} states), simulated {np.percentile(sim, q)} ({len(sim)}); "
        f"KS statistic {test.statistic:.3f}, p = {test.pvalue:.2g}"
    )


def calibration_table(cfg: SimConfig, flights) -> None:
    """Issue 67's table: each quantity simulated against real on the fit and the check half."""
    from xairl_uav_handover import network_check as nc

    grid = [(o, t) for o in (2.0, 4.0, 6.0) for t in (0.16, 0.64, 1.28)]
    print("| quantity | half | simulated | real | target | met |\n|---|---|---|---|---|---|")
    for part in (nc.sinr_rows, nc.failure_rows, lambda c, f: nc.a3_rows(c, f, grid), nc.ring_rows):
        for r in part(cfg, flights):
            real = "" if np.isnan(r.real) else f"{r.real:.3g}"
            met = ("yes" if r.met else "no") if r.target else ""
            print(f"| {r.quantity} | {r.half} | {r.simulated:.3g} | {real} | {r.target} | {met} |")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--real", default=str(ROOT.parent / "shared/data/ukm-uav-lte/raw"))
    ap.add_argument("--checkpoint", default=None)
    ap.add_argument("--set", nargs="*", default=[], help="simulator overrides section.field=JSON")
    ap.add_argument("--table", action="store_true", help="issue 67's calibration table (network_check.py)")
    ap.add_argument("--calibrated", action="store_true", help="network_check.CALIBRATED over the checkpoint's network")
    args = ap.parse_args()
    ckpt = load_checkpoint(args.checkpoint)
    cfg = overridden(calibrated(ckpt.sim_config) if args.calibrated else ckpt.sim_config, args.set)
    ckpt = dataclasses.replace(ckpt, sim_config=cfg)
    t0 = time.time()
    flights, _ = load_folder(args.real)
    if args.table:
        calibration_table(cfg, flights)
        print(f"({time.time() - t0:.0f} s)")
        return
    walks = [walk(f, cfg) for f in flights]
    chm_real = [chm_handovers(f, sim_config=cfg) for f in flights]
    print(
        f"{len(flights)} real flights; live network {sum(f.observed_handovers for f in flights) / sum(f.t[-1] / 60 for f in flights):.2f} HO/min"
    )
    print(
        f"{'band':<12}{'flights':>8}{'live/min':>10}{'CHM real/min':>14}{'CHM sim 40ms':>14}{'CHM sim 1.28s':>15}"
        f"{'sim/real':>10}"
    )
    for r in band_rows(flights, chm_real, cfg, seed=0):
        print(
            f"{r.band:<12}{r.flights:>8}{r.live_per_min:>10.2f}{r.chm_real_per_min:>14.2f}{r.chm_sim_per_min:>14.2f}"
            f"{r.chm_sim_sampled_per_min:>15.2f}{r.sim_over_real:>10.2f}"
        )
    fit = link_loss_fit(flights, cfg)
    print(
        f"link loss fitted on {len(split_flights(flights)[0])} real flights: {fit['link_loss_db']:.1f} dB (now "
        f"{cfg.radio.link_loss_db:g}); held-out flights' serving RSRP median {fit['real_held_out_median']:.1f} dBm, "
        f"simulated at the fitted loss {fit['sim_held_out_median']:.1f} dBm"
    )
    spread_report(cfg, walks)
    cap, q_sim = simulated_link(cfg)
    q_real = np.concatenate([w.queue_bits for w in walks])
    full = cfg.buffer.q_max_bits
    print(
        f"uplink capacity under CHM: median {np.median(cap) / 1e6:.1f} Mbit/s (video {cfg.buffer.video_rate_mbps:g}); "
        f"buffer non-empty / full: simulated {100 * np.mean(q_sim > 0):.1f} / {100 * np.mean(q_sim >= full):.1f} %, "
        f"real {100 * np.mean(q_real > 0):.1f} / {100 * np.mean(q_real >= full):.1f} % (target full < 20 %)"
    )
    real = np.concatenate([w.states for w in walks])
    sim = dqn_decision_states(ckpt, 5000, seed=2, epsilon=0.5, n_flights=256)
    print(
        f"real states with any feature outside the simulated 0.5-99.5 % range: "
        f"{100 * outside(real, sim).any(axis=1).mean():.1f} % (target <= 5 %); per feature (p5 / p50 / p95):"
    )
    for r in quantile_rows(sim, real):
        print(
            f"  {r.feature:<18} sim {r.sim_p5:9.1f} {r.sim_p50:9.1f} {r.sim_p95:9.1f}   real {r.real_p5:9.1f} "
            f"{r.real_p50:9.1f} {r.real_p95:9.1f}   outside {r.real_outside_pct:5.1f} %"
        )
    print(f"({time.time() - t0:.0f} s)")


if __name__ == "__main__":
    main()
