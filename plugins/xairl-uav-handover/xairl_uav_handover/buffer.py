"""The UAV's uplink buffer: Poisson data arrivals, control packets at handovers, Shannon-rate service, overflow."""
from __future__ import annotations

import numpy as np


def service_bits(sinr_db, rb_per_uav: int, rb_bandwidth_hz: float, dt_s: float):
    """Bits served in one step: s = W_s |B| log2(1 + SINR) dt."""
    return rb_bandwidth_hz * rb_per_uav * np.log2(1.0 + 10.0 ** (np.asarray(sinr_db) / 10.0)) * dt_s


def buffer_step(q, arrivals_bits, served_bits, q_max: float):
    """One step of q' = min(max(q + a - s, 0), q_max); returns (q', bits lost to overflow)."""
    q_new = np.maximum(np.asarray(q) + arrivals_bits - served_bits, 0.0)
    lost = np.maximum(q_new - q_max, 0.0)
    return q_new - lost, lost
