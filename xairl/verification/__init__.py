"""Every word checked against the numbers: one verifier, three verdicts.

- :mod:`.own`: xairl's own narratives, checked by provenance (each tracked value is its fact; a claim word is
  declared through a template filter, and a literal one leaves its sentence unchecked);
- :mod:`.prose`: anything else (outside prose), read by the rule table (``prose/rules.yaml``);
- :mod:`.counterfactual`: a counterfactual sentence re-run through the policy;
- :mod:`.result`: :class:`Claim`, :class:`SentenceCheck`, :class:`Verification` (verified, contradicted, partly
  checked);
- :mod:`.text`: sentences and normalisation, shared by both readers.
"""

from __future__ import annotations

from collections.abc import Sequence

from xairl.errors import InputError
from xairl.explanations.explanation import Explanation
from xairl.facts import DomainFacts
from xairl.policies.policy import Policy
from xairl.templates.tracking import Span
from xairl.verification import own, prose
from xairl.verification.result import Claim, SentenceCheck, Verification
from xairl.verification.text import normalise

__all__ = ["Claim", "SentenceCheck", "Verification", "verify"]


def verify(
    text: str,
    explanation: Explanation,
    index: int | None = 0,
    policy: Policy | None = None,
    facts: DomainFacts | None = None,
    provenance: Sequence[Span] | None = None,
) -> Verification:
    """Check every claim of ``text`` against the explanation of state ``index`` (``None``: the global view).

    :param policy: optional, for feature descriptions, aliases and units, action aliases and domain facts.
    :param facts: optional :class:`xairl.facts.DomainFacts` beyond the explanation (e.g. a flight's handover counts):
        its numbers may be cited. With ``index=None`` a summary is taken to be made from them.
    :param provenance: the tracked spans of an own narrative (:attr:`xairl.Narrative.provenance`, or a rendering's
        ``spans``): each is checked by its fact. Without it the text is read as outside prose.
    :returns: a :class:`Verification` (``.status``: 'verified', 'contradicted' or 'partly checked'); never raises on
        odd text (empty, very long, another language).
    """
    if not isinstance(text, str):
        raise InputError(
            f"verify() reads text (a str), not {type(text).__name__}: decode it first, e.g. data.decode('utf-8')."
        )
    several = explanation.output == "continuous" and explanation.values.shape[2] > 1 and index is not None
    if not provenance or several or normalise(text) != text:
        # (the spans of several dimensions do not say which one: narrate checks each; a text whose spelling
        # normalisation changes was not rendered as it stands, so its offsets would not hold)
        result = prose.read(text, explanation, index, policy, facts)
    else:
        result = own.verify(text, explanation, index, policy, facts, provenance)
    # what the text's features account for of the margin, and what it leaves out (issue 65: beside the coverage)
    from dataclasses import replace

    from xairl.policies.regions import in_regions
    from xairl.verification.account import account, features_named

    named = features_named(result.claims, provenance or ())
    return replace(result, account=account(in_regions(explanation), index, named))
