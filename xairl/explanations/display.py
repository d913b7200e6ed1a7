"""What a notebook shows of an explanation: an HTML table of its first decisions and their largest contributions,
in the margin view (the narratives' view), the view named. A Narrative shows its evidence card
(:func:`xairl.explanations.evidence.card_html`); a decision's counterfactuals their own small card (:func:`counterfactual_html`,
also inside a decision card), or lines on a terminal (:func:`counterfactual_text`). Also a progress bar that is quiet
in a notebook (:func:`progress`), and a long step's heartbeat on stderr (:func:`heartbeat`).
"""

from __future__ import annotations

import contextlib
import html
import sys
import threading
import time
import warnings

import numpy as np

from xairl.numbers import format_number

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
    :func:`xairl.runs.stream.explain_to_parquet` does), so logs, pipes and tests stay quiet."""
    if progress is not None:
        return progress
    isatty = getattr(sys.stderr, "isatty", None)
    return bool(isatty and isatty())


#: seconds of work before progress shows unasked: a bar on a terminal past ``QUIET_S``; elsewhere (a log, a pipe, a
#: notebook) a plain line every ``LINE_EVERY_S``, so that a run of minutes is never silent and a quick one says nothing
QUIET_S, LINE_EVERY_S = 3.0, 10.0


class WorkProgress:
    """Progress over ``total`` units (states, or one state's batches), fed in fractions of a unit.

    :param show: True, a bar at once; False, nothing; None (the default of long work), a bar past :data:`QUIET_S`
        when stderr is a terminal, else a plain line to stderr every :data:`LINE_EVERY_S` ('exact: 37% (1.5 of 4
        states), 52 s, about 88 s left').
    """

    def __init__(self, show: bool | None, total: int, desc: str, unit: str):
        self.total, self.desc, self.unit, self.done = total, desc, unit, 0.0
        self.start = self.shown_at = time.monotonic()
        self.whole = 0  # whole units given to the bar
        terminal = show_progress(None)
        self.bar = (
            progress(total=total, desc=desc, unit=unit, delay=0 if show else QUIET_S)
            if show or (show is None and terminal)
            else None
        )
        self.lines = show is None and not terminal

    def advance(self, amount: float) -> None:
        self.done += amount
        now = time.monotonic()
        if self.bar is not None:
            whole = min(int(self.done + 1e-9), self.total)
            if whole > self.whole:
                self.bar.update(whole - self.whole)
                self.whole = whole
            elif now - self.shown_at >= 1 and now - self.start >= self.bar.delay:  # within a long unit: its share
                self.bar.set_postfix_str(f"{self.done - whole:.0%} of the next {self.unit}")
                self.shown_at = now
        elif self.lines and now - self.shown_at >= LINE_EVERY_S:
            took = now - self.start
            left = f", about {took * (self.total - self.done) / self.done:.0f} s left" if self.done else ""
            print(
                f"{self.desc}: {self.done / self.total:.0%} ({self.done:.3g} of {self.total} "
                f"{self.unit}{'es' if self.unit.endswith(('s', 'ch')) else 's'}), "
                f"{took:.0f} s{left}",
                file=sys.stderr,
                flush=True,
            )
            self.shown_at = now

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


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


def counterfactual_text(cf: dict) -> list[str]:
    """A decision's counterfactuals (the plain dict of :func:`xairl.counterfactuals.show.summary`) as terminal lines:
    one per counterfactual, 'rsrp_1 -83.2 dBm -> -71.5 dBm: handover_to_candidate_1 (margin 0.0052)' (a threshold's:
    the output's new value), or the one line 'none found within the bounds (a grid search: <why>)'."""
    if not cf.get("found"):
        return [_miss(cf)]
    return [f"{_changes(one, ' -> ')}: {_then(cf, one)} (margin {_g(one['margin'])}, distance {one['distance']:.2f})"
            for one in cf["found"]]  # fmt: skip


def counterfactual_meta(cf: dict, chosen: bool = True) -> str:
    """The heading's words: what was chosen and asked, and how the values shown were checked: re-run through the
    policy as written (``as_written``), or, for a bare answer, rounded away from the state's value, just past the
    line (the search re-ran its own unrounded values, not these)."""
    how = (
        "each re-run through the policy as shown"
        if cf.get("as_written")
        else "values rounded away from the state's, just past the line; the search re-ran its unrounded ones"
    )
    return f"{'chose ' + str(cf['chosen']) + '; ' if chosen else ''}asked: {cf['target']}; {how}"


def _miss(cf: dict) -> str:
    """Why none is shown: a search's miss as 'none found within the bounds (a grid search: ...)', never as a claim
    that none exists; another reason ('it already chooses B') as 'none: ...'."""
    why = str(cf.get("reason") or "no change found")
    miss = " (a grid search: a miss is no proof that none exists)"
    return f"none found within the bounds (a grid search: {why.replace(miss, '')})" if miss in why else f"none: {why}"


def _then(cf: dict, one: dict) -> str:
    """What the policy then does: the action, or a threshold's output and its new value ('steer = 0.21')."""
    if not (cf.get("threshold") and "output" in one):
        return str(one["action"])
    return f"{one['action']} = {_g(one['output'])}"


def _g(x) -> str:
    """3 significant digits, never in scientific notation (0.00064 and 2391 as the words write them)."""
    return f"{x:.3g}" if 1e-3 <= abs(x) < 1000 else format_number(x)


def _changes(one: dict, arrow: str, escape=lambda s: s) -> str:
    return " and ".join(
        f"{escape(c['feature'])} {escape(c['before_text'])}{arrow}{escape(c['after_text'])}" for c in one["changes"]
    )


#: the counterfactual card's look (beside a decision card's, or alone in a notebook)
CF_STYLE = (
    ".xairl-cf{margin:.5em 0;font-size:90%}.xairl-cf table{border-collapse:collapse}"
    ".xairl-cf td,.xairl-cf th{border:1px solid #ddd;padding:1px 6px}"
)


def counterfactual_html(cf: dict) -> str:
    """'What would have changed it': a decision's counterfactuals (the dict of
    :func:`xairl.counterfactuals.show.summary`) as a small HTML card: each one's changes, the action the policy then
    takes and its margin, or why none is reachable within the bounds."""
    e = html.escape
    head = f"<b>What would have changed it</b> <span class=meta>({e(counterfactual_meta(cf))})</span>"
    if not cf.get("found"):
        body = f"<p class=cf-none>{e(_miss(cf)).capitalize()}.</p>"
    else:
        rows = "".join(
            f"<tr><td>{_changes(one, ' &rarr; ', e)}</td><td>{e(_then(cf, one))}</td><td>{_g(one['margin'])}</td>"
            f"<td>{one['distance']:.2f}</td></tr>"
            for one in cf["found"]
        )
        then = "then its output" if cf.get("threshold") else "then the policy chooses"
        body = (
            f"<table><tr><th>change</th><th>{then}</th><th>margin</th><th>distance (quantiles)</th></tr>{rows}</table>"
        )
    return f"<div class=xairl-cf>{head}{body}</div>"


#: the longest a long step stays silent, in seconds (tests shorten it)
EVERY = 10.0
#: the steps under way, innermost last (only the innermost speaks), and when stderr last heard from one of them
_STEPS: list[object] = []
_LAST = [0.0]


@contextlib.contextmanager
def heartbeat(what: str, enabled: bool = True, every: float | None = None, stream=None):
    """Says on stderr what a long step is doing, whatever stderr is (a terminal, a log, a pipe), so that it is never
    silent for more than ``every`` seconds (default :data:`EVERY`, 10): once nothing has been said for that long
    (for half as long before the outermost step's first line), the innermost step under way says
    ``xairl: WHAT ...`` (its first line), then ``xairl: still WHAT (N s)``; a step that was said ends with
    ``xairl: WHAT: done in N s``. A quick step says nothing, so an error in it stays the one line on stderr. A progress bar on the stream is cleared and redrawn around each line
    (tqdm.write). ``enabled=False``: nothing is said."""
    if not enabled:
        yield
        return
    quiet_tqdm()
    from tqdm.auto import tqdm

    every = EVERY if every is None else every
    t0, stop, token, said = time.monotonic(), threading.Event(), object(), []

    def say(line: str) -> None:
        tqdm.write(f"xairl: {line}", file=stream or sys.stderr)
        (stream or sys.stderr).flush()
        _LAST[0] = time.monotonic()
        said.append(line)

    poll = max(every / 10, 0.01)

    def beat() -> None:
        while not stop.wait(poll):  # said one poll early, so that the silence never runs past ``every``
            if _STEPS and _STEPS[-1] is token and time.monotonic() - _LAST[0] >= every - poll:
                say(f"still {what} ({time.monotonic() - t0:.0f} s)" if said else f"{what} ...")

    if not _STEPS:  # the silence starts now; the first step is said once it has run for half of ``every``
        _LAST[0] = t0 - every / 2
    _STEPS.append(token)
    thread = threading.Thread(target=beat, name="xairl-heartbeat", daemon=True)
    thread.start()
    try:
        yield
    finally:
        stop.set()
        thread.join()
        _STEPS.remove(token)
    if said:
        say(f"{what}: done in {time.monotonic() - t0:.0f} s")
