"""What a notebook shows of an explanation: an HTML table of its first decisions and their largest contributions,
in the margin view (the narratives' view), the view named. A Narrative shows its evidence card
(:func:`xairl.evidence.card_html`). Also what figures and tables share with the narratives: a feature's value as the
narratives write it (:func:`value_text`), and a progress bar that is quiet in a notebook (:func:`progress`).
"""

from __future__ import annotations

import html
import sys
import warnings

import numpy as np

#: what tqdm.auto warns, once per process, in a notebook without ipywidgets (shap and transformers import it)
_NO_WIDGETS = "IProgress not found"


def quiet_tqdm() -> None:
    """Import ``tqdm.auto`` with its 'IProgress not found' warning silenced: it warns once, at its first import, in
    a notebook without ipywidgets, and libraries (shap, transformers) import it. Call it before importing them; it
    is idempotent and cheap (tqdm only)."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=_NO_WIDGETS)
        import tqdm.auto  # noqa: F401 (imported for its side effect: the module is cached, warned or not)


def progress(iterable=None, **kwargs):
    """A tqdm progress bar that is safe in a notebook: a widget bar where ipywidgets is installed, tqdm's text bar
    elsewhere, and never the 'IProgress not found' warning. ``kwargs`` are tqdm's (``desc``, ``total``, ``unit``,
    ``disable``)."""
    quiet_tqdm()
    from tqdm.auto import tqdm

    return tqdm(iterable, **kwargs)


def show_progress(progress: bool | None) -> bool:
    """Whether to show a progress bar: ``True`` or ``False`` as given; ``None`` only when stderr is a terminal (as
    :func:`xairl.stream.explain_to_parquet` does), so logs, pipes and tests stay quiet."""
    if progress is not None:
        return progress
    isatty = getattr(sys.stderr, "isatty", None)
    return bool(isatty and isatty())


def explanation_html(exp, states: int = 5, top: int = 6) -> str:
    """The summary line, then the first ``states`` decisions with their ``top`` contributions to the margin over the
    runner-up (to the first output when nothing is chosen)."""
    n = len(exp.values)
    view, _, value = exp.contributions("margin")
    rows = []
    for i in range(min(n, states)):
        c, r = int(exp.focus[i]), int(exp.runner_up[i])
        what = (
            f"chose <b>{html.escape(exp.action_names[c])}</b> over {html.escape(exp.action_names[r])} by {value[i]:.4g}"
            if exp.decides
            else f"{html.escape(exp.action_names[c])} = {value[i]:.4g}"
        )
        top_j = np.argsort(-np.abs(view[i]), kind="stable")[:top]
        cells = ", ".join(f"{html.escape(exp.feature_names[j])} {view[i, j]:+.3g}" for j in top_j)
        rows.append(f"<tr><td>{i}</td><td>{what}</td><td>{cells}</td></tr>")
    target = "the margin over the runner-up" if exp.decides else html.escape(exp.action_names[0])
    more = f"<p>... and {n - states} more states</p>" if n > states else ""
    return (
        f"<div class=xairl-explanation><p><code>{html.escape(repr(exp))}</code></p><table><tr><th>state</th>"
        f"<th>decision</th><th>largest contributions to {target}</th></tr>{''.join(rows)}</table>{more}</div>"
    )
