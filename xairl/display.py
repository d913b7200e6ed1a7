"""What a notebook shows of an explanation: an HTML table of its first decisions and their largest contributions,
in the margin view (the narratives' view), the view named. A Narrative shows its evidence card
(:func:`xairl.evidence.card_html`)."""
from __future__ import annotations

import html

import numpy as np


def explanation_html(exp, states: int = 5, top: int = 6) -> str:
    """The summary line, then the first ``states`` decisions with their ``top`` contributions to the margin over the
    runner-up (to the first output when nothing is chosen)."""
    n = len(exp.values)
    view, _, value = exp.contributions("margin")
    rows = []
    for i in range(min(n, states)):
        c, r = int(exp.focus[i]), int(exp.runner_up[i])
        what = (f"chose <b>{html.escape(exp.action_names[c])}</b> over {html.escape(exp.action_names[r])} by "
                f"{value[i]:.4g}" if exp.decides else f"{html.escape(exp.action_names[c])} = {value[i]:.4g}")
        top_j = np.argsort(-np.abs(view[i]), kind="stable")[:top]
        cells = ", ".join(f"{html.escape(exp.feature_names[j])} {view[i, j]:+.3g}" for j in top_j)
        rows.append(f"<tr><td>{i}</td><td>{what}</td><td>{cells}</td></tr>")
    target = "the margin over the runner-up" if exp.decides else html.escape(exp.action_names[0])
    more = f"<p>... and {n - states} more states</p>" if n > states else ""
    return (f"<div class=xairl-explanation><p><code>{html.escape(repr(exp))}</code></p><table><tr><th>state</th>"
            f"<th>decision</th><th>largest contributions to {target}</th></tr>{''.join(rows)}</table>{more}</div>")
