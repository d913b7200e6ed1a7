"""Figures through shap.plots and matplotlib, written as PNG files. Contributions are to the chosen action."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .explanation import Explanation


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


#: more features than this are plotted in groups (image patches, dict keys) or only the strongest are shown
MAX_SHOWN = 40


def image_shape(exp: Explanation):
    from .observation import Observation

    return None if exp.observation is None else Observation.from_dict(exp.observation).image_shape()


def readable(exp: Explanation) -> Explanation:
    """An explanation a beeswarm can show: images grouped into at most ~100 patches, dicts by key."""
    from .observation import patches

    if exp.values.shape[1] <= MAX_SHOWN or exp.observation is None:
        return exp
    shape = image_shape(exp)
    if shape is not None:
        side = max(1, int(np.ceil(max(shape[-2:]) / 10)))
        return exp.grouped(patches(shape, side))
    by_part = exp.groups_by_part()
    return exp.grouped(by_part) if len(by_part) > 1 else exp


def images(exp: Explanation, index: int, path: Path) -> Path:
    """The state's frame (mean over channels) and, per output, its contributions summed over channels."""
    plt = _plt()
    shape = image_shape(exp)
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
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def shap_explanation(exp: Explanation):
    """The chosen action's (or the first output's) contributions as a ``shap.Explanation`` (for shap.plots)."""
    import shap

    idx = np.arange(len(exp.values))
    a = exp.chosen if exp.output == "actions" else np.zeros(len(idx), dtype=int)  # else the first output
    return shap.Explanation(values=exp.values[idx, :, a], base_values=exp.base_values[idx, a],
                            data=exp.states, feature_names=list(exp.feature_names))


def importance_order(exp: Explanation) -> np.ndarray:
    """Feature indices by mean |contribution to the chosen action|, largest first."""
    return np.argsort(-np.abs(exp.for_chosen()).mean(axis=0), kind="stable")


def beeswarms(panels: list[tuple[str, Explanation]], path: Path, order: np.ndarray | None = None) -> Path:
    """Beeswarms side by side with one feature order (the first panel's importance unless ``order`` is given)."""
    import shap

    plt = _plt()
    order = importance_order(panels[0][1]) if order is None else order
    fig, axes = plt.subplots(1, len(panels), figsize=(7.5 * len(panels), 6.5))
    for ax, (title, exp) in zip(np.atleast_1d(axes), panels):
        shap.plots.beeswarm(shap_explanation(exp), order=order, max_display=min(len(order), MAX_SHOWN), ax=ax,
                            show=False,
                            plot_size=None, color_bar=ax is np.atleast_1d(axes)[-1])
        ax.set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def waterfall(exp: Explanation, index: int, path: Path, title: str = "") -> Path:
    import shap

    plt = _plt()
    shap.plots.waterfall(shap_explanation(exp)[index], max_display=10, show=False)
    fig = plt.gcf()
    fig.set_size_inches(8, 5.5)
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
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
        vals = np.abs(exp.for_chosen()).mean(axis=0)[order]
        ax.barh(np.arange(len(names)) + k * h, vals, height=h, label=title)
    ax.set_yticks(np.arange(len(names)) + 0.4 - h / 2, names)
    ax.invert_yaxis()
    ax.set_xlabel("mean |contribution to the chosen action's Q-value|")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path
