"""Vectorised uplink simulator: K UAV flights over a hexagonal grid of N ground BSs, one numpy step for all.

Per step (dt): measurements (RSRP/RSRQ of every BS, uplink SINR at the serving BS) -> the controller's target BS ->
handover bookkeeping (interruption, control packet, ping-pong) -> buffer -> motion (waypoints, trajectory.py) ->
channel update.

Shadow fading and the LoS state are spatially correlated per UAV-BS link: each link carries two standard-normal
latents that follow an AR(1) process with correlation exp(-distance moved / shadow_corr_m) (Gudmundson). Shadowing
is sigma(LoS state) times one latent; the link is LoS while Phi(other latent) < P_LOS(h, d2D), so the LoS
probability of TR 36.777 holds at every point and the state does not flicker from step to step. A third latent,
correlated in time (fading_corr_s) and scaled by fading_db, is the fast-fading residual that layer-3 filtering
is left in each 40 ms sample. What the UE reports (``meas_rsrp``, ``meas_rsrq``: what controllers and observations
see) is the L1 average over each measurement period, layer-3 filtered (``ObservationConfig``); neighbours count as
measured only above the detection threshold. The uplink (SINR with aerial co-channel interference, capacity) is in
uplink.py.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.special import ndtr

from .buffer import buffer_step
from .channel import los_probability, path_loss, shadow_sigma
from .config import LayoutConfig, SimConfig
from .features import N_CANDIDATES, state_rows
from .trajectory import Waypoints
from .uplink import capacity_bps, interference_mw, rsrp_offset_db, sinr_db


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
    back_after_s: np.ndarray  # a handover back to the previous BS: the seconds spent at the one left; else inf


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
        self.route = Waypoints(cfg.flight, self.radius, rng, n_uavs)  # flights through waypoints (trajectory.py)
        self.pos = self.route.start.copy()
        self.g_shadow = rng.standard_normal((n_uavs, self.N))
        self.g_los = rng.standard_normal((n_uavs, self.N))
        self.g_fast = rng.standard_normal((n_uavs, self.N))
        self._rho_fast = np.exp(-self.dt / cfg.channel.fading_corr_s)
        rad, obs = cfg.radio, cfg.observation
        self._rsrp_offset = rsrp_offset_db(cfg)
        self._dl_noise_mw = 10 ** ((-174 + 10 * np.log10(rad.n_rb * 180e3) + rad.ue_noise_figure_db) / 10)
        self._ul_interference = interference_mw(cfg, self.bs_xy, rng, n_uavs)  # (K, N): one uplink drop per flight
        # domain randomisation per flight (RadioConfig): cell load and antenna gain deviations
        self._load = rng.uniform(*rad.load_range, (n_uavs, 1))
        self._gain = rng.uniform(-rad.gain_spread_db, rad.gain_spread_db, (n_uavs, 1))
        self._meas_every = max(1, int(round(obs.measurement_period_s / self.dt)))
        self._l3_a = 1.0 / 2 ** (obs.l3_filter_k / 4)
        self._measure()
        self.meas_rsrp, self.meas_rsrq = self.rsrp.copy(), self.rsrq.copy()  # what the UE reports
        self._acc = [np.zeros_like(self.rsrp), np.zeros_like(self.rsrq), 0]
        self.serving = self.meas_rsrp.argmax(axis=1)
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
        self.loss_db = (
            path_loss(c.scenario, h, d3d, c.carrier_ghz, los, c.bs_height_m)
            + shadow_sigma(c.scenario, h, los) * self.g_shadow
            + c.fading_db * self.g_fast
        )
        self.rsrp = self._rsrp_offset + self._gain - self.loss_db
        rsrp_mw = 10 ** (self.rsrp / 10)
        n_re = 12 * self.cfg.radio.n_rb
        rssi = n_re * self._load * rsrp_mw.sum(axis=1, keepdims=True) + self._dl_noise_mw
        self.rsrq = 10 * np.log10(self.cfg.radio.n_rb * rsrp_mw / rssi)

    def _report(self) -> None:
        """Average the samples of each measurement period, then layer-3 filter them into the reported values."""
        acc = self._acc
        acc[0] += self.rsrp
        acc[1] += self.rsrq
        acc[2] += 1
        if acc[2] == self._meas_every:
            a = self._l3_a
            self.meas_rsrp = (1 - a) * self.meas_rsrp + a * acc[0] / acc[2]
            self.meas_rsrq = (1 - a) * self.meas_rsrq + a * acc[1] / acc[2]
            self._acc = [np.zeros_like(self.rsrp), np.zeros_like(self.rsrq), 0]

    @property
    def done(self) -> bool:
        return self.t >= self.n_steps

    def ul_sinr_db(self) -> np.ndarray:
        """Uplink SINR of each UAV at its serving BS (uplink.py)."""
        k = np.arange(self.K)
        loss = self.loss_db[k, self.serving] - self._gain[:, 0]  # the same antenna both ways
        return sinr_db(self.cfg, loss, self._ul_interference[k, self.serving])

    def candidates(self) -> np.ndarray:
        """(K, 4) BS ids: the serving BS, then the strongest measured neighbours by reported RSRP; -1 for a slot
        with no measured neighbour."""
        k = np.arange(self.K)
        masked = np.where(self.meas_rsrq > self.cfg.observation.detection_rsrq_db, self.meas_rsrp, -np.inf)
        masked[k, self.serving] = -np.inf
        top = np.argsort(-masked, axis=1)[:, : N_CANDIDATES - 1]
        top = np.where(np.isfinite(np.take_along_axis(masked, top, axis=1)), top, -1)
        return np.concatenate([self.serving[:, None], top], axis=1)

    def observe(self) -> tuple[np.ndarray, np.ndarray]:
        """Features (K, 13) in :data:`features.FEATURES` order, and the candidate BS ids (K, 4; -1: none)."""
        cand = self.candidates()
        rows = np.arange(self.K)[:, None]
        missing = cand < 0
        rsrp = np.where(missing, np.nan, self.meas_rsrp[rows, cand])
        rsrq = np.where(missing, np.nan, self.meas_rsrq[rows, cand])
        return state_rows(self.pos, self.q, self.serving, rsrp, rsrq, self.cfg.observation), cand

    def step(self, target: np.ndarray) -> StepInfo:
        """Associate every UAV with ``target`` (BS ids, (K,)), then advance one dt."""
        cfg, k = self.cfg, np.arange(self.K)
        target = np.asarray(target, dtype=np.int64)
        ho = target != self.serving
        stay_steps = self.t - self.entered
        back = ho & (target == self.prev_serving)
        pingpong = back & (stay_steps * self.dt < cfg.handover.min_time_of_stay_s)
        back_after_s = np.where(back, stay_steps * self.dt, np.inf)  # ping-pongs at any window (evaluate.py)
        self.prev_serving = np.where(ho, self.serving, self.prev_serving)
        self.entered = np.where(ho, self.t, self.entered)
        self.serving = target
        self.interrupt = np.where(ho, int(round(cfg.handover.interruption_s / self.dt)), self.interrupt)

        b = cfg.buffer
        sinr = self.ul_sinr_db()
        serving_now = self.interrupt == 0
        served = capacity_bps(cfg, sinr) * self.dt * serving_now
        arrivals = self.rng.poisson(b.packet_rate_hz * self.dt, self.K) * b.data_packet_bits
        arrivals = arrivals + ho * b.control_packet_bits
        self.q, lost = buffer_step(self.q, arrivals, served, b.q_max_bits)
        self.interrupt = np.maximum(self.interrupt - 1, 0)
        hc = cfg.handover
        radio_ok = sinr >= hc.sinr_min_db
        info = StepInfo(
            ho,
            pingpong,
            serving_now & radio_ok,
            radio_ok,
            self.meas_rsrp[k, self.serving] < hc.rsrp_threshold_dbm,
            self.meas_rsrq[k, self.serving] < hc.rsrq_threshold_db,
            self.q.copy(),
            lost,
            sinr,
            back_after_s,
        )
        self._move()
        self._measure()
        self._report()
        self.t += 1
        self.last = info
        return info

    def _move(self) -> None:
        new = self.route.advance(self.pos, self.dt)
        step = np.linalg.norm(new - self.pos, axis=1)  # distance moved: the channel decorrelates over it
        self.pos = new
        rho = np.exp(-step / self.cfg.channel.shadow_corr_m)[:, None]
        innov = np.sqrt(1 - rho**2)
        self.g_shadow = rho * self.g_shadow + innov * self.rng.standard_normal((self.K, self.N))
        self.g_los = rho * self.g_los + innov * self.rng.standard_normal((self.K, self.N))
        rf = self._rho_fast
        self.g_fast = rf * self.g_fast + np.sqrt(1 - rf**2) * self.rng.standard_normal((self.K, self.N))
