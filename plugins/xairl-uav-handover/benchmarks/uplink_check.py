"""The uplink and the flights against the real UKM flights and IMC'22 (issue 53, objections 2, 4, 5, 11): median
uplink capacity in simulation (CHM, held-out flights) and on the real flights (their measured RSRP through
real_data.UplinkBuffer, fit and check halves), the buffer's empty / partly filled / full shares at decision states
(every 0.2 s) in both, CHM's handovers per minute and lost data, and the simulated altitude and vertical speed.

Run: .venv/bin/python plugins/xairl-uav-handover/benchmarks/uplink_check.py [--flights 200] [--real DIR]
"""

import argparse
import time
from pathlib import Path

import numpy as np

from xairl_uav_handover.baselines import CHM
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.env import HandoverVecEnv
from xairl_uav_handover.evaluate import HELD_OUT_SEED
from xairl_uav_handover.exports import load_folder
from xairl_uav_handover.real_data import UplinkBuffer, walk
from xairl_uav_handover.uplink import capacity_bps

ROOT = Path(__file__).resolve().parents[3]
MEASURED_MBPS = {"IMC'22 operator B urban": 37.7, "IMC'22 operator A urban": 31.5}


def shares(q: np.ndarray, q_max: float) -> str:
    full, empty = q >= q_max, q <= 0
    return f"empty {100 * empty.mean():.1f} % / partly {100 * (~full & ~empty).mean():.1f} % / full {100 * full.mean():.1f} %"


def simulated(cfg: SimConfig, n: int):
    env = HandoverVecEnv(cfg, n, decision_every=1)
    env.reset(seed=HELD_OUT_SEED)
    chm = CHM()
    chm.reset(env)
    sim, every = env.sim, 5
    ho, lost, caps, queues, z = np.zeros(n), np.zeros(n), [], [], []
    for i in range(sim.n_steps):
        if i % every == 0:
            caps.append(capacity_bps(cfg, sim.ul_sinr_db()))
            queues.append(sim.q.copy())
            z.append(sim.pos[:, 2].copy())
        *_, info = env.step(chm(env))
        ho += info["handover"]
        lost += info["lost_bits"]
    minutes = sim.n_steps * sim.dt / 60
    return ho / minutes, lost, np.concatenate(caps), np.concatenate(queues), np.array(z), every * sim.dt


def real(cfg: SimConfig, folder: str):
    flights, _ = load_folder(folder)
    out = []
    for f in flights:
        link = UplinkBuffer(cfg, f.altitude_m, 0, f.name)
        cap = np.array([capacity_bps(cfg, link.sinr_db(float(r), p)) for r, p in zip(f.rsrp, f.pci)])
        out.append((f.name, f.altitude_m, cap, walk(f, cfg).queue_bits))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--flights", type=int, default=200)
    ap.add_argument("--real", default=str(ROOT.parent / "shared/data/ukm-uav-lte/raw"))
    args = ap.parse_args()
    cfg, t0 = SimConfig(), time.time()
    q_max = cfg.buffer.q_max_bits
    rate, lost, cap, q, z, dt = simulated(cfg, args.flights)
    print(f"simulated, {args.flights} held-out flights (seed {HELD_OUT_SEED}), CHM:")
    print(
        f"  handovers/min mean {rate.mean():.2f} median {np.median(rate):.2f}; lost data per flight mean {lost.mean() / 1e6:.1f} Mbit, median {np.median(lost) / 1e6:.1f}"
    )
    print(
        f"  uplink capacity median {np.median(cap) / 1e6:.1f} Mbit/s (p5 {np.percentile(cap, 5) / 1e6:.1f}, p95 {np.percentile(cap, 95) / 1e6:.1f})"
    )
    print(f"  buffer at decision states (q_max {q_max / 1e6:g} Mbit): {shares(q, q_max)}")
    vz = np.diff(z, axis=0).ravel() / dt
    p = lambda a: f"median {np.median(a):.1f}, p5 {np.percentile(a, 5):.1f}, p95 {np.percentile(a, 95):.1f}"  # noqa: E731
    print(
        f"  altitude m: {p(z)}; vertical speed m/s: {p(vz)}; |vz| > 0.1 m/s in {100 * np.mean(np.abs(vz) > 0.1):.1f} % of 0.2 s steps"
    )
    rows = real(cfg, args.real)
    for name, part in (("fit half (even files)", rows[0::2]), ("check half (odd files)", rows[1::2]), ("all", rows)):
        c = np.concatenate([r[2] for r in part])
        print(
            f"real UKM {name}: {len(part)} flights, capacity median {np.median(c) / 1e6:.1f} Mbit/s (p5 {np.percentile(c, 5) / 1e6:.1f}, p95 {np.percentile(c, 95) / 1e6:.1f})"
        )
    qr = np.concatenate([r[3] for r in rows])
    print(f"real buffer at samples: {shares(qr, q_max)}")
    alt = np.array([r[1] for r in rows])
    print(f"real UKM nominal altitudes m: {p(alt)} (per file; no vertical speed in the data: fixed-height legs)")
    for k, v in MEASURED_MBPS.items():
        print(
            f"  vs {k} {v} Mbit/s: sim {100 * (np.median(cap) / 1e6 / v - 1):+.1f} %, real {100 * (np.median(np.concatenate([r[2] for r in rows])) / 1e6 / v - 1):+.1f} %"
        )
    print(f"({time.time() - t0:.0f} s)")


if __name__ == "__main__":
    main()
