"""Flights through random waypoints with climbs and descents, all flights advanced at once.

Each flight starts at a random point of the service area at a take-off height drawn in ``FlightConfig.altitude_m``
(the climb from the ground, below the channel model's heights, is not simulated) and flies to waypoints drawn
uniformly over the area, each at a height drawn uniformly in ``altitude_m``. Towards a waypoint it moves
horizontally at its own speed (drawn once per flight in ``speed_mps``) and vertically at the drone's climb or
descent speed (``climb_mps``, ``descent_mps``), the two at once; where it arrives above the waypoint before its
height, it hovers while climbing or descending. A waypoint is reached when the flight stands on it; the next one
is taken then (every flight draws a candidate at every step). Every draw comes from the generator given, so a seed
fixes the flights.
"""

from __future__ import annotations

import numpy as np

from .config import FlightConfig


class Waypoints:
    """K flights' waypoints inside a disc of ``radius`` around the origin.

    :param config: :class:`FlightConfig` (heights, horizontal and vertical speeds).
    :param radius: the service area's radius in metres.
    :param rng: the source of every draw.
    :param n_flights: K.
    """

    def __init__(self, config: FlightConfig, radius: float, rng: np.random.Generator, n_flights: int):
        self.cfg, self.radius, self.rng, self.K = config, radius, rng, n_flights
        self.start = self._draw(n_flights)  # (K, 3): take-off point and height
        self.speed = rng.uniform(*config.speed_mps, n_flights)
        self.target = self._draw(n_flights)
        self.reached = np.zeros(n_flights, dtype=np.int64)  # waypoints reached so far, per flight

    def _draw(self, n: int) -> np.ndarray:
        r = self.radius * np.sqrt(self.rng.uniform(0, 1, n))
        phi = self.rng.uniform(0, 2 * np.pi, n)
        return np.stack([r * np.cos(phi), r * np.sin(phi), self.rng.uniform(*self.cfg.altitude_m, n)], 1)

    def advance(self, pos: np.ndarray, dt: float) -> np.ndarray:
        """The positions (K, 3) after ``dt`` seconds from ``pos``; flights on their waypoint get the next one."""
        f = self.cfg
        d_xy = self.target[:, :2] - pos[:, :2]
        dist = np.hypot(d_xy[:, 0], d_xy[:, 1])
        frac = np.minimum(1.0, self.speed * dt / np.maximum(dist, 1e-12))
        new = pos.copy()
        new[:, :2] = pos[:, :2] + frac[:, None] * d_xy
        dz = self.target[:, 2] - pos[:, 2]
        new[:, 2] = pos[:, 2] + np.clip(dz, -f.descent_mps * dt, f.climb_mps * dt)
        arrived = (frac >= 1.0) & (np.abs(dz) <= np.where(dz > 0, f.climb_mps, f.descent_mps) * dt)
        new[arrived] = self.target[arrived]
        # every flight draws a candidate every step and keeps it only on arrival: each flight's stream advances
        # alike whatever the other flights do, so a flight is the same in any batch (streams.py)
        candidate = self._draw(self.K)
        self.target[arrived] = candidate[arrived]
        self.reached += arrived
        return new
