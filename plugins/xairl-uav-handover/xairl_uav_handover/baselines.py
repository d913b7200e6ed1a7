"""Rule-based handover controllers. A controller maps the simulator's current measurements to target BS ids.

- :class:`CHM`: the conventional A3 handover: hand over to the strongest neighbour once its RSRP has exceeded the
  serving RSRP by ``offset_db`` continuously for ``ttt_s`` (TR 36.777 Table A.2.1-1: 2 dB, 160 ms).
- :class:`SAMRO`: the same A3 mechanism, with its margin and TTT tuned per UAV from measured service availability
  (the idea of Meer et al., IEEE TNSM 2024; their exact rule is not public). The rule we implement, every
  ``window_s``: if the radio service availability in the window (share of steps with uplink SINR >= minimum; the
  interruptions that handovers cause themselves are left out, else the rule would feed on its own handovers) fell
  below ``target_availability`` the UAV needs better cells sooner, so margin -= step and TTT moves one value down the 3GPP TTT list; if availability met the target but
  the UAV still handed over in the window, those handovers bought nothing, so margin += step and TTT one value up.
  Margin stays in ``margin_range_db``. Mobility robustness is thus driven by the service the UAV actually got.
"""
from __future__ import annotations

import numpy as np

from .config import CHMConfig, SAMROConfig
from .simulator import Simulator

#: 3GPP TS 36.331 timeToTrigger values, seconds
TTT_VALUES = np.array([0, 40, 64, 80, 100, 128, 160, 256, 320, 480, 512, 640, 1024, 1280, 2560, 5120]) / 1000.0


class A3Trigger:
    """Per-(UAV, BS) A3 timers: a neighbour wins once Mn > Ms + offset has held for TTT (the condition is checked
    at every step; holding from t0 through t0 + TTT triggers at t0 + TTT)."""

    def __init__(self, k: int, n: int, dt: float):
        self.since = np.full((k, n), -1, dtype=np.int64)  # step at which the condition started, -1 = not holding
        self.dt = dt
        self.t = 0

    def targets(self, rsrp: np.ndarray, serving: np.ndarray, offset_db, ttt_s) -> np.ndarray:
        k = np.arange(len(serving))
        ms = rsrp[k, serving][:, None]
        cond = rsrp > ms + np.asarray(offset_db, dtype=float).reshape(-1, 1)
        cond[k, serving] = False
        self.since = np.where(cond, np.where(self.since < 0, self.t, self.since), -1)
        held = (self.t - self.since) * self.dt >= np.asarray(ttt_s, dtype=float).reshape(-1, 1) - 1e-9
        fired = cond & held
        best = np.where(fired, rsrp, -np.inf).argmax(axis=1)
        target = np.where(fired.any(axis=1), best, serving)
        self.since[target != serving] = -1  # after a handover every timer starts again
        self.t += 1
        return target


class CHM:
    """Conventional A3 handover with fixed offset and time-to-trigger."""

    name = "CHM"

    def __init__(self, config: CHMConfig | None = None):
        self.cfg = config or CHMConfig()

    def reset(self, sim: Simulator) -> None:
        self.a3 = A3Trigger(sim.K, sim.N, sim.dt)

    def __call__(self, sim: Simulator) -> np.ndarray:
        return self.a3.targets(sim.rsrp, sim.serving, self.cfg.offset_db, self.cfg.ttt_s)


class SAMRO:
    """A3 handover whose margin and TTT adapt per UAV to measured service availability (rule in the module doc)."""

    name = "SA-MRO"

    def __init__(self, config: SAMROConfig | None = None):
        self.cfg = config or SAMROConfig()

    def reset(self, sim: Simulator) -> None:
        c = self.cfg
        self.a3 = A3Trigger(sim.K, sim.N, sim.dt)
        self.margin = np.full(sim.K, c.offset_db)
        self.ttt_idx = np.full(sim.K, int(np.abs(TTT_VALUES - c.ttt_s).argmin()))
        self.window = max(1, int(round(c.window_s / sim.dt)))
        self.avail = np.zeros(sim.K)
        self.hos = np.zeros(sim.K)
        self.n = 0

    def __call__(self, sim: Simulator) -> np.ndarray:
        if sim.last is not None:
            self.avail += sim.last.radio_ok
            self.hos += sim.last.handover
            self.n += 1
        if self.n == self.window:
            c = self.cfg
            poor = self.avail / self.n < c.target_availability
            wasted = ~poor & (self.hos > 0)
            self.margin = np.clip(self.margin - c.margin_step_db * poor + c.margin_step_db * wasted,
                                  *c.margin_range_db)
            self.ttt_idx = np.clip(self.ttt_idx - poor + wasted, 0, len(TTT_VALUES) - 1)
            self.avail[:], self.hos[:], self.n = 0, 0, 0
        return self.a3.targets(sim.rsrp, sim.serving, self.margin, TTT_VALUES[self.ttt_idx])
