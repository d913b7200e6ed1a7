"""Figures with matplotlib, written as PNG files. Contributions are to the chosen action (or, where nothing is
chosen, to the first output)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .explanation import Explanation
from .files import save_figure


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


#: more features than this are plotted in groups (image patches, dict keys) or only the strongest are shown
MAX_SHOWN = 40


def readable(exp: Explanation) -> Explanation:
    """An explanation a beeswarm can show: images grouped into at most ~100 patches, dicts by key."""
    from .observation import patches

    if exp.values.shape[1] <= MAX_SHOWN or exp.observation is None:
        return exp
    shape = exp.image_shape
    if shape is not None:
        side = max(1, int(np.ceil(max(shape[-2:]) / 10)))
        return exp.grouped(patches(shape, side))
    by_part = exp.groups_by_part()
    return exp.grouped(by_part) if len(by_part) > 1 else exp


def images(exp: Explanation, index: int, path: Path) -> Path:
    """The state's frame (mean over channels) and, per output, its contributions summed over channels."""
    plt = _plt()
    shape = exp.image_shape
    frame = exp.states[index].reshape(shape)
    frame = frame.mean(axis=0) if len(shape) == 3 else frame
    heat = [exp.image(a)[index] for a in range(exp.values.shape[2])]
    heat = [h.sum(axis=0) if len(shape) == 3 else h for h in heat]
    lim = max(float(np.abs(h).max()) for h in heat) or 1.0
    n = len(heat) + 1
    fig, axes = plt.subplots(1, n, figsize=(2.6 * n, 3))
    axes[0].imshow(frame, cmap="gray")
    axes[0].set_title("state")
    for ax, h, name in zip(axes[1:], heat, exp.action_names):
        ax.imshow(frame, cmap="gray", alpha=0.35)
        ax.imshow(h, cmap="bwr", vmin=-lim, vmax=lim, alpha=0.8)
        chosen = exp.output == "actions" and name == exp.action_names[exp.chosen[index]]
        ax.set_title(f"{name}{' (chosen)' if chosen else ''}", fontsize=9)
    for ax in axes:
        ax.axis("off")
    fig.tight_layout()
    save_figure(fig, path, dpi=90)
    plt.close(fig)
    return path


def contributions(exp: Explanation) -> np.ndarray:
    """(n_states, n_features) contributions to the plotted output of each state."""
    return exp.values[np.arange(len(exp.values)), :, exp.focus]


def importance_order(exp: Explanation) -> np.ndarray:
    """Feature indices by mean |contribution to the chosen action|, largest first."""
    return np.argsort(-np.abs(contributions(exp)).mean(axis=0), kind="stable")


def beeswarms(panels: list[tuple[str, Explanation]], path: Path, order: np.ndarray | None = None) -> Path:
    """Beeswarms side by side with one feature order (the first panel's importance unless ``order`` is given):
    one dot per state and feature at its contribution, coloured by the feature's value (low blue, high red).

    Drawn with matplotlib alone: importing shap for its plots costs ~3 s, half the CLI's budget for 10k states.
    """
    plt = _plt()
    order = (importance_order(panels[0][1]) if order is None else order)[:MAX_SHOWN]
    rng = np.random.default_rng(0)
    fig, axes = plt.subplots(1, len(panels), figsize=(7.5 * len(panels), 0.3 * len(order) + 2), squeeze=False)
    for ax, (title, exp) in zip(axes[0], panels):
        c = contributions(exp)
        keep = rng.choice(len(c), size=min(len(c), 2000), replace=False)  # enough dots to show the spread
        for row, j in enumerate(order):
            vals = c[keep, j]
            if exp.states is not None:
                ranks = np.argsort(np.argsort(exp.states[keep, j])) / max(len(keep) - 1, 1)
                colour = plt.cm.coolwarm(ranks)
            else:
                colour = "0.4"
            ax.scatter(vals, row + rng.uniform(-0.3, 0.3, len(vals)), s=4, c=colour, alpha=0.7, linewidths=0)
        ax.axvline(0, color="0.5", lw=0.8)
        ax.set_yticks(range(len(order)), [exp.feature_names[j] for j in order])
        ax.invert_yaxis()
        ax.set_xlabel("contribution (SHAP value)")
        ax.set_title(title)
    if panels[0][1].states is not None:
        bar = fig.colorbar(plt.cm.ScalarMappable(cmap="coolwarm"), ax=axes[0, -1], ticks=[0, 1], fraction=0.03)
        bar.ax.set_yticklabels(["low", "high"])
        bar.set_label("feature value")
    fig.tight_layout()
    save_figure(fig, path, dpi=90)
    plt.close(fig)
    return path


def waterfall(exp: Explanation, index: int, path: Path, title: str = "", shown: int = 10) -> Path:
    """From the base value to the output of state ``index``: the ``shown`` largest contributions as steps, the
    rest as one step."""
    plt = _plt()
    a = int(exp.focus[index])
    c = exp.values[index, :, a]
    order = np.argsort(-np.abs(c), kind="stable")
    top, rest = order[:shown], order[shown:]
    labels = [exp.feature_names[j] + ("" if exp.states is None else f" = {exp.states[index, j]:.3g}") for j in top]
    steps = list(c[top])
    if len(rest):
        labels.append(f"{len(rest)} other features")
        steps.append(float(c[rest].sum()))
    start = float(exp.base_values[index, a]) + np.concatenate([[0.0], np.cumsum(steps[::-1])])[:-1][::-1]
    fig, ax = plt.subplots(figsize=(8, 0.4 * len(steps) + 1.8))
    y = np.arange(len(steps))
    ax.barh(y, steps, left=start, color=["#d62728" if v >= 0 else "#1f77b4" for v in steps])
    for yi, v, x0 in zip(y, steps, start):
        ax.text(x0 + v, yi, f" {v:+.3g}", va="center", ha="left" if v >= 0 else "right", fontsize=8)
    ax.set_yticks(y, labels)
    ax.invert_yaxis()
    ax.axvline(exp.base_values[index, a], color="0.5", ls=":", lw=0.8)
    ax.set_xlabel(f"{exp.action_names[a]}: base {exp.base_values[index, a]:.3g} -> output {exp.outputs[index, a]:.3g}")
    if title:
        ax.set_title(title, fontsize=10)
    fig.tight_layout()
    save_figure(fig, path, dpi=90)
    plt.close(fig)
    return path


def importance_bars(panels: list[tuple[str, Explanation]], path: Path) -> Path:
    """Mean |contribution| per feature, one bar group per panel, in the first panel's order."""
    plt = _plt()
    order = importance_order(panels[0][1])[:MAX_SHOWN]
    names = [panels[0][1].feature_names[j] for j in order]
    fig, ax = plt.subplots(figsize=(8, 0.35 * len(names) + 1.5))
    h = 0.8 / len(panels)
    for k, (title, exp) in enumerate(panels):
        vals = np.abs(contributions(exp)).mean(axis=0)[order]
        ax.barh(np.arange(len(names)) + k * h, vals, height=h, label=title)
    ax.set_yticks(np.arange(len(names)) + 0.4 - h / 2, names)
    ax.invert_yaxis()
    ax.set_xlabel("mean |contribution to the chosen action's Q-value|")
    ax.legend()
    fig.tight_layout()
    save_figure(fig, path, dpi=90)
    plt.close(fig)
    return path
