"""Vectorised uplink simulator: K UAV flights over a hexagonal grid of N ground BSs, one numpy step for all.

Per step (dt): measurements (RSRP/RSRQ of every BS, uplink SINR at the serving BS) -> the controller's target BS ->
handover bookkeeping (interruption, control packet, ping-pong) -> buffer -> motion -> channel update.

Shadow fading and the LoS state are spatially correlated per UAV-BS link: each link carries two standard-normal
latents that follow an AR(1) process with correlation exp(-distance moved / shadow_corr_m) (Gudmundson). Shadowing
is sigma(LoS state) times one latent; the link is LoS while Phi(other latent) < P_LOS(h, d2D), so the LoS
probability of TR 36.777 holds at every point and the state does not flicker from step to step. A third latent,
correlated in time (fading_corr_s) and scaled by fading_db, is the fast-fading residual that layer-3 filtering
leaves in measured RSRP; it is what makes an A3 handover with a small offset ping-pong at height.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.special import ndtr

from .buffer import buffer_step, service_bits
from .channel import los_probability, path_loss, shadow_sigma
from .config import LayoutConfig, SimConfig
from .features import N_CANDIDATES, state_rows


def n_sites(layout: LayoutConfig) -> int:
    """Sites of the hexagonal grid: the centre plus 6 r sites in ring r."""
    return 1 + 3 * layout.rings * (layout.rings + 1)


def hex_layout(isd: float, rings: int) -> np.ndarray:
    """(N, 2) site positions of a hexagonal grid: the centre plus ``rings`` rings (1, 7, 19, 37, ... sites)."""
    sites = [(0.0, 0.0)]
    dirs = [(np.cos(np.pi / 3 * k + np.pi / 6), np.sin(np.pi / 3 * k + np.pi / 6)) for k in range(6)]
    for r in range(1, rings + 1):
        x, y = r * isd * dirs[4][0], r * isd * dirs[4][1]
        for side in range(6):
            for _ in range(r):
                sites.append((x, y))
                x, y = x + isd * dirs[side][0], y + isd * dirs[side][1]
    return np.array(sites)


@dataclass
class StepInfo:
    """What happened to each UAV in one step (arrays of shape (K,)). ``available``: served and SINR >= minimum;
    ``radio_ok``: SINR >= minimum whether or not a handover interrupted service."""

    handover: np.ndarray
    pingpong: np.ndarray
    available: np.ndarray
    radio_ok: np.ndarray
    rsrp_violation: np.ndarray
    rsrq_violation: np.ndarray
    queue_bits: np.ndarray
    lost_bits: np.ndarray
    sinr_db: np.ndarray


class Simulator:
    """K independent UAV flights (one per row), all stepped at once.

    :param config: :class:`SimConfig`.
    :param n_uavs: flights simulated in parallel.
    :param seed: every random draw (flights, channel, arrivals) comes from this seed.
    """

    def __init__(self, config: SimConfig | None = None, n_uavs: int = 1, seed: int = 0):
        self.cfg = cfg = config or SimConfig()
        self.rng = rng = np.random.default_rng(seed)
        self.bs_xy = hex_layout(cfg.layout.isd_m, cfg.layout.rings)
        self.K, self.N = n_uavs, len(self.bs_xy)
        self.dt = cfg.flight.dt_s
        self.n_steps = cfg.flight.n_steps
        self.radius = (cfg.layout.rings + 0.5) * cfg.layout.isd_m * np.sqrt(3) / 2  # inside the outer ring
        r = self.radius * np.sqrt(rng.uniform(0, 1, n_uavs))
        phi = rng.uniform(0, 2 * np.pi, n_uavs)
        self.pos = np.stack([r * np.cos(phi), r * np.sin(phi), rng.uniform(*cfg.flight.altitude_m, n_uavs)], 1)
        self.heading = rng.uniform(0, 2 * np.pi, n_uavs)
        self.speed = rng.uniform(*cfg.flight.speed_mps, n_uavs)
        self.g_shadow = rng.standard_normal((n_uavs, self.N))
        self.g_los = rng.standard_normal((n_uavs, self.N))
        self.g_fast = rng.standard_normal((n_uavs, self.N))
        self._rho_fast = np.exp(-self.dt / cfg.channel.fading_corr_s)
        rad = cfg.radio
        self._rsrp_offset = rad.bs_tx_power_dbm - 10 * np.log10(12 * rad.n_rb) + rad.bs_antenna_gain_db
        bw = rad.n_rb * 180e3
        self._dl_noise_mw = 10 ** ((-174 + 10 * np.log10(bw) + rad.ue_noise_figure_db) / 10)
        self._ul_noise_db = -174 + 10 * np.log10(bw) + rad.bs_noise_figure_db + rad.ul_interference_db
        self._measure()
        self.serving = self.rsrp.argmax(axis=1)
        self.prev_serving = self.serving.copy()
        self.entered = np.zeros(n_uavs, dtype=np.int64)
        self.interrupt = np.zeros(n_uavs, dtype=np.int64)
        self.q = np.zeros(n_uavs)
        self.t = 0
        self.last: StepInfo | None = None

    def _measure(self) -> None:
        c = self.cfg.channel
        d2d = np.hypot(self.pos[:, None, 0] - self.bs_xy[None, :, 0], self.pos[:, None, 1] - self.bs_xy[None, :, 1])
        h = self.pos[:, 2:3]
        d3d = np.hypot(d2d, h - c.bs_height_m)
        los = ndtr(self.g_los) < los_probability(c.scenario, h, d2d)
        self.loss_db = (path_loss(c.scenario, h, d3d, c.carrier_ghz, los) + shadow_sigma(c.scenario, h, los)
                        * self.g_shadow + c.fading_db * self.g_fast)
        self.rsrp = self._rsrp_offset - self.loss_db
        rsrp_mw = 10 ** (self.rsrp / 10)
        n_re = 12 * self.cfg.radio.n_rb
        rssi = n_re * self.cfg.radio.load * rsrp_mw.sum(axis=1, keepdims=True) + self._dl_noise_mw
        self.rsrq = 10 * np.log10(self.cfg.radio.n_rb * rsrp_mw / rssi)

    @property
    def done(self) -> bool:
        return self.t >= self.n_steps

    def ul_sinr_db(self) -> np.ndarray:
        """Uplink SINR of each UAV at its serving BS."""
        rad = self.cfg.radio
        loss = self.loss_db[np.arange(self.K), self.serving]
        return rad.ue_tx_power_dbm + rad.bs_antenna_gain_db - loss - self._ul_noise_db

    def candidates(self) -> np.ndarray:
        """(K, 4) BS ids: the serving BS, then the three strongest others by RSRP."""
        masked = self.rsrp.copy()
        masked[np.arange(self.K), self.serving] = -np.inf
        top = np.argsort(-masked, axis=1)[:, : N_CANDIDATES - 1]
        return np.concatenate([self.serving[:, None], top], axis=1)

    def observe(self) -> tuple[np.ndarray, np.ndarray]:
        """Features (K, 13) in :data:`features.FEATURES` order, and the candidate BS ids (K, 4)."""
        cand = self.candidates()
        rows = np.arange(self.K)[:, None]
        return state_rows(self.pos, self.q, self.serving, self.rsrp[rows, cand], self.rsrq[rows, cand]), cand

    def step(self, target: np.ndarray) -> StepInfo:
        """Associate every UAV with ``target`` (BS ids, (K,)), then advance one dt."""
        cfg, k = self.cfg, np.arange(self.K)
        target = np.asarray(target, dtype=np.int64)
        ho = target != self.serving
        stay_steps = self.t - self.entered
        pingpong = ho & (target == self.prev_serving) & (stay_steps * self.dt < cfg.handover.min_time_of_stay_s)
        self.prev_serving = np.where(ho, self.serving, self.prev_serving)
        self.entered = np.where(ho, self.t, self.entered)
        self.serving = target
        self.interrupt = np.where(ho, int(round(cfg.handover.interruption_s / self.dt)), self.interrupt)

        b = cfg.buffer
        sinr = self.ul_sinr_db()
        serving_now = self.interrupt == 0
        served = service_bits(sinr, b.rb_per_uav, b.rb_bandwidth_hz, self.dt) * serving_now
        arrivals = self.rng.poisson(b.packet_rate_hz * self.dt, self.K) * b.data_packet_bits
        arrivals = arrivals + ho * b.control_packet_bits
        self.q, lost = buffer_step(self.q, arrivals, served, b.q_max_bits)
        self.interrupt = np.maximum(self.interrupt - 1, 0)
        hc = cfg.handover
        radio_ok = sinr >= hc.sinr_min_db
        info = StepInfo(ho, pingpong, serving_now & radio_ok, radio_ok,
                        self.rsrp[k, self.serving] < hc.rsrp_threshold_dbm,
                        self.rsrq[k, self.serving] < hc.rsrq_threshold_db, self.q.copy(), lost, sinr)
        self._move()
        self._measure()
        self.t += 1
        self.last = info
        return info

    def _move(self) -> None:
        f, dt = self.cfg.flight, self.dt
        turn = self.rng.uniform(0, 1, self.K) < dt / f.turn_every_s
        self.heading = self.heading + turn * self.rng.normal(0, np.pi / 3, self.K)
        step = self.speed * dt
        self.pos[:, 0] += step * np.cos(self.heading)
        self.pos[:, 1] += step * np.sin(self.heading)
        out = np.hypot(self.pos[:, 0], self.pos[:, 1]) > self.radius  # turn back towards the centre, with jitter
        inward = np.arctan2(-self.pos[:, 1], -self.pos[:, 0]) + self.rng.uniform(-np.pi / 4, np.pi / 4, self.K)
        self.heading = np.where(out, inward, self.heading)
        rho = np.exp(-step / self.cfg.channel.shadow_corr_m)[:, None]
        innov = np.sqrt(1 - rho ** 2)
        self.g_shadow = rho * self.g_shadow + innov * self.rng.standard_normal((self.K, self.N))
        self.g_los = rho * self.g_los + innov * self.rng.standard_normal((self.K, self.N))
        rf = self._rho_fast
        self.g_fast = rf * self.g_fast + np.sqrt(1 - rf ** 2) * self.rng.standard_normal((self.K, self.N))
