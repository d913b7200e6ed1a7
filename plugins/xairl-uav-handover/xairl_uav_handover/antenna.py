"""Sectored base-station antennas, down-tilted towards the ground, and what a UAV above them receives.

Each site of the hexagonal grid carries three cells, their antennas pointing 120 degrees apart (boresights 30, 150
and 270 degrees from east; 3GPP TR 36.814 Figure A.2.1.1-1's three-sector layout, as in TR 36.777's evaluation). A
cell's gain towards a point is the 3D sector pattern of TR 36.814 Table A.2.1.1-2 (the pattern TR 36.777's
macro evaluations inherit):

    A_H(phi)   = -min(12 (phi / phi_3dB)^2, A_m)                      horizontal, phi off boresight
    A_V(theta) = -min(12 ((theta - theta_tilt) / theta_3dB)^2, SLA_V)  vertical, theta below the horizon
    G          = G_max - min(-(A_H + A_V), A_m)

with phi_3dB 70 deg, theta_3dB 10 deg, A_m 25 dB, SLA_V 20 dB, G_max 14 dBi and a 15 deg down-tilt (the table's
values; ``AntennaConfig``). A ground user a few hundred metres away sits in the main lobe; a UAV at 100 m flies above
it, in the side lobes (the effect TR 36.777 describes for aerial UEs), so its downlink and uplink both see a gain
well below a ground user's, and the cells of one site differ by where the UAV lies around the mast.
"""

from __future__ import annotations

import numpy as np

#: boresight of each of a site's three cells, degrees counter-clockwise from east
SECTOR_AZIMUTHS_DEG = (30.0, 150.0, 270.0)


def cell_layout(sites_xy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The cells of ``sites_xy`` (S, 2): (their positions (3S, 2), their site (3S,), their boresights in radians
    (3S,)); cell 3s + j is sector j of site s."""
    n = len(sites_xy)
    site = np.repeat(np.arange(n), len(SECTOR_AZIMUTHS_DEG))
    azimuth = np.tile(np.deg2rad(SECTOR_AZIMUTHS_DEG), n)
    return sites_xy[site], site, azimuth


def gain_db(antenna, dx, dy, dz, boresight) -> np.ndarray:
    """Gain (dBi) of cells with ``boresight`` (radians) towards points dx, dy east/north and dz above the antenna
    (metres; broadcast together): TR 36.814 Table A.2.1.1-2's pattern, as the module doc writes it."""
    return pattern_db(antenna, np.arctan2(dy, dx), np.degrees(np.arctan2(-dz, np.hypot(dx, dy))), boresight)


def pattern_db(antenna, azimuth, below_deg, boresight) -> np.ndarray:
    """:func:`gain_db` from the angles: ``azimuth`` (radians from east) and ``below_deg`` (degrees below the
    horizon) of the points as seen from the antenna (so a site's three cells share them)."""
    phi = np.angle(np.exp(1j * (azimuth - boresight)), deg=True)  # off boresight, in (-180, 180]
    a_h = -np.minimum(12 * (phi / antenna.h_beamwidth_deg) ** 2, antenna.front_back_db)
    a_v = -np.minimum(12 * ((below_deg - antenna.downtilt_deg) / antenna.v_beamwidth_deg) ** 2, antenna.side_lobe_db)
    return antenna.max_gain_dbi - np.minimum(-(a_h + a_v), antenna.front_back_db)
