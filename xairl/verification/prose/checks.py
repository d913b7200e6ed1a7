"""What the checks of names share: a claim over a name that may mean several features, the action a mention means,
a direction said of names."""

from __future__ import annotations

import re

import numpy as np

from xairl.verification.prose.book import FactBook
from xairl.verification.prose.names import Mention
from xairl.verification.result import Claim

CHECKED = {"number", "direction", "rank", "action", "category", "magnitude"}
EITHER = "either"  # a sentence's view when its words weigh two options without naming the view (margin or score)

_POS = (
    r"rais\w*|increas\w*|boost\w*|lift\w*|add(?:s|ed|ing)?|supports?|supported|supporting|favou?r(?:s|ed|ing)?|"
    r"in favou?r of|toward|towards|push(?:es|ed|ing)? (?:\w+ ){0,2}up|pull(?:s|ed|ing)? (?:\w+ ){0,2}up|"
    r"nudg\w* (?:\w+ )?up|drives?|driven by|driving|tipped|tips|argu\w* for|counted for|counts for|"
    r"positive(?:ly)?|more likely|up by|help(?:s|ed|ing)?|more high|less low"
)
_NEG = (
    r"lower\w*|decreas\w*|reduc\w*|cut(?:s|ting)?|drag\w*|pull(?:s|ed|ing)? (?:\w+ ){0,2}down|"
    r"push(?:es|ed|ing)? (?:\w+ ){0,2}down|nudg\w* (?:\w+ )?down|subtract\w*|"
    r"tak(?:es|ing|e) (?:[\w.,$€£]+ ){0,4}(?:off|away)|"
    r"took (?:[\w.,$€£]+ ){0,4}(?:off|away)|cost(?:s|ing)?|knock\w*|against|away from|oppos(?:e|es|ed|ing)|"
    r"negative(?:ly)?|"
    r"less likely|more low|less high|"
    r"less attractive|weigh\w* against|argu\w* against|drops?|down by|works? against|worked against|loses?|"
    r"los(?:t|ing)|diminish\w*|penali[sz]\w*|hurt(?:s|ing)?|h[eo]ld(?:s|ing)? (?:\w+ ){0,2}back(?: from)?|"
    r"discourag\w*"
)
DIRECTION_RE = re.compile(rf"\b(?:(?P<pos>{_POS})|(?P<neg>{_NEG}))\b", re.IGNORECASE)


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
