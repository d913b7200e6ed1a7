"""A flight at a glance: one simulated or real flight as a timeline figure and a narrated, verified summary.

- Simulated: the DQN flies a held-out flight (closed loop, one decision every 0.2 s); CHM flies the same flight
  (same seed: same trajectory and channel) on its own, and its handover times are marked.
- Real: every sample of a real flight, as the network flew it (:func:`real_data.walk`); the DQN and CHM propose an
  action at each sample (open loop, as in the report's agreement table) and the live network's handovers are
  marked.

The timeline shows the serving and strongest-neighbour RSRP, the buffer's fill, the handovers, and the three
reasons with the largest mean |contribution to the margin| over time. The summary states the flight's counts and the
reason that most often came first, and is checked by :func:`xairl.verify` against the flight's explanation and
its counts (:class:`xairl.facts.DomainFacts`).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import xairl
from xairl import Explanation, Policy, verify

from .features import BUFFER, RSRP, snapshot
from .memory import Memory, walk_states
from .policy import Checkpoint, greedy, memory_of

HISTORY = 10  # earlier states a decision's facts may look back on


@dataclass
class FlightTimeline:
    """One flight: its decision states over time and whose handovers happened (or were proposed) when.

    :param label: 'simulated flight (seed 3)' or the real file's name.
    :param t: seconds of each state; ``states`` (T, 13) in :data:`features.FEATURES` order.
    :param dqn_handover: (T,) True where the DQN handed over (simulated) or proposed a handover (real).
    :param chm_times: seconds at which CHM handed over (simulated, closed loop) or proposed one (real).
    :param live_times: the live network's handovers (real flights only).
    :param closed_loop: True when the DQN flew the flight itself.
    """

    label: str
    t: np.ndarray
    states: np.ndarray
    dqn_handover: np.ndarray
    chm_times: np.ndarray
    live_times: np.ndarray | None
    closed_loop: bool

    @property
    def duration_s(self) -> float:
        return float(self.t[-1] - self.t[0]) if len(self.t) > 1 else 0.0


def simulated_flight(ckpt: Checkpoint, seed: int = 0) -> FlightTimeline:
    """One held-out flight flown by the DQN, with CHM's handovers on the same flight."""
    from .baselines import CHM
    from .env import HandoverVecEnv
    from .evaluate import HELD_OUT_SEED

    cfg = ckpt.sim_config
    env = HandoverVecEnv(cfg, 1)
    obs, _ = env.reset(seed=HELD_OUT_SEED + seed)
    memory = Memory() if memory_of(ckpt.meta) else None  # the DQN with memory decides on its window
    obs = obs if memory is None else memory.start(env)
    states, handed, ended = [], [], False
    while not ended:
        states.append(obs[0])
        action = greedy(ckpt.net, obs, cfg)
        handed.append(bool(action[0] != 0))
        obs, _, _, truncated, info = env.step(action)
        obs = obs if memory is None else memory.step(env, info["handover"])
        ended = bool(truncated.all())
    step_s = cfg.flight.dt_s * env.decision_every
    chm_env, chm = HandoverVecEnv(cfg, 1, decision_every=1), CHM()
    chm_env.reset(seed=HELD_OUT_SEED + seed)
    chm.reset(chm_env)
    chm_times, k, ended = [], 0, False
    while not ended:
        *_, truncated, info = chm_env.step(chm(chm_env))
        k += 1
        if info["handover"][0] > 0:
            chm_times.append(k * cfg.flight.dt_s)
        ended = bool(truncated.all())
    return FlightTimeline(
        f"simulated flight (seed {seed})",
        np.arange(len(states)) * step_s,
        np.array(states),
        np.array(handed),
        np.array(chm_times),
        None,
        True,
    )


def real_flight(flight, ckpt: Checkpoint, seed: int = 0) -> FlightTimeline:
    """A real flight's samples with the DQN's and CHM's proposals (open loop) and the network's handovers."""
    from .baselines import CHMOnSamples
    from .real_data import walk

    w = walk(flight, ckpt.sim_config, seed=seed)
    states = walk_states(w, ckpt.sim_config) if memory_of(ckpt.meta) else w.states  # the DQN's own states
    dqn = greedy(ckpt.net, states, ckpt.sim_config) != 0
    chm = CHMOnSamples(flight.cells)
    chm_times = [float(t) for s, c, t in zip(w.states, w.candidates, w.t) if chm(s, c, float(t)) != 0]
    live = flight.t[1:][np.diff(flight.pci) != 0]
    return FlightTimeline(flight.name, np.asarray(w.t, float), states, dqn, np.array(chm_times), live, False)


def _first_reasons(tl: FlightTimeline, exp: Explanation, policy: Policy) -> list[tuple[int, str | None]]:
    """(chosen action, name of its first reason or None) per decision, with the flight's history."""
    out = []
    for i in range(len(tl.states)):
        d = xairl.facts.decision_facts(exp, i, policy, k=1, history=tl.states[max(0, i - HISTORY) : i])
        out.append((int(exp.chosen[i]), d.reasons[0].label if d.reasons else None))
    return out


def summary(tl: FlightTimeline, exp: Explanation, policy: Policy) -> tuple[str, xairl.facts.DomainFacts]:
    """The flight in three sentences, and the facts its numbers come from (for :func:`xairl.verify`)."""
    dqn, chm = int(tl.dqn_handover.sum()), len(tl.chm_times)
    reasons = _first_reasons(tl, exp, policy)
    stays = [r for a, r in reasons if a == 0]
    top = Counter(r for r in stays if r).most_common(1)
    comparisons = [
        xairl.facts.Comparison(f"{xairl.facts.format_number(tl.duration_s)} s", round(tl.duration_s, 1), "s"),
        xairl.facts.Comparison(f"{len(tl.states)} decisions", len(tl.states), "decisions"),
        xairl.facts.Comparison(f"{len(stays)} decisions", len(stays), "decisions"),
    ]
    if tl.closed_loop:
        first = (
            f"Over {xairl.facts.format_number(tl.duration_s)} s the DQN handed over {dqn} {'time' if dqn == 1 else 'times'}, where CHM "
            f"flying the same flight handed over {chm} {'time' if chm == 1 else 'times'}."
        )
        comparisons += [
            xairl.facts.Comparison(f"{dqn} times", dqn, "times"),
            xairl.facts.Comparison(f"{chm} times", chm, "times"),
        ]
    else:
        live = len(tl.live_times)
        first = (
            f"Over {xairl.facts.format_number(tl.duration_s)} s of this real flight the DQN would have proposed a handover at {dqn} "
            f"samples and CHM at {chm}; the live network handed over {live} times."
        )
        comparisons += [
            xairl.facts.Comparison(f"{dqn} samples", dqn, "samples"),
            xairl.facts.Comparison(f"{chm} samples", chm, "samples"),
            xairl.facts.Comparison(f"{live} times", live, "times"),
        ]
    would = "" if tl.closed_loop else " would have"
    text = [first, f"The DQN{would} stayed at {len(stays)} of its {len(tl.states)} decisions."]
    if top:
        name, n = top[0]
        comparisons.append(xairl.facts.Comparison(f"{n} decisions", n, "decisions"))
        text.append(f"For staying, its first reason was most often {name}, in {n} decisions.")
    return " ".join(text), xairl.facts.DomainFacts(comparisons=tuple(comparisons))


def narrate_flight(tl: FlightTimeline, exp: Explanation, policy: Policy):
    """(summary text, its :class:`xairl.Verification`)."""
    text, facts = summary(tl, exp, policy)
    return text, verify(text, exp, None, policy, facts=facts)


def timeline_figure(tl: FlightTimeline, exp: Explanation, policy: Policy, path: str | Path) -> Path:
    """Serving and strongest-neighbour RSRP, buffer fill, handovers, and the top margin contributions over time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    q_max = policy.features["buffer_queue_size"].capacity or 1.0
    us = xairl.facts.narration_units(exp, policy)
    margin = exp.margin()
    contrib = np.stack([margin[:, list(u.columns)].sum(axis=1) for u in us], axis=1)
    keep = [j for j, u in enumerate(us) if u.info.kind != "identifier"]
    top = sorted(keep, key=lambda j: -np.abs(contrib[:, j]).mean())[:3]
    fig, ax = plt.subplots(4, 1, figsize=(9, 8), sharex=True, gridspec_kw={"height_ratios": [3, 1.5, 1, 2.5]})
    now = snapshot(tl.states)  # (the newest step of a memory DQN's window)
    rsrp = now[:, RSRP]
    ax[0].plot(tl.t, rsrp[:, 0], lw=1, label="serving RSRP")
    ax[0].plot(tl.t, rsrp[:, 1], lw=1, label="strongest neighbour RSRP")
    ax[0].set_ylabel("dBm")
    ax[0].legend(fontsize=8, loc="lower left")
    ax[1].plot(tl.t, 100 * now[:, BUFFER] / q_max, color="tab:purple", lw=1)
    ax[1].set_ylabel("buffer %")
    ax[1].set_ylim(-5, 105)
    rows = [("DQN", tl.t[tl.dqn_handover], "tab:red"), ("CHM", tl.chm_times, "tab:gray")]
    if tl.live_times is not None:
        rows.append(("network", tl.live_times, "tab:green"))
    for y, (_name, times, color) in enumerate(rows):
        ax[2].plot(times, np.full(len(times), y), "|", ms=12, color=color)
    ax[2].set_yticks(range(len(rows)), [f"{n} ({len(t)})" for n, t, _ in rows], fontsize=8)
    ax[2].set_ylim(-0.7, len(rows) - 0.3)
    ax[2].set_ylabel("handovers" if tl.closed_loop else "proposed / made", fontsize=8)
    for j in top:
        ax[3].plot(tl.t, contrib[:, j], lw=1, label=us[j].info.description or us[j].name)
    ax[3].axhline(0, color="0.5", lw=0.6)
    ax[3].set_ylabel("to the margin")
    ax[3].set_xlabel("time (s)")
    ax[3].legend(fontsize=8, loc="lower left")
    ax[0].set_title(tl.label, fontsize=10)
    fig.tight_layout()
    path = Path(path)
    xairl.plugin.save_figure(fig, path, dpi=80)
    plt.close(fig)
    return path
