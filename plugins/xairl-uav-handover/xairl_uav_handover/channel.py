"""3GPP TR 36.777 Annex B air-to-ground channel for aerial UEs: LoS probability, path loss, shadow-fading sigma.

All functions are vectorised over numpy arrays. Heights and distances in metres, carrier frequency in GHz.
Scenarios: UMa-AV (h 22.5-300 m), UMi-AV (22.5-300 m), RMa-AV (10-300 m). At or below 22.5 m TR 36.777 takes UMa-AV's
UEs as terrestrial ones (its Table B-1 points to the UMa model of TR 36.873); this module uses that model in TR
38.901's form (Tables 7.4.1-1, 7.4.2-1; shadowing 4 / 6 dB) for UMa-AV from 1.5 m, so flights as low as the real
ones (20 m) can be simulated. The two models meet with a step at 22.5 m, as in the TR.
"""

from __future__ import annotations

import numpy as np

SCENARIOS = ("UMa-AV", "UMi-AV", "RMa-AV")
#: (min exclusive, max inclusive) UAV height the model is defined for (UMa-AV: terrestrial UMa at or below 22.5 m)
HEIGHT_RANGE = {"UMa-AV": (1.5, 300.0), "UMi-AV": (22.5, 300.0), "RMa-AV": (10.0, 300.0)}


def _los_from_d1_p1(d2d, d1, p1):
    d2d = np.maximum(d2d, 1e-9)
    p = d1 / d2d + np.exp(-d2d / p1) * (1.0 - d1 / d2d)
    return np.where(d2d <= d1, 1.0, p)


TERRESTRIAL_M = 22.5  # UMa-AV at or below this height: the terrestrial UMa model


def _terrestrial_uma_los(h, d2d):
    """TR 38.901 Table 7.4.2-1, UMa: the height factor C'(h) raises P_LOS for UEs above 13 m."""
    c = np.where(h <= 13, 0.0, (np.clip(h, 13, 23) - 13) / 10) ** 1.5
    base = _los_from_d1_p1(d2d, 18.0, 63.0)
    return np.where(d2d <= 18, 1.0, base * (1 + c * 1.25 * (d2d / 100) ** 3 * np.exp(-d2d / 150)))


def _terrestrial_uma_loss(h, d3d, fc_ghz, bs_height_m):
    """TR 38.901 Table 7.4.1-1, UMa: LoS with its breakpoint (effective environment height 1 m); NLoS never below."""
    d_bp = 4 * (bs_height_m - 1) * np.maximum(h - 1, 0.5) * fc_ghz * 1e9 / 3e8
    lg_fc = 20.0 * np.log10(fc_ghz)
    pl1 = 28.0 + 22.0 * np.log10(d3d) + lg_fc
    pl2 = 28.0 + 40.0 * np.log10(d3d) + lg_fc - 9.0 * np.log10(d_bp**2 + (bs_height_m - h) ** 2)
    pl_los = np.where(d3d <= d_bp, pl1, pl2)
    return pl_los, np.maximum(pl_los, 13.54 + 39.08 * np.log10(d3d) + lg_fc - 0.6 * (h - 1.5))


def _where_low(h, aerial, terrestrial, d):
    """UMa-AV's aerial values (one array or a tuple), replaced at or below 22.5 m by ``terrestrial(h, d)`` evaluated
    on those elements only: the simulator calls this every step, and most heights are aerial."""
    aerial = aerial if isinstance(aerial, tuple) else (aerial,)
    low = h <= TERRESTRIAL_M
    if not np.any(low):
        return aerial
    hb, db, low = np.broadcast_arrays(h, d, low)
    out = tuple(np.array(np.broadcast_to(a, hb.shape), dtype=float) for a in aerial)
    for o, t in zip(out, terrestrial(hb[low], db[low])):
        o[low] = t
    return out


def los_probability(scenario: str, h, d2d):
    """P_LOS for a UAV at height ``h`` and horizontal distance ``d2d`` (TR 36.777 Table B-1)."""
    h, d2d = np.asarray(h, dtype=float), np.asarray(d2d, dtype=float)
    lg = np.log10(h)
    if scenario == "UMa-AV":  # LoS certain above 100 m; terrestrial at or below 22.5 m
        p = np.where(
            h > 100, 1.0, _los_from_d1_p1(d2d, np.maximum(460 * lg - 700, 18.0), np.maximum(4300 * lg - 3800, 1.0))
        )
        return _where_low(h, p, lambda hl, dl: (_terrestrial_uma_los(hl, dl),), d2d)[0]
    if scenario == "UMi-AV":
        return _los_from_d1_p1(d2d, np.maximum(294.05 * lg - 432.94, 18.0), 233.98 * lg - 0.95)
    if scenario == "RMa-AV":  # LoS certain above 40 m
        p = _los_from_d1_p1(d2d, np.maximum(1350.8 * lg - 1602, 18.0), np.maximum(15021 * lg - 16053, 1000.0))
        return np.where(h > 40, 1.0, p)
    raise ValueError(f"unknown scenario '{scenario}'; use one of {', '.join(SCENARIOS)}")


def path_loss(scenario: str, h, d3d, fc_ghz: float, los, bs_height_m: float = 25.0):
    """Path loss in dB (TR 36.777 Table B-2); ``los`` selects the LoS or NLoS formula per element. ``bs_height_m``
    matters only to the terrestrial UMa model (its LoS breakpoint)."""
    h, d3d = np.asarray(h, dtype=float), np.maximum(np.asarray(d3d, dtype=float), 1.0)
    lg_h, lg_d = np.log10(h), np.log10(d3d)
    if scenario == "UMa-AV":
        pl_los = 28.0 + 22.0 * lg_d + 20.0 * np.log10(fc_ghz)
        pl_nlos = -17.5 + (46.0 - 7.0 * lg_h) * lg_d + 20.0 * np.log10(40.0 * np.pi * fc_ghz / 3.0)
        pl_los, pl_nlos = _where_low(
            h, (pl_los, pl_nlos), lambda hl, dl: _terrestrial_uma_loss(hl, dl, fc_ghz, bs_height_m), d3d
        )
    elif scenario == "UMi-AV":
        fspl = 32.45 + 20.0 * np.log10(fc_ghz) + 20.0 * lg_d
        pl_los = np.maximum(fspl, 30.9 + (22.25 - 0.5 * lg_h) * lg_d + 20.0 * np.log10(fc_ghz))
        pl_nlos = np.maximum(pl_los, 32.4 + (43.2 - 7.6 * lg_h) * lg_d + 20.0 * np.log10(fc_ghz))
    elif scenario == "RMa-AV":
        fspl_term = 20.0 * np.log10(40.0 * np.pi * fc_ghz / 3.0)
        pl_los = np.maximum(23.9 - 1.8 * lg_h, 20.0) * lg_d + fspl_term
        pl_nlos = np.maximum(pl_los, -12.0 + (35.0 - 5.3 * lg_h) * lg_d + fspl_term)
    else:
        raise ValueError(f"unknown scenario '{scenario}'; use one of {', '.join(SCENARIOS)}")
    return np.where(los, pl_los, pl_nlos)


def shadow_sigma(scenario: str, h, los):
    """Shadow-fading standard deviation in dB (TR 36.777 Table B-3)."""
    h = np.asarray(h, dtype=float)
    if scenario == "UMa-AV":
        s_los, s_nlos = np.where(h <= TERRESTRIAL_M, 4.0, 4.64 * np.exp(-0.0066 * h)), 6.0
    elif scenario == "UMi-AV":
        s_los, s_nlos = np.maximum(5.0 * np.exp(-0.01 * h), 2.0), 8.0
    elif scenario == "RMa-AV":
        s_los, s_nlos = 4.2 * np.exp(-0.0046 * h), 6.0
    else:
        raise ValueError(f"unknown scenario '{scenario}'; use one of {', '.join(SCENARIOS)}")
    return np.where(los, s_los, s_nlos)
