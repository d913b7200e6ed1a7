"""What the checks of names share: a claim over a name that may mean several features, the action a mention means,
a direction said of names."""

from __future__ import annotations

import numpy as np

from xairl.verification.prose.book import FactBook
from xairl.verification.prose.names import Mention
from xairl.verification.result import Claim

EITHER = "either"  # a sentence's view when its words weigh two options without naming the view (margin or score)


def over_keys(keys: tuple[str, ...], test, what: str, text: str, kind: str) -> Claim:
    """A claim about a mention that may mean several features: verified when it holds for all of them,
    contradicted when for none, else unchecked (ambiguous)."""
    results = [test(k) for k in keys]
    known = [r for r in results if r is not None]
    if not known:
        return Claim(kind, text, "unchecked", f"nothing known to check it against ({what})")
    if all(r[0] for r in known) and len(known) == len(results):
        return Claim(kind, text, "verified", known[0][1])
    if not any(r[0] for r in known):
        return Claim(kind, text, "contradicted", known[0][1])
    return Claim(kind, text, "unchecked", f"ambiguous: it may mean {', '.join(keys)}")


def resolve_action(m: Mention, book: FactBook) -> str | None:
    """The action a mention means: itself, or for a head word shared by several actions the chosen (else the
    runner-up) one among them."""
    if len(m.keys) == 1:
        return m.keys[0]
    for a in (book.chosen, book.runner_up):
        if a in m.keys:
            return a
    return None


def check_direction(subjects: list[Mention], polarity: int, ctx: str, word: str, book: FactBook) -> list[Claim]:
    def test(key):
        contribs = book.features[key].contribs
        views = [v for v in book.contexts if v in contribs] if ctx == EITHER else [ctx if ctx in contribs else "chosen"]
        cs = [(v, contribs.get(v)) for v in views if contribs.get(v)]
        if not cs:
            return None
        ok = [(v, c) for v, c in cs if np.sign(c) == polarity]
        v, c = (ok or cs)[0]
        return bool(ok), f"{key}'s contribution ({v}) is {c:+.3g}"

    return [over_keys(s.keys, test, ctx, word, "direction") for s in subjects]
