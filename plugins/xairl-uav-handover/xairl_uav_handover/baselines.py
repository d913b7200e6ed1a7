"""Rule-based handover controllers. A controller acts through :class:`env.HandoverVecEnv`: ``reset(env)``, then
``controller(env)`` returns one action per flight (the index of the candidate to serve; 0 = stay).

The UE measures the serving BS and the strongest neighbours (the env's 4 candidates), so A3 sees those cells only:
a neighbour that drops out of the strongest three starts its time-to-trigger again, as in a real measurement
report. :class:`A3Trigger` runs on time stamps, so the same rule also runs on real flights' irregular samples.

- :class:`CHM`: the conventional A3 handover: hand over to the strongest neighbour once its RSRP has exceeded the
  serving RSRP by ``offset_db`` continuously for ``ttt_s`` (TR 36.777 Table A.2.1-1: 2 dB, 160 ms).
- :class:`SAMRO`: self-adaptive mobility robustness optimisation, as 3GPP describes MRO (TS 36.300 sec. 22.4.2,
  TS 36.902 sec. 4.5): A3 with a cell individual offset per (serving, neighbour) pair, which the network raises after
  too-early handovers and ping-pongs on that pair and lowers after too-late ones, once per window
  (:class:`MobilityRobustness` has the events' definitions). Offsets are the network's, shared by every UAV it serves.
- :class:`RSRQRule`: a two-threshold rule on the DQN's own 13 inputs, at its decision period (ours, not the paper's):
  hand over to the best-RSRQ candidate on poor serving RSRQ with data waiting, or on a nearly full buffer. It marks
  where the handovers/RSRQ/availability frontier lies (benchmarks/rule_frontier.py) and is the demonstrator a DQN can
  learn from (``TrainConfig.demonstrations``).
"""

from __future__ import annotations

import numpy as np

from .config import CHMConfig, SAMROConfig
from .features import BUFFER, RSRP, RSRQ, available_actions


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
        ``now`` (default: measurement count x dt); ``offset_db`` one per UAV, or (k, n) one per UAV and cell."""
        now = self.t * self.dt if now is None else float(now)
        k = np.arange(len(serving))
        ms = rsrp[k, serving][:, None]
        offset = np.asarray(offset_db, dtype=float)
        cond = rsrp > ms + (offset if offset.ndim == 2 else offset.reshape(-1, 1))  # per UAV, or per UAV and cell
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
        return _action_of(
            env, self.a3.targets(_candidate_rsrp(env), env.sim.serving, self.cfg.offset_db, self.cfg.ttt_s)
        )


class MobilityRobustness:
    """The network's MRO state: a cell individual offset (dB, added to the A3 offset) per (serving, neighbour) pair.

    Events, per UAV: a radio link failure (RLF) is uplink SINR below the minimum for ``rlf_s`` (counted once per
    failure). An RLF within ``early_s`` of a handover makes that handover too early (on its source, target pair); any
    other RLF while a neighbour is stronger than the serving cell is a too-late handover (on the serving, strongest
    neighbour pair: the one that should have happened); a handover back to the source within ``pingpong_s`` counts
    on the first handover's pair as too early. Every ``window_s`` each pair with more too-early than too-late events
    gets ``margin_step_db`` more offset (hand over later), one with more too-late ones that much less; the total
    offset stays in ``margin_range_db``.
    """

    def __init__(self, cfg: SAMROConfig, k: int, n: int):
        self.cfg = cfg
        self.cio = np.zeros((n, n))
        self.early, self.late = np.zeros((n, n)), np.zeros((n, n))
        self.fail_since = np.full(k, np.nan)
        self.ho_time, self.source = np.full(k, -np.inf), np.full(k, -1)
        self.window_start = 0.0

    def offsets(self, serving: np.ndarray) -> np.ndarray:
        """(k, n) A3 offsets of each UAV towards each cell, from its serving cell."""
        return self.cfg.offset_db + self.cio[serving]

    def observe(self, now: float, serving, radio_ok, stronger, handed, previous) -> None:
        """One step's outcome: ``serving`` cells now, ``radio_ok`` uplink SINR at least the minimum, ``stronger``
        the strongest neighbour when it beats the serving cell (-1: none), ``handed`` handovers from ``previous``."""
        c = self.cfg
        back = handed & (serving == self.source) & (now - self.ho_time < c.pingpong_s)
        np.add.at(self.early, (serving[back], previous[back]), 1)
        self.source, self.ho_time = np.where(handed, previous, self.source), np.where(handed, now, self.ho_time)
        failing = ~np.asarray(radio_ok, dtype=bool)
        self.fail_since = np.where(failing, np.where(np.isnan(self.fail_since), now, self.fail_since), np.nan)
        rlf = failing & (now - self.fail_since >= c.rlf_s)
        self.fail_since[rlf] = np.inf  # one event per failure
        early = rlf & (now - self.ho_time <= c.early_s) & (self.source >= 0)
        np.add.at(self.early, (self.source[early], serving[early]), 1)
        late = rlf & ~early & (stronger >= 0)
        np.add.at(self.late, (serving[late], stronger[late]), 1)
        if now - self.window_start >= c.window_s:
            step = c.margin_step_db * ((self.early > self.late).astype(float) - (self.late > self.early))
            low, high = c.margin_range_db
            self.cio = np.clip(self.cio + step, low - c.offset_db, high - c.offset_db)
            self.early[:], self.late[:], self.window_start = 0, 0, now


class SAMRO:
    """A3 handover with the network's per-pair offsets adapted by mobility robustness optimisation (module doc)."""

    name = "SA-MRO"
    decision_every = 1

    def __init__(self, config: SAMROConfig | None = None):
        self.cfg = config or SAMROConfig()

    def reset(self, env) -> None:
        sim = env.sim
        self.a3 = A3Trigger(sim.K, sim.N, sim.dt)
        self.mro = MobilityRobustness(self.cfg, sim.K, sim.N)
        self.previous = sim.serving.copy()

    def __call__(self, env) -> np.ndarray:
        sim, rsrp = env.sim, _candidate_rsrp(env)
        if sim.last is not None:
            k, nb = np.arange(sim.K), env.candidates[:, 1]
            stronger = np.where((nb >= 0) & (rsrp[k, np.maximum(nb, 0)] > rsrp[k, sim.serving]), nb, -1)
            self.mro.observe(
                sim.t * sim.dt, sim.serving, sim.last.radio_ok, stronger, sim.last.handover.astype(bool), self.previous
            )
        self.previous = sim.serving.copy()
        return _action_of(env, self.a3.targets(rsrp, sim.serving, self.mro.offsets(sim.serving), self.cfg.ttt_s))


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

    def _margin_ttt(self, state, candidates, previous, t: float):
        """A3's offset (a number, or (1, cells) per cell) and time-to-trigger at this sample; ``previous``: the
        serving cell at the sample before (None at the first)."""
        return self.cfg.offset_db, self.cfg.ttt_s

    def __call__(self, state, candidates, t: float) -> int:
        previous = self.serving
        if candidates[0] != self.serving:
            self.a3.since[:] = np.nan
            self.serving = candidates[0]
        rsrp = np.full((1, len(self.cells)), -np.inf)
        for k, cell in enumerate(candidates):
            rsrp[0, self.col[cell]] = state[RSRP][k]
        margin, ttt = self._margin_ttt(state, candidates, previous, t)
        target = self.a3.targets(rsrp, np.array([self.col[candidates[0]]]), margin, ttt, now=t)[0]
        return list(candidates).index(self.cells[target])


class SAMROOnSamples(CHMOnSamples):
    """SA-MRO on real samples: :class:`MobilityRobustness` for one UAV over the flight's cells, fed with the network's
    own handovers and with radio availability from the uplink model at the sample's serving RSRP."""

    name = "SA-MRO"

    def __init__(self, cells, sim_config, config: SAMROConfig | None = None):
        super().__init__(cells, None)
        self.sa, self.sim_cfg = config or SAMROConfig(), sim_config
        self.mro = MobilityRobustness(self.sa, 1, len(self.cells))
        self.interference: dict[float, float] = {}

    def _radio_ok(self, state) -> bool:
        from .simulator import hex_layout
        from .uplink import interference_mw, rsrp_offset_db, sinr_db

        cfg = self.sim_cfg
        if not self.interference:  # the centre cell of one uplink drop (seed 0), as the real flights' buffer
            layout = hex_layout(cfg.layout.isd_m, cfg.layout.rings)
            self.interference[0] = float(interference_mw(cfg, layout, np.random.default_rng(0), 1)[0, 0])
        sinr = sinr_db(cfg, rsrp_offset_db(cfg) - float(state[RSRP][0]), self.interference[0])
        return bool(sinr >= cfg.handover.sinr_min_db)

    def _margin_ttt(self, state, candidates, previous, t: float):
        serving = np.array([self.col[candidates[0]]])
        rsrp = state[RSRP]
        stronger = self.col[candidates[1]] if len(candidates) > 1 and rsrp[1] > rsrp[0] else -1
        handed = previous is not None and previous != candidates[0]
        self.mro.observe(
            t,
            serving,
            np.array([self._radio_ok(state)]),
            np.array([stronger]),
            np.array([handed]),
            np.array([self.col[previous] if previous is not None else serving[0]]),
        )
        return self.mro.offsets(serving), self.sa.ttt_s


class RSRQRule:
    """Stay unless the serving cell's reported RSRQ is below ``threshold_db`` while the buffer holds data, or the
    buffer holds at least ``full_share`` of its size; then hand over to the measured candidate with the best RSRQ, if
    that one is at least ``margin_db`` better than the serving cell."""

    decision_every = None  # the simulator config's, as the DQN's

    def __init__(self, threshold_db: float = -14.0, margin_db: float = 3.0, full_share: float = 0.5):
        self.threshold_db, self.margin_db, self.full_share = threshold_db, margin_db, full_share
        self.name = f"rule {threshold_db:g},{margin_db:g},{full_share:g}"

    def reset(self, env) -> None:
        pass

    def __call__(self, env) -> np.ndarray:
        return self.act(env.obs, env.cfg)

    def act(self, obs: np.ndarray, cfg) -> np.ndarray:
        """The rule's action for each of the states ``obs`` (n, 13) under simulator config ``cfg``."""
        rsrq = np.where(available_actions(obs, cfg.observation), obs[:, RSRQ], -np.inf)
        rsrq[:, 0] = -np.inf
        best = rsrq.argmax(axis=1)
        serving = obs[:, RSRQ][:, 0]
        better = rsrq[np.arange(len(obs)), best] > serving + self.margin_db
        queue = obs[:, BUFFER]
        trigger = ((serving < self.threshold_db) & (queue > 0)) | (queue >= self.full_share * cfg.buffer.q_max_bits)
        return np.where(trigger & better, best, 0)
