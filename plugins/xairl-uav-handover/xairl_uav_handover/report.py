"""The reference plugin's report (``xairl report --plugin uav-handover [-o real=PATH|ukm]``): Table I; with real
flights, the calibration against them (handover rates per altitude band, the buffer, sim vs real state quantiles),
open-loop agreement with the live network, and which of the paper's findings hold. xairl's report does the
explanations, figures (beeswarms sim vs real, importance, groups) and narration. Where real flights come from:
:func:`real_source` (``ukm``: ukm.py).
"""

from __future__ import annotations

import sys
from dataclasses import astuple
from pathlib import Path

import numpy as np
from pydantic import Field

import xairl
from xairl import Explanation, InputError

from .baselines import CHM, SAMRO, SAMROConfig
from .calibration import LOG_INTERVAL_S, agreement_rows, band_rows, outside, quantile_rows
from .evaluate import PAPER
from .features import FEATURES, GROUPS, SIGNALS
from .memory import controller, walk_states
from .policy import Checkpoint, dqn_decision_states, load_checkpoint, memory_of, uav_policy
from .report_figures import altitude_figure, frontier_section


def glance_caption(label: str, text: str, check) -> str:
    """A flight at a glance's caption: its summary, the verdict as every surface says it (verified, contradicted, or
    partly checked with its coverage) and what the summary's features carry of the importance, and leave out."""
    mark = check.status + (f" (coverage {100 * check.coverage:.0f} %)" if check.status == "partly checked" else "")
    said = f"; {check.account}" if check.account else ""
    return f"Flight at a glance: {label}. {text} [verdict: {mark}{said}]"


class UAVReportOptions(xairl.plugin.Options):
    """The UAV report's own settings (``-o key=value``)."""

    real: str | None = Field(
        None,
        description="folder of real flight exports (Nemo CSV) or a zip of them, e.g. "
        "../shared/data/ukm-uav-lte/raw; or 'ukm': the UKM flights "
        "($XAIRL_UKM_DATA, else the copy cached in the user data folder, else "
        "downloaded once; skipped with a note when they cannot be had)",
    )
    flights: int = Field(100, ge=1, le=10_000, description="held-out simulated flights for Table I")
    calibration_flights: int = Field(
        256,
        ge=8,
        le=10_000,
        description="simulated flights the real ones are compared with: the reference states (x1) and the handover "
        "rate at each altitude of the figure (5/32 of them, 40 by default); fewer make a quick, rougher report",
    )
    timelines: int = Field(
        2,
        ge=0,
        le=20,
        description="simulated flights shown at a glance (timeline and summary; with real data, its first flight too)",
    )
    checkpoint: str | None = Field(
        None,
        description="a DQN checkpoint to report on (default: the committed one); one trained with memory "
        "(issue 55) is explained per signal and time step",
    )
    frontier: str | None = Field(
        None,
        description="frontier.json written by benchmarks/oracle_frontier.py: adds the hindsight bound's figure "
        "(the frontier, 0.2-5 s of foresight, CHM, SA-MRO and the DQN on it)",
    )


def _table(rows: list) -> str:
    return xairl.plugin.table_html(type(rows[0]).HEADER, [list(astuple(r)) for r in rows])


def _identifier(policy: xairl.Policy, name: str) -> bool:
    """Whether ``policy`` declares feature ``name`` an identifier or a category: a label, not a quantity."""
    return getattr(policy.features.get(name), "kind", "numeric") in ("identifier", "categorical")


def _quantiles(rows: list, policy: xairl.Policy) -> str:
    """The quantile table with each value in its unit, as the narratives write it ('77.2 % full', '-85.8 dBm')."""
    return xairl.plugin.table_html(
        type(rows[0]).HEADER,
        [
            [r.feature, *(xairl.facts.value_text(v, policy.features.get(r.feature)) for v in astuple(r)[1:-1])]
            + [r.real_outside_pct]
            for r in rows
        ],
    )


def shown_path(path) -> str:
    """``path`` as a shared report may print it: relative to the working folder when inside it, else its name
    (an absolute path says where the author keeps files, and is wrong on every other machine)."""
    p = Path(path)
    try:
        return str(p.resolve().relative_to(Path.cwd().resolve()))
    except (ValueError, OSError):
        return p.name or str(p)


def same_as_chm(did: dict, where: str, cfg: SAMROConfig, why: str = "") -> str:
    """Why SA-MRO's figures equal CHM's on ``where``: its offsets start at CHM's and move only on the events it
    counts; ``did`` says what its network counted and did (:func:`calibration.mro_record`)."""
    c = did["counted"]
    events = (
        f"{c['too_early']} too-early, {c['too_late']} too-late and {c['wrong_cell']} wrong-cell handovers and "
        f"{c['pingpong']} ping-pongs"
    )
    updates = f"{did['updates']} update{'' if did['updates'] == 1 else 's'}"
    moved = (
        f"its offsets never left CHM's ({updates})"
        if did["largest_offset_db"] == 0
        else f"its offsets moved by at most {did['largest_offset_db']:g} dB ({updates}), which changed no decision"
    )
    return (
        f"SA-MRO's figures equal CHM's on {where}. SA-MRO is CHM's A3 rule ({cfg.offset_db:g} dB, "
        f"{1000 * cfg.ttt_s:g} ms) plus a per-cell-pair offset that its network moves only after too-early, "
        f"too-late or wrong-cell handovers and ping-pongs, at most once per {cfg.update_every_flights} flights' "
        f"time; it counted {events}, so {moved}.{why}"
    )


class UAVReport(xairl.plugin.Report):
    """Table I on held-out simulated flights; with ``real``, the calibration and agreement with real flights."""

    name = "uav-handover"
    Options = UAVReportOptions

    def build(self, req: xairl.plugin.ReportRequest) -> xairl.plugin.ReportContent:
        real, real_setting = real_source(self.options.real)
        with xairl.plugin.heartbeat("reading the real flights", req.progress and real is not None):
            loaded = _load_real(real) if real is not None else None  # a bad file is named before Table I's minutes
        ckpt = load_checkpoint(self.options.checkpoint)
        cfg = ckpt.sim_config
        policy = uav_policy(ckpt)
        sampled = min(64, max(req.n_states, 8))  # flights to draw the states from: about one a state, at most 64
        content = xairl.plugin.ReportContent(
            title="xairl report: UAV handover DQN (Meer et al.), calibrated reproduction",
            policy=policy,
            background=policy.background(100, seed=req.seed + 7),
            datasets=[("simulated", dqn_decision_states(ckpt, req.n_states, seed=req.seed + 1, n_flights=sampled))],
            tables=[],  # Table I is put first below, computed after the states are drawn (the steps said in order)
            settings={
                "checkpoint": ckpt.path.name,
                "training command": ckpt.meta.get("command"),
                "simulated states": req.n_states,
                "real data": real_setting,  # (a path as shown_path writes it: a report is shared)
                "video rate Mbit/s": cfg.buffer.video_rate_mbps,
                "x, y quantised to (m)": cfg.observation.position_grid_m or "not quantised",
            },
            template="handover",
            commentary=findings,
            notes=[
                "Simulated states: the DQN's own decision states on held-out flights (TR 36.777 UMa-AV, the "
                "calibrated link and load of config.py). Contributions are to the margin of the chosen action's "
                "Q-value over the runner-up's, in every figure, card and importance table (the main findings also "
                "rank by the chosen action's own Q-value); the background is 100 states after 10 s of flight under "
                "conventional handover.",
            ],
        )
        table_one, same = self._table_one(ckpt, req.seed)
        content.tables.insert(0, table_one)
        content.notes += same
        with xairl.plugin.heartbeat(
            "comparing with the real flights (calibration, agreement)", req.progress and loaded
        ):
            flights = self._add_real_flights(content, ckpt, req, real, *loaded) if loaded else []
        with xairl.plugin.heartbeat("simulating and explaining the flights at a glance", req.progress):
            self._add_timelines(content, ckpt, req, flights[:1])
        if self.options.frontier:
            content.figures.append(frontier_section(self.options.frontier, req.out))
        return content

    def _add_timelines(
        self, content: xairl.plugin.ReportContent, ckpt: Checkpoint, req: xairl.plugin.ReportRequest, real: list
    ) -> None:
        """A few flights at a glance: ``timelines`` simulated ones, and the ``real`` flights given."""
        from xairl import explain

        from .flight import narrate_flight, real_flight, simulated_flight, timeline_figure

        lines = [simulated_flight(ckpt, seed=req.seed + s) for s in range(self.options.timelines)]
        lines += [real_flight(f, ckpt, seed=req.seed) for f in real] if self.options.timelines else []
        for n, tl in enumerate(lines):
            exp = explain(content.policy, tl.states, background=content.background)
            text, check = narrate_flight(tl, exp, content.policy)
            path = timeline_figure(tl, exp, content.policy, Path(req.out) / f"flight_{n}.png")
            content.figures.append((glance_caption(tl.label, text, check), path))

    def _table_one(self, ckpt: Checkpoint, seed: int) -> tuple[tuple[str, str], list[str]]:
        """Table I with bootstrap 95 % intervals (table.py), and in words where the DQN loses to CHM; and a note
        when SA-MRO's column is CHM's (why)."""
        from .table import flights, html_table, verdict, with_intervals

        n, cfg = self.options.flights, ckpt.sim_config
        stay = cfg.handover.min_time_of_stay_s
        sa_mro = SAMRO(SAMROConfig(warmup_flights=n))  # the network adapts on as many flights as the table has
        with xairl.plugin.heartbeat(f"Table I: CHM, SA-MRO and the DQN on {n} simulated flight{'s' * (n != 1)}"):
            res = {c.name: with_intervals(flights(c, cfg, n, [seed])) for c in (CHM(), sa_mro, controller(ckpt))}
        paper = ", ".join(f"{name} {ho} handovers and {pp} % ping-pongs" for name, (ho, pp) in PAPER.items())
        same = []
        if res["SA-MRO"] == res["CHM"]:
            largest = float(np.abs(sa_mro.mro.cio).max())
            did = {"counted": sa_mro.mro.counted, "updates": sa_mro.updates, "largest_offset_db": largest}
            where = f"Table I's {2 * n} simulated flights ({n} to adapt on, then {n} held out)"
            same.append(same_as_chm(did, where, sa_mro.cfg))
        table = (
            f"Table I: {n} held-out simulated flights of {cfg.flight.duration_s:g} s (SA-MRO's offsets adapted on "
            f"{n} flights first), value [bootstrap 95 % interval]. {verdict(res, min_stay_s=stay)} (The paper's "
            f"medians per flight: {paper}.)",
            xairl.plugin.table_html(*html_table(res, stay)),
        )
        return table, same

    def _add_real_flights(
        self,
        content: xairl.plugin.ReportContent,
        ckpt: Checkpoint,
        req: xairl.plugin.ReportRequest,
        real: Path,
        flights: list,
        bad: list[str],
    ) -> list:
        """The calibration and agreement tables against the ``flights`` loaded from folder ``real`` (``bad``: why
        the others were skipped); returns the flights."""

        from .real_data import chm_handovers, walk

        cfg = ckpt.sim_config
        walks = [
            walk(f, cfg, seed=req.seed)
            for f in xairl.plugin.progress(flights, desc="real flights", disable=not req.progress)
        ]
        chm_real = [chm_handovers(f, sim_config=cfg) for f in flights]
        states = np.concatenate([w.states for w in walks])  # the walks' snapshot states
        if memory_of(ckpt.meta):  # the DQN's own states on the real flights: its windows
            seen = np.concatenate([walk_states(w, ckpt.sim_config) for w in walks])
        else:
            seen = states
        pick = np.random.default_rng(req.seed).choice(len(states), size=min(req.n_states, len(states)), replace=False)
        content.datasets.append(("real", seen[np.sort(pick)]))
        n_ref = self.options.calibration_flights
        names, states, sim_ref = _reference(ckpt, states, seen, req, n_ref)
        with xairl.plugin.heartbeat("simulating handovers per altitude band (calibration)", req.progress):
            bands = band_rows(flights, chm_real, cfg, req.seed, n_flights=8, duration_s=30.0)
        mro: dict = {}  # what SA-MRO's network counted and did on the real samples
        with xairl.plugin.heartbeat("replaying the real flights open-loop (agreement)", req.progress):
            agreeing = agreement_rows(walks, ckpt, cfg, mro)
        queue = np.concatenate([w.queue_bits for w in walks])
        where = f"{len(flights)} real flights from {shown_path(real)}" + (f" ({len(bad)} skipped)" if bad else "")
        keep = [j for j, f in enumerate(names) if not _identifier(content.policy, f)]  # an id has no percentiles
        content.tables += [
            (
                f"Calibration: handovers per minute by altitude band ({where})",
                _table(bands),
            ),
            (
                f"Real states in the training distribution: buffer full in {100 * np.mean(queue >= cfg.buffer.q_max_bits):.1f} "
                f"% of real states, non-empty in {100 * np.mean(queue > 0):.1f} %; any feature outside the simulated "
                f"0.5-99.5 % range in {100 * outside(states[:, keep], sim_ref[:, keep]).any(axis=1).mean():.1f} % of real states",
                _quantiles(quantile_rows(sim_ref[:, keep], states[:, keep], [names[j] for j in keep]), content.policy),
            ),
            (
                f"Open-loop agreement with the live network's decisions ({where})",
                _table(agreeing),
            ),
        ]
        content.notes += _why_samro_is_chm(agreeing, mro, cfg, len(flights))
        content.notes += [f"skipped file: {b.replace(str(real), shown_path(real))}" for b in bad] + REAL_NOTES
        with xairl.plugin.heartbeat("simulating handovers by altitude (the figure)", req.progress):
            content.figures.append(
                altitude_figure(req.out, str(real), cfg, flights, chm_real, req.seed, max(8, n_ref * 5 // 32))
            )
        return flights


def _load_real(real: Path) -> tuple[list, list[str]]:
    """The flights of folder ``real`` and why the others were skipped, said on stderr too (the report's notes list
    them all): a skipped file is never silent."""
    from .exports import load_folder

    flights, bad = load_folder(real)
    if bad:
        print(
            f"xairl: report: skipped {len(bad)} of {len(bad) + len(flights)} flight file(s) (listed in the "
            f"report's notes); first: {bad[0]}",
            file=sys.stderr,
        )
    return flights, bad


def real_source(real: str | None) -> tuple[Path | None, str]:
    """The folder of real flights for ``-o real=VALUE`` and the report's "real data" setting. A PATH is used as
    given (a zip extracted once; one that is neither is refused at once); ``ukm`` locates or fetches the UKM flights
    (ukm.py) and, when they cannot be had, prints one line to stderr and returns None with the reason."""
    from . import ukm

    if real is None:
        return None, f"not given (-o real=PATH, or -o real={ukm.KEYWORD} to fetch the UKM flights)"
    if real.strip().lower() != ukm.KEYWORD:
        folder = ukm.flights_folder(real)
        if not folder.is_dir():  # before Table I's minutes are spent
            raise InputError(
                f"-o real={real}: no such folder or zip of flight exports; give the folder of the "
                f"Nemo CSVs, the UKM zip, or -o real={ukm.KEYWORD} to fetch the UKM flights."
            )
        return folder, shown_path(real)
    try:
        folder = ukm.flights_folder()
    except InputError as exc:
        print(f"xairl: report: real-data half skipped: {exc}", file=sys.stderr)
        return None, f"not available: {exc}"
    return (
        folder,
        f"{shown_path(folder)} (-o real={ukm.KEYWORD}: UKM flights, {ukm.LICENCE}, {ukm.REPO} at {ukm.COMMIT[:12]})",
    )


REAL_NOTES = [
    "Real states are built like simulated ones: the same layout, the same detection limit for neighbours (an empty "
    "slot reads as a cell at the limit) and the same position frame (metres east and north of the centre of the "
    "area flown: the grid's centre site in simulation, the campaign area's centre for the UKM flights). That frame "
    "places real flights inside the simulated area, but the simulator's BS layout is not the real network's, so "
    "position carries no transferable meaning about cells.",
    "The buffer is not in the data: the simulator's uplink model, driven by the measured serving RSRP at the "
    "flight's altitude, fills it (uplink.py); each real cell's uplink interference level is drawn as the simulator "
    "draws one per cell and flight, so the real buffer carries the same kind of information as the simulated one.",
    "Open-loop proposals: a proposal the network does not carry out stands at every later sample until the policy "
    "changes its mind; 'new HO proposals' counts it once (as A3 counts one trigger), the column before counts "
    "every sample at which one stands.",
    "Open loop: at every real sample each policy proposes an action for the state the network's own choices led "
    "to; nothing is steered, so every instant compares like with like. CHM and SA-MRO restart their timers when "
    "the network hands over.",
]


def findings(exps: dict[str, Explanation]) -> list[str]:
    """Which of the paper's findings hold here, read off the explanations (mean |contribution to the margin|, and to
    the chosen action's score), and why where they do not."""
    out = []
    for label, exp in exps.items():
        exp = exp.by_signal() if exp.observation and exp.observation["kind"] == "window" else exp  # (with memory)
        grouped = exp.grouped({"position": GROUPS["position"]})
        imp = np.abs(grouped.margin()).mean(axis=0)
        order = [grouped.feature_names[j] for j in np.argsort(-imp)]
        by_score = [grouped.feature_names[j] for j in np.argsort(-np.abs(grouped.for_chosen()).mean(axis=0))]
        buf, pos = order.index("buffer_queue_size") + 1, order.index("position") + 1
        buf_score = by_score.index("buffer_queue_size") + 1
        holds = "holds" if buf == 1 and pos == 2 else "does not hold"
        why = (
            ""
            if buf == 1
            else f" The buffer {'leads' if buf_score == 1 else 'does not lead'} the chosen action's score: it "
            f"weighs whether to act; which way the decision goes against the runner-up is decided by "
            f"{', '.join(order[:2])}."
        )
        out.append(
            f"Paper's Figure 2 finding (buffer first, position second) {holds} on the {label} states: by mean "
            f"|contribution to the margin over the runner-up| the buffer ranks {buf} and position (x, y, z) {pos}; "
            f"the top three are {', '.join(order[:3])}. By mean |contribution to the chosen action's score| the "
            f"buffer ranks {buf_score} and position {by_score.index('position') + 1}.{why}"
        )
    return out


def _reference(ckpt: Checkpoint, states, seen, req, n_ref: int) -> tuple:
    """(feature names, the real states, the simulated reference states) compared in the in-distribution table, from
    ``n_ref`` simulated flights."""
    with xairl.plugin.heartbeat(
        f"simulating {n_ref} flights: the states the real ones are compared with", req.progress
    ):
        if memory_of(ckpt.meta):  # the newest step, times included, against the greedy DQN's own states: a time on
            # the cell grows as the DQN stays, so only its own decisions compare like with like
            ref = dqn_decision_states(ckpt, 5000, seed=req.seed + 2, n_flights=n_ref)
            return SIGNALS, seen[:, -len(SIGNALS) :], ref[:, -len(SIGNALS) :]
        # the mix of exploration and greedy steps that training sees
        return FEATURES, states, dqn_decision_states(ckpt, 5000, seed=req.seed + 2, epsilon=0.5, n_flights=n_ref)


def _why_samro_is_chm(agreeing: list, mro: dict, cfg, n_flights: int) -> list[str]:
    """The note saying why SA-MRO's open-loop row equals CHM's, when it does (from what its network counted)."""
    by = {r.policy.split(" ")[0]: astuple(r)[1:] for r in agreeing}
    if by["CHM"] != by["SA-MRO"]:
        return []
    why = (
        " On real samples a failure comes only from the modelled uplink (the logs record none), and a return within "
        f"the {cfg.handover.min_time_of_stay_s:g} s minimum time of stay cannot show between samples "
        f"{LOG_INTERVAL_S:g} s apart (the logs' median)."
    )
    return [same_as_chm(mro, f"the {n_flights} real flights' samples", SAMROConfig(), why)]
