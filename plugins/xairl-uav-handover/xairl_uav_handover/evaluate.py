"""Run controllers on the same held-out flights (per-flight metrics; table.py makes them Table I).

Flight ``i`` of evaluation seed ``s`` draws from its own stream (``[HELD_OUT_SEED + s, i]``, streams.py), so every
controller meets the same flights whatever the batch (the streams cost 8 % more simulator time than one stream for
the batch: 0.66 against 0.61 ms a step for 200 flights). SA-MRO's network warms up on flights of ``WARM_UP_SEED``
(not a held-out seed) before the held-out ones, and flies in vectors that end at its updates: 200 held-out flights
after 200 warm-up flights take 36 s on one core (CHM's 200: 3 s).
"""

from __future__ import annotations

import numpy as np

from .baselines import CHM
from .config import SimConfig
from .env import METRICS, PINGPONG_WINDOWS_S, HandoverVecEnv
from .features import BUFFER
from .streams import flight_seeds

#: seeds of evaluation flights start here; training flights use seeds below it (see train.py)
HELD_OUT_SEED = 1_000_000
#: SA-MRO's network adapts on flights of this seed before the evaluated ones (below HELD_OUT_SEED: not held out)
WARM_UP_SEED = HELD_OUT_SEED - 1
#: the paper's Table I (median per flight): handovers, ping-pong %
PAPER = {"CHM": (75, 40), "SA-MRO": (32, 27), "DQN": (12, 14)}


def run_flights(controller, config: SimConfig, n_flights: int, seed: int, first: int = 0) -> dict[str, np.ndarray]:
    """Fly held-out flights ``first`` .. ``first + n_flights - 1`` of evaluation ``seed`` under ``controller``;
    per-flight metrics as arrays of shape (n_flights,). Each flight has its own random stream (streams.py), so it is
    the same flight in any batch. A controller that learns across flights (``batch``/``warm_up``: SA-MRO's network)
    first warms up, then flies them in order, as many together as its cadence allows (:func:`fly_in_order`)."""
    warm_up = getattr(controller, "warm_up", None)
    if warm_up is not None:  # on flights of WARM_UP_SEED, not held out
        warm_up(lambda n: fly_in_order(controller, config, flight_seeds(WARM_UP_SEED, 0, n)))
    return fly_in_order(controller, config, flight_seeds(HELD_OUT_SEED + seed, first, n_flights))


def fly_in_order(controller, config: SimConfig, seeds: list) -> dict[str, np.ndarray]:
    """Fly the flights of ``seeds`` (one per flight) in that order: all in one vector, or in the vectors the
    controller's ``batch(n_left)`` asks for."""
    batch = getattr(controller, "batch", None)
    if batch is None:
        return _fly(controller, config, seeds)
    parts, done = [], 0
    while done < len(seeds):
        k = batch(len(seeds) - done)
        parts.append(_fly(controller, config, seeds[done : done + k]))
        done += k
    return {key: np.concatenate([p[key] for p in parts]) for key in parts[0]}


def _fly(controller, config: SimConfig, seeds: list) -> dict[str, np.ndarray]:
    """One vector of flights, one per seed, flown to the end (per-flight metrics)."""
    n_flights = len(seeds)
    env = HandoverVecEnv(config, n_flights, decision_every=controller.decision_every)
    env.reset(seed=seeds)
    controller.reset(env)
    windows = tuple(f"pingpong_{w:g}s" for w in PINGPONG_WINDOWS_S)
    tot = {k: np.zeros(n_flights) for k in METRICS + windows}
    nonempty, decisions, ended = np.zeros(n_flights), 0, False
    ho_nonempty, ho_full = np.zeros(n_flights), np.zeros(n_flights)
    while not ended:
        queue = env.obs[:, BUFFER].copy()  # the decision state's buffer
        nonempty += queue > 0
        decisions += 1
        *_, truncated, info = env.step(controller(env))
        for key in METRICS + windows:
            tot[key] += info[key]
        ho_nonempty += info["handover"] * (queue > 0)
        ho_full += info["handover"] * (queue >= config.buffer.q_max_bits)
        ended = bool(truncated.all())
    finish = getattr(controller, "finish", None)
    if finish is not None:
        finish(env)
    n = env.sim.n_steps
    return {
        "handovers": tot["handover"],
        "handovers_buffer_nonempty": ho_nonempty,  # decided with a non-empty buffer
        "handovers_buffer_full": ho_full,  # and with a full one
        "buffer_nonempty_pct": 100 * nonempty / decisions,
        "pingpongs": tot["pingpong"],  # within HandoverConfig.min_time_of_stay_s, the one window
        **{f"pingpongs_{w:g}s": tot[f"pingpong_{w:g}s"] for w in PINGPONG_WINDOWS_S},
        "minutes": np.full(n_flights, n * env.sim.dt / 60.0),
        "service_availability_pct": 100 * tot["available"] / n,
        "mean_buffer_kbit": tot["queue_bits"] / n / 1e3,
        "lost_data_kbit": tot["lost_bits"] / 1e3,
        "rsrp_violation_pct": 100 * tot["rsrp_violation"] / n,
        "rsrq_violation_pct": 100 * tot["rsrq_violation"] / n,
        "handover_failures": tot["hof"],
        "radio_link_failures": tot["rlf"],
        "outage_pct": 100 * tot["outage"] / n,
    }


def importance(ckpt, states: np.ndarray, seed: int = 0, groups: dict | None = None) -> dict[str, np.ndarray]:
    """Mean |contribution| per feature (deep_shap) on ``states``: ``margin`` to the margin over the runner-up (the
    paper's Figure 2 as the cards read it) and ``score`` to the chosen action's score; ``names`` the features (of
    the DQN with memory: its signals, each summed over its window), or with ``groups`` ({name: members}) each group summed per state in place of its members."""
    import xairl

    from .policy import uav_policy

    policy = uav_policy(ckpt)
    exp = xairl.explain(policy, states, background=policy.background(100, seed=seed + 7))
    exp = exp.by_signal() if policy.window else exp  # the DQN with memory: each signal over its window
    exp = exp.grouped(groups) if groups else exp
    return {
        "margin": np.abs(exp.margin()).mean(axis=0),
        "score": np.abs(exp.for_chosen()).mean(axis=0),
        "names": np.array(exp.feature_names),
    }


def ranked(imp: dict[str, np.ndarray], view: str = "margin") -> list[str]:
    """The names of :func:`importance`, most important first in ``view`` ('margin' or 'score')."""
    return [str(f) for f in imp["names"][np.argsort(-imp[view])]]


def rankings(ckpt, n_states: int, seed: int) -> dict[str, list[str]]:
    """Features by :func:`importance` on the DQN's own decision states of held-out flights, most important first."""
    from .policy import dqn_decision_states

    imp = importance(ckpt, dqn_decision_states(ckpt, n_states, seed), seed)
    return {view: ranked(imp, view) for view in ("margin", "score")}


def held_at(config: SimConfig, height_m: float, duration_s: float) -> SimConfig:
    """``config`` with every flight held at ``height_m`` (all its waypoints there) for ``duration_s``."""
    data = config.model_dump()
    data["flight"].update(altitude_m=(height_m, height_m), duration_s=duration_s)
    return SimConfig.model_validate(data)


def chm_rate_by_altitude(
    altitudes,
    config: SimConfig,
    n_flights: int = 40,
    duration_s: float = 60.0,
    seed: int = 0,
    sample_s: float | None = None,
) -> np.ndarray:
    """Conventional handovers per minute for flights held at each altitude (simulator); with ``sample_s`` CHM sees
    the measurements only that often, as CHM replayed on a real log does (calibration.band_rows)."""
    every = 1 if sample_s is None else max(1, int(round(sample_s / config.flight.dt_s)))
    rates = []
    for h in altitudes:
        m = run_flights(CHM(decision_every=every), held_at(config, h, duration_s), n_flights, seed)
        rates.append(float(np.mean(m["handovers"])) / (duration_s / 60.0))
    return np.array(rates)
