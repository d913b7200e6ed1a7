"""The UAV's uplink: power control, the interference other cells' users cause, SINR and a bounded capacity.

Power control (TS 36.213 sec. 5.1.1.1, open loop): a UE sending on M resource blocks uses
P = min(P_CMAX, P0 + 10 lg M + alpha PL), PL being its coupling loss to its own cell as it estimates it
(referenceSignalPower - RSRP: its coupling loss, antenna gain and link loss included). Per resource block that is min(P_CMAX - 10 lg M, P0 + alpha PL) (:func:`psd_dbm`).
The UAV and every interfering UE follow it, each towards its own cell; the UAV's follows its height through its
path loss, which the simulator updates at every step.

Interference (objection 2 of issue 53, from TR 36.777's evaluation drop): each cell serves ``ues_per_cell`` UEs,
each one aerial with probability ``aerial_ue_ratio`` (flying at a height of the flight range) and otherwise
terrestrial (1.5 m), dropped uniformly over the cell's sector. In a TTI a cell schedules one of its UEs on the
UAV's resource blocks with probability equal to its uplink load, so the mean interference cell j causes at cell b
is load_j times the mean over j's UEs of their power per resource block times their coupling gain to b (LoS and
NLoS mixed by P_LOS, TR 36.777, and b's sector antenna towards them, antenna.py). One drop per flight: cells differ because their
loads and their UEs differ, above all in whether they hold an aerial UE, which is seen in line of sight by many
cells. The interference at the serving cell does not depend on the UAV's own height (other UEs cause it); the
UAV's own signal does. A real flight takes, for each real cell, a random cell of one such drop
(real_data.UplinkBuffer): sim and real buffers are driven by one uplink model.

Capacity (TR 36.942 Annex A, truncated Shannon): M W (0 below SINR_min, else min(att log2(1 + SINR), SE_max)),
with M the UAV's scheduler share of the uplink carrier's resource blocks (BufferConfig).
"""

from __future__ import annotations

import numpy as np

from . import antenna
from .channel import los_probability, path_loss
from .config import SimConfig


def rsrp_offset_db(cfg: SimConfig) -> float:
    """RSRP = offset - coupling loss: the BS power per resource element (the coupling loss is the path loss and
    every other loss minus the antenna gain, the same both ways: simulator.py)."""
    rad = cfg.radio
    return rad.bs_tx_power_dbm - 10 * np.log10(12 * rad.n_rb)


def noise_dbm(cfg: SimConfig) -> float:
    """Thermal noise plus the BS noise figure over one resource block."""
    return -174 + 10 * np.log10(cfg.buffer.rb_bandwidth_hz) + cfg.radio.bs_noise_figure_db


def psd_dbm(cfg: SimConfig, coupling_db) -> np.ndarray:
    """Open-loop PUSCH power per resource block (dBm) of a UE on the UAV's M blocks at ``coupling_db`` to its cell."""
    rad = cfg.radio
    m = cfg.buffer.rb_per_uav
    return np.minimum(rad.ue_tx_power_dbm - 10 * np.log10(m), rad.p0_pusch_dbm + rad.pc_alpha * np.asarray(coupling_db))


def _path_gain(cfg: SimConfig, xy, h, site_xy):
    """Linear path gain of UEs at ``xy`` (..., 2), heights ``h`` to a site's antennas, averaged over LoS and NLoS by
    P_LOS, and the UEs' azimuth (radians) and elevation below the horizon (degrees) as the site sees them."""
    c = cfg.channel
    dx, dy = xy[..., 0] - site_xy[0], xy[..., 1] - site_xy[1]
    d2d = np.hypot(dx, dy)
    d3d = np.hypot(d2d, h - c.bs_height_m)
    p_los = los_probability(c.scenario, h, np.maximum(d2d, 1.0))
    g = p_los * 10 ** (-path_loss(c.scenario, h, d3d, c.carrier_ghz, True, c.bs_height_m) / 10)
    g = g + (1 - p_los) * 10 ** (-path_loss(c.scenario, h, d3d, c.carrier_ghz, False, c.bs_height_m) / 10)
    return g, np.arctan2(dy, dx), np.degrees(np.arctan2(-(h - c.bs_height_m), d2d))


def _mean_gain(cfg: SimConfig, xy, h, site_xy, boresight) -> np.ndarray:
    """Linear coupling gain of UEs at ``xy`` (..., 2), heights ``h`` to a cell at ``site_xy`` with ``boresight``:
    the path gain (:func:`_path_gain`) times the cell's antenna gain towards them (antenna.py), less the link loss
    (RadioConfig.link_loss_db)."""
    path, azimuth, below = _path_gain(cfg, xy, h, site_xy)
    pattern = antenna.pattern_db(cfg.antenna, azimuth, below, boresight) - cfg.radio.link_loss_db
    return path * 10 ** (pattern / 10)


def drop_ues(cfg: SimConfig, sites_xy: np.ndarray, rng: np.random.Generator, n_flights: int):
    """One TR 36.777 drop per flight: positions (K, N, U, 2) and heights (K, N, U) of each cell's UEs, uniform over
    its sector (the 120-degree wedge of a disc of the site's hexagon area around its boresight)."""
    rad, u = cfg.radio, cfg.radio.ues_per_cell
    cell_xy, _, boresight = antenna.cell_layout(sites_xy)
    n = len(cell_xy)
    site_r = cfg.layout.isd_m * np.sqrt(np.sqrt(3) / (2 * np.pi))  # a disc of the site's hexagon area
    r = site_r * np.sqrt(rng.uniform(0, 1, (n_flights, n, u)))
    phi = boresight[None, :, None] + rng.uniform(-np.pi / 3, np.pi / 3, (n_flights, n, u))
    xy = cell_xy[None, :, None, :] + np.stack([r * np.cos(phi), r * np.sin(phi)], -1)
    aerial = rng.uniform(0, 1, (n_flights, n, u)) < rad.aerial_ue_ratio
    h = np.where(aerial, rng.uniform(*cfg.flight.altitude_m, (n_flights, n, u)), rad.ground_ue_height_m)
    return xy, h


def interference_mw(cfg: SimConfig, sites_xy: np.ndarray, rng: np.random.Generator, n_flights: int) -> np.ndarray:
    """(K, N): mean interference per resource block (mW) at each of the sites' cells, one drop per flight (see the
    module doc). A site's three cells share the path and the angles to every UE; only their patterns differ."""
    cell_xy, _, boresight = antenna.cell_layout(sites_xy)
    xy, h = drop_ues(cfg, sites_xy, rng, n_flights)
    k, n, u = h.shape
    load = rng.uniform(*cfg.radio.ul_load_range, (k, n))  # each cell's uplink load: its chance to use the UAV's blocks
    own = np.stack([_mean_gain(cfg, xy[:, j], h[:, j], cell_xy[j], boresight[j]) for j in range(n)], axis=1)
    psd_mw = 10 ** (psd_dbm(cfg, -10 * np.log10(own)) / 10)  # (K, N, U)
    out = np.zeros((k, n))
    sectors = len(antenna.SECTOR_AZIMUTHS_DEG)
    for site, site_xy in enumerate(sites_xy):  # a loop over sites keeps memory at K x N x U
        path, azimuth, below = _path_gain(cfg, xy, h, site_xy)
        for b in range(site * sectors, (site + 1) * sectors):  # victim cell b
            pattern = antenna.pattern_db(cfg.antenna, azimuth, below, boresight[b]) - cfg.radio.link_loss_db
            per_cell = load * (psd_mw * (path * 10 ** (pattern / 10))).mean(axis=2)  # (K, N): each cell j towards b
            per_cell[:, b] = 0.0  # b's own UE on these blocks is the UAV
            out[:, b] = per_cell.sum(axis=1)
    return out


def sinr_db(cfg: SimConfig, loss_db, interference: np.ndarray, estimate_db=None) -> np.ndarray:
    """Uplink SINR per resource block for a coupling loss ``loss_db`` to the serving cell (path loss and link loss
    minus its antenna gain, the same both ways) and the interference (mW per resource block) there; the UAV's
    power follows :func:`psd_dbm` of the path loss it estimates (``estimate_db``: referenceSignalPower - its
    filtered RSRP; default: the coupling loss itself)."""
    coupling = np.asarray(loss_db)
    estimate = coupling if estimate_db is None else np.asarray(estimate_db)
    signal_mw = 10 ** ((psd_dbm(cfg, estimate) - coupling) / 10)
    return 10 * np.log10(signal_mw / (10 ** (noise_dbm(cfg) / 10) + interference))


def capacity_bps(cfg: SimConfig, sinr: np.ndarray) -> np.ndarray:
    """Truncated Shannon (TR 36.942 Annex A) over the UAV's M resource blocks, bits per second."""
    rad, b = cfg.radio, cfg.buffer
    s = np.asarray(sinr, dtype=float)
    se = np.minimum(rad.ul_attenuation * np.log2(1.0 + 10.0 ** (s / 10.0)), rad.ul_max_se)
    return b.rb_bandwidth_hz * b.rb_per_uav * np.where(s < rad.ul_sinr_min_db, 0.0, se)
