"""The reference plugin's report: Table I, the DQN and CHM replayed on real flights, handover rate vs altitude."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from xairl.report import ReportContent, ReportRequest, table_html

from .baselines import CHM, SAMRO
from .config import SimConfig
from .evaluate import PAPER, chm_rate_by_altitude, table_one
from .policy import DEFAULT_CHECKPOINT, DQNController, background_states, load_checkpoint, uav_policy

PP_WINDOWS = (1.0, 5.0)


def _a3(state, candidates, offset_db=2.0):
    """CHM on a real flight: samples are ~1.3 s apart, longer than the 160 ms TTT, so A3 at one sample triggers."""
    best = int(np.argmax(state[5:9]))
    return best if best and state[5 + best] > state[5] + offset_db else 0


def build(req: ReportRequest) -> ReportContent:
    import torch
    from tqdm import tqdm

    policy = uav_policy()
    net, meta = load_checkpoint(DEFAULT_CHECKPOINT)
    cfg = SimConfig.model_validate(meta["sim_config"])
    rows = table_one([CHM(), SAMRO(), DQNController(net)], cfg, 100, req.seed)
    table = table_html(["policy", "HO/flight (median)", "ping-pong % (median)", "ping-pong % (pooled)",
                        "service availability %", "mean buffer kbit", "lost kbit", "RSRQ<thr %", "paper HO / PP %"],
                       [[name, r["handovers_median"], r["pingpong_pct_median"], r["pingpong_pct_pooled"],
                         r["service_availability_pct_mean"], r["mean_buffer_kbit_mean"], r["lost_data_kbit_mean"],
                         r["rsrq_violation_pct_mean"], "%d / %d" % PAPER[name]] for name, r in rows.items()])
    content = ReportContent(
        title="xairl report: UAV handover DQN (Meer et al.)", policy=policy,
        background=background_states(100, seed=req.seed + 7, config=cfg),
        datasets=[("simulated", background_states(req.n_states, seed=req.seed + 1, config=cfg))],
        tables=[(f"Table I: 100 held-out simulated flights of {cfg.flight.duration_s:g} s (ping-pong window "
                 f"{cfg.handover.min_time_of_stay_s:g} s)", table)],
        settings={"checkpoint": DEFAULT_CHECKPOINT.name, "training command": meta.get("command"),
                  "simulated states": req.n_states, "real data": req.real or "not given (--real PATH)"},
        template="handover",
        notes=["Simulated states: UAVs after 10 s of flight under conventional handover (TR 36.777 UMa-AV).",
               "Contributions are to the chosen action's Q-value; the background is 100 simulated states."])
    if req.real:
        from .real_data import load_folder, replay

        flights, bad = load_folder(req.real)
        dqn = lambda s, c: int(net(torch.as_tensor(s)[None]).argmax())  # noqa: E731
        stats = {name: [] for name in ("network (observed)", "DQN", "CHM (A3 2 dB)")}
        real_states = []
        for f in tqdm(flights, desc="replaying real flights", disable=not req.progress):
            for name, decide in zip(stats, (None, dqn, _a3)):
                run = replay(f, decide, cfg, seed=req.seed)
                stats[name].append((run.handovers, *(run.pingpongs(w) for w in PP_WINDOWS), run.forced,
                                    run.mean_buffer_kbit, f.t[-1] / 60))
                if decide is None:
                    real_states.append(run.states)
        states = np.concatenate(real_states)
        pick = np.random.default_rng(req.seed).choice(len(states), size=min(req.n_states, len(states)), replace=False)
        content.datasets.append(("real", states[np.sort(pick)]))
        trows = []
        for name, s in stats.items():
            a = np.array(s, dtype=float)
            trows.append([name, float(np.median(a[:, 0])), float(a[:, 0].sum() / a[:, 5].sum()),
                          100 * a[:, 1].sum() / max(a[:, 0].sum(), 1), 100 * a[:, 2].sum() / max(a[:, 0].sum(), 1),
                          int(a[:, 3].sum()), float(a[:, 4].mean())])
        content.tables.append((f"Real flights: {len(flights)} loaded from {req.real}" + (f", {len(bad)} skipped"
                                                                                         if bad else ""),
                               table_html(["decisions by", "HO/flight (median)", "HO/min", "ping-pong % (1 s)",
                                           "ping-pong % (5 s)", "forced (cell vanished)", "mean buffer kbit"], trows)))
        content.notes += [f"skipped file: {b}" for b in bad]
        content.notes += [
            "Real data: the buffer is not in the data; the real link quality (RS SNR) drives the plugin's buffer "
            "model along the real trajectory. Ping-pong at 1 s is shown as configured, but samples are ~1.3 s apart, "
            "so the 5 s window is the informative one here.",
            "The DQN and CHM rows replay each policy in closed loop on the real measurements; a policy whose cell "
            "is no longer measured falls back to the strongest measured cell (forced).",
            f"Sim-to-real gap: the DQN makes {trows[1][1] / max(trows[0][1], 1):.1f}x the network's handovers on the "
            "real flights. Its inputs are out of distribution there (real RSRP ~20 dB lower, saturated buffer, "
            "positions and BS ids of another network), and its decisions lean on absolute position, which encodes "
            "the simulator's BS layout. Read the real-data SHAP values as how this policy reacts to real conditions, "
            "not as a validated controller."]
        content.figures.append(_altitude_figure(req, cfg, flights))
    return content


def _altitude_figure(req, cfg, flights) -> tuple[str, Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .real_data import baltaci_rate_by_altitude

    alts = np.arange(30, 151, 20)
    sim = chm_rate_by_altitude(alts, cfg, seed=req.seed)
    fig, ax = plt.subplots(figsize=(7.5, 4.5))
    ax.plot(alts, sim, "o-", label="simulator, CHM (A3 2 dB / 160 ms)")
    ukm = sorted((f.altitude_m, f.observed_handovers / (f.t[-1] / 60)) for f in flights if f.t[-1] > 60)
    ax.plot(*zip(*ukm), "s", label="UKM flights, live network (nominal height)")
    baltaci = next((p / "baltaci-imc22-handovers" for p in Path(req.real).resolve().parents
                    if (p / "baltaci-imc22-handovers" / "handovers.csv").is_file()), None)
    caption = "Handover rate vs altitude"
    if baltaci is not None:
        bins, rate, n = baltaci_rate_by_altitude(baltaci)
        ax.plot(bins + 5, rate, "^-", label=f"Baltaci et al. IMC'22 flights ({n} handovers, per modem)")
        caption += f" (Baltaci et al. data: {baltaci})"
    ax.set_xlabel("height (m)")
    ax.set_ylabel("handovers per minute")
    ax.legend(fontsize=8)
    fig.tight_layout()
    path = Path(req.out) / "handover_rate_vs_altitude.png"
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return caption, path
