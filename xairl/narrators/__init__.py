"""Narration: facts by code, words by a template or a local language model, every claim verified."""
from __future__ import annotations

from typing import Iterable

from ..explanation import Explanation
from ..policy import Policy
from .base import Narrative, Narrator, confidence
from .facts import decision_facts, global_facts
from .verify import Verification, verify


def narrate(explanation: Explanation, index: int | None = 0, narrator: str = "template", template: str | None = None,
            policy: Policy | None = None, background=None, options: dict | None = None,
            prompt_dirs: Iterable[str] = (), k: int = 3, store=None) -> Narrative:
    """Words for decision ``index`` (``None``: a global summary over all states), checked against the numbers.

    :param narrator: a registered narrator ('template', 'local_lm').
    :param template: template name or .yaml path; default 'explain_action' (or 'global_summary').
    :param policy: gives feature descriptions, domain facts, and (with ``background``) the agreement and
        stability parts of the confidence.
    :param options: the narrator's options (e.g. ``{"mode": "rewrite"}`` for local_lm).
    :param store: a :class:`xairl.feedback.FeedbackStore` that records the shown narrative.
    """
    from .. import prompts
    from ..errors import InputError
    from ..plugins import registry
    from .template import TemplateNarrator

    tpl = prompts.load(template or ("global_summary" if index is None else "explain_action"), prompt_dirs)
    if (tpl.spec.kind == "global") != (index is None):
        raise InputError(f"template '{tpl.name}' is a {tpl.spec.kind} template; use "
                         f"{'index=None' if tpl.spec.kind == 'global' else 'a state index'} with it.")
    facts = global_facts(explanation, policy, k=max(k, 3)) if index is None else decision_facts(
        explanation, index, policy, k)
    variants = tpl.render_variants(facts.context())
    cls = registry("narrator").load(narrator)
    writer: Narrator = cls(**(options or {}))
    text = writer.compose(variants, facts.context())
    check = verify(text, explanation, index, policy)
    source = writer.name
    if not check.ok and writer.name != "template":
        problem = check.problems()[0]
        text = TemplateNarrator().compose(variants, facts.context())
        check = verify(text, explanation, index, policy)
        source = f"template (fallback: {writer.name} text failed verification: {problem.text!r} {problem.status})"
    score, components = confidence(explanation, index, check.ok, policy, background)
    narrative = Narrative(text=text, claims=check.claims, verified=check.ok, confidence=score,
                          components=components, source=source, template=tpl.name, index=index,
                          extras={"method": explanation.method})
    if store is not None:
        store.record(narrative, policy=policy)
    return narrative


__all__ = ["Narrative", "Narrator", "Verification", "confidence", "narrate", "verify"]
