"""Vectorised simulator: K UAV flights over a hexagonal grid of sites, three sectored cells each (antenna.py), one
numpy step for all.

Per step (dt): measurements (RSRP/RSRQ of every cell, downlink and uplink SINR) -> the controller's target cell ->
handover bookkeeping (interruption, control packet, ping-pong) -> handover and radio link failures, with
re-establishment (failures.py) -> buffer -> motion (waypoints, trajectory.py) -> channel update.

Shadow fading and the LoS state are spatially correlated per UAV-site link: each link carries two standard-normal
latents that follow an AR(1) process with correlation exp(-distance moved / shadow_corr_m) (Gudmundson). Shadowing
is sigma(LoS state) times one latent; the link is LoS while Phi(other latent) < P_LOS(h, d2D), so the LoS
probability of TR 36.777 holds at every point and the state does not flicker from step to step. A third latent,
correlated in time (fading_corr_s), is the fast fading left in each 40 ms sample, its size set by the Rician
K-factor and the looks averaged (:func:`fading_std_db`). A cell's coupling loss is its site's path minus its
antenna's gain towards the UAV plus ``link_loss_db``, the same both ways. RSRQ uses each cell's own load
(:meth:`Simulator._measure`). What the UE reports (``meas_rsrp``, ``meas_rsrq``: what controllers and observations
see) is the L1 average over each measurement period with each cell's measurement error (TS 36.133), layer-3
filtered (``ObservationConfig``); neighbours count as measured only above the detection threshold. The uplink
(SINR with aerial co-channel interference, capacity) is in uplink.py.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.special import ndtr

from . import antenna
from .buffer import buffer_step
from .channel import los_probability, path_loss, shadow_sigma
from .config import LayoutConfig, SimConfig
from .failures import RS_SHARE_SYMBOL, LinkMonitor, downlink_sinr_db, rssi_activity
from .features import N_CANDIDATES, state_rows
from .streams import random_source
from .trajectory import Waypoints
from .uplink import capacity_bps, interference_mw, rsrp_offset_db, sinr_db


def n_sites(layout: LayoutConfig) -> int:
    """Sites of the hexagonal grid: the centre plus 6 r sites in ring r."""
    return 1 + 3 * layout.rings * (layout.rings + 1)


def n_cells(layout: LayoutConfig) -> int:
    """Cells of the grid: three sectors per site (antenna.py)."""
    return len(antenna.SECTOR_AZIMUTHS_DEG) * n_sites(layout)


def fading_std_db(k_factor_db: float | None, looks: int) -> float:
    """Std (dB) of the fast fading left in a sample that averages ``looks`` independent looks at a Rician channel
    (``k_factor_db``; None: Rayleigh): the power's variance (1 + 2K) / (1 + K)^2 over the looks, in dB to first
    order (10 / ln 10 times the relative std)."""
    k = 0.0 if k_factor_db is None else 10 ** (k_factor_db / 10)
    return float(10 / np.log(10) * np.sqrt((1 + 2 * k) / (1 + k) ** 2 / looks))


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
    hof: np.ndarray  # a handover that failed (failures.py); the UE re-established instead
    rlf: np.ndarray  # a radio link failure (T310 expired)
    outage: np.ndarray  # no service while re-establishing after either


class Simulator:
    """K independent UAV flights (one per row), all stepped at once.

    :param config: :class:`SimConfig`.
    :param n_uavs: flights simulated in parallel.
    :param seed: every random draw (flights, channel, arrivals) comes from this seed; or one seed per flight
        (a list of ``n_uavs``: each flight its own stream, the same flight in any batch; streams.py).
    """

    def __init__(self, config: SimConfig | None = None, n_uavs: int = 1, seed: int = 0):
        self.cfg = cfg = config or SimConfig()
        self.rng = rng = random_source(seed, n_uavs)
        self.sites_xy = hex_layout(cfg.layout.isd_m, cfg.layout.rings)
        self.bs_xy, self.site, self.boresight = antenna.cell_layout(self.sites_xy)  # per cell
        self.K, self.N = n_uavs, len(self.bs_xy)
        n_site = len(self.sites_xy)
        self.dt = cfg.flight.dt_s
        self.n_steps = cfg.flight.n_steps
        self.radius = cfg.layout.flight_radius_m  # the flights' disc (LayoutConfig.area_radius_m)
        self.route = Waypoints(cfg.flight, self.radius, rng, n_uavs)  # flights through waypoints (trajectory.py)
        self.pos = self.route.start.copy()
        # one link per UAV and site: the three cells of a site share its path, differing by their antennas
        self.g_shadow = rng.standard_normal((n_uavs, n_site))
        self.g_los = rng.standard_normal((n_uavs, n_site))
        self.g_fast = rng.standard_normal((n_uavs, n_site))
        self._rho_fast = np.exp(-self.dt / cfg.channel.fading_corr_s)
        self._fading_db = (
            fading_std_db(cfg.channel.los_k_factor_db, cfg.channel.fading_looks),
            fading_std_db(None, cfg.channel.fading_looks),
        )
        rad, obs = cfg.radio, cfg.observation
        self._rsrp_offset = rsrp_offset_db(cfg)
        self._noise_re_mw = 10 ** ((-174 + 10 * np.log10(15e3) + rad.ue_noise_figure_db) / 10)  # per element
        self._ul_interference = interference_mw(cfg, self.sites_xy, rng, n_uavs)  # (K, N): one uplink drop a flight
        self._load = rng.uniform(*rad.load_range, (n_uavs, self.N))  # each cell's downlink load, per flight
        self.monitor = LinkMonitor(cfg.handover, n_uavs, self.dt)
        self._meas_every = max(1, int(round(obs.measurement_period_s / self.dt)))
        self._l3_a = 1.0 / 2 ** (obs.l3_filter_k / 4)
        self._measure()
        self.meas_rsrp, self.meas_rsrq = self.rsrp.copy(), self.rsrq.copy()  # what the UE reports
        self._acc = [np.zeros_like(self.rsrp), np.zeros_like(self.rsrq), 0]
        self.serving = self.meas_rsrp.argmax(axis=1)
        self.prev_serving = self.serving.copy()
        self.entered = np.zeros(n_uavs, dtype=np.int64)
        self.interrupt = np.zeros(n_uavs, dtype=np.int64)
        self.outage = np.zeros(n_uavs, dtype=np.int64)  # steps left re-establishing after a failure
        self.q = np.zeros(n_uavs)
        self.t = 0
        self.last: StepInfo | None = None

    def _measure(self) -> None:
        """Coupling loss, RSRP and RSRQ of every cell, and the downlink SINR, at the UAVs' positions now.

        RSRQ = N RSRP / RSSI (TS 36.214 sec. 5.1.3), RSSI measured over the measured cell's own reference-signal
        symbols. Cells are not frame-synchronised (an FDD network need not be), so in those symbols the measured
        cell puts its reference signals (4 of 12 elements) and its data at its own load, and every other cell its
        average over a subframe at its load (failures.rssi_activity). RSRQ therefore carries each cell's load and
        the measured cell's share of the total power: information RSRP alone does not.
        """
        c, a = self.cfg.channel, self.cfg.antenna
        dx = self.pos[:, None, 0] - self.sites_xy[None, :, 0]
        dy = self.pos[:, None, 1] - self.sites_xy[None, :, 1]
        d2d, h = np.hypot(dx, dy), self.pos[:, 2:3]
        d3d = np.hypot(d2d, h - c.bs_height_m)
        los = ndtr(self.g_los) < los_probability(c.scenario, h, d2d)
        site_loss = (
            path_loss(c.scenario, h, d3d, c.carrier_ghz, los, c.bs_height_m)
            + shadow_sigma(c.scenario, h, los) * self.g_shadow
            + np.where(los, self._fading_db[0], self._fading_db[1]) * self.g_fast
        )[:, self.site]
        gain = antenna.gain_db(a, dx[:, self.site], dy[:, self.site], h - c.bs_height_m, self.boresight)
        self.loss_db = site_loss - gain + self.cfg.radio.link_loss_db  # coupling loss, the same both ways
        self.rsrp = self._rsrp_offset - self.loss_db
        p = 10 ** (self.rsrp / 10)
        others = (p * rssi_activity(self._load)).sum(axis=1, keepdims=True) - p * rssi_activity(self._load)
        own = p * rssi_activity(self._load, RS_SHARE_SYMBOL)
        self.rsrq = 10 * np.log10(p / (12 * (own + others) + 12 * self._noise_re_mw))
        self.dl_sinr = downlink_sinr_db(self.rsrp, self._load, self._noise_re_mw)

    def _report(self) -> None:
        """Average the samples of each measurement period, add the UE's measurement error (each cell's own,
        ``ObservationConfig``), then layer-3 filter them into the reported values."""
        acc = self._acc
        acc[0] += self.rsrp
        acc[1] += self.rsrq
        acc[2] += 1
        if acc[2] == self._meas_every:
            a, obs = self._l3_a, self.cfg.observation
            l1_rsrp = acc[0] / acc[2] + obs.rsrp_error_db * self.rng.standard_normal(self.rsrp.shape)
            l1_rsrq = acc[1] / acc[2] + obs.rsrq_error_db * self.rng.standard_normal(self.rsrq.shape)
            self.meas_rsrp = (1 - a) * self.meas_rsrp + a * l1_rsrp
            self.meas_rsrq = (1 - a) * self.meas_rsrq + a * l1_rsrq
            self._acc = [np.zeros_like(self.rsrp), np.zeros_like(self.rsrq), 0]

    @property
    def done(self) -> bool:
        return self.t >= self.n_steps

    def ul_sinr_db(self) -> np.ndarray:
        """Uplink SINR of each UAV at its serving cell (uplink.py): its power set from the path loss it estimates
        from its reported RSRP, received through the coupling loss of now."""
        k = np.arange(self.K)
        estimate = self._rsrp_offset - self.meas_rsrp[k, self.serving]
        return sinr_db(self.cfg, self.loss_db[k, self.serving], self._ul_interference[k, self.serving], estimate)

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
        # a UE re-establishing after a failure has no connection to hand over: it stays where it re-establishes
        target = np.where(self.outage > 0, self.serving, np.asarray(target, dtype=np.int64))
        ho = target != self.serving
        stay_steps = self.t - self.entered
        back = ho & (target == self.prev_serving)
        pingpong = back & (stay_steps * self.dt < cfg.handover.min_time_of_stay_s)
        back_after_s = np.where(back, stay_steps * self.dt, np.inf)  # ping-pongs at any window (evaluate.py)
        self.prev_serving = np.where(ho, self.serving, self.prev_serving)
        self.entered = np.where(ho, self.t, self.entered)
        self.serving = target
        self.interrupt = np.where(
            ho, np.maximum(self.interrupt, int(round(cfg.handover.interruption_s / self.dt))), self.interrupt
        )
        hof, rlf = self._failures(ho)

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
            hof,
            rlf,
            self.outage > 0,
        )
        self.outage = np.maximum(self.outage - 1, 0)
        self._move()
        self._measure()
        self._report()
        self.t += 1
        self.last = info
        return info

    def _failures(self, handed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Handover and radio link failures this step (failures.py), each followed by a re-establishment to the
        strongest cell it measures now with no service for ``reestablish_s``; (hof, rlf), bool (K,)."""
        hc, none = self.cfg.handover, np.zeros(self.K, dtype=bool)
        if not hc.failures:
            return none, none
        avg = self.monitor.average_db(self.dl_sinr)
        hof = self.monitor.handover_fails(avg, self.serving, handed)
        self.monitor.reset(handed)
        connected = self.outage == 0
        rlf = self.monitor.radio_link_fails(np.where(connected, avg[np.arange(self.K), self.serving], np.inf))
        rlf &= connected & ~hof
        failed = hof | rlf
        if failed.any():
            best = self.rsrp.argmax(axis=1)  # cell selection on what the UE measures now (TS 36.331 sec. 5.3.7)
            moved = failed & (best != self.serving)
            self.prev_serving = np.where(moved, self.serving, self.prev_serving)
            self.entered = np.where(moved, self.t, self.entered)
            self.serving = np.where(failed, best, self.serving)
            steps = int(round(hc.reestablish_s / self.dt))
            self.outage = np.where(failed, steps, self.outage)
            self.interrupt = np.where(failed, np.maximum(self.interrupt, steps), self.interrupt)
            self.monitor.reset(failed)
        return hof, rlf

    def _move(self) -> None:
        new = self.route.advance(self.pos, self.dt)
        step = np.linalg.norm(new - self.pos, axis=1)  # distance moved: the channel decorrelates over it
        self.pos = new
        rho = np.exp(-step / self.cfg.channel.shadow_corr_m)[:, None]
        innov = np.sqrt(1 - rho**2)
        self.g_shadow = rho * self.g_shadow + innov * self.rng.standard_normal(self.g_shadow.shape)
        self.g_los = rho * self.g_los + innov * self.rng.standard_normal(self.g_los.shape)
        rf = self._rho_fast
        self.g_fast = rf * self.g_fast + np.sqrt(1 - rf**2) * self.rng.standard_normal(self.g_fast.shape)
