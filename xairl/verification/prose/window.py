"""A window of observations (:mod:`xairl.policies.windows`) read as it is narrated: per signal, with each signal's newest
value, its change over the window and the window's span among the numbers a text may cite."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from xairl.explanations.explanation import Explanation
from xairl.facts import Comparison, DomainFacts, domain_facts
from xairl.policies.policy import Policy
from xairl.policies.windows import real_start, said_change, window_of
from xairl.verification.prose.book import FactBook, FeatureFacts, add_facts


def per_signal(explanation: Explanation) -> Explanation:
    """A window read as it is narrated: per signal with its newest value, each signal's change over the window and
    the window's span kept in ``extras['window']`` (numbers a text may cite: :func:`aids`)."""
    window = window_of(explanation)
    out = explanation.by_signal()
    cols = np.stack(list(window.signal_columns().values()))  # (signals, steps)
    states, start = explanation.states, real_start(explanation.states, window)  # its padding is no observation
    oldest = states[np.arange(len(states))[:, None], cols[:, start].T]
    changes = states[:, cols[:, -1]] - oldest
    steps = window.steps - start  # per state: the observed steps
    span = None if window.step_s is None else (steps - 1) * window.step_s
    kept = {"changes": changes, "span_s": span, "steps": steps, "states": states}
    if window.frames:  # a frame stack: each frame's patch stays citable by its own name ('patch F6 of frame 2')
        kept["slots"] = {"names": explanation.feature_names, "values": explanation.values}
    return replace(out, extras={**out.extras, "window": kept})


def _window_facts(explanation: Explanation, index: int, policy: Policy | None) -> DomainFacts:
    """Each signal's change over the window as narratives say it (:func:`xairl.policies.windows.said_change`, before its
    unit) and the window's span."""
    w, out = explanation.extras["window"], []
    for j, name in enumerate(explanation.feature_names):
        info = policy.features.get(name) if policy else None
        if info is not None and info.kind != "numeric":  # a label or an id has no change to cite
            continue
        size, unit = said_change(float(w["changes"][index, j]), *((info.unit, info.capacity) if info else ("", None)))
        out.append(Comparison(f"{name} changed", abs(size), unit))
    span = None if w["span_s"] is None else float(w["span_s"][index])
    out += [Comparison("window", span, "s")] if span else []
    return DomainFacts(comparisons=(*out, Comparison("window steps", float(w["steps"][index]), "observations")))


def add_window_facts(book: FactBook, explanation: Explanation, index: int, policy: Policy | None) -> None:
    """The changes and the span as citable numbers, each signal's change as one of its facts, and the policy's own
    facts (its hook sees the whole window, which the per-signal explanation no longer holds)."""
    facts = _window_facts(explanation, index, policy)
    add_facts(book, facts)
    if policy is not None and policy.facts_hook is not None:  # the plugin's facts, from the whole window
        chosen, runner_up = int(explanation.chosen[index]), int(explanation.runner_up[index])
        add_facts(book, domain_facts(policy, explanation.extras["window"]["states"][index], chosen, runner_up))
    _add_slots(book, explanation, index)
    for c in facts.comparisons:
        name = c.text.removesuffix(" changed")
        if name in book.features and c.text.endswith(" changed"):
            book.features[name].change = c.value


def _add_slots(book: FactBook, explanation: Explanation, index: int) -> None:
    """A frame stack's patches frame by frame, as facts of their own: their mean pixel value and their push to the
    chosen action and to the margin (ranks are said of the regions over the frames, as narrated)."""
    w = explanation.extras["window"]
    if "slots" not in w:
        return
    chosen, runner_up = int(explanation.chosen[index]), int(explanation.runner_up[index])
    values, deciding = w["slots"]["values"][index], explanation.output == "actions" and runner_up != chosen
    for j, name in enumerate(w["slots"]["names"]):
        contribs = {"chosen": float(values[j, chosen])}
        if deciding:
            contribs["margin"] = float(values[j, chosen] - values[j, runner_up])
        book.features[name] = FeatureFacts(value=float(w["states"][index, j]), contribs=contribs)
