"""Probe of a design not built: would a multi-carrier network give the real flights' spread of RSRQ - RSRP?

The simulator is one 2 GHz carrier: every cell's RSSI is the same carrier's total, so RSRQ - RSRP differs between
candidates only by the measured cell's own share and the measurement errors (calibrate.py: KS 0.22 against the
real UKM flights). This script patches the simulator in this process only, for two changes:

- ``--carriers``: every sector carries one cell per carrier (co-sited), each carrier with its own path loss (TR
  36.777's 20 lg fc term), its own cells' loads and its own RSSI; the UE measures every cell on every carrier.
- ``--shared-error``: the L1 RSRQ error is the RSRP error plus an RSSI error, since the UE computes RSRQ from the
  same RSRP estimate (N RSRP / RSSI, TS 36.214). The RSSI error's std, sqrt(1.5^2 - 1.2^2) = 0.9 dB, keeps TS
  36.133's RSRQ accuracy.

The yardstick is the real flights' own variation: each real flight's KS statistic against all the other flights
pooled. A simulator whose KS against the real pool lies below their p90 looks like one more real flight. The real
pool is split by name (calibration.split_flights): the carriers were not fitted, so both halves are held out.

Run: .venv/bin/python plugins/xairl-uav-handover/benchmarks/multi_carrier_probe.py
     [--carriers 0.9,1.8,2.6] [--shared-error]   (about 20 s a configuration on 2 cores)
"""

import argparse
from pathlib import Path

import numpy as np
from scipy.special import ndtr
from scipy.stats import ks_2samp

from xairl_uav_handover import antenna, simulator
from xairl_uav_handover.baselines import CHM
from xairl_uav_handover.calibration import rsrq_spread, split_flights
from xairl_uav_handover.channel import los_probability, path_loss, shadow_sigma
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.env import HandoverVecEnv
from xairl_uav_handover.exports import load_folder
from xairl_uav_handover.failures import RS_SHARE_SYMBOL, rssi_activity
from xairl_uav_handover.real_data import walk

ROOT = Path(__file__).resolve().parents[3]


def patch(carriers: tuple[float, ...], shared_error: bool) -> None:
    """Patch the simulator class (this process only) for ``carriers`` (GHz) and the shared RSRQ error."""
    single_layout, single_uplink = antenna.cell_layout, simulator.interference_mw
    n_car = len(carriers)

    def layout(sites):  # cell j of carrier c is cell c * 3S + j
        xy, site, boresight = single_layout(sites)
        return np.tile(xy, (n_car, 1)), np.tile(site, n_car), np.tile(boresight, n_car)

    def uplink(cfg, sites, rng, k):  # the probe measures the downlink: each carrier gets the same uplink drop
        antenna.cell_layout = single_layout
        try:
            return np.tile(single_uplink(cfg, sites, rng, k), (1, n_car))
        finally:
            antenna.cell_layout = layout

    def measure(self):
        c = self.cfg.channel
        dx = self.pos[:, None, 0] - self.sites_xy[None, :, 0]
        dy = self.pos[:, None, 1] - self.sites_xy[None, :, 1]
        d2d, h = np.hypot(dx, dy), self.pos[:, 2:3]
        d3d = np.hypot(d2d, h - c.bs_height_m)
        los = ndtr(self.g_los) < los_probability(c.scenario, h, d2d)
        rest = shadow_sigma(c.scenario, h, los) * self.g_shadow
        rest = rest + np.where(los, self._fading_db[0], self._fading_db[1]) * self.g_fast
        per_carrier = len(self.sites_xy) * len(antenna.SECTOR_AZIMUTHS_DEG)
        site = self.site[:per_carrier]
        site_loss = np.concatenate(
            [(path_loss(c.scenario, h, d3d, f, los, c.bs_height_m) + rest)[:, site] for f in carriers], axis=1
        )
        gain = antenna.gain_db(self.cfg.antenna, dx[:, self.site], dy[:, self.site], h - c.bs_height_m, self.boresight)
        self.loss_db = site_loss - gain + self.cfg.radio.link_loss_db
        self.rsrp = self._rsrp_offset - self.loss_db
        p = 10 ** (self.rsrp / 10)
        active = p * rssi_activity(self._load)
        carrier = np.arange(self.N) // per_carrier
        total = np.stack([active[:, carrier == j].sum(axis=1) for j in range(n_car)], axis=1)[:, carrier]
        own = p * rssi_activity(self._load, RS_SHARE_SYMBOL)
        self.rsrq = 10 * np.log10(p / (12 * (own + total - active) + 12 * self._noise_re_mw))
        self.dl_sinr = 10 * np.log10(p / (total - active + self._noise_re_mw))

    def report(self):
        acc = self._acc
        acc[0], acc[1], acc[2] = acc[0] + self.rsrp, acc[1] + self.rsrq, acc[2] + 1
        if acc[2] == self._meas_every:
            a, obs = self._l3_a, self.cfg.observation
            e_rsrp = obs.rsrp_error_db * self.rng.standard_normal(self.rsrp.shape)
            e_rssi = np.sqrt(obs.rsrq_error_db**2 - obs.rsrp_error_db**2) * self.rng.standard_normal(self.rsrq.shape)
            self.meas_rsrp = (1 - a) * self.meas_rsrp + a * (acc[0] / acc[2] + e_rsrp)
            self.meas_rsrq = (1 - a) * self.meas_rsrq + a * (acc[1] / acc[2] + e_rsrp + e_rssi)
            self._acc = [np.zeros_like(self.rsrp), np.zeros_like(self.rsrq), 0]

    antenna.cell_layout, simulator.interference_mw = layout, uplink
    simulator.Simulator._measure = measure
    if shared_error:
        simulator.Simulator._report = report


def simulated_spread(cfg: SimConfig, n: int = 100, seconds: float = 60.0, seed: int = 3) -> tuple[np.ndarray, float]:
    """The spread over CHM's flights sampled once a second (as calibrate.py), and CHM's handovers per minute."""
    env = HandoverVecEnv(cfg, n, decision_every=1)
    env.reset(seed=seed)
    chm, out, handovers = CHM(), [], 0
    chm.reset(env)
    for i in range(int(seconds / cfg.flight.dt_s)):
        env.step(chm(env))
        handovers += int(env.sim.last.handover.sum())
        if i % 25 == 24:
            out.append(rsrq_spread(env.obs, env.candidates >= 0))
    return np.concatenate(out), handovers / n / (seconds / 60)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--real", default=str(ROOT.parent / "shared/data/ukm-uav-lte/raw"))
    ap.add_argument("--carriers", default="2.0", help="carrier frequencies in GHz, comma-separated")
    ap.add_argument("--shared-error", action="store_true")
    args = ap.parse_args()
    cfg = SimConfig()
    flights, _ = load_folder(args.real)
    spread = {}
    for f in flights:
        w = walk(f, cfg)
        spread[f.name] = rsrq_spread(w.states, np.array([[k < len(c) for k in range(4)] for c in w.candidates]))
    own = [
        ks_2samp(s, np.concatenate([o for m, o in spread.items() if m != name])).statistic
        for name, s in spread.items()
        if len(s) >= 100
    ]
    patch(tuple(float(x) for x in args.carriers.split(",")), args.shared_error)
    sim, chm_rate = simulated_spread(cfg)
    q = [25, 50, 75, 90, 99]
    print(f"carriers {args.carriers} GHz, shared RSRQ error {args.shared_error}; CHM {chm_rate:.2f} HO/min")
    print(f"  simulated spread p{'/p'.join(map(str, q))}: {np.percentile(sim, q)} dB ({len(sim)} states)")
    print(f"  a real flight against the others: KS p50 {np.median(own):.3f}, p90 {np.percentile(own, 90):.3f}")
    for label, half in zip(("even-named", "odd-named"), split_flights(flights)):
        real = np.concatenate([spread[f.name] for f in half])
        test = ks_2samp(sim, real)
        print(
            f"  {label} real flights p{'/p'.join(map(str, q))}: {np.percentile(real, q)} dB; "
            f"KS {test.statistic:.3f} (p = {test.pvalue:.2g})"
        )


if __name__ == "__main__":
    main()
