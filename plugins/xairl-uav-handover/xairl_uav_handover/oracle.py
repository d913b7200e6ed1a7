"""The hindsight bound: the fewest handovers and the least time below the RSRQ threshold that any handover policy
could reach on the same flights, knowing each flight's future.

Why it is exact. The simulator's random draws (trajectories, the channel latents, packet arrivals) come from each
flight's own stream (streams.py) in a fixed order and in fixed sizes, whatever the policy does (tests/test_uav_oracle.py flies two
schedules and compares every draw). So one flight, flown once, fixes every cell's reported RSRQ at every step.
:func:`record` keeps, per simulator step and cell, whether the reported RSRQ (``sim.meas_rsrq`` as
``Simulator.step`` reads it for ``rsrq_violation``) is below the threshold, and, per decision, the cells ranked as
``Simulator.candidates`` ranks them (detected neighbours by reported RSRP).

- :func:`cost` is the simulator's own bookkeeping on any *realised* serving sequence (``sim.serving`` after each
  step): handovers are changes of the serving cell, RSRQ time is the steps whose serving cell reads below the
  threshold. It reproduces the simulator's sums exactly for any policy (tests: CHM, the DQN, the bound's own schedule).
  The bound is over handover schedules: a failed handover or a radio link failure (failures.py) moves the UE to
  another cell by re-establishment, which is no handover and depends on the history of the link, so the bound
  and every policy placed on it fly with failures off (:func:`bound_config`).
- :func:`solve` is the shortest path over (decision step, serving cell) minimising
  ``w_ho x handovers + seconds below the RSRQ threshold``. A handover happens only at a decision (every
  ``SimConfig.decision_every`` steps), to a cell the env offers then: the serving cell's 3 strongest detected
  neighbours (``any_measured=True``: any detected cell). It plans commanded handovers as if every one succeeds.
  With ``w_cap`` it adds ``w_cap x capacity shortfall`` (Mbit): per step, how far the serving cell's uplink
  capacity (``uplink.capacity_bps`` of the SINR ``Simulator.step`` computes there) falls short of the mean offered
  video rate, and the whole offered rate on the steps a handover interrupts (``HandoverConfig.interruption_s``).
  It is defined without the buffer (a buffer carries data over; the shortfall does not), so it is the bound's own
  measure and has no simulator sum to match; its SINR and interruptions do match the simulator's (tests).
- :func:`receding` solves the same problem over the next ``horizon_s`` only at each decision, commits the first
  decision, and moves on: how much foresight the bound needs.
- :class:`ScheduleController` replays a schedule through :class:`env.HandoverVecEnv` (evaluate.run_flights);
  :class:`Recorded` wraps any controller and keeps what it realised, step by step.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from xairl import InputError

from .config import SimConfig
from .evaluate import HELD_OUT_SEED
from .features import N_CANDIDATES
from .simulator import Simulator
from .streams import flight_seeds
from .uplink import capacity_bps, sinr_db


@dataclass
class Record:
    """One batch of flights, recorded. T steps, K flights, N cells, D decisions."""

    below: np.ndarray  # (T, K, N) bool: reported RSRQ below the threshold, as Simulator.step compares it
    rsrq: np.ndarray  # (T, K, N) float32: the reported RSRQ (dB), for reading only
    top: np.ndarray  # (D, K, 4) int: the 4 strongest detected cells by reported RSRP at each decision; -1: none
    detected: np.ndarray  # (D, K, N) bool: reported RSRQ above the detection threshold at each decision
    initial: np.ndarray  # (K,) the serving cell before the first step
    dt: float
    every: int  # simulator steps per decision
    short: np.ndarray | None = None  # (T, K, N) float32 Mbit: uplink capacity short of the offered rate, per step
    offered_mbit: float = 0.0  # offered data per step (Mbit): what an interrupted step lacks
    interrupt: int = 0  # steps without service from a handover on (the handover's step included)
    sinr: np.ndarray | None = None  # (T, K, N) float32: uplink SINR (dB) at each cell, as Simulator.step computes it

    @property
    def shape(self) -> tuple[int, int, int, int]:
        """(T, K, N, D)."""
        t, k, n = self.below.shape
        return t, k, n, len(self.top)

    def step_costs(self, w_cap: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """(D, K, N) cost of serving each cell through each decision's steps: seconds below the threshold (+ w_cap x
        shortfall), and (D, K, N) what a handover into the cell adds there (w_cap x the interrupted steps' loss)."""
        if not w_cap:
            return self._sums[0], np.zeros_like(self._sums[0])
        if self.short is None or self.interrupt > self.every:
            raise InputError("w_cap needs a record with uplink shortfalls and interruptions within a decision.")
        rsrq_s, short, interrupted = self._sums
        return rsrq_s + w_cap * short, w_cap * interrupted

    @cached_property
    def _sums(self) -> tuple[np.ndarray, ...]:
        """Per decision and cell: seconds below the RSRQ threshold, shortfall (Mbit), and the shortfall a handover
        adds on its interrupted steps (offered minus what those steps would have lacked anyway)."""
        starts = np.arange(0, self.below.shape[0], self.every)
        rsrq_s = np.add.reduceat(self.below, starts, axis=0, dtype=np.int32) * self.dt
        if self.short is None:
            return rsrq_s, None, None
        short = np.add.reduceat(self.short, starts, axis=0, dtype=np.float64)
        interrupted = np.zeros_like(short)
        for j in range(min(self.interrupt, self.every)):
            there = starts + j < len(self.short)  # a short last decision has fewer steps to interrupt
            interrupted[there] += self.offered_mbit - self.short[starts[there] + j]
        return rsrq_s, short, interrupted


def ranking(meas_rsrp: np.ndarray, meas_rsrq: np.ndarray, detection_db: float) -> tuple[np.ndarray, np.ndarray]:
    """The 4 strongest detected cells by reported RSRP ((K, 4), -1: none) and the detected mask (K, N): the env's
    candidates from serving cell s are s and the first 3 of these other than s (Simulator.candidates)."""
    detected = meas_rsrq > detection_db
    masked = np.where(detected, meas_rsrp, -np.inf)
    top = np.argsort(-masked, axis=1)[:, :N_CANDIDATES]
    top = np.where(np.isfinite(np.take_along_axis(masked, top, axis=1)), top, -1)
    pad = np.full((len(top), N_CANDIDATES - top.shape[1]), -1)  # fewer cells than candidate slots
    return np.concatenate([top, pad], axis=1), detected


def bound_config(config: SimConfig) -> SimConfig:
    """``config`` with handover and radio link failures off: the simulator the bound is exact on (module doc)."""
    data = config.model_dump()
    data["handover"]["failures"] = False
    return SimConfig.model_validate(data)


def record(config: SimConfig, n_flights: int, seed: int) -> Record:
    """Fly the held-out flights of ``seed`` (the ones evaluate.run_flights flies) once and record them; ``config``
    must have failures off (:func:`bound_config`)."""
    if config.handover.failures:
        raise InputError("the bound is exact without handover failures: record on oracle.bound_config(config).")
    sim = Simulator(config, n_uavs=n_flights, seed=flight_seeds(HELD_OUT_SEED + seed, 0, n_flights))
    t_all, every, thr = sim.n_steps, config.decision_every, config.handover.rsrq_threshold_db
    d_all = -(-t_all // every)
    below = np.empty((t_all, sim.K, sim.N), dtype=bool)
    rsrq = np.empty((t_all, sim.K, sim.N), dtype=np.float32)
    top = np.empty((d_all, sim.K, N_CANDIDATES), dtype=np.int16)
    detected = np.empty((d_all, sim.K, sim.N), dtype=bool)
    initial, short, sinr = sim.serving.copy(), np.empty_like(rsrq), np.empty_like(rsrq)
    offered = config.buffer.packet_rate_hz * config.buffer.data_packet_bits * sim.dt
    for t in range(t_all):
        if t % every == 0:
            top[t // every], detected[t // every] = ranking(
                sim.meas_rsrp, sim.meas_rsrq, config.observation.detection_rsrq_db
            )
        below[t] = sim.meas_rsrq < thr
        rsrq[t] = sim.meas_rsrq
        sinr[t] = cell_sinr = all_cells_sinr_db(sim)
        short[t] = np.maximum(offered - capacity_bps(config, cell_sinr) * sim.dt, 0.0) / 1e6
        sim.step(sim.serving)
    n_int = int(round(config.handover.interruption_s / sim.dt))
    return Record(below, rsrq, top, detected, initial, sim.dt, every, short, offered / 1e6, n_int, sinr)


def all_cells_sinr_db(sim: Simulator) -> np.ndarray:
    """(K, N) uplink SINR of every UAV at every cell, as ``Simulator.ul_sinr_db`` computes it at the serving one."""
    return sinr_db(sim.cfg, sim.loss_db, sim._ul_interference, sim._rsrp_offset - sim.meas_rsrp)


@dataclass
class Cost:
    """A schedule's cost parts per flight, (K,) each."""

    handovers: np.ndarray  # int
    rsrq_steps: np.ndarray  # int: steps below the RSRQ threshold
    rsrq_s: np.ndarray  # seconds below it
    shortfall_mbit: np.ndarray | None = None  # uplink capacity short of the offered rate (record.short)
    interrupted: np.ndarray | None = None  # (K, T) bool: steps without service after a handover


def cost(rec: Record, serving: np.ndarray) -> Cost:
    """Handovers and RSRQ time of a realised serving sequence ``serving`` ((K, T): the serving cell at each step)."""
    t_all, k_all, _, _ = rec.shape
    serving = np.asarray(serving)
    if serving.shape != (k_all, t_all):
        raise InputError(
            f"serving must be (flights, steps) = {(k_all, t_all)}, got {serving.shape}; one cell per step."
        )
    previous = np.concatenate([rec.initial[:, None], serving[:, :-1]], axis=1)
    ho = serving != previous
    steps = np.take_along_axis(rec.below, serving.T[:, :, None], axis=2)[:, :, 0].sum(axis=0)
    if rec.short is None:
        return Cost(ho.sum(axis=1), steps, steps * rec.dt)
    interrupted = np.zeros_like(ho)
    for j in range(rec.interrupt):  # a handover at step t interrupts t .. t + interrupt - 1
        interrupted[:, j:] |= ho[:, : t_all - j]
    short = np.take_along_axis(rec.short, serving.T[:, :, None], axis=2)[:, :, 0].T
    shortfall = np.where(interrupted, rec.offered_mbit, short).sum(axis=1)
    return Cost(ho.sum(axis=1), steps, steps * rec.dt, shortfall, interrupted)


def per_step(rec: Record, cells: np.ndarray) -> np.ndarray:
    """A schedule's serving cell per decision (K, D) as the serving cell per step (K, T)."""
    return np.repeat(cells, rec.every, axis=1)[:, : rec.shape[0]]


def _best_other(value: np.ndarray, allowed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each cell s, the least ``value`` over allowed cells other than s, and which cell it is ((K, N) each)."""
    v = np.where(allowed, value, np.inf)
    if v.shape[1] == 1:
        return np.full_like(v, np.inf), np.zeros(v.shape, dtype=np.int64)
    order = np.argpartition(v, 1, axis=1)  # the least first, the next least second
    m1, m2 = order[:, 0], order[:, 1]
    rows = np.arange(len(v))
    is_m1 = np.arange(v.shape[1])[None, :] == m1[:, None]
    best = np.where(is_m1, v[rows, m2][:, None], v[rows, m1][:, None])
    arg = np.where(is_m1, m2[:, None], m1[:, None])
    return best, arg


def _into(value: np.ndarray, top: np.ndarray, any_measured: bool, detected: np.ndarray):
    """Forward step: for each target cell, the cheapest source a handover into it can come from ((K, N) value and
    source). Candidates: a top-3 cell is offered from any other cell, the 4th only from the top 3."""
    best, arg = _best_other(value, np.ones(value.shape, dtype=bool))
    if any_measured:
        return np.where(detected, best, np.inf), arg
    out, src, rows = np.full_like(value, np.inf), np.zeros_like(arg), np.arange(len(value))
    for r in range(N_CANDIDATES):
        cell = top[:, r]
        ok = cell >= 0
        if r < N_CANDIDATES - 1:
            out[rows[ok], cell[ok]], src[rows[ok], cell[ok]] = best[rows[ok], cell[ok]], arg[rows[ok], cell[ok]]
        else:
            top3 = top[:, :-1]
            v3 = np.where(top3 >= 0, value[rows[:, None], np.maximum(top3, 0)], np.inf)
            j = v3.argmin(axis=1)
            out[rows[ok], cell[ok]], src[rows[ok], cell[ok]] = v3[rows, j][ok], top3[rows, j][ok]
    return out, src


def _out_of(value: np.ndarray, top: np.ndarray, any_measured: bool, detected: np.ndarray):
    """Backward step: for each source cell, the cheapest cell a handover from it can go to ((K, N) value, target).
    Candidates: from a top-3 cell, the other top-4 cells; from any other cell, the top 3."""
    if any_measured:
        return _best_other(value, detected)
    rows = np.arange(len(value))
    vt = np.where(top >= 0, value[rows[:, None], np.maximum(top, 0)], np.inf)  # (K, 4)
    j3 = vt[:, :-1].argmin(axis=1)
    out = np.broadcast_to(vt[rows, j3][:, None], value.shape).copy()
    arg = np.broadcast_to(top[rows, j3][:, None], value.shape).copy()
    for r in range(N_CANDIDATES - 1):
        others = np.delete(vt, r, axis=1)
        j = others.argmin(axis=1)
        cell, ok = top[:, r], top[:, r] >= 0
        out[rows[ok], cell[ok]] = others[rows, j][ok]
        arg[rows[ok], cell[ok]] = np.delete(top, r, axis=1)[rows, j][ok]
    return out, arg


@dataclass
class Schedule:
    """A schedule (serving cell per decision, (K, D)) and its cost parts; ``total`` = w_ho x handovers + rsrq_s
    (+ w_cap x shortfall_mbit)."""

    cells: np.ndarray
    cost: Cost
    total: np.ndarray


def _scheduled(rec: Record, cells: np.ndarray, w_ho: float, w_cap: float) -> Schedule:
    c = cost(rec, per_step(rec, cells))
    return Schedule(cells, c, w_ho * c.handovers + c.rsrq_s + (w_cap * c.shortfall_mbit if w_cap else 0.0))


def solve(rec: Record, w_ho: float, any_measured: bool = False, w_cap: float = 0.0) -> Schedule:
    """The exact least ``w_ho x handovers + seconds below the RSRQ threshold (+ w_cap x shortfall)`` per flight
    (forward shortest path over (decision, serving cell), vectorised over flights and cells), and its schedule."""
    _, k_all, n_all, d_all = rec.shape
    step, extra = rec.step_costs(w_cap)
    value = np.full((k_all, n_all), np.inf)
    value[np.arange(k_all), rec.initial] = 0.0
    parent = np.empty((d_all, k_all, n_all), dtype=np.int16)
    stay_cell = np.broadcast_to(np.arange(n_all), (k_all, n_all))
    for d in range(d_all):
        into, src = _into(value, rec.top[d], any_measured, rec.detected[d])
        into = into + w_ho + extra[d]
        take = into < value
        value = np.where(take, into, value) + step[d]
        parent[d] = np.where(take, src, stay_cell)
    cells = np.empty((k_all, d_all), dtype=np.int64)
    cells[:, -1] = value.argmin(axis=1)
    rows = np.arange(k_all)
    for d in range(d_all - 1, 0, -1):
        cells[:, d - 1] = parent[d][rows, cells[:, d]]
    return _scheduled(rec, cells, w_ho, w_cap)


def receding(rec: Record, w_ho: float, horizon_s: float, any_measured: bool = False, w_cap: float = 0.0) -> Schedule:
    """At each decision, the best first decision over the next ``horizon_s`` seconds (at least one decision) as
    :func:`solve` would take it with nothing known beyond; commit it and move on."""
    _, k_all, n_all, d_all = rec.shape
    h = max(1, int(round(horizon_s / (rec.dt * rec.every))))
    (step, extra), rows = rec.step_costs(w_cap), np.arange(k_all)
    serving, cells = rec.initial.astype(np.int64), np.empty((k_all, d_all), dtype=np.int64)
    for d in range(d_all):
        to_go = np.zeros((k_all, n_all))
        for j in range(min(d + h, d_all) - 1, d - 1, -1):  # backward over the horizon
            here = step[j] + to_go
            away, target = _out_of(here + extra[j], rec.top[j], any_measured, rec.detected[j])
            to_go = np.minimum(here, away + w_ho)
        move = away[rows, serving] + w_ho < here[rows, serving]
        serving = np.where(move, target[rows, serving], serving)
        cells[:, d] = serving
    return _scheduled(rec, cells, w_ho, w_cap)


def frontier(
    rec: Record, w_hos, horizon_s: float | None = None, any_measured: bool = False, w_cap: float = 0.0
) -> dict[str, list]:
    """Mean handovers per flight, % of time below the RSRQ threshold and uplink shortfall (Mbit per flight) for
    each ``w_ho`` (exact, or receding with ``horizon_s`` of foresight)."""
    t_all = rec.shape[0]
    out = {"w_ho": [], "handovers": [], "rsrq_pct": [], "shortfall_mbit": []}
    for w in w_hos:
        if horizon_s is None:
            s = solve(rec, w, any_measured, w_cap)
        else:
            s = receding(rec, w, horizon_s, any_measured, w_cap)
        out["w_ho"].append(float(w))
        out["handovers"].append(float(s.cost.handovers.mean()))
        out["rsrq_pct"].append(float(100 * s.cost.rsrq_steps.mean() / t_all))
        short = s.cost.shortfall_mbit
        out["shortfall_mbit"].append(None if short is None else float(short.mean()))
    return out


def handovers_at(points: dict[str, list], rsrq_pct: float) -> float:
    """Handovers per flight the frontier ``points`` reaches at ``rsrq_pct`` (linear between points; NaN outside)."""
    h, r = np.asarray(points["handovers"]), np.asarray(points["rsrq_pct"])
    o = np.argsort(r)
    return float(np.interp(rsrq_pct, r[o], h[o], left=np.nan, right=np.nan))


def rsrq_at(points: dict[str, list], handovers: float) -> float:
    """% time below the RSRQ threshold the frontier ``points`` reaches at ``handovers`` per flight (linear)."""
    h, r = np.asarray(points["handovers"]), np.asarray(points["rsrq_pct"])
    o = np.argsort(h)  # beyond the most handovers swept, more handovers cannot cost the bound RSRQ time
    return float(np.interp(handovers, h[o], r[o], left=np.nan, right=r[o][-1]))


class ScheduleController:
    """Plays a schedule (serving cell per decision, (K, D)) through :class:`env.HandoverVecEnv`."""

    name = "schedule"

    def __init__(self, cells: np.ndarray, every: int):
        self.cells, self.decision_every = np.asarray(cells), every

    def reset(self, env) -> None:
        pass

    def __call__(self, env) -> np.ndarray:
        target = self.cells[:, env.sim.t // self.decision_every]
        hit = env.candidates == target[:, None]
        if not hit.any(axis=1).all():
            raise InputError("the schedule names a cell the env does not offer; replay only schedules of solve().")
        return hit.argmax(axis=1)


class Recorded:
    """Any controller, with what the simulator realised under it: the serving cell after each step (``serving``,
    (K, T)), the sums of ``StepInfo.handover`` and ``rsrq_violation`` per flight, and :meth:`realised`."""

    def __init__(self, controller):
        self.inner, self.name, self.decision_every = controller, controller.name, controller.decision_every

    def reset(self, env) -> None:
        self.inner.reset(env)
        sim, sim_step, served = env.sim, env.sim.step, []
        self.served, self.handovers, self.rsrq_steps = served, np.zeros(sim.K, int), np.zeros(sim.K, int)
        self.infos = []

        def step(target):  # the simulator's own step, then what it realised
            info = sim_step(target)
            served.append(sim.serving.copy())
            self.infos.append((info.sinr_db, info.available, info.radio_ok))
            self.handovers += info.handover
            self.rsrq_steps += info.rsrq_violation
            return info

        sim.step = step

    def __call__(self, env) -> np.ndarray:
        return self.inner(env)

    @property
    def serving(self) -> np.ndarray:
        return np.stack(self.served, axis=1)

    def realised(self, name: str) -> np.ndarray:
        """(K, T) ``sinr_db``, ``available`` or ``radio_ok`` of each step (StepInfo)."""
        return np.stack([i[("sinr_db", "available", "radio_ok").index(name)] for i in self.infos], axis=1)
