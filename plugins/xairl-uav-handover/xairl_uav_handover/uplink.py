"""The UAV's uplink: SINR at its serving BS, with the co-channel interference aerial UEs cause, and its capacity.

Interference (TR 36.777: aerial UEs see line of sight to many cells, so the uplink interference they cause rises
with height): every other cell j has a co-channel aerial UE on the UAV's resource blocks a share ``ul_activity`` of
the time, flying at the UAV's height over cell j's site and sending at full power (no power control: a stated
simplification). Its mean received power at BS b mixes the LoS and NLoS path losses of TR 36.777 by P_LOS(h, d),
so it grows with height as P_LOS does. The sum over j is precomputed per flight (heights are constant in flight).
Cells differ in uplink load (how many UEs they serve, and where): each cell's interference level deviates from the
layout's mean by a per-flight draw, uniform within +-``ul_interference_spread_db`` (:func:`cell_deviation`; a
modelling choice, its size measured in config.py). The downlink RSRP the UE measures does not show this; only the
uplink buffer does, so the buffer tells a handover policy something its radio measurements do not.
A real flight uses the same model at its altitude: each real cell takes the mean level of a random cell of the
layout times its own deviation, and the path loss is read from the measured RSRP (real_data.UplinkBuffer); sim and
real buffers are thus driven by one uplink model.

Capacity is the paper's ``W_s |B| log2(1 + SINR)``; signal and noise are over the UAV's |B| resource blocks.
"""

from __future__ import annotations

import numpy as np

from .channel import los_probability, path_loss
from .config import SimConfig


def rsrp_offset_db(cfg: SimConfig) -> float:
    """RSRP = offset - coupling loss: the BS power per resource element (the coupling loss is the path loss and
    every other loss minus the antenna gain, the same both ways: simulator.py)."""
    rad = cfg.radio
    return rad.bs_tx_power_dbm - 10 * np.log10(12 * rad.n_rb)


def noise_dbm(cfg: SimConfig) -> float:
    """Thermal noise plus the BS noise figure over the UAV's resource blocks."""
    b = cfg.buffer
    return -174 + 10 * np.log10(b.rb_per_uav * b.rb_bandwidth_hz) + cfg.radio.bs_noise_figure_db


def interference_mw(cfg: SimConfig, bs_xy: np.ndarray, heights: np.ndarray) -> np.ndarray:
    """(K, N): mean co-channel interference at each BS for UAVs at ``heights`` (K,) (see the module doc)."""
    c, rad = cfg.channel, cfg.radio
    h = np.asarray(heights, dtype=float)[:, None, None]
    d2d = np.hypot(*(bs_xy[:, None, :] - bs_xy[None, :, :]).transpose(2, 0, 1))[None]  # (1, N, N): site j -> BS b
    d3d = np.hypot(d2d, h - c.bs_height_m)
    p_los = los_probability(c.scenario, h, np.maximum(d2d, 1.0))
    gain = p_los * 10 ** (-path_loss(c.scenario, h, d3d, c.carrier_ghz, True, c.bs_height_m) / 10) + (
        1 - p_los
    ) * 10 ** (-path_loss(c.scenario, h, d3d, c.carrier_ghz, False, c.bs_height_m) / 10)
    n = len(bs_xy)
    gain = gain * (1 - np.eye(n))[None]  # a cell's own UE is the UAV, not an interferer
    per_interferer = 10 ** ((rad.ue_tx_power_dbm + rad.bs_antenna_gain_db) / 10)
    return rad.ul_activity * per_interferer * gain.sum(axis=1)


def cell_deviation(cfg: SimConfig, rng: np.random.Generator, shape) -> np.ndarray:
    """Factors (``shape``) on each cell's mean interference: 10^(u/10), u uniform in +-ul_interference_spread_db."""
    spread = cfg.radio.ul_interference_spread_db
    return 10 ** (rng.uniform(-spread, spread, shape) / 10)


def sinr_db(cfg: SimConfig, loss_db, interference: np.ndarray) -> np.ndarray:
    """Uplink SINR for a coupling loss ``loss_db`` (antenna gains included) to the serving BS and the interference
    (mW) there."""
    rad = cfg.radio
    signal_mw = 10 ** ((rad.ue_tx_power_dbm - np.asarray(loss_db)) / 10)
    return 10 * np.log10(signal_mw / (10 ** (noise_dbm(cfg) / 10) + interference))


def capacity_bps(cfg: SimConfig, sinr: np.ndarray) -> np.ndarray:
    """W_s |B| log2(1 + SINR), bits per second."""
    b = cfg.buffer
    return b.rb_bandwidth_hz * b.rb_per_uav * np.log2(1.0 + 10.0 ** (np.asarray(sinr) / 10.0))
