"""Run controllers on the same held-out flights and summarise them as the paper's Table I."""
from __future__ import annotations

import numpy as np

from .config import SimConfig
from .env import METRICS, PINGPONG_WINDOWS_S, HandoverVecEnv
from .features import FEATURES

BUFFER = FEATURES.index("buffer_queue_size")

#: seeds of evaluation flights start here; training flights use seeds below it (see train.py)
HELD_OUT_SEED = 1_000_000
#: the paper's Table I (median per flight): handovers, ping-pong %
PAPER = {"CHM": (75, 40), "SA-MRO": (32, 27), "DQN": (12, 14)}


def run_flights(controller, config: SimConfig, n_flights: int, seed: int) -> dict[str, np.ndarray]:
    """Fly ``n_flights`` held-out flights (all at once, through :class:`HandoverVecEnv`) under ``controller``;
    per-flight metrics as arrays of shape (n_flights,)."""
    env = HandoverVecEnv(config, n_flights, decision_every=controller.decision_every)
    env.reset(seed=HELD_OUT_SEED + seed)
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
    n = env.sim.n_steps
    return {
        "handovers": tot["handover"],
        "handovers_buffer_nonempty": ho_nonempty,   # decided with a non-empty buffer
        "handovers_buffer_full": ho_full,           # and with a full one
        "buffer_nonempty_pct": 100 * nonempty / decisions,
        "pingpongs": tot["pingpong"],
        **{f"pingpongs_{w:g}s": tot[f"pingpong_{w:g}s"] for w in PINGPONG_WINDOWS_S},
        "minutes": np.full(n_flights, n * env.sim.dt / 60.0),
        "service_availability_pct": 100 * tot["available"] / n,
        "mean_buffer_kbit": tot["queue_bits"] / n / 1e3,
        "lost_data_kbit": tot["lost_bits"] / 1e3,
        "rsrp_violation_pct": 100 * tot["rsrp_violation"] / n,
        "rsrq_violation_pct": 100 * tot["rsrq_violation"] / n,
    }


def summarise(m: dict[str, np.ndarray]) -> dict[str, float]:
    """Table I row: medians per flight for handovers and ping-pong share (as the paper), the mean handovers per flight
    (a median of a few handovers per flight moves in whole steps), pooled ping-pong share
    (all ping-pongs / all handovers), mean ping-pong share over flights with a handover, and means per flight for
    the rest (``buffer_nonempty_pct``: share of decision states with a non-empty buffer)."""
    pp_share = 100 * m["pingpongs"] / np.maximum(m["handovers"], 1)
    handed = m["handovers"] > 0
    row = {"handovers_median": float(np.median(m["handovers"])), "handovers_mean": float(np.mean(m["handovers"])),
           "pingpong_pct_median": float(np.median(pp_share)),
           "pingpong_pct_pooled": float(100 * m["pingpongs"].sum() / max(m["handovers"].sum(), 1)),
           "pingpong_pct_mean": float(pp_share[handed].mean()) if handed.any() else 0.0}
    for key in ("service_availability_pct", "mean_buffer_kbit", "buffer_nonempty_pct", "lost_data_kbit",
                "rsrp_violation_pct", "rsrq_violation_pct"):
        row[f"{key}_mean"] = float(np.mean(m[key]))
    return row


def table_one(controllers, config: SimConfig, n_flights: int, seed: int) -> dict[str, dict[str, float]]:
    """{policy name: Table I row} with every controller flying the same held-out flights."""
    return {c.name: summarise(run_flights(c, config, n_flights, seed)) for c in controllers}


def format_table(rows: dict[str, dict[str, float]], config: SimConfig, n_flights: int) -> str:
    cols = [("handovers_median", "HO/flight", "{:.1f}"), ("handovers_mean", "HO (mean)", "{:.2f}"),
            ("pingpong_pct_median", "PP % (med)", "{:.1f}"),
            ("pingpong_pct_pooled", "PP % (pool)", "{:.1f}"), ("pingpong_pct_mean", "PP % (mean)", "{:.1f}"),
            ("service_availability_pct_mean", "SA %", "{:.2f}"), ("mean_buffer_kbit_mean", "buffer kbit", "{:.1f}"),
            ("buffer_nonempty_pct_mean", "buf>0 %", "{:.1f}"), ("lost_data_kbit_mean", "lost kbit", "{:.1f}"),
            ("rsrp_violation_pct_mean", "RSRP<thr %", "{:.1f}"), ("rsrq_violation_pct_mean", "RSRQ<thr %", "{:.1f}")]
    f = config.flight
    lines = [f"Table I on {n_flights} held-out flights of {f.duration_s:g} s (dt {f.dt_s * 1000:g} ms); ping-pong: "
             f"back to the previous BS within {config.handover.min_time_of_stay_s:g} s (minimum time of stay)",
             f"{'policy':<8}" + "".join(f"{name:>13}" for _, name, _ in cols) + f"{'paper HO / PP %':>18}"]
    for policy, row in rows.items():
        paper = PAPER.get(policy)
        lines.append(f"{policy:<8}" + "".join(f"{fmt.format(row[key]):>13}" for key, _, fmt in cols)
                     + (f"{paper[0]:>12} / {paper[1]}" if paper else ""))
    return "\n".join(lines)


def margin_ranking(ckpt, n_states: int, seed: int) -> list[str]:
    """Features by mean |contribution to the margin over the runner-up| (deep_shap) on the DQN's own decision states
    of held-out flights, most important first (the reproduction's check of the paper's Figure 2)."""
    import xairl

    from .policy import background_states, dqn_decision_states, uav_policy

    exp = xairl.explain(uav_policy(ckpt), dqn_decision_states(ckpt, n_states, seed),
                        background=background_states(100, seed=seed + 7, config=ckpt.sim_config))
    return [FEATURES[j] for j in np.argsort(-np.abs(exp.margin()).mean(axis=0))]


def chm_rate_by_altitude(altitudes, config: SimConfig, n_flights: int = 40, duration_s: float = 60.0,
                         seed: int = 0) -> np.ndarray:
    """Conventional handovers per minute for flights held at each altitude (simulator)."""
    from .baselines import CHM

    rates = []
    for h in altitudes:
        data = config.model_dump()
        data["flight"].update(altitude_m=(h, h), duration_s=duration_s)
        m = run_flights(CHM(), SimConfig.model_validate(data), n_flights, seed)
        rates.append(float(np.mean(m["handovers"])) / (duration_s / 60.0))
    return np.array(rates)
