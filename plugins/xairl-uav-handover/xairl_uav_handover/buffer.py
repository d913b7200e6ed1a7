"""The UAV's uplink buffer: arrivals (video packets, control packets at handovers), service, overflow.

The service rate is the uplink capacity (uplink.py).
"""

from __future__ import annotations

import numpy as np


def buffer_step(q, arrivals_bits, served_bits, q_max: float):
    """One step of q' = min(max(q + a - s, 0), q_max); returns (q', bits lost to overflow)."""
    q_new = np.maximum(np.asarray(q) + arrivals_bits - served_bits, 0.0)
    lost = np.maximum(q_new - q_max, 0.0)
    return q_new - lost, lost
