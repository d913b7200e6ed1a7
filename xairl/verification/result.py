"""The result types: a claim, a sentence's claims, a text's verdict.

Three verdicts (:attr:`Verification.status`):

- ``verified``: every claim was checked, and each is true;
- ``contradicted``: a claim the words bind (by a tracked fact, grammar or adjacency) is false;
- ``partly checked``: nothing contradicted, but some claim was left unchecked; :attr:`Verification.coverage` says
  how much was checked.

A sentence that states nothing to check (no name, number nor claim word) neither blocks nor counts toward a verdict.
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class Claim:
    """kind: number | feature | direction | rank | action | category | magnitude; status: verified | contradicted
    | unchecked; ``rule``: which reading bound it, where one is named (``xairl verify --trace`` shows it)."""

    kind: str
    text: str
    status: str
    detail: str = ""
    rule: str = ""
    #: (the feature a number was bound to, the feature whose fact it states instead), for a number left unchecked
    #: because it states another feature's fact: two numbers of a text that cross this way are swapped
    crosses: tuple[str, ...] = field(default=(), repr=False, compare=False)
    #: the tracked span (:class:`xairl.templates.tracking.Span`: where, what fact) of a claim about a value xairl printed
    #: itself; None for a claim the reader made from words
    span: object = field(default=None, repr=False, compare=False)


#: the kinds of claim that state something checkable (a name's mere mention does not)
CHECKED = frozenset(
    {"number", "direction", "rank", "action", "category", "magnitude", "level", "comparison", "role", "text"}
)
#: the rule of a counterfactual sentence's claims (:mod:`xairl.verification.own.counterfactual`)
COUNTERFACTUAL = "tracked.counterfactual"
VERDICTS = ("verified", "contradicted", "partly checked")


def _counts(claims) -> bool:
    """Whether a sentence's claims state something: a checkable kind, a tracked value (a name printed from the facts
    is checked by its fact) or anything left unchecked."""
    return any(c.status == "unchecked" or c.kind in CHECKED or c.span is not None for c in claims)


@dataclass(frozen=True)
class SentenceCheck:
    """One sentence: its claims and status: 'contradicted' (a claim is false), 'verified' (every claim checked and
    true), 'unchecked' (something in it was not checked, nothing false) or 'none' (it states nothing to check)."""

    text: str
    claims: tuple[Claim, ...]

    @property
    def status(self) -> str:
        if any(c.status == "contradicted" for c in self.claims):
            return "contradicted"
        if any(c.status == "unchecked" for c in self.claims):
            return "unchecked"
        return "verified" if _counts(self.claims) else "none"


@dataclass(frozen=True)
class Verification:
    """The verdict on a text: every claim, every sentence, the claim coverage and one of three verdicts (module doc).

    :param account: for a decision, what the narrative's features account for of the margin (or score) and what it
        leaves out ('4 more features pushed against it, together -14.8'); '' when not known.
    """

    sentences: tuple[SentenceCheck, ...]
    note: str = ""
    account: str = ""

    @property
    def claims(self) -> tuple[Claim, ...]:
        return tuple(c for s in self.sentences for c in s.claims)

    @property
    def coverage(self) -> float:
        """The share of the text's checkable claims that were checked (1.0 for a text that states nothing)."""
        counted = [c for c in self.claims if _counts((c,))]
        return sum(c.status != "unchecked" for c in counted) / len(counted) if counted else 0.0

    @property
    def status(self) -> str:
        """'verified', 'contradicted' or 'partly checked' (module doc)."""
        if any(s.status == "contradicted" for s in self.sentences):
            return "contradicted"
        said = [s for s in self.sentences if s.status != "none"]
        return "verified" if said and all(s.status == "verified" for s in said) else "partly checked"

    @property
    def accurate(self) -> bool:
        """Nothing the text says is contradicted (coverage aside)."""
        return self.status != "contradicted"

    @property
    def ok(self) -> bool:
        """Verified: every claim checked and true (what narration gates on)."""
        return self.status == "verified"

    def problems(self) -> list[Claim]:
        """Contradicted claims first, then (for a text that is not verified) what was left unchecked."""
        bad = [c for c in self.claims if c.status == "contradicted"]
        if not bad and not self.ok:
            bad = [c for c in self.claims if c.status == "unchecked"] or [
                Claim("coverage", "", "unchecked", "the text states nothing to check")
            ]
        return bad
