"""Narrative (the result) and the Narrator interface.

:meth:`Narrator.narrate` does the shared work for every narrator: facts by code, the template rendered in its
sandbox, the subclass's :meth:`Narrator._compose` for the words, the verifier, the template fallback when the
words fail verification, and the confidence score (xairl.narrators.confidence).
"""

from __future__ import annotations

import html
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field, replace
from functools import partial
from typing import Any, ClassVar

import numpy as np

from xairl.counterfactual_facts import said_counterfactual
from xairl.errors import InputError
from xairl.explanations.evidence import CARD_STYLE, VERDICTS, card_html, evidence
from xairl.explanations.explanation import Explanation
from xairl.facts import DomainFacts, decision_facts, global_facts
from xairl.narrators.confidence import confidence
from xairl.narrators.options import NarrationOptions
from xairl.options import Options, parse_options
from xairl.policies.policy import Policy
from xairl.policies.regions import in_regions
from xairl.templates.tracking import Rendered, Span, joined, locate, track_decision, track_global
from xairl.values import state_value_text
from xairl.verification import verify
from xairl.verification.result import Claim, Verification


@dataclass(frozen=True)
class Narrative:
    """Words for one decision (or the global view), checked against the numbers.

    :param source: the narrator's name, or 'template (fallback: ...)' when its text failed verification.
    :param rejected: the narrator's own text when it failed verification and the template's was shown instead.
    :param verified: the verdict is 'verified' (every claim checked, and true).
    :param sentences: (sentence, status) per sentence of ``text``: 'verified', 'contradicted', 'unchecked' (a claim
        left unchecked) or 'none' (nothing to check), as the verifier found them; the report and the review page mark
        each.
    :param evidence: what an operator checks the words against (:func:`xairl.explanations.evidence.evidence`: the state, the
        contributions to the margin, the sentences' statuses); a notebook shows it as the report's card.
    :param claims: every claim the verifier checked; a claim about a value the template printed carries its tracked
        span (``Claim.span``: where, and the fact it came from).
    :param provenance: the tracked span of every value xairl printed (:class:`xairl.templates.tracking.Span`); give it back to
        ``xairl.verify(text, ..., provenance=narrative.provenance)`` to check the text again by its facts.
    :param status: the verdict on all its checks: 'verified', 'contradicted' or 'partly checked'
        (:attr:`xairl.Verification.status`); a narrative of several outputs (a continuous action's dimensions) takes
        the worst: contradicted, then partly checked. Left out, it is read from ``verified`` and the sentences.
    :param coverage: the share of its checkable claims that were checked (:attr:`xairl.Verification.coverage`).
    :param account: what its features account for of the margin (or score) and what it leaves out
        (:attr:`xairl.Verification.account`); one per output, joined by ' | ', for several.
    """

    text: str
    claims: tuple[Claim, ...]
    verified: bool
    confidence: float
    components: dict[str, float | None]
    source: str
    template: str
    index: int | None
    rejected: str | None = None
    extras: dict = field(default_factory=dict)
    sentences: tuple[tuple[str, str], ...] = ()
    evidence: dict | None = field(default=None, repr=False, compare=False)
    provenance: tuple[Span, ...] = field(default=(), repr=False, compare=False)
    status: str = ""
    coverage: float = 1.0
    account: str = ""

    def __post_init__(self) -> None:
        if not self.status:
            said = {st for _, st in self.sentences}
            worst = "verified" if self.verified else "contradicted" if "contradicted" in said else "partly checked"
            object.__setattr__(self, "status", worst)
        elif self.status not in VERDICTS or self.verified != (self.status == "verified"):
            raise InputError(
                f"a narrative's status is one of {', '.join(VERDICTS)}, and 'verified' exactly when "
                f"verified is true; got {self.status!r} with verified={self.verified}."
            )

    def _repr_html_(self) -> str:
        """Jupyter's view: the evidence card of the HTML report (each sentence marked, the state, the waterfall)."""
        meta = html.escape(f"{self.source}, template {self.template}, state {self.index}")
        return f"<style>{CARD_STYLE}</style>" + card_html(
            self.text,
            self.evidence
            or {
                "sentences": [list(s) for s in self.sentences],
                "confidence": self.confidence,
                "status": self.status,
                "coverage": self.coverage,
                "account": self.account,
            },
            meta,
        )


def join_sentences(sentences: Iterable[str]) -> Rendered:
    """Sentences joined by a space, or by a line break next to a sentence of several lines (a template's list), with
    the tracked spans of those that have them (:class:`xairl.templates.tracking.Rendered`)."""
    parts = [s for s in sentences if s]
    seps = [("\n" if "\n" in a + b else " ") for a, b in zip(parts, parts[1:])]
    return joined([(s, getattr(s, "spans", ())) for s in parts], seps)


def first_phrasings(variants: list[list[str]]) -> Rendered:
    """The deterministic text: the first phrasing of every sentence, with its tracked spans."""
    return join_sentences(s[0] for s in variants if s)


def _checks(words: list[tuple]):
    """(output index, verification) per narrated view: None for a single view, j for dimension j of a continuous
    action (each its own output)."""
    return [(j if len(words) > 1 else None, w[1]) for j, w in enumerate(words)]


def _template(explanation: Explanation, index: int | None, template: str | None, prompt_dirs: Iterable[str]):
    """The template to narrate with (``template``, or the default for the output kind), refused in one line when it
    does not fit a decision or a summary, or the policy's output kind."""
    from xairl.templates import prompts

    default = (
        "global_summary" if index is None else "explain_action" if explanation.output == "actions" else "explain_output"
    )
    tpl = prompts.load(template or default, prompt_dirs)
    if (tpl.spec.kind == "global") != (index is None):
        raise InputError(
            f"template '{tpl.name}' is a {tpl.spec.kind} template; use "
            f"{'index=None' if tpl.spec.kind == 'global' else 'a state index'} with it."
        )
    if index is not None and explanation.output not in tpl.spec.outputs:
        raise InputError(
            f"template '{tpl.name}' narrates {' or '.join(tpl.spec.outputs)} outputs; this policy's "
            f"output is {explanation.output}: use template '{default}'."
        )
    return tpl


def _plan(explanation: Explanation, index: int | None, o: NarrationOptions):
    """(the template, the explanation narrated, its views, the counterfactual said) of one narration."""
    tpl = _template(explanation, index, o.template, o.prompt_dirs)
    # an image is narrated in regions, not pixels (the confidence's robustness still reads the pixels); a
    # continuous action: each dimension is its own output, narrated and verified on its own
    narrated = in_regions(explanation)
    views = (
        [narrated.output_slice(j) for j in range(narrated.values.shape[2])]
        if index is not None and explanation.output == "continuous"
        else [narrated]
    )
    return tpl, narrated, views, said_counterfactual(explanation, index, o.policy, o.counterfactual, o.background)


def _variants(explanation: Explanation, index: int | None, tpl, policy: Policy | None, k: int, history, said):
    """(every variant of every sentence rendered with tracked facts, the template variables, the domain facts the
    words are made from) of one view."""
    facts = (
        global_facts(explanation, policy, k=max(k, 3))
        if index is None
        else replace(decision_facts(explanation, index, policy, k, history), counterfactual=said)
    )
    context = facts.context()
    variants = tpl.render_variants(track_global(context) if index is None else track_decision(context))
    # the domain facts the words were made from (a facts hook given the episode's history states more)
    domain = DomainFacts(facts.extras, facts.comparisons) if index is not None else None
    return variants, context, domain


def variants_of(explanation: Explanation, requests: Iterable[tuple[int, NarrationOptions]]) -> list[list[list]]:
    """The rendered variants of every view of each requested narration, as :meth:`Narrator.narrate` renders them
    (for :meth:`Narrator.prepare`)."""
    out = []
    for index, o in requests:
        index = explanation.check_index(index)
        tpl, _, views, said = _plan(explanation, index, o)
        out += [_variants(view, index, tpl, o.policy, o.k, o.history, said)[0] for view in views]
    return out


class Narrator:
    """Turns an Explanation into words that are checked against its numbers.

    Subclasses set ``name``, optionally an ``Options`` model (pydantic, derived from :class:`xairl.plugin.Options`), and
    implement :meth:`_compose`. :meth:`narrate` is the public method and is not overridden.

    :param options: a dict or an instance of the subclass's ``Options`` model; unknown keys are an error.
    """

    name: ClassVar[str] = ""
    Options: ClassVar[type[Options]] = Options

    def __init__(self, options: dict | Options | None = None):
        self.options = parse_options(self.Options, options, f"{self.name} narrator options")

    def narrate(
        self, explanation: Explanation, index: int | None = 0, *, narration: NarrationOptions | None = None, **given
    ) -> Narrative:
        """Words for decision ``index`` (``None``: a global summary over all states), verified, with confidence.

        :param narration: how to narrate (:class:`NarrationOptions`: template, policy, background, prompt_dirs, k,
            robustness, history, counterfactual); any of its fields may be given as keyword arguments instead, and
            those win.
        """
        o = NarrationOptions.of(narration, **given)
        index = None if index is None else explanation.check_index(index)
        tpl, narrated, views, said = _plan(explanation, index, o)
        words = [self._words(view, index, tpl, o.policy, o.k, o.history, said) for view in views]
        scores, comps = zip(
            *(confidence(explanation, index, c.ok, o, output=j, coverage=c.coverage) for j, c in _checks(words))
        )
        worst = int(np.argmin(scores))  # a continuous action is as trustworthy as its least trustworthy dimension
        told = self._told(words, scores[worst], comps[worst], tpl.name, index, explanation.method)
        return replace(told, evidence=evidence(narrated, told, partial(state_value_text, narrated, policy=o.policy)))

    def _told(self, words: list[tuple], score: float, components: dict, template: str, index, method) -> Narrative:
        """The narrative of the words of every view (a continuous action's dimensions, joined), with its confidence."""
        chosen = [sum(counts) for counts in zip(*(getattr(w[0], "chosen", (0, 0, 0)) or (0, 0, 0) for w in words))]
        sources = [source for _, _, source, _, _ in words]
        text = joined([(w[0], w[0].spans) for w in words], [" "] * (len(words) - 1))
        checks = [check for _, check, _, _, _ in words]
        statuses = {check.status for check in checks}
        return Narrative(
            text=text,
            claims=tuple(c for _, check, _, _, _ in words for c in check.claims),
            provenance=text.spans,
            verified=all(check.ok for _, check, _, _, _ in words),
            confidence=score,
            components=components,
            source=next((s for s in sources if s != self.name), self.name),
            template=template,
            index=index,
            rejected=" ".join(bad for _, _, _, bad, _ in words if bad) or None,
            extras={"method": method, "tries": max(w[4] for w in words)}
            | ({"chosen": tuple(chosen)} if chosen[2] else {}),
            sentences=tuple((s.text, s.status) for _, check, _, _, _ in words for s in check.sentences),
            status=next(v for v in reversed(VERDICTS) if v in statuses),  # the worst of its outputs'
            coverage=Verification(tuple(s for check in checks for s in check.sentences)).coverage,
            account=" | ".join(check.account for check in checks if check.account),
        )

    def _words(
        self, explanation: Explanation, index: int | None, tpl, policy: Policy | None, k: int, history=None, said=None
    ):
        """(text, verification, source, rejected text) for one explanation: the subclass's words, verified, or the
        template's first phrasings when they fail."""
        variants, context, domain = _variants(explanation, index, tpl, policy, k, history, said)
        first = None
        for tries, text in enumerate(self._tries(variants, context), 1):
            if text is None:  # refused by the narrator itself (its words lost a fact)
                first = first or (None, Claim("words", "", "unchecked", "a try lost or added a name or number"))
                continue
            text = text if isinstance(text, Rendered) else Rendered(text, locate(text, variants))
            check = verify(text, explanation, index, policy, facts=domain, provenance=text.spans)
            if check.ok or text == first_phrasings(variants):
                return text, check, self.name, None, tries
            first = first or (text, check.problems()[0])
        rejected, problem = first
        text = first_phrasings(variants)
        check = verify(text, explanation, index, policy, facts=domain, provenance=text.spans)
        source = f"template (fallback: {self.name} text failed verification: {problem.text!r} {problem.status})"
        if rejected is None:
            source = f"template (fallback: {self.name}: {problem.detail})"
        return text, check, source, None if rejected is None else str(rejected), tries

    def prepare(self, explanation: Explanation, requests: Iterable[tuple[int, NarrationOptions]]) -> None:
        """Get ready to narrate these decisions ((index, how) each): a narrator that words several decisions
        together does it here, and :meth:`narrate` then shows each as it would have alone. Default: nothing."""

    def _tries(self, variants: list[list[Rendered]], context: dict[str, Any]) -> Iterator[str | None]:
        """The subclass's words, try after try: the first that verifies is shown, and the template's when none does
        (default: one try, ``_compose``); None is a try the subclass refused itself."""
        yield self._compose(variants, context)

    def _compose(self, variants: list[list[str]], context: dict[str, Any]) -> str:
        """The subclass's words.

        :param variants: one list per sentence of the template; each lists phrasings that state the same facts
            (the first is the template author's default; an empty string means the sentence is left out).
        :param context: the template variables (:meth:`DecisionFacts.context` or :meth:`GlobalFacts.context`),
            for narrators that word the facts themselves.
        :returns: the text to verify. Anything may be returned: a text that fails verification is replaced by
            the template's first phrasings and reported as a fallback.
        """
        raise NotImplementedError
