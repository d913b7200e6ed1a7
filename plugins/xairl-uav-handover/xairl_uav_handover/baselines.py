"""Rule-based handover controllers. A controller acts through :class:`env.HandoverVecEnv`: ``reset(env)``, then
``controller(env)`` returns one action per flight (the index of the candidate to serve; 0 = stay).

The UE measures the serving BS and the strongest neighbours (the env's 4 candidates), so A3 sees those cells only:
a neighbour that drops out of the strongest three starts its time-to-trigger again, as in a real measurement
report. :class:`A3Trigger` runs on time stamps, so the same rule also runs on real flights' irregular samples.

- :class:`CHM`: the conventional A3 handover: hand over to the strongest neighbour once its RSRP has exceeded the
  serving RSRP by ``offset_db`` continuously for ``ttt_s`` (TR 36.777 Table A.2.1-1: 2 dB, 160 ms).
- :class:`SAMRO`: self-adaptive mobility robustness optimisation, as 3GPP describes MRO (TS 36.300 sec. 22.4.2,
  TS 36.902 sec. 4.5): A3 with a cell individual offset per (serving, neighbour) pair, which the network raises after
  too-early handovers, handovers to a wrong cell and ping-pongs on that pair and lowers after too-late ones
  (:class:`MobilityRobustness` has the events' definitions). The offsets are the network's: they persist across
  flights, which it sees in the order they are flown, and it updates them once every ``update_every_flights``
  flights, after ``warmup_flights`` training flights; so a result does not depend on how many flights one vector
  holds. Failures are the simulator's downlink radio link and handover failures (:func:`link_failures`).
- :class:`RSRQRule`: a two-threshold rule on the DQN's own 13 inputs, at its decision period (ours, not the paper's):
  hand over to the best-RSRQ candidate on poor serving RSRQ with data waiting, or on a nearly full buffer. It marks
  where the handovers/RSRQ/availability frontier lies (benchmarks/rule_frontier.py) and is the demonstrator a DQN can
  learn from (``TrainConfig.demonstrations``).
"""

from __future__ import annotations

import numpy as np
from pydantic import Field

from .config import Strict
from .features import BUFFER, RSRP, RSRQ, available_actions


class CHMConfig(Strict):
    """Conventional handover: A3 event (TR 36.777 Table A.2.1-1 defaults)."""

    offset_db: float = Field(2.0, description="A3 offset: neighbour RSRP must exceed serving RSRP by this")
    ttt_s: float = Field(0.16, ge=0, description="time-to-trigger")


class SAMROConfig(Strict):
    """Mobility robustness optimisation (see baselines.SAMRO): A3 with a cell individual offset per (serving,
    neighbour) pair, kept by the network across flights and adapted from the too-late, too-early, wrong-cell and
    ping-pong handovers counted on each pair (3GPP TS 36.300 sec. 22.4.2, TS 36.902 sec. 4.5). A ping-pong is a
    return within ``HandoverConfig.min_time_of_stay_s``."""

    offset_db: float = Field(2.0, description="A3 offset every pair starts from (CHM's)")
    ttt_s: float = Field(0.16, ge=0, description="time-to-trigger (CHM's; MRO tunes offsets only)")
    update_every_flights: int = Field(
        20,
        ge=1,
        description="the network updates the offsets from the counts of each this many flights, in the order "
        "flown (ours: TS 36.902 sec. 4.5 sets no period; real MRO counts over OAM periods of minutes to hours; 20 "
        "flights of 2 min = 40 UAV-minutes of counts, so 200 held-out flights see 10 updates. Measured before "
        "the simulator's downlink failures (issue 53): every 10 flights 0.79x CHM's handovers in 67 s, every 20 "
        "0.79x in 36 s; with them, 1.05x: docs/uav-reference.md)",
    )
    warmup_flights: int = Field(
        200,
        ge=0,
        description="flights on training seeds (below evaluate.HELD_OUT_SEED) the network adapts on before the first "
        "evaluated flight (ours: as many as one evaluation seed's flights. Before the simulator's downlink "
        "failures the offsets had not settled by then: 0.79x CHM's handovers after 200, 0.74x after 400)",
    )
    rlf_s: float = Field(
        0.5,
        gt=0,
        description="on real logs, which record no failures (SAMROOnSamples): a failure is the modelled uplink "
        "SINR below the minimum this long (ours, not a standard's); in simulation MRO reads StepInfo.rlf and .hof",
    )
    early_s: float = Field(
        2.0,
        gt=0,
        description="a failure this soon after a handover makes it too early or to the wrong cell (TS 36.300 sec. "
        "22.4.2 says 'shortly after'; the value is ours, not confirmed in a standard)",
    )
    margin_step_db: float = Field(
        1.0, gt=0, description="change of a pair's offset per update (ours; CIO steps are whole dB, TS 36.331)"
    )
    margin_range_db: tuple[float, float] = Field(
        (-4.0, 10.0), description="range of A3 offset plus cell individual offset (ours; within TS 36.331's +/-24 dB)"
    )


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
    """Conventional A3 handover with fixed offset and time-to-trigger, acting at every simulator step, or every
    ``decision_every`` steps (to compare with a log sampled that often)."""

    name = "CHM"

    def __init__(self, config: CHMConfig | None = None, decision_every: int = 1):
        self.cfg, self.decision_every = config or CHMConfig(), decision_every
        if decision_every > 1:
            self.name = f"CHM, every {decision_every} steps"

    def reset(self, env) -> None:
        self.a3 = A3Trigger(env.sim.K, env.sim.N, env.sim.dt * env.decision_every)

    def __call__(self, env) -> np.ndarray:
        return _action_of(
            env, self.a3.targets(_candidate_rsrp(env), env.sim.serving, self.cfg.offset_db, self.cfg.ttt_s)
        )


class MobilityRobustness:
    """The network's MRO state: a cell individual offset (dB, added to the A3 offset) per (serving, neighbour) pair,
    kept across flights, and the counts since the last update (TS 36.300 sec. 22.4.2's definitions).

    A radio link failure (or a handover failure) within ``early_s`` of a handover from S to T is *too early* on
    (S, T) when the UE would re-establish in S (the strongest cell), and *to the wrong cell* when in a third cell X
    (counted too early on (S, T) and too late on (S, X)). A failure with no recent handover, after which the UE
    re-establishes in another cell X, is *too late* on (the failed cell, X). A *ping-pong* (back to S within ``min_stay_s``) counts too early
    on (S, T). :meth:`update` moves each pair with more too-early than too-late counts ``margin_step_db`` up (hand
    over later), one with more too-late ones that much down, within ``margin_range_db``, and starts new counts.

    :param n: cells; ``min_stay_s``: the ping-pong window (``HandoverConfig.min_time_of_stay_s``).
    """

    def __init__(self, cfg: SAMROConfig, n: int, min_stay_s: float):
        self.cfg, self.min_stay_s = cfg, min_stay_s
        self.cio = np.zeros((n, n))
        self.early, self.late = np.zeros((n, n)), np.zeros((n, n))
        self.counted = {"too_early": 0, "too_late": 0, "wrong_cell": 0, "pingpong": 0}
        self.start(1)

    def start(self, k: int) -> None:
        """New flights: ``k`` UAVs with no handover yet."""
        self.ho_time, self.source, self.target = np.full(k, -np.inf), np.full(k, -1), np.full(k, -1)

    def offsets(self, serving: np.ndarray) -> np.ndarray:
        """(k, n) A3 offsets of each UAV towards each cell, from its serving cell."""
        return self.cfg.offset_db + self.cio[serving]

    def observe(self, now: float, serving, failed, best, handed, previous, pingpong=None) -> None:
        """One step's outcome per UAV: ``serving`` cells now, ``failed`` a radio link or handover failure,
        ``best`` the strongest cell (where the UE would re-establish), ``handed`` handovers from ``previous``;
        ``pingpong`` the simulator's own flags (default: a return within ``min_stay_s`` of the last handover)."""
        if pingpong is None:
            pingpong = handed & (serving == self.source) & (now - self.ho_time < self.min_stay_s)
        self._count("pingpong", self.early, serving, previous, pingpong)
        self.source = np.where(handed, previous, self.source)
        self.target = np.where(handed, serving, self.target)
        self.ho_time = np.where(handed, now, self.ho_time)
        recent = failed & (now - self.ho_time <= self.cfg.early_s) & (self.source >= 0)
        self._count("too_early", self.early, self.source, self.target, recent & (best == self.source))
        wrong = recent & (best != self.source) & (best != self.target)
        self._count("wrong_cell", self.early, self.source, self.target, wrong)
        np.add.at(self.late, (self.source[wrong], best[wrong]), 1)
        # too late: the link failed on the cell served before (``previous``) and the UE re-established elsewhere
        self._count("too_late", self.late, previous, best, failed & ~recent & (best != previous))

    def _count(self, name: str, table: np.ndarray, rows, cols, where) -> None:
        np.add.at(table, (rows[where], cols[where]), 1)
        self.counted[name] += int(np.count_nonzero(where))

    def update(self) -> None:
        """The network's periodic step (module doc), then new counts."""
        c = self.cfg
        step = c.margin_step_db * ((self.early > self.late).astype(float) - (self.late > self.early))
        low, high = c.margin_range_db
        self.cio = np.clip(self.cio + step, low - c.offset_db, high - c.offset_db)
        self.early[:], self.late[:] = 0, 0


class UplinkFailure:
    """A radio link failure on real samples, whose logs record none: the modelled uplink SINR below the minimum for
    ``rlf_s`` (one event per failure). The simulator reports its own (``StepInfo.rlf``, failures.py)."""

    def __init__(self, rlf_s: float, k: int):
        self.rlf_s, self.since = rlf_s, np.full(k, np.nan)

    def __call__(self, now: float, radio_ok) -> np.ndarray:
        failing = ~np.asarray(radio_ok, dtype=bool)
        self.since = np.where(failing, np.where(np.isnan(self.since), now, self.since), np.nan)
        rlf = failing & (now - self.since >= self.rlf_s)
        self.since[rlf] = np.inf
        return rlf


def link_failures(sim) -> np.ndarray:
    """Radio link or handover failure per flight in the simulator's last step (``StepInfo.rlf | StepInfo.hof``)."""
    return sim.last.rlf | sim.last.hof


class SAMRO:
    """A3 handover with the network's per-pair offsets adapted by mobility robustness optimisation (module doc).

    One instance is one network: its offsets persist across ``reset`` calls, and it counts the flights it has
    seen. :meth:`batch` tells ``evaluate.run_flights`` how many flights to fly together (up to the next update),
    :meth:`finish` closes them, and :meth:`warm_up` first flies ``warmup_flights`` training flights, so the result
    is that of flying every flight in sequence, whatever the batch size."""

    name = "SA-MRO"
    decision_every = 1

    def __init__(self, config: SAMROConfig | None = None):
        self.cfg = config or SAMROConfig()
        self.mro: MobilityRobustness | None = None
        self.flown, self.warm, self.updates = 0, False, 0

    def batch(self, n: int) -> int:
        """Flights to fly together next, of ``n`` left: none past the next update of the offsets."""
        return min(n, self.cfg.update_every_flights - self.flown % self.cfg.update_every_flights)

    def warm_up(self, fly) -> None:
        """Fly ``warmup_flights`` training flights once, before the first evaluated flight: ``fly(n)`` flies ``n``
        of them in order under this controller (the evaluation's loop, :func:`evaluate.run_flights`, passes it: the
        rules know no flight loop)."""
        if not self.warm:
            self.warm = True
            if self.cfg.warmup_flights:
                fly(self.cfg.warmup_flights)

    def reset(self, env) -> None:
        sim = env.sim
        if self.mro is None:
            self.mro = MobilityRobustness(self.cfg, sim.N, env.cfg.handover.min_time_of_stay_s)
        self.mro.start(sim.K)
        self.a3 = A3Trigger(sim.K, sim.N, sim.dt)
        self.previous = sim.serving.copy()

    def _observe(self, env, rsrp: np.ndarray) -> None:
        sim = env.sim
        last = sim.last
        failed = link_failures(sim)
        handed = last.handover.astype(bool)
        best = np.where(failed, sim.serving, rsrp.argmax(axis=1))  # after a failure: where the UE re-established
        self.mro.observe(sim.t * sim.dt, sim.serving, failed, best, handed, self.previous, last.pingpong)
        self.previous = sim.serving.copy()

    def __call__(self, env) -> np.ndarray:
        sim, rsrp = env.sim, _candidate_rsrp(env)
        if sim.last is not None:
            self._observe(env, rsrp)
        return _action_of(env, self.a3.targets(rsrp, sim.serving, self.mro.offsets(sim.serving), self.cfg.ttt_s))

    def finish(self, env) -> None:
        """The flights of ``env`` have ended: count their last step, then update the offsets on the cadence."""
        self._observe(env, _candidate_rsrp(env))
        self.flown += env.sim.K
        if self.flown % self.cfg.update_every_flights == 0:
            self.mro.update()
            self.updates += 1


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
    own handovers and with radio link failures from the uplink model at the sample's serving RSRP and altitude
    (:class:`UplinkFailure`; the real logs record none). One flight is too short for the network's cadence, so the
    offsets are updated once per ``update_every_flights`` x 2 min of samples."""

    name = "SA-MRO"

    def __init__(self, cells, sim_config, config: SAMROConfig | None = None):
        super().__init__(cells, None)
        self.sa, self.sim_cfg = config or SAMROConfig(), sim_config
        self.mro = MobilityRobustness(self.sa, len(self.cells), sim_config.handover.min_time_of_stay_s)
        self.failure = UplinkFailure(self.sa.rlf_s, 1)
        self.interference: dict[float, float] = {}
        self.last_update, self.updates = None, 0

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
        best = self.col[candidates[1]] if len(candidates) > 1 and rsrp[1] > rsrp[0] else serving[0]
        handed = previous is not None and previous != candidates[0]
        failed = self.failure(t, np.array([self._radio_ok(state)]))
        prev = np.array([self.col[previous] if previous is not None else serving[0]])
        self.mro.observe(t, serving, failed, np.array([best]), np.array([handed]), prev)
        self.last_update = t if self.last_update is None else self.last_update
        if t - self.last_update >= self.sa.update_every_flights * self.sim_cfg.flight.duration_s:
            self.mro.update()
            self.last_update, self.updates = t, self.updates + 1
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
