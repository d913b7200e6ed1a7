"""``xairl report --plugin NAME --out DIR``: explanations, figures, narrated decisions, one self-contained HTML.

A plugin's :class:`Report` (hook ``register_reports``) declares its own options and supplies the policy, the
datasets to explain, a background, and its own tables and figures (:class:`ReportContent`); this module does the
rest the same way for every plugin (:func:`write_report`).
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import ClassVar

import numpy as np

from xairl.explanations.evidence import evidence
from xairl.explanations.explanation import Explanation
from xairl.explanations.explanation_io import StateRecord
from xairl.options import Options, parse_options
from xairl.outputs import report_counterfactuals as cfs
from xairl.outputs.report_html import page, table_html
from xairl.policies.policy import Policy
from xairl.policies.regions import in_regions
from xairl.policies.windows import window_of
from xairl.runs.files import atomic_write, write_text
from xairl.values import state_value_text

#: an image's report lists this many regions by importance (its cards list every region, sorted)
TOP_REGIONS = 20
REGIONS_ARE = (
    "regions (patches of one channel or frame on a grid: letters count columns, numbers rows, from the "
    "top left; the pixels each covers beside it, counted from 0)"
)


@dataclass
class ReportRequest:
    """What the user asked of any report (the plugin's own settings are its :attr:`Report.Options`).

    :param out: the folder written. ``method`` and ``options``: the attributor and its validated options.
    :param narrate: narrate ``n_narrated`` decisions and a global summary with ``narrator`` and ``template``;
        ``robustness``: include the confidence's agreement and stability (three extra explanations per decision).
    :param seed: seed of everything the plugin samples; ``n_states``: states per dataset.
    """

    out: Path
    method: str = "deep_shap"
    options: dict = field(default_factory=dict)
    narrate: bool = True
    narrator: str = "template"
    narrator_options: dict = field(default_factory=dict)
    template: str | None = None
    prompt_dirs: list = field(default_factory=list)
    seed: int = 0
    n_states: int = 500
    n_narrated: int = 6
    robustness: bool = True
    progress: bool = True
    records: bool = True  # write explanations.jsonl (False when the explanations are already written as Parquet)
    counterfactuals: bool = True  # cards: 'What would have changed it'; the run: each feature's single flips
    counterfactual_target: str | int | None = None  # the cards' target: the runner-up (None), an action or 'any'
    max_changes: int = 2  # the cards' counterfactuals change at most this many features


@dataclass
class ReportContent:
    """What a plugin's report supplies: the policy, a background, the datasets to explain, and its own parts.

    :param datasets: (label, states) pairs; the first is the reference for feature order and narrated decisions.
    :param tables: (title, HTML) pairs, e.g. from :func:`table_html`; ``figures`` (caption, PNG path) pairs.
    :param notes: sentences listed at the end; ``settings`` extra rows of the settings table.
    :param template: the decision template narrated by default (None: 'explain_action' for discrete actions,
        'explain_output' for a value or a continuous action).
    :param commentary: optional ``f({label: Explanation}) -> [sentence, ...]``, called once the datasets are
        explained: the plugin's reading of the explanations (e.g. which of a paper's findings hold), the page's
        main findings, shown first.
    """

    title: str
    policy: Policy
    background: np.ndarray
    datasets: list[tuple[str, np.ndarray]]  # (label, states); the first is the reference for feature order
    tables: list[tuple[str, str]] = field(default_factory=list)  # (title, html table)
    figures: list[tuple[str, Path]] = field(default_factory=list)  # (caption, png)
    notes: list[str] = field(default_factory=list)
    settings: dict = field(default_factory=dict)
    template: str | None = None  # None: the default for the policy's output kind
    commentary: Callable[[dict[str, Explanation]], list[str]] | None = None


class Report:
    """A plugin's report: subclasses set ``Options`` (their own settings, ``xairl report -o key=value``) and
    implement :meth:`build`. Registered through the ``register_reports`` hook.

    :param options: a dict or an instance of ``Options``; unknown keys are an error.
    """

    name: ClassVar[str] = ""
    Options: ClassVar[type[Options]] = Options

    def __init__(self, options: dict | Options | None = None):
        self.options = parse_options(self.Options, options, f"{self.name or 'report'} report options")

    def build(self, request: ReportRequest) -> ReportContent:
        """The plugin's content for ``request`` (figures it draws go into ``request.out``)."""
        raise NotImplementedError


def importance_table(
    exps: list[tuple[str, Explanation]], top: int | None = None, what: str = "features"
) -> tuple[str, str]:
    """Each feature's rank by mean |contribution| in the margin view (:func:`xairl.plots.view_label`: to the margin
    over the runner-up for discrete actions, as the narratives and figures rank them) per dataset (the ``top`` first
    only, when given), and the Spearman rank correlation of every dataset's global importance with the first's."""
    from xairl.plots import view_label

    imp = [np.abs(e.contributions("margin")[0]).mean(axis=0) for _, e in exps]
    ranks = [np.argsort(np.argsort(-v)) + 1 for v in imp]
    names = exps[0][1].feature_names
    extents = (exps[0][1].extras or {}).get("regions")  # an image's regions: the pixels each grid name covers
    extents = extents if isinstance(extents, dict) and any(f in extents for f in names) else None
    rows = [
        [f, *([str(extents.get(f, ""))] if extents else []), *[int(r[j]) for r in ranks], *[float(v[j]) for v in imp]]
        for j, f in sorted(enumerate(names), key=lambda t: ranks[0][t[0]])
    ][:top]
    rhos = [float(_spearman(imp[0], v)) for v in imp[1:]]
    named = view_label(exps[0][1])
    title = (
        "Global importance by dataset"
        if len(rows) == len(names)
        else f"The {len(rows)} most important of {len(names)} {what} ({exps[0][0]})"
    )
    title += f", by mean |{named}|" + "".join(
        f"; Spearman rank correlation {label} vs {exps[0][0]}: {rho:.2f}" for (label, _), rho in zip(exps[1:], rhos)
    )
    header = [
        "feature",
        *(["pixels"] if extents else []),
        *[f"rank ({label})" for label, _ in exps],
        *[f"mean |{named}| ({label})" for label, _ in exps],
    ]
    return title, table_html(header, rows)


def _spearman(a: np.ndarray, b: np.ndarray) -> float:
    from scipy.stats import spearmanr  # seconds to import: only for a report of several datasets

    return spearmanr(a, b).statistic


def _figures(
    exps: list[tuple[str, Explanation]], pick: int, groups: dict, out: Path, policy: Policy | None = None
) -> list[tuple[str, Path]]:
    """The report's figures, all in the margin view (the narratives' and the cards'; the first output when nothing
    is chosen), each captioned with what its contributions add up to. Images are plotted in the regions their
    narratives name and dicts by key (thousands of pixels are no beeswarm); the image plot shows the pixels. The
    waterfall writes values in their units (``policy``'s features)."""
    from xairl import plots

    (ref_label, ref), decides = exps[0], exps[0][1].output == "actions"
    shown = [(label, plots.readable(e)) for label, e in exps]
    target = plots.view_label(ref)
    what = f"{ref_label} state {pick}" + (f": {ref.action_names[ref.chosen[pick]]}" if decides else "")
    figures = [
        (
            (
                f"SHAP values, {target}: {' vs '.join(label for label, _ in exps)} (same feature order, by {ref_label} "
                "importance)"
            ),
            plots.save(plots.beeswarm(shown, policy=policy), out / "beeswarm.png"),
        ),
        (f"Global importance: mean |{target}|", plots.save(plots.importance(shown), out / "importance.png")),
        (
            f"One {'decision' if decides else 'state'} ({what}): {target}{', as in its card' if decides else ''}",
            plots.save(plots.waterfall(shown[0][1], pick, policy=policy), out / "waterfall.png"),
        ),
    ]
    if ref.image_shape is not None:
        figures.append(
            (
                (
                    f"Contributions over the frame ({ref_label} state {pick}; {target}; red raises it, blue "
                    "lowers it; summed over channels)"
                ),
                plots.save(plots.image(ref, pick), out / "image.png"),
            )
        )
    for label, e in [(lb, x) for lb, x in exps if window_of(x) is not None]:  # which signals, which moments
        figures.append(
            (
                f"Signals over the window ({label} states): mean |{target}| per signal and time step",
                plots.save(plots.window_heatmap(e), out / f"window_{len(figures)}.png"),
            )
        )
    if groups:
        figures.append(
            (
                (
                    f"Global importance by group, mean |{target}| "
                    f"({'; '.join(g + ' = ' + ', '.join(m) for g, m in groups.items())})"
                ),
                plots.save(
                    plots.importance([(label, e.grouped(groups)) for label, e in exps]), out / "importance_groups.png"
                ),
            )
        )
    return figures


def _interesting(exp: Explanation) -> int:
    """A decision worth a waterfall: the first whose action is not the most common one, else the closest call; among
    the decisions that had a choice (a runner-up other than the action: a mask may leave one action), when any did."""
    idx = np.arange(len(exp.values))
    chose = idx[exp.runner_up != exp.chosen] if exp.output == "actions" else idx
    chose = chose if len(chose) else idx
    common = np.bincount(exp.chosen[chose]).argmax()
    rare = chose[exp.chosen[chose] != common]
    if len(rare):
        return int(rare[0])
    if exp.output != "actions":
        return 0
    gap = exp.outputs[chose, exp.chosen[chose]] - exp.outputs[chose, exp.runner_up[chose]]
    return int(chose[np.argmin(gap)])


def write_report(req: ReportRequest, content: ReportContent, explained: dict[str, Explanation] | None = None) -> Path:
    """Write explanations.jsonl (+ its JSON schema), PNG figures and report.html into ``req.out``.

    :param explained: explanations already computed, by dataset label (the others are explained here).
    """
    from xairl.explanations.display import heartbeat

    t0 = time.time()
    out = Path(req.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "report.html").unlink(missing_ok=True)  # a failed re-run must not leave the last run's report beside it
    exps = _explain_datasets(req, content, explained or {})
    if req.records:
        _write_records(out, exps)
    ref = exps[0][1]
    pick = _interesting(ref)
    with heartbeat("drawing the figures", req.progress):
        figures = _figures(exps, pick, dict(content.policy.groups), out, content.policy) + list(content.figures)
    # an image's importance by region (the top ones), not by pixel; its narratives' cards list regions too
    regioned = [(label, in_regions(e)) for label, e in exps]
    image = regioned[0][1] is not ref
    tables = list(content.tables) + (
        [importance_table(regioned, TOP_REGIONS, REGIONS_ARE) if image else importance_table(exps)]
        if len(exps) > 1 or image
        else []
    )
    findings = content.commentary({label: e for label, e in exps}) if content.commentary else []
    notes = list(content.notes)
    if req.counterfactuals and cfs.shown(content.policy, ref):  # the run's distance to another action, by feature
        title, header, rows, sentence = cfs.flip_rows(content.policy, ref, content.background)
        tables.append((title, table_html(header, rows)))
        notes.append(sentence)
    with heartbeat(f"narrating {min(req.n_narrated, len(ref.values))} decisions", req.progress and req.narrate):
        narratives = _narratives(req, content, ref, regioned[0][1], pick) if req.narrate else []
    settings = {
        "method": req.method,
        "options": req.options,
        "narrator": req.narrator,
        "seed": req.seed,
        "background states": len(content.background),
        "seconds to explain, plot and narrate": round(time.time() - t0, 1),
        **content.settings,
    }
    path = out / "report.html"
    write_text(
        path,
        page(
            content.title,
            findings=findings,
            tables=tables,
            notes=notes,
            exps=exps,
            figures=figures,
            narratives=narratives,
            settings=settings,
        ),
    )
    return path


def _explain_datasets(req: ReportRequest, content: ReportContent, explained: dict) -> list[tuple[str, Explanation]]:
    """(label, explanation) of each dataset: the ones in ``explained`` as given, the others explained here."""
    from xairl.attributors import explain
    from xairl.explanations.display import heartbeat, progress

    exps = []
    bar = progress(content.datasets, desc=f"explaining ({req.method})", disable=not req.progress)
    for label, states in bar:  # a bar of a few steps: a long one also said every 10 s
        said = req.progress and label not in explained
        with heartbeat(f"explaining ({req.method}) {len(states)} {label} states", said):
            exp = explained.get(label) or explain(
                content.policy, states, background=content.background, method=req.method, options=req.options
            )
        exps.append((label, exp))
    return exps


def _write_records(out: Path, exps: list[tuple[str, Explanation]]) -> None:
    """explanations.jsonl (one StateRecord a state, by dataset) and its JSON schema."""
    with atomic_write(out / "explanations.jsonl") as fh:
        for label, exp in exps:
            for rec in exp.records(dataset=label):
                fh.write(rec.model_dump_json() + "\n")
    write_text(out / "explanations.schema.json", json.dumps(StateRecord.model_json_schema(), indent=2))


def _narratives(req: ReportRequest, content: ReportContent, ref: Explanation, shown: Explanation, pick: int) -> list:
    """(narrative, evidence) for narrated decisions of the reference dataset (``pick`` first), its global summary
    and, with groups, the summary with each group as one reason; the evidence is of ``shown`` (``ref`` in regions,
    for an image: what the narratives speak of)."""
    from xairl.explanations.display import progress
    from xairl.narrators import narrate

    idx = [pick] + [i for i in range(len(ref.values)) if i != pick][: max(req.n_narrated - 1, 0)]
    on = req.counterfactuals and cfs.shown(content.policy, ref)
    ask = (req.counterfactual_target, req.max_changes)
    found = cfs.decisions(content.policy, ref, idx, content.background, *ask) if on else {}
    out = [
        narrate(
            ref,
            i,
            narrator=req.narrator,
            template=req.template or content.template,
            policy=content.policy,
            background=content.background,
            options=req.narrator_options,
            prompt_dirs=req.prompt_dirs,
            robustness=req.robustness,
            **({"counterfactual": found[i]} if i in found else {}),  # its sentence, checked by a re-run
        )
        for i in progress(idx, desc=f"narrating ({req.narrator})", disable=not req.progress)
    ]
    out.append(narrate(ref, None, policy=content.policy, prompt_dirs=req.prompt_dirs))
    texts = partial(state_value_text, shown, policy=content.policy)  # values in their units, as the words say them
    pairs = [(n, n.evidence if n.evidence is not None else evidence(shown, n, texts)) for n in out]  # its regions
    cfs.attach(pairs, found, content.policy)
    if content.policy.groups:
        grouped = ref.grouped(dict(content.policy.groups))
        n = narrate(grouped, None, policy=content.policy, prompt_dirs=req.prompt_dirs)
        pairs.append((n, evidence(grouped, n, partial(state_value_text, grouped, policy=content.policy))))
    return pairs
