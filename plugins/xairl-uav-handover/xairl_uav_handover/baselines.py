"""Rule-based handover controllers. A controller acts through :class:`env.HandoverVecEnv`: ``reset(env)``, then
``controller(env)`` returns one action per flight (the index of the candidate to serve; 0 = stay).

The UE measures the serving BS and the strongest neighbours (the env's 4 candidates), so A3 sees those cells only:
a neighbour that drops out of the strongest three starts its time-to-trigger again, as in a real measurement
report. :class:`A3Trigger` runs on time stamps, so the same rule also runs on real flights' irregular samples.

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
from .features import RSRP

#: 3GPP TS 36.331 timeToTrigger values, seconds
TTT_VALUES = np.array([0, 40, 64, 80, 100, 128, 160, 256, 320, 480, 512, 640, 1024, 1280, 2560, 5120]) / 1000.0


class A3Trigger:
    """Per-(UAV, cell) A3 timers: a neighbour wins once Mn > Ms + offset has held for TTT. The condition is checked
    at every measurement; holding from t0 through t0 + TTT triggers at the first measurement at or after t0 + TTT.
    Cells with RSRP -inf are not measured (the condition does not hold for them).

    :param k: UAVs; ``n`` cells; ``dt``: seconds between measurements when :meth:`targets` is given no time.
    """

    def __init__(self, k: int, n: int, dt: float = 0.0):
        self.since = np.full((k, n), np.nan)  # time at which the condition started to hold, NaN = not holding
        self.dt = dt
        self.t = 0

    def targets(self, rsrp: np.ndarray, serving: np.ndarray, offset_db, ttt_s, now: float | None = None) -> np.ndarray:
        """Target cell per UAV (the serving one when no neighbour fired) for measurements ``rsrp`` (k, n) at time
        ``now`` (default: measurement count x dt)."""
        now = self.t * self.dt if now is None else float(now)
        k = np.arange(len(serving))
        ms = rsrp[k, serving][:, None]
        cond = rsrp > ms + np.asarray(offset_db, dtype=float).reshape(-1, 1)
        cond[k, serving] = False
        self.since = np.where(cond, np.where(np.isnan(self.since), now, self.since), np.nan)
        fired = cond & (now - self.since >= np.asarray(ttt_s, dtype=float).reshape(-1, 1) - 1e-9)
        best = np.where(fired, rsrp, -np.inf).argmax(axis=1)
        target = np.where(fired.any(axis=1), best, serving)
        self.since[target != serving] = np.nan  # after a handover every timer starts again
        self.t += 1
        return target


def _candidate_rsrp(env) -> np.ndarray:
    """The reported RSRP of the env's measured candidates; every other cell unmeasured (-inf)."""
    sim, cand = env.sim, env.candidates
    rows = np.broadcast_to(np.arange(sim.K)[:, None], cand.shape)
    rsrp = np.full_like(sim.meas_rsrp, -np.inf)
    ok = cand >= 0
    rsrp[rows[ok], cand[ok]] = sim.meas_rsrp[rows[ok], cand[ok]]
    return rsrp


def _action_of(env, target: np.ndarray) -> np.ndarray:
    """Index of each flight's target BS among its candidates (A3 targets are always candidates)."""
    return (env.candidates == target[:, None]).argmax(axis=1)


class CHM:
    """Conventional A3 handover with fixed offset and time-to-trigger, acting at every measurement."""

    name = "CHM"
    decision_every = 1

    def __init__(self, config: CHMConfig | None = None):
        self.cfg = config or CHMConfig()

    def reset(self, env) -> None:
        self.a3 = A3Trigger(env.sim.K, env.sim.N, env.sim.dt)

    def __call__(self, env) -> np.ndarray:
        return _action_of(env, self.a3.targets(_candidate_rsrp(env), env.sim.serving, self.cfg.offset_db,
                                               self.cfg.ttt_s))


class SAMRO:
    """A3 handover whose margin and TTT adapt per UAV to measured service availability (rule in the module doc)."""

    name = "SA-MRO"
    decision_every = 1

    def __init__(self, config: SAMROConfig | None = None):
        self.cfg = config or SAMROConfig()

    def reset(self, env) -> None:
        sim, c = env.sim, self.cfg
        self.a3 = A3Trigger(sim.K, sim.N, sim.dt)
        self.margin = np.full(sim.K, c.offset_db)
        self.ttt_idx = np.full(sim.K, int(np.abs(TTT_VALUES - c.ttt_s).argmin()))
        self.window = max(1, int(round(c.window_s / sim.dt)))
        self.avail = np.zeros(sim.K)
        self.hos = np.zeros(sim.K)
        self.n = 0

    def __call__(self, env) -> np.ndarray:
        sim = env.sim
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
        return _action_of(env, self.a3.targets(_candidate_rsrp(env), sim.serving, self.margin,
                                               TTT_VALUES[self.ttt_idx]))


class CHMOnSamples:
    """CHM on measurement samples at arbitrary times (a real flight's ~1.3 s samples): the same :class:`A3Trigger`
    over the candidates' RSRP, keyed by cell id. Called as ``chm(state, candidates, t) -> action``; open loop, so
    when the serving cell changes (the network handed over) every timer starts again.

    :param cells: every cell id the flight may measure (its columns in the trigger).
    """

    name = "CHM"

    def __init__(self, cells, config: CHMConfig | None = None):
        self.cfg = config or CHMConfig()
        self.cells = list(cells)
        self.col = {c: j for j, c in enumerate(self.cells)}
        self.a3 = A3Trigger(1, len(self.cells))
        self.serving = None

    def _margin_ttt(self, state, network_handed: bool, t: float) -> tuple[float, float]:
        return self.cfg.offset_db, self.cfg.ttt_s

    def __call__(self, state, candidates, t: float) -> int:
        network_handed = self.serving is not None and candidates[0] != self.serving
        if candidates[0] != self.serving:
            self.a3.since[:] = np.nan
            self.serving = candidates[0]
        rsrp = np.full((1, len(self.cells)), -np.inf)
        for k, cell in enumerate(candidates):
            rsrp[0, self.col[cell]] = state[RSRP][k]
        margin, ttt = self._margin_ttt(state, network_handed, t)
        target = self.a3.targets(rsrp, np.array([self.col[candidates[0]]]), margin, ttt, now=t)[0]
        return list(candidates).index(self.cells[target])


class SAMROOnSamples(CHMOnSamples):
    """SA-MRO on real samples: the rule of :class:`SAMRO`, with radio availability from the uplink model at the
    sample's serving RSRP and altitude, and the network's own handovers counted in the window."""

    name = "SA-MRO"

    def __init__(self, cells, sim_config, config: SAMROConfig | None = None):
        super().__init__(cells, None)
        self.sa, self.sim_cfg = config or SAMROConfig(), sim_config
        self.margin = self.sa.offset_db
        self.ttt_idx = int(np.abs(TTT_VALUES - self.sa.ttt_s).argmin())
        self.window: list[tuple[bool, bool]] = []  # (radio ok, handed over) per sample
        self.window_start: float | None = None
        self.interference: dict[float, float] = {}

    def _radio_ok(self, state) -> bool:
        from .simulator import hex_layout
        from .uplink import interference_mw, rsrp_offset_db, sinr_db

        cfg, h = self.sim_cfg, float(state[2])
        if h not in self.interference:
            layout = hex_layout(cfg.layout.isd_m, cfg.layout.rings)
            self.interference[h] = float(interference_mw(cfg, layout, np.array([h]))[0, 0])
        sinr = sinr_db(cfg, rsrp_offset_db(cfg) - float(state[RSRP][0]), self.interference[h])
        return bool(sinr >= cfg.handover.sinr_min_db)

    def _margin_ttt(self, state, network_handed: bool, t: float) -> tuple[float, float]:
        self.window.append((self._radio_ok(state), network_handed))
        self.window_start = t if self.window_start is None else self.window_start
        if t - self.window_start >= self.sa.window_s:
            ok = np.array(self.window)
            poor = ok[:, 0].mean() < self.sa.target_availability
            wasted = not poor and ok[:, 1].any()
            step = self.sa.margin_step_db
            self.margin = float(np.clip(self.margin - step * poor + step * wasted, *self.sa.margin_range_db))
            self.ttt_idx = int(np.clip(self.ttt_idx - poor + wasted, 0, len(TTT_VALUES) - 1))
            self.window, self.window_start = [], None
        return self.margin, TTT_VALUES[self.ttt_idx]
