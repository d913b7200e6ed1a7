"""Radio link failure and handover failure on the downlink, and the re-establishment that follows either.

- **Radio link monitoring** (TS 36.331 sec. 5.3.11, TS 36.133 sec. 7.6): the UE judges its serving cell's downlink
  every step from the wideband SINR averaged over the last Qout evaluation period (200 ms, TS 36.133 sec.
  7.6.2.1). Below Qout (-8 dB, the SINR of a 10 % PDCCH block error rate) it is out of sync; above Qin (-6 dB, 2 %)
  in sync. After N310 consecutive out-of-sync indications T310 starts; N311 consecutive in-sync indications stop
  it; when it expires, the radio link has failed (RLF). Defaults are TS 36.331's: N310 = N311 = 1, T310 = 1 s.
- **Handover failure** (TR 36.839 sec. 5.2's definition for its mobility study): a handover fails when the target
  cell's averaged SINR is below Qout as the UE arrives at it.
- **Re-establishment** (TS 36.331 sec. 5.3.7): after either failure the UE selects the strongest cell it measures
  and is without service for ``reestablish_s`` (HandoverConfig: TS 36.133 sec. 5.3.2's re-establishment delay for
  a known cell). A re-establishment is not a handover: the counts keep them apart.

Downlink SINR: the cell's reference power per resource element over the power every other cell puts on that
element (its reference signals plus its data at its load, ``rssi_activity``) and the UE's noise per element.
"""

from __future__ import annotations

import numpy as np

#: share of a 2-port cell's resource elements that carry reference signals over a subframe (16 of 168 per RB pair,
#: TS 36.211 sec. 6.10.1.2) and within one of its reference-signal symbols (4 of 12)
RS_SHARE_SUBFRAME, RS_SHARE_SYMBOL = 16 / 168, 4 / 12


def rssi_activity(load, rs_share: float = RS_SHARE_SUBFRAME):
    """Average power a cell puts on a resource element, relative to its reference-signal power: its reference
    signals always, its data on the rest in proportion to its load."""
    return rs_share + (1 - rs_share) * load


def downlink_sinr_db(rsrp_dbm: np.ndarray, load: np.ndarray, noise_re_mw: float) -> np.ndarray:
    """(K, N) wideband SINR of each cell at each UAV: RSRP over the other cells' average power per element plus
    noise. ``load`` (K, N): each cell's share of resource elements carrying data."""
    p = 10 ** (rsrp_dbm / 10)
    other = (p * rssi_activity(load)).sum(axis=1, keepdims=True) - p * rssi_activity(load)
    return 10 * np.log10(p / (other + noise_re_mw))


class LinkMonitor:
    """T310/N310/N311 radio link monitoring for K UAVs, and the handover-failure check (module doc).

    :param cfg: :class:`config.HandoverConfig`; ``dt`` the simulator step in seconds.
    """

    def __init__(self, cfg, k: int, dt: float):
        self.cfg, self.dt = cfg, dt
        self.window = max(1, int(round(cfg.qout_period_s / dt)))
        self.history: list[np.ndarray] = []  # the last ``window`` steps' SINR of every cell, linear
        self.out_count = np.zeros(k, dtype=np.int64)
        self.in_count = np.zeros(k, dtype=np.int64)
        self.t310 = np.full(k, np.nan)  # seconds T310 has run; NaN: not running

    def average_db(self, sinr_db: np.ndarray) -> np.ndarray:
        """Record one step's (K, N) SINR and return its average over the Qout evaluation period, in dB."""
        self.history = (self.history + [10 ** (sinr_db / 10)])[-self.window :]
        return 10 * np.log10(np.mean(self.history, axis=0))

    def handover_fails(self, avg_db: np.ndarray, target: np.ndarray, handed: np.ndarray) -> np.ndarray:
        """(K,) bool: a handover to ``target`` that the target's averaged SINR cannot carry (TR 36.839)."""
        return handed & (avg_db[np.arange(len(target)), target] < self.cfg.qout_db)

    def radio_link_fails(self, serving_avg_db: np.ndarray) -> np.ndarray:
        """Advance T310 by one step on the serving cells' averaged SINR (K,); (K,) bool where it expired."""
        c = self.cfg
        out, ok = serving_avg_db < c.qout_db, serving_avg_db > c.qin_db
        self.out_count = np.where(out, self.out_count + 1, 0)
        self.in_count = np.where(ok, self.in_count + 1, 0)
        running = np.isfinite(self.t310)
        start = ~running & (self.out_count >= c.n310)
        stop = running & (self.in_count >= c.n311)
        self.t310 = np.where(start, 0.0, np.where(stop, np.nan, self.t310))
        self.t310 = np.where(np.isfinite(self.t310) & ~start, self.t310 + self.dt, self.t310)
        failed = self.t310 >= c.t310_s - 1e-9
        self.reset(failed)
        return failed

    def reset(self, which: np.ndarray) -> None:
        """A new connection (after a handover or a re-establishment) starts with its timers and counters clear."""
        self.t310 = np.where(which, np.nan, self.t310)
        self.out_count = np.where(which, 0, self.out_count)
        self.in_count = np.where(which, 0, self.in_count)
