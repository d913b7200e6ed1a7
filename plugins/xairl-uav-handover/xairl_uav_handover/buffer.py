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


def buffer_steps(q: float, lost: float, arrivals_bits, served_bits, q_max: float) -> tuple[float, float]:
    """:func:`buffer_step` applied to one buffer over a sequence of steps (Python floats: the same arithmetic, bit for
    bit, at a fraction of the cost of a NumPy call a step); returns (q at the end, ``lost`` plus the bits lost)."""
    for a, s in zip(arrivals_bits, served_bits):
        q = max(q + a - s, 0.0)
        over = max(q - q_max, 0.0)
        q, lost = q - over, lost + over
    return q, lost
