"""Figures of explanations, with matplotlib: each function returns a ``matplotlib.figure.Figure`` (shown inline
in a notebook; :func:`save` writes it atomically). Nothing here imports shap.

Every figure about a decision says what its contributions add up to (its ``view``): ``"margin"`` (default for
discrete actions) is the chosen action's score minus the runner-up's, the view of the narratives and the evidence
cards, why this action and not the next best; ``"score"`` is the chosen action's own score (Q-value or logit).
Policies without a choice (values, continuous actions) show their first output. Every figure names its view in
an axis label or title (:func:`view_label`), and writes a feature's value as the narratives do, in its unit
(``policy=``: '100 % full', '-85.3 dBm').

    >>> from xairl import plots
    >>> plots.beeswarm(exp)                      # every state, the strongest features
    >>> plots.waterfall(exp, index=3)            # one decision, from the expected margin to this one
    >>> plots.save(plots.image(exp, 0), "frame.png")
"""

from __future__ import annotations

import textwrap
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from xairl.explanations.explanation import Explanation
from xairl.facts import state_value_text
from xairl.policies.regions import in_regions
from xairl.policies.windows import window_of
from xairl.runs.files import save_figure

#: figures are laid out and saved at this many dots per inch
DPI = 90
#: more features than this are plotted in groups (image patches, dict keys) or only the strongest are shown
MAX_SHOWN = 40
#: a plot's axes are never narrower than this (inches), however long the feature names beside them
MIN_AXES_WIDTH = 4.5
#: the actions' marks in a timeline: markers and a palette of their own, none of the features' line colours (tab10)
ACTION_MARKERS = "osD^vP*Xph"
ACTION_COLOURS = ("#000000", "#8c6d31", "#7b4173", "#637939", "#3182bd", "#e6550d", "#843c39", "#5254a3")
#: an Explanation, or titled explanations side by side: ``[("simulated", e1), ("real", e2)]``
Panels = Explanation | Sequence[tuple[str, Explanation]]


def _figure(**kwargs):
    """A Figure of its own, outside pyplot: no backend is chosen or changed, nothing stays open; a notebook shows
    the returned Figure, and :func:`save` renders it with Agg (the canvas attached here, to measure text)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(**{"dpi": DPI, **kwargs})  # laid out at the dpi it is saved with: text measures as written
    FigureCanvasAgg(fig)
    return fig


def _layout(fig, axes, min_width: float = MIN_AXES_WIDTH) -> None:
    """tight_layout, then a wider figure while the narrowest of ``axes`` is under ``min_width`` inches: long tick
    labels (region names, 'name = value unit') take width from the figure, not from the plot; then :func:`_fit`."""
    for _ in range(3):
        fig.tight_layout()
        narrowest = min(ax.get_position().width for ax in axes) * fig.get_figwidth()
        if narrowest >= min_width - 0.05:
            break
        fig.set_figwidth(fig.get_figwidth() + (min_width - narrowest) * len(axes) + 0.1)
    else:
        fig.tight_layout()
    _fit(fig)


def _fit(fig) -> None:
    """A wider figure while any of its text runs past an edge: tight_layout moves the axes, but cannot make room
    for an axis label wider than the figure (a waterfall's 'margin of handover_to_candidate_1 over stay: ...')."""
    renderer, pad = fig.canvas.get_renderer(), 0.15  # inches kept free at the right edge (tight_layout's at the left)
    for _ in range(6):
        box = fig.get_tightbbox(renderer)  # inches, everything drawn
        over = max(0.0, -box.x0) + max(0.0, box.x1 - fig.get_figwidth() + pad)
        if over <= 0.01:
            return
        # a label centred under its axes gains half of what the figure gains on each side
        fig.set_figwidth(fig.get_figwidth() + 2 * over + 0.1)
        fig.tight_layout()


def _keep_inside(fig, ax, texts, pad: float = 4.0) -> None:
    """Widen ``ax``'s x-limits until every text of ``texts`` (value labels at the bars' ends) lies inside the axes,
    ``pad`` pixels from its edges: off the tick labels beside it and within the figure."""
    renderer = fig.canvas.get_renderer()
    for _ in range(6 if texts else 0):
        fig.tight_layout()  # the new limits' tick labels (one may now sit at an edge) get their room
        box = ax.get_window_extent(renderer)
        extents = [t.get_window_extent(renderer) for t in texts]
        left = max(box.x0 + pad - e.x0 for e in extents)  # pixels beyond the left edge (> 0: outside)
        right = max(e.x1 - (box.x1 - pad) for e in extents)
        if left <= 0 and right <= 0:
            return
        lo, hi = ax.get_xlim()
        per_px = (hi - lo) / box.width
        # the scale shrinks as the limits widen: a little more than the overshoot, then measure again
        ax.set_xlim(lo - 1.3 * max(left, 0) * per_px, hi + 1.3 * max(right, 0) * per_px)
    else:
        fig.tight_layout()
    _fit(fig)


def _cmap(name: str):
    import matplotlib

    return matplotlib.colormaps[name]


def save(fig, path: str | Path, dpi: int = DPI) -> Path:
    """Write ``fig`` to ``path`` (format from the suffix) atomically; returns the path."""
    if dpi != fig.dpi:  # text measures a little differently at another dpi: fit it again there
        fig.set_dpi(dpi)
        _fit(fig)
    return save_figure(fig, path, dpi=dpi)


def _view(exp: Explanation, view: str) -> str:
    exp.contributions(view)  # refuses an unknown view
    return view if exp.decides else "output"


def contributions(exp: Explanation, view: str = "margin") -> np.ndarray:
    """(n_states, n_features) contributions in ``view`` (:meth:`xairl.Explanation.contributions`)."""
    return exp.contributions(view)[0]


def view_label(exp: Explanation, view: str = "margin") -> str:
    """What the contributions of ``view`` add up to, in words for an axis or a title."""
    kind = _view(exp, view)
    if kind == "margin":
        return "contribution to the margin over the runner-up"
    if kind == "score":
        return "contribution to the chosen action's score"
    return f"contribution to {exp.action_names[0]}"


def readable(exp: Explanation) -> Explanation:
    """An explanation a beeswarm can show: a window per signal (as its narratives name them), images in the regions
    their narratives name (:func:`xairl.in_regions`), dicts by key."""
    if window_of(exp) is not None:
        return exp.by_signal()
    if exp.values.shape[1] <= MAX_SHOWN or exp.observation is None:
        return exp
    if exp.image_shape is not None:
        return in_regions(exp)
    by_part = exp.groups_by_part()
    return exp.grouped(by_part) if len(by_part) > 1 else exp


def _panels(explanations: Panels) -> list[tuple[str, Explanation]]:
    return [("", explanations)] if isinstance(explanations, Explanation) else list(explanations)


def importance_order(exp: Explanation, view: str = "margin") -> np.ndarray:
    """Feature indices by mean |contribution| in ``view``, largest first."""
    return np.argsort(-np.abs(contributions(exp, view)).mean(axis=0), kind="stable")


def beeswarm(
    explanations: Panels,
    view: str = "margin",
    order: np.ndarray | None = None,
    max_display: int = 20,
    *,
    policy=None,
):
    """One dot per state and feature at its contribution, coloured by the feature's value (low blue, high red);
    several titled explanations side by side share one feature order (the first's importance unless ``order``) and
    one x scale. Images and dict observations are shown by patch and by key.

    :param policy: the :class:`xairl.Policy` explained: a feature it declares an identifier or a category (a cell's
        id, a colour) is drawn grey, for its value has no low or high.
    """
    panels = [(t, readable(e)) for t, e in _panels(explanations)]
    order = (importance_order(panels[0][1], view) if order is None else order)[:max_display]
    rng = np.random.default_rng(0)
    fig = _figure(figsize=(7.5 * len(panels), 0.3 * len(order) + 2))
    axes = fig.subplots(1, len(panels), squeeze=False, sharex=True)  # one scale: panels compare at a glance
    features = getattr(policy, "features", None) or {}
    for ax, (title, exp) in zip(axes[0], panels):
        c = contributions(exp, view)
        keep = rng.choice(len(c), size=min(len(c), 2000), replace=False)  # enough dots to show the spread
        for row, j in enumerate(order):
            colour = "0.4"
            info = features.get(exp.feature_names[j])
            if exp.states is not None and getattr(info, "kind", "numeric") not in ("identifier", "categorical"):
                colour = _cmap("coolwarm")(np.argsort(np.argsort(exp.states[keep, j])) / max(len(keep) - 1, 1))
            ax.scatter(c[keep, j], row + rng.uniform(-0.3, 0.3, len(keep)), s=4, c=colour, alpha=0.7, linewidths=0)
        ax.axvline(0, color="0.5", lw=0.8)
        ax.set_yticks(range(len(order)), [exp.feature_names[j] for j in order])
        ax.tick_params(axis="y", labelleft=ax is axes[0, 0])  # one order: its names once, at the left
        ax.invert_yaxis()
        ax.set_xlabel(view_label(exp, view))
        ax.set_title(title)
    if panels[0][1].states is not None:
        from matplotlib.cm import ScalarMappable

        bar = fig.colorbar(ScalarMappable(cmap="coolwarm"), ax=axes[0, -1], ticks=[0, 1], fraction=0.03)
        bar.ax.set_yticklabels(["low", "high"])
        named = [panels[0][1].feature_names[j] for j in order]
        grey = [f for f in named if getattr(features.get(f), "kind", "numeric") in ("identifier", "categorical")]
        bar.set_label("feature value" + (f"\n(grey: {', '.join(grey)}, no low or high)" if grey else ""))
    _layout(fig, list(axes[0]))
    return fig


def importance(explanations: Panels, view: str = "margin", max_display: int = 20):
    """Mean |contribution| per feature, one bar per titled explanation, in the first one's order."""
    panels = [(t, readable(e)) for t, e in _panels(explanations)]
    order = importance_order(panels[0][1], view)[:max_display]
    names = [panels[0][1].feature_names[j] for j in order]
    fig = _figure(figsize=(8, 0.35 * len(names) + 1.5))
    ax = fig.subplots()
    h = 0.8 / len(panels)
    for k, (title, exp) in enumerate(panels):
        ax.barh(
            np.arange(len(names)) + k * h,
            np.abs(contributions(exp, view)).mean(axis=0)[order],
            height=h,
            label=title or None,
        )
    ax.set_yticks(np.arange(len(names)) + 0.4 - h / 2, names)
    ax.invert_yaxis()
    ax.set_xlabel("mean |" + view_label(panels[0][1], view) + "|")
    if any(t for t, _ in panels):
        ax.legend()
    _layout(fig, [ax])
    return fig


def waterfall(exp: Explanation, index: int = 0, view: str = "margin", shown: int = 10, title: str = "", *, policy=None):
    """From the expected value (over the background) to state ``index``'s: the ``shown`` largest contributions as
    steps, the rest as one step. In the margin view the numbers are those of the narrative's evidence card (and, as
    there, a decision with one action available, hence no runner-up, is shown in the score view, the title says so).

    :param policy: the :class:`xairl.Policy` explained: each feature's value is then written as its narratives
        write it, in its unit or as its fill ('buffer = 100 % full'); without it, in their number format.
    """
    i = exp.check_index(index)
    alone = _view(exp, view) == "margin" and exp.runner_up[i] == exp.chosen[i]
    view = "score" if alone else view  # one action was available: no margin, its score (as its card shows)
    values, expected, value = exp.contributions(view)
    c, a, base, end = values[i], int(exp.focus[i]), float(expected[i]), float(value[i])
    order = np.argsort(-np.abs(c), kind="stable")
    top, rest = order[:shown], order[shown:]
    labels = [
        exp.feature_names[j] + ("" if exp.states is None else f" = {state_value_text(exp, i, j, policy)}") for j in top
    ]
    steps = list(c[top])
    if len(rest):
        labels.append(f"{len(rest)} other features")
        steps.append(float(c[rest].sum()))
    start = base + np.concatenate([[0.0], np.cumsum(steps[::-1])])[:-1][::-1]
    fig = _figure(figsize=(8, 0.4 * len(steps) + 1.8))
    ax = fig.subplots()
    y = np.arange(len(steps))
    ax.barh(y, steps, left=start, color=["#d62728" if v >= 0 else "#1f77b4" for v in steps])
    texts = [
        ax.annotate(
            f"{v:+.3g}",
            (x0 + v, yi),
            xytext=(3 if v >= 0 else -3, 0),
            textcoords="offset points",
            va="center",
            ha="left" if v >= 0 else "right",
            fontsize=8,
        )
        for yi, v, x0 in zip(y, steps, start)
    ]  # outward from the bar's end, kept inside the axes below
    ax.set_yticks(y, labels)
    ax.invert_yaxis()
    ax.axvline(base, color="0.5", ls=":", lw=0.8)
    what = {
        "margin": f"margin of {exp.action_names[a]} over {exp.action_names[int(exp.runner_up[i])]}",
        "score": f"{exp.action_names[a]}'s score (chosen)",
        "output": exp.action_names[a],
    }[_view(exp, view)]
    ax.set_xlabel(f"{what}: expected {base:.3g} -> this state {end:.3g}")
    ax.set_title(
        title or f"state {i}: {view_label(exp, view)}" + (" (the only action available)" if alone else ""), fontsize=10
    )
    _layout(fig, [ax])
    _keep_inside(fig, ax, texts)
    return fig


def image(exp: Explanation, index: int = 0, view: str = "margin"):
    """An image policy's frame (mean over channels) beside its contributions summed over channels (red raises, blue
    lowers): in the ``"margin"`` view (discrete actions) one map of the margin of the chosen action over the
    runner-up; in the ``"score"`` view (or when nothing is chosen) one map per output, of its own score."""
    from xairl.errors import InputError

    shape = exp.image_shape
    if shape is None:
        raise InputError(
            "plots.image needs an image observation (Observation with an image shape); use "
            "plots.waterfall or plots.beeswarm for flat features."
        )
    i = exp.check_index(index)
    frame = exp.states[i].reshape(shape)
    frame = frame.mean(axis=0) if len(shape) == 3 else frame
    kind = _view(exp, view)
    if kind == "margin":
        c, r = exp.action_names[exp.chosen[i]], exp.action_names[exp.runner_up[i]]
        maps = [(f"{c} over {r}", contributions(exp, view)[i].reshape(shape))]
        named = "contribution to the margin over the runner-up"
    else:
        chosen = exp.action_names[exp.chosen[i]] if exp.output == "actions" else None
        maps = [
            (f"{name}{' (chosen)' if name == chosen else ''}", exp.image(a)[i])
            for a, name in enumerate(exp.action_names)
        ]
        named = "contribution to each action's score" if exp.output == "actions" else "contribution to each output"
    heat = [(t, h.sum(axis=0) if len(shape) == 3 else h) for t, h in maps]
    lim = max(float(np.abs(h).max()) for _, h in heat) or 1.0
    n = len(heat) + 1
    fig = _figure(figsize=(max(2.6 * n, 5.2), 3.3))
    axes = fig.subplots(1, n)
    axes[0].imshow(frame, cmap="gray")
    axes[0].set_title("state", fontsize=9)
    for ax, (t, h) in zip(axes[1:], heat):
        ax.imshow(frame, cmap="gray", alpha=0.35)
        ax.imshow(h, cmap="bwr", vmin=-lim, vmax=lim, alpha=0.8)
        ax.set_title(t, fontsize=9)
    for ax in axes:
        ax.axis("off")
    fig.suptitle(
        textwrap.fill(f"state {i}: {named} (red raises it, blue lowers it)", int(11 * fig.get_figwidth())), fontsize=10
    )
    fig.tight_layout()
    return fig


def timeline(exp: Explanation, view: str = "margin", top: int = 5, title: str = ""):
    """States in order (an episode, a flight): the ``top`` features' contributions over the steps (lines), and above
    them the decision at each step (a marker and colour per action, none of them the lines'), so a reader sees when
    a feature started to decide."""
    exp = readable(exp)
    c = contributions(exp, view)
    order = importance_order(exp, view)[:top]
    steps = np.arange(len(c))
    fig = _figure(figsize=(9, 4.2))
    ax_act, ax = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [1, 4]})
    decided = exp.chosen if exp.output == "actions" else np.zeros(len(c), dtype=int)
    for a, name in enumerate(exp.action_names):
        at = decided == a
        if at.any():
            ax_act.scatter(
                steps[at],
                decided[at],
                s=14,
                marker=ACTION_MARKERS[a % len(ACTION_MARKERS)],
                color=ACTION_COLOURS[a % len(ACTION_COLOURS)],
                linewidths=0,
                label=name,
            )
    ax_act.set_yticks(range(len(exp.action_names)), exp.action_names, fontsize=7)
    ax_act.set_ylim(-0.6, len(exp.action_names) - 0.4)
    ax_act.set_ylabel("chosen" if exp.output == "actions" else "", fontsize=8)
    for j in order:
        ax.plot(steps, c[:, j], lw=1.2, label=exp.feature_names[j])
    ax.axhline(0, color="0.5", lw=0.8)
    ax.set_xlabel("step (state index)")
    ax.set_ylabel(view_label(exp, view).replace(" over the", "\nover the"), fontsize=8)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), title="features", title_fontsize=7)
    ax_act.set_title(title or f"{len(c)} states in order", fontsize=10)
    fig.tight_layout()
    return fig


def window_heatmap(exp: Explanation, index: int | None = None, view: str = "margin", top: int = 12):
    """A policy that sees time (:mod:`xairl.policies.windows`): contributions per signal (rows, the ``top`` largest) and per
    time step (columns, oldest to newest) for state ``index``, or their mean |contribution| over every state
    (``index=None``), so a reader sees which signals and which moments of the window drove the decisions."""
    from xairl.policies.windows import over_time

    groups = exp.time_groups()
    signals, steps = (list(g) for g in groups)
    cells = over_time(contributions(exp, view), *groups)
    if index is None:
        heat, cmap, what = np.abs(cells).mean(axis=0), "Reds", f"mean |contribution| over {len(cells)} states"
    else:
        heat, cmap, what = cells[exp.check_index(index)], "bwr", f"state {index} (red raises it, blue lowers it)"
    order = np.argsort(-np.abs(heat).sum(axis=1), kind="stable")[:top]
    heat = heat[order]
    lim = float(np.abs(heat).max()) or 1.0
    fig = _figure(figsize=(max(4.5, 0.8 * len(steps) + 3), max(2.4, 0.32 * len(order) + 1.4)))
    ax = fig.subplots()
    image = ax.imshow(heat, cmap=_cmap(cmap), vmin=0 if index is None else -lim, vmax=lim, aspect="auto")
    ax.set_xticks(range(len(steps)), steps, fontsize=8)
    ax.set_yticks(range(len(order)), [signals[j] for j in order], fontsize=8)
    ax.set_xlabel("time step (oldest to newest)")
    fig.colorbar(image, ax=ax, shrink=0.85).set_label(textwrap.fill(view_label(exp, view), 28), fontsize=8)
    ax.set_title(textwrap.fill(what, 60), fontsize=9)
    _layout(fig, [ax])
    return fig
