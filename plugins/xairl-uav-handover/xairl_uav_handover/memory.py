"""The DQN with memory (issue 55): its state is the last second of what the snapshot DQN sees, plus time.

A snapshot DQN decides on one 0.2 s state (:data:`features.FEATURES`). The hindsight bound (oracle.py) shows that 1 s
of foresight gives both fewer handovers and less RSRQ time than CHM, where a 0.2 s snapshot does not. A policy cannot
see the future, but it can see the recent past: whether a neighbour's RSRQ is rising or the serving cell's falling.

**The state.** It is a window (:mod:`xairl.policies.windows`) of :data:`STEPS` decisions, oldest first, of :data:`SIGNALS`:

- the 13 features of the snapshot;
- ``on_cell_s``: seconds since the UAV came onto its serving cell, by handover or by re-establishment after a
  failure;
- ``since_handover_s``: seconds since its last handover.

Both times are capped at :data:`TIME_CAP_S`. Flat, it has 5 x 15 = 75 columns, time-major (``layout='stacked'``).

**The candidates' past.** Candidate slot k's RSRP and RSRQ at an earlier step are that step's measurements of the
cell in slot k *now*. So a slot keeps one cell through the window even when the ranking of neighbours changed. The
UE reports every detected cell, and :class:`Memory` keeps every cell's reported values.

**The start of a flight.** The window repeats the first observation: there is no past yet.
"""

from __future__ import annotations

import numpy as np

import xairl

from .acting import DQNController, greedy, memory_of
from .baselines import CHM, CHMConfig
from .env import HandoverVecEnv
from .features import (
    ACTION_ALIASES,
    ACTIONS,
    SIGNALS,
    HandoverFacts,
    RsrqFeasible,
    available_actions,
    feature_info,
    snapshot,
    state_rows,
)
from .features import MEMORY_STEPS as STEPS

#: the times are capped here (seconds): a 120 s flight's cells last tens of seconds, and a cap keeps a rare long
#: stay from stretching the network's input scale
TIME_CAP_S = 30.0
N_FEATURES = STEPS * len(SIGNALS)


def decision_s(config) -> float:
    """Seconds between two decisions, the window's steps (0.2 s by default)."""
    return config.flight.dt_s * config.decision_every


def observation(config) -> xairl.Observation:
    """The memory DQN's input as an xairl observation: a stacked window of :data:`SIGNALS`, a decision apart."""
    return xairl.Observation.window(SIGNALS, STEPS, layout="stacked", step_s=decision_s(config))


class Memory:
    """The last :data:`STEPS` decisions of K flights: every cell's reported RSRP and RSRQ, the position, buffer,
    serving cell and times. :meth:`start` after ``env.reset``, :meth:`step` after each ``env.step``; both return
    the memory states (K, 75)."""

    def start(self, env) -> np.ndarray:
        sim = env.sim
        self.since_ho = np.zeros(sim.K)
        now = self._now(env)
        self.past = [now] * STEPS
        return self.states(env)

    def step(self, env, handover: np.ndarray) -> np.ndarray:
        decision_s = env.sim.dt * env.decision_every
        self.since_ho = np.where(np.asarray(handover) > 0, 0.0, self.since_ho + decision_s)
        self.past = [*self.past[1:], self._now(env)]
        return self.states(env)

    def _now(self, env) -> dict:
        sim = env.sim
        on_cell = (sim.t - sim.entered) * sim.dt
        return {
            "pos": sim.pos.copy(),
            "q": sim.q.copy(),
            "rsrp": sim.meas_rsrp.copy(),
            "rsrq": sim.meas_rsrq.copy(),
            "times": np.minimum(np.stack([on_cell, self.since_ho], axis=1), TIME_CAP_S),
        }

    def states(self, env) -> np.ndarray:
        """(K, 75): for each step, the 13 features of the cells in today's candidate slots, then the two times."""
        sim, cand = env.sim, env.candidates
        rows, missing = np.arange(sim.K)[:, None], cand < 0
        out = []
        for then in self.past:
            rsrp = np.where(missing, np.nan, then["rsrp"][rows, np.maximum(cand, 0)])
            rsrq = np.where(missing, np.nan, then["rsrq"][rows, np.maximum(cand, 0)])
            snap = state_rows(then["pos"], then["q"], sim.serving, rsrp, rsrq, sim.cfg.observation)
            out.append(np.concatenate([snap, then["times"].astype(np.float32)], axis=1))
        return np.concatenate(out, axis=1).astype(np.float32)


class MemoryDQNController:
    """Acts greedily with a memory Q-network (states from :class:`Memory`), one decision per env step."""

    name = "DQN"  # (Table I's column: the DQN, whichever state it sees)
    decision_every = None  # the simulator config's

    def __init__(self, net):
        self.net = net.eval()

    def reset(self, env) -> None:
        self.memory, self.states = Memory(), None

    def __call__(self, env) -> np.ndarray:
        if self.states is None:
            self.states = self.memory.start(env)
        else:  # the step just flown, as training records it
            self.states = self.memory.step(env, env.info["handover"])
        return greedy(self.net, self.states, env.cfg)


def controller(ckpt):
    """The controller that flies a checkpoint: the DQN with memory keeps its window, the snapshot DQN needs none."""
    return MemoryDQNController(ckpt.net) if memory_of(ckpt.meta) else DQNController(ckpt.net)


def background(n: int, seed: int = 0, config=None) -> np.ndarray:
    """``n`` memory states met in flight: ``n`` simulated UAVs after 10 s under conventional handover, decided every
    0.2 s (the memory's cadence)."""
    env = HandoverVecEnv(config, n_flights=n)
    env.reset(seed=seed)
    chm, memory = CHM(), Memory()
    chm.reset(env)
    states = memory.start(env)
    for _ in range(int(round(10.0 / (env.sim.dt * env.decision_every)))):
        info = env.step(chm(env))[4]
        states = memory.step(env, info["handover"])
    return states


def memory_policy(ckpt) -> xairl.Policy:
    """The DQN with memory as an xairl Policy (``uav_policy`` of its checkpoint): a window of :data:`SIGNALS`, so
    its explanations group per signal and per step and its narratives speak of trends; the action mask, the facts
    hook and the rule comparisons read the newest observation."""
    config = ckpt.sim_config
    facts = HandoverFacts(config.buffer.q_max_bits, CHMConfig().offset_db, config.observation.detection_rsrq_db)
    info = {k: v for k, v in feature_info(config.buffer.q_max_bits).items() if v.kind != "group"}
    # (described without the word 'time': '14 times' in a flight's summary would name them)
    info["on_cell_s"] = xairl.FeatureInfo("s", "how long the UAV had been on its serving cell", "briefly", "long")
    info["since_handover_s"] = xairl.FeatureInfo("s", "how long since the last handover", "recently", "long ago")
    return xairl.Policy(
        ckpt.net,
        observation=observation(config),
        action_names=ACTIONS,
        features=info,
        background_sampler=lambda n, seed: background(n, seed, config),
        name="uav-dqn-memory",
        action_aliases=ACTION_ALIASES,
        facts_hook=lambda state, chosen, runner_up, history=None: facts(
            snapshot(state), chosen, runner_up, None if history is None else snapshot(history)
        ),
        action_mask=lambda x: available_actions(x, config.observation),
        feasible=RsrqFeasible(config.radio.ue_noise_figure_db, config.observation.detection_rsrq_db),
    )


def walk_states(walk, config) -> np.ndarray:
    """Memory states (n, 75) along a real flight (:func:`real_data.walk`): at each sample, the window's steps 0.2 s
    apart back from it. Each step's measurements, position and buffer are the last sample's at or before its time
    (the logs report every 1.28 s in the median, so a window holds one or two samples: sample and hold, as a UE's
    report holds between reports); a cell that sample did not report is at the detection limit, and the serving
    cell, if it was not reported then, holds its newest report. Each step's times are counted at its own instant on
    the network's path (its serving cell changes are its handovers)."""
    key = (decision_s(config), config.observation.model_dump_json())
    if key not in walk.windows:  # (the report and the benchmarks ask for a walk's windows more than once)
        walk.windows[key] = _walk_states(walk, config)
    return walk.windows[key]


def _walk_states(walk, config) -> np.ndarray:
    t, cands, step = np.asarray(walk.t, float), walk.candidates, decision_s(config)
    serving = np.array([c[0] for c in cands])
    changed = np.flatnonzero(serving[1:] != serving[:-1]) + 1
    began = t[np.concatenate([[0], changed])[np.searchsorted(changed, np.arange(len(t)), side="right")]]
    out = np.empty((len(t), STEPS * len(SIGNALS)), dtype=np.float32)
    for i in range(len(t)):
        slots = list(cands[i]) + [None] * (4 - len(cands[i]))
        rows = []
        for d in range(STEPS - 1, -1, -1):
            at = t[i] - step * d
            j = max(int(np.searchsorted(t, at + 1e-9, side="right")) - 1, 0)
            then = {**walk.measured[j]}
            then.setdefault(slots[0], walk.measured[i][slots[0]])
            rsrp, rsrq = ([then.get(c, (np.nan, np.nan))[k] for c in slots] for k in (0, 1))
            snap = walk.states[j]
            fixed = state_rows(snap[:3], snap[3], walk.states[i][4], rsrp, rsrq, config.observation)[0]
            since = min(max(at - began[j], 0.0), TIME_CAP_S)
            rows.append(np.concatenate([fixed, [since, since]]))
        out[i] = np.concatenate(rows)
    return out


def without_past(states: np.ndarray, step_s: float = 0.2) -> np.ndarray:
    """Memory states whose measurements, position and buffer hold the newest step's values through the window, as
    if nothing had changed over the last second: what the same network decides when it may not look back. The times
    keep counting (each step ``step_s`` less, not below 0): time on the cell is part of the state, not its past."""
    w = np.repeat(np.asarray(states).reshape(len(states), STEPS, len(SIGNALS))[:, -1:], STEPS, axis=1)
    back = step_s * np.arange(STEPS - 1, -1, -1)[None, :, None]
    times = [SIGNALS.index(t) for t in ("on_cell_s", "since_handover_s")]
    w[:, :, times] = np.maximum(w[:, :, times] - back, 0.0)
    return w.reshape(len(states), -1)


def on_trends(net, states: np.ndarray, config) -> np.ndarray:
    """Bool per state: the memory DQN hands over there and would stay without its past (:func:`without_past`): a
    handover taken on a trend, which a snapshot of the same state would not give."""
    acts, flat = greedy(net, states, config), greedy(net, without_past(states, decision_s(config)), config)
    return (acts > 0) & (flat == 0)
