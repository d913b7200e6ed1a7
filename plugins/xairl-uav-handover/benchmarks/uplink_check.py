"""The uplink and the flights against real measurements (issue 53, objections 2, 4, 5, 11): median uplink capacity
in simulation (CHM, held-out flights) and on the real UKM flights (their measured RSRP through
real_data.UplinkBuffer; the even files are the fit half of radio.p0_pusch_dbm, the odd ones the check half) against
IMC'22's measured medians; the buffer's empty / partly filled / full shares at decision states (every 0.2 s) in
both; CHM's handovers per minute and lost data; the simulated altitude and vertical speed, also at CHM's handovers,
against the IMC'22 DJI flight logs at the handovers of baltaci-imc22-handovers (the UKM data has fixed heights).

Run: .venv/bin/python plugins/xairl-uav-handover/benchmarks/uplink_check.py [--flights 200] [--real DIR]
     [--baltaci DIR]   (about 30 s on 2 cores)
"""

import argparse
import time
from pathlib import Path

import numpy as np
import pandas as pd

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


def spread(a) -> str:
    return f"median {np.median(a):.1f}, p5 {np.percentile(a, 5):.1f}, p95 {np.percentile(a, 95):.1f}"


def simulated(cfg: SimConfig, n: int) -> dict:
    """CHM on ``n`` held-out flights: per-flight handovers per minute and lost bits; capacity, queue and height
    every 0.2 s; vertical speed at each handover."""
    env = HandoverVecEnv(cfg, n, decision_every=1)
    env.reset(seed=HELD_OUT_SEED)
    chm = CHM()
    chm.reset(env)
    sim, every = env.sim, 5
    out = {"ho": np.zeros(n), "lost": np.zeros(n), "cap": [], "q": [], "z": [], "vz_ho": []}
    for i in range(sim.n_steps):
        if i % every == 0:
            out["cap"].append(capacity_bps(cfg, sim.ul_sinr_db()))
            out["q"].append(sim.q.copy())
            out["z"].append(sim.pos[:, 2].copy())
        before = sim.pos[:, 2].copy()
        *_, info = env.step(chm(env))
        out["vz_ho"].append(((sim.pos[:, 2] - before) / sim.dt)[info["handover"] > 0])
        out["ho"] += info["handover"]
        out["lost"] += info["lost_bits"]
    out["rate"] = out["ho"] / (sim.n_steps * sim.dt / 60)
    out["vz"] = np.diff(np.array(out["z"]), axis=0).ravel() / (every * sim.dt)
    for key in ("cap", "q", "z", "vz_ho"):
        out[key] = np.concatenate(out[key])
    return out


def real(cfg: SimConfig, folder: str) -> list[tuple]:
    """Per real flight: (name, nominal height, capacity at each sample, the modelled queue at each sample)."""
    flights, _ = load_folder(folder)
    out = []
    for f in flights:
        link = UplinkBuffer(cfg, f.altitude_m, 0, f.name)
        cap = np.array([capacity_bps(cfg, link.sinr_db(float(r), p)) for r, p in zip(f.rsrp, f.pci)])
        out.append((f.name, f.altitude_m, cap, walk(f, cfg).queue_bits))
    return out


def print_sim(s: dict, n: int, q_max: float) -> None:
    print(f"simulated, {n} held-out flights (seed {HELD_OUT_SEED}), CHM:")
    print(f"  handovers/min mean {s['rate'].mean():.2f} median {np.median(s['rate']):.2f}")
    print(f"  lost data per flight mean {s['lost'].mean() / 1e6:.1f} Mbit, median {np.median(s['lost']) / 1e6:.1f}")
    print(f"  uplink capacity Mbit/s: {spread(s['cap'] / 1e6)}")
    print(f"  buffer at decision states (q_max {q_max / 1e6:g} Mbit): {shares(s['q'], q_max)}")
    print(f"  altitude m: {spread(s['z'])}")
    print(
        f"  vertical speed m/s: {spread(s['vz'])}; |vz| > 0.1 in {100 * np.mean(np.abs(s['vz']) > 0.1):.1f} % of 0.2 s"
    )
    vz = s["vz_ho"]
    print(
        f"  at CHM's handovers: vertical speed m/s {spread(vz)}, |vz| > 0.1 in {100 * np.mean(np.abs(vz) > 0.1):.1f} %"
    )


def print_real(rows: list[tuple], sim_cap: np.ndarray, q_max: float) -> None:
    for name, part in (("fit half (even files)", rows[0::2]), ("check half (odd files)", rows[1::2]), ("all", rows)):
        c = np.concatenate([r[2] for r in part]) / 1e6
        print(f"real UKM {name}: {len(part)} flights, capacity Mbit/s {spread(c)}")
    print(f"real buffer at samples: {shares(np.concatenate([r[3] for r in rows]), q_max)}")
    print(f"real UKM nominal heights m: {spread([r[1] for r in rows])} (one per file: fixed-height legs)")
    real_median = np.median(np.concatenate([r[2] for r in rows])) / 1e6
    for k, v in MEASURED_MBPS.items():
        sim = np.median(sim_cap) / 1e6
        print(f"  vs {k} {v} Mbit/s: sim {100 * (sim / v - 1):+.1f} %, real {100 * (real_median / v - 1):+.1f} %")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--flights", type=int, default=200)
    ap.add_argument("--real", default=str(ROOT.parent / "shared/data/ukm-uav-lte/raw"))
    ap.add_argument("--baltaci", default=str(ROOT.parent / "shared/data/baltaci-imc22-handovers"))
    args = ap.parse_args()
    cfg, t0 = SimConfig(), time.time()
    s = simulated(cfg, args.flights)
    print_sim(s, args.flights, cfg.buffer.q_max_bits)
    print_real(real(cfg, args.real), s["cap"], cfg.buffer.q_max_bits)
    if Path(args.baltaci, "handovers.csv").is_file():
        ev = pd.read_csv(Path(args.baltaci, "handovers.csv"))
        vz, h = -ev["vel_d"].dropna().to_numpy(), ev["relative_height"].dropna().to_numpy()
        print(f"IMC'22 DJI logs at {len(ev)} handovers: height m {spread(h)}")
        print(
            f"  vertical speed m/s {spread(vz)}, |vz| > 0.1 in {100 * np.mean(np.abs(vz) > 0.1):.1f} %, p1 "
            f"{np.percentile(vz, 1):.2f}, p99 {np.percentile(vz, 99):.2f}"
        )
    print(f"({time.time() - t0:.0f} s)")


if __name__ == "__main__":
    main()
