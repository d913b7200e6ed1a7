"""Narration: facts by code, words by a template or a local language model, every claim verified."""

from __future__ import annotations

from pathlib import Path

from xairl.explanations.explanation import Explanation
from xairl.narrators.base import Narrative, Narrator
from xairl.narrators.confidence import confidence
from xairl.narrators.options import NarrationOptions
from xairl.verification import verify
from xairl.verification.result import Verification


def narrate(
    explanation: Explanation,
    index: int | None = 0,
    *,
    narrator: str = "template",
    options: dict | None = None,
    store=None,
    narration: NarrationOptions | None = None,
    **given,
) -> Narrative:
    """Words for decision ``index`` (``None``: a global summary over all states), checked against the numbers.

    :param narrator: a registered narrator ('template', 'local_lm', or a plugin's).
    :param options: the narrator's options (e.g. ``{"audience": "operator"}`` for local_lm), validated.
    :param store: a :class:`xairl.outputs.feedback.FeedbackStore` that records the shown narrative, with its evidence
        (the state, the margin's contributions, the sentences' statuses) for the review page.
    :param narration: how to narrate (:class:`NarrationOptions`); its fields may be given as keyword arguments
        instead (``xairl.narrate(exp, 0, policy=policy, background=bg)``), and those win.
    """
    from xairl.registry.plugins import registry

    how = NarrationOptions.of(narration, **given)  # (checked before a narrator, maybe a language model, loads)
    writer: Narrator = registry("narrator").load(narrator)(options)
    narrative = writer.narrate(explanation, index, narration=how)
    if store is not None:
        store.record(narrative, policy=how.policy)  # with its evidence: the numbers of what it says
    return narrative


def prepare(
    explanation: Explanation,
    requests: list[tuple[int, NarrationOptions | dict]],
    *,
    narrator: str = "template",
    options: dict | None = None,
) -> None:
    """Let ``narrator`` word several decisions together before :func:`narrate` shows them one by one:
    ``requests`` holds (index, how to narrate it) pairs, as :func:`narrate` takes them. ``local_lm`` scores each
    step's choices of all of them in one batched forward pass; the texts are those :func:`narrate` gives alone.
    The template narrator does nothing here."""
    from xairl.registry.plugins import registry

    asked = [(i, NarrationOptions.of(None, **dict(how))) for i, how in requests]
    registry("narrator").load(narrator)(options).prepare(explanation, asked)


def check_template(path: str | Path, *, notes: bool = False, verbose=None) -> list[str]:
    """Problems of a template file, one line each: the static checks of :func:`xairl.templates.prompts.check` with a trial
    rendering on sample facts, then the battery (:mod:`xairl.narrators.battery`): each claim word the template writes
    as literal text (with its file:line and the filter to write it with), then the template rendered on generated
    decisions of every policy kind, each rendering verified by provenance, and each contradicted one reported with
    the template's file:line, the decision, the sentence and the claim. What ``xairl prompts check`` prints.

    :param notes: also return the advice lines, prefixed 'note:' (a plugin template that needs its plugin's extras;
        a plugin policy left out of the battery), after the problems.
    :param verbose: called with a line saying how many cases and renderings the battery ran, how many problems it
        found, and in what time.
    """
    from xairl.narrators.battery import run
    from xairl.narrators.samples import sample_context
    from xairl.templates import prompts

    problems = prompts.check(path, sample_context)
    if problems:
        return problems
    report = run(prompts.parse(Path(path)))
    if verbose is not None:
        verbose(report.summary())
    return report.problems + (report.notes if notes else [])


__all__ = [
    "NarrationOptions",
    "Narrative",
    "Narrator",
    "Verification",
    "check_template",
    "confidence",
    "narrate",
    "prepare",
    "verify",
]
