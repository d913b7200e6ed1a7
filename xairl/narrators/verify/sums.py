"""Numbers that sum over several features: 'A and B together add x' (:func:`sum_number`), totals or side sums after
words that say so, 'the positives add up to x', '11.3 of 21.9 points' (:func:`aggregate_number`), and the output less
one feature's push, 'without A it would sit at x' (:func:`without_number`)."""

from __future__ import annotations

import re
from dataclasses import replace

from xairl.narrators.verify.book import FactBook
from xairl.narrators.verify.checks import EITHER, Claim
from xairl.narrators.verify.numbers import Number, matches, percent_reading

#: words that say a number sums over the features: 'the positives add up to', 'total absolute attribution',
#: 'sum_shap=', 'net', 'n_features='
AGGREGATE_CUE = re.compile(
    r"\b(?:total|sum\w*|add(?:s|ed)?\s+up|altogether|combined|in all|overall|net|positives|"
    r"negatives|(?:positive|negative|upward|downward)\s+(?:side|factors|contributions|push|"
    r"pressure|drivers|ones)|absolute|pos|neg|pos_\w+|neg_\w+|n_features)\b",
    re.IGNORECASE,
)


#: 'x of y': the whole a part is of ('11.3 of 21.9 points', '$665 of roughly $806')
_PART_OF = re.compile(
    r"\d[\d.,]*\s*(?:points?|pts|%)?\s+of\s+(?:roughly\s+|about\s+|around\s+|some\s+)?[$€£]?\s*$", re.IGNORECASE
)


#: a total's word right after it: '6.3 points in total', '$806 in total reductions'
_TOTAL_AFTER = re.compile(r"\s*(?:(?:points?|pts)\s*)?(?:in total|in all|altogether|combined|overall)\b", re.IGNORECASE)


def sum_reading(n: Number, masked: str, names, book: FactBook) -> Claim | None:
    """:func:`aggregate_number`, else :func:`without_number`, each with its rule's id; None for neither."""
    summed = aggregate_number(n, masked, book)
    if summed is not None:  # 'the positives add up to about +0.39', 'total absolute attribution of 1.62'
        return replace(summed, rule=summed.rule or "number.aggregate")
    removed = without_number(n, masked, names, book)  # 'without the add-on's contribution it would sit at 12.4%'
    return replace(removed, rule="number.without") if removed is not None else None


def aggregate_number(n: Number, masked: str, book: FactBook) -> Claim | None:
    """A number after words that sum over the features, equal to one such sum (:attr:`FactBook.aggregates`):
    verified; after words naming one side ('the positives add up to'), the other side's sum in size is a sign error,
    contradicted (``number.other-side``); otherwise None (its other readings decide)."""
    before = masked[max(0, n.start - 50) : n.start]
    after = _SIDE_AFTER.match(masked, n.end)  # ('about 57% of the 22.4 h upward push')
    if not book.aggregates or not (
        AGGREGATE_CUE.search(before) or _PART_OF.search(before) or _TOTAL_AFTER.match(masked, n.end) or after
    ):
        return None

    def states(v: float) -> bool:  # ('50 %' is a share; '21.9 points' a sum of contributions in points, or of
        return (matches(n, v) and (n.points or not n.percent)) or (n.points and percent_reading(n, v))  # probabilities

    side = [after] if after else [m for m in _SIDE.finditer(before) if not re.search(r"[\0\d,]", before[m.end() :])]
    if side:  # 'the positives add up to +0.39': that side's sum, in any view; the other side's is a sign error
        said = "positive" if side[-1].group("pos") else "negative"
        other = "negative" if said == "positive" else "positive"
        stated = next((w for w, v in book.aggregates.items() if f" {other} " not in w and states(v)), None)
        if stated is not None:  # (its side's sum, or a whole the words may mean: the net)
            return Claim("number", n.text, "verified", stated)
        size = replace(n, value=abs(n.value), sign="", alternatives=())
        wrong = [(w, v) for w, v in book.aggregates.items() if f" {other} " in w and matches(size, abs(v))]
        if wrong and not after:  # (a side named after the number only verifies: 'adds 6.9 of positive ...')
            said_sums = ", ".join(f"{w} is {v:+.4g}" for w, v in book.aggregates.items() if f" {said} " in w)
            return Claim(
                "number",
                n.text,
                "contradicted",
                f"{said_sums}; {n.text} is the size of {wrong[0][0]}",
                "number.other-side",
            )
        if wrong:
            return None  # (not the other side's sum read as verified either)
    for what, v in book.aggregates.items():
        if states(v):
            return Claim("number", n.text, "verified", what)
    return None


#: a side of the decision named right before its sum ('the positives add up to', 'downward ones about', 'pos_sum=')
_SIDE = re.compile(
    r"\b(?:(?P<pos>positives?|upward|pos(?:_\w+)?|pushing (?:it |the \w+ )?up)|"
    r"(?P<neg>negatives?|downward|neg(?:_\w+)?|pulling (?:it |the \w+ )?down))\b",
    re.IGNORECASE,
)


#: a side named right after its sum: '22.4 h upward push', '2.84 of positive contributions'
_SIDE_AFTER = re.compile(
    r"\s*(?:[a-zA-Z%]{1,6}\s+)?(?:of\s+)?(?:(?P<pos>upward|positive)|(?P<neg>downward|negative))"
    r"\s+(?:push|pressure|contributions?|side|total|factors|effects?)\b",
    re.IGNORECASE,
)


def sum_number(n: Number, members: list[tuple[str, ...]], ctx: str | None, book: FactBook) -> Claim:
    """'A and B together add x': x is the sum of their contributions (in the sentence's view, any when it names none);
    a member that may mean several features counts only when every meaning agrees."""
    contexts = book.contexts if ctx in (EITHER, None) else (ctx,)
    combos = [()]
    for keys in members:
        combos = [c + (k,) for c in combos for k in keys]

    def close(total: float, k: int) -> bool:  # a sum of k rounded figures may be off by k half-steps
        return (
            matches(n, total)
            or (
                not n.hedge
                and abs(abs(n.value) - abs(total)) <= k * n.unit / 2 + 1e-9
                and (not n.sign or (n.value < 0) == (total < 0))
            )
            or (n.points and percent_reading(n, total if n.sign else abs(total)))
        )  # ('25 points' of -0.246)

    if n.percent and not n.points:  # 'A and B together explain about 70 % of the attribution': their shares (of
        # all |contributions|, of their side's, of the net change: 'together add 34.1, about 87 % of it')
        results = [
            any(
                all(view in getattr(book.features[k], kind) for k in combo)
                and matches(n, sum(getattr(book.features[k], kind)[view] for k in combo))
                for view in contexts
                for kind in ("shares", "side_shares", "net_shares")
            )
            for combo in combos
        ]
        total = sum(book.features[k].shares.get(contexts[0], 0.0) for k in combos[0])
        text = f"the sum of {', '.join(combos[0])}'s shares is {total:.3g} %"
        return _sum_claim(n, results, text)
    results = [
        any(
            all(view in book.features[k].contribs for k in combo)
            and close(sum(book.features[k].contribs[view] for k in combo), len(combo))
            for view in contexts
        )
        for combo in combos
    ]
    total = sum(book.features[k].contribs.get(contexts[0], 0.0) for k in combos[0])
    return _sum_claim(n, results, f"the sum of {', '.join(combos[0])}'s contributions is {total:.4g}")


def _sum_claim(n: Number, results: list[bool], text: str) -> Claim:
    """Verified when every reading of the members holds, contradicted when none does, else ambiguous."""
    if all(results):
        return Claim("number", n.text, "verified", text)
    return Claim(
        "number",
        n.text,
        "unchecked" if any(results) else "contradicted",
        "ambiguous: a member may mean several features" if any(results) else text,
    )


#: a name removed from the decision: 'without the warranty add-on's contribution', 'even without the battery term'
#: words that take features' pushes away: 'without the', 'remove the', 'ignoring', 'excluding', 'minus', 'but for'
_WITHOUT = re.compile(
    r"\b(?:without|remov(?:e|ing)|ignor(?:e|ing)|exclud(?:e|ing)|minus|tak(?:e|ing) away|"
    r"leav(?:e|ing) out|set(?:ting)? aside|strip(?:ping)? out|but for|absent)\s+"
    r"(?:the\s+|its\s+|his\s+|her\s+|their\s+)?",
    re.IGNORECASE,
)


#: a hypothetical that takes the names after it away once its removal is said: 'if A had contributed nothing', 'had
#: A been removed', 'if the A term were removed (its -0.47)', 'had A matched (no contribution from that feature)'
_IF = re.compile(r"\b(?:if|had|were|suppose|imagine|assuming)\b", re.IGNORECASE)
_REMOVED_AFTER = re.compile(
    r"\b(?:(?:had|has|have)\s+)?(?:contributed|added|counted)\s+(?:nothing|zero|0)\b|"
    r"\b(?:were|was|is|are|be|been)\s+(?:removed|dropped|taken out|zeroed|excluded|ignored|"
    r"left out|set to (?:zero|0)|switched off|turned off)\b|\bno contribution\b|"
    r"\bremoving (?:its|their|that)\b|\((?:its|their)\s+[+\-−]?\d",
    re.IGNORECASE,
)


def _removed(n: Number, masked: str, names) -> list:
    """The names a clause before ``n`` takes away: those after a cue of :data:`_WITHOUT`, or, in a hypothetical
    (:data:`_IF`), those between its word and the removal said after them (:data:`_REMOVED_AFTER`)."""

    def unbroken(a: int) -> bool:  # no sentence break between there and the number
        return not re.search(r"(?<!\d)[.;]|[.;](?!\d)", masked[a : n.start])

    cue = next(
        (c for c in reversed(list(_WITHOUT.finditer(masked, max(0, n.start - 120), n.start))) if unbroken(c.end())),
        None,
    )
    after = [m for m in names if cue is not None and cue.end() <= m.start and m.end <= n.start]
    if after:
        return after
    said = next(
        (
            c
            for c in reversed(list(_REMOVED_AFTER.finditer(masked, max(0, n.start - 120), n.start)))
            if unbroken(c.end())
        ),
        None,
    )
    for word in reversed(list(_IF.finditer(masked, max(0, n.start - 160), said.start()) if said else [])):
        inside = [m for m in names if word.end() <= m.start and m.end <= said.start()]
        if inside or not unbroken(word.end()):
            return inside
    return []


def without_number(n: Number, masked: str, names, book: FactBook) -> Claim | None:
    """A number in a clause that takes named features' pushes away ('without the warranty add-on's contribution it
    would sit at about 12.4%', 'even without the battery term, returning would still sit 1.55 above the average',
    'Remove the state-of-charge penalty and the Q-value would sit at about 0.77', 'Without A (-0.18) and B (-0.29),
    it would have been about 2.97'): verified when it is the prediction, its change from the baseline or the margin
    less those pushes; otherwise None (its other readings decide)."""
    removed = _removed(n, masked, names)
    if not removed or any(len(m.keys) != 1 or m.keys[0] not in book.features for m in removed):
        return None
    keys = list(dict.fromkeys(m.keys[0] for m in removed))
    contribs = [book.features[k].contribs for k in keys]
    score = book.scores.get(book.chosen)
    readings = []
    if score is not None and all("chosen" in c for c in contribs):
        pushed = sum(c["chosen"] for c in contribs)
        readings.append(("the prediction", score - pushed))
        if book.base is not None:
            readings.append(("the change from the baseline", score - book.base - pushed))
    if book.margin is not None and all("margin" in c for c in contribs):
        readings.append(("the margin", book.margin - sum(c["margin"] for c in contribs)))
    for what, v in readings:
        if matches(n, v) or (n.percent and percent_reading(n, v)):
            return Claim("number", n.text, "verified", f"{what} without {' and '.join(keys)}'s contribution is {v:.4g}")
    return None
