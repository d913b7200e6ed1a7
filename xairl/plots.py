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


def shap_explanation(exp: Explanation):
    """The chosen action's contributions as a ``shap.Explanation`` (for shap.plots)."""
    import shap

    idx = np.arange(len(exp.values))
    return shap.Explanation(values=exp.for_chosen(), base_values=exp.base_values[idx, exp.chosen],
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
        shap.plots.beeswarm(shap_explanation(exp), order=order, max_display=len(order), ax=ax, show=False,
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
    order = importance_order(panels[0][1])
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
