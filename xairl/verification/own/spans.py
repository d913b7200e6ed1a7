"""One sentence of an own narrative: its tracked spans, and the rules that tie each span to the literal words right
beside it (sign, label, view, trend, a score's action, base) or to its feature's name (binding). No rule reads a
claim word: a claim word is declared through a template filter (its fact checks it), and a literal one leaves the
sentence unchecked (:func:`xairl.verification.own.undeclared`)."""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import replace

from xairl.templates.tracking import Span
from xairl.verification.own.lexicon import (
    AS_CONTRIBUTION,
    BASE_AFTER,
    BASE_WORDS,
    CELL_SCORE,
    DIFFERENCE,
    LABEL_FITS,
    LABELS,
    LESS,
    MORE,
    NUMERIC,
    SCORE_FOR_AFTER,
    SCORE_OF_BEFORE,
    SCORE_SUBJECT,
    SEGMENT,
    SIGN_AFTER,
    SIGN_BEFORE,
    TREND_BEFORE,
    TREND_FITS,
    VIEW_AFTER,
)
from xairl.verification.own.lexicon import CHOSEN_LABEL as _CHOSEN_LABEL
from xairl.verification.own.lexicon import RUNNER_LABEL as _RUNNER_LABEL
from xairl.verification.own.lexicon import SCORE_NEXT as _SCORE_NEXT
from xairl.verification.own.parts import Part, is_name, literal, parts
from xairl.verification.own.truth import MISSING, Truth, number, view_of
from xairl.verification.result import Claim


class Sentence:
    """One sentence's tracked spans and literal words, and the rules that judge the words."""

    def __init__(self, sentence: str, spans: Sequence[Span], truth: Truth):
        self.text, self.truth = sentence, truth
        self.parts = parts(sentence, spans)
        self.spans = [p for p in self.parts if p.span is not None]
        self.names = [p for p in self.spans if is_name(p)]

    def before(self, p: Part, n: int = 40) -> str:
        """The literal words right before ``p`` in its segment (up to the previous span)."""
        prev = [q for q in self.spans if q.end <= p.start]
        a = max([prev[-1].end if prev else 0, p.start - n])
        return self.text[a : p.start]

    def after(self, p: Part, n: int = 40) -> str:
        nxt = [q for q in self.spans if q.start >= p.end]
        return self.text[p.end : min(nxt[0].start if nxt else len(self.text), p.end + n)]

    def binding(self, p: Part) -> Claim | None:
        """A feature's number said of another feature: the name before it in its block (cut at ; : | and line
        breaks), else the first after it in its block, else (a block naming none) the name before it in the sentence;
        a group of names followed by their numbers ('A and B: a against b') pairs them in order."""
        feature, quantity = p.span.fact.feature, p.span.fact.quantity
        own = [q for q in self.names if q.block == p.block]
        before = [q for q in own if q.end <= p.start] or ([] if own else [q for q in self.names if q.end <= p.start])
        if not before:
            after = [q for q in own if q.start >= p.end]
            return None if not after or after[0].span.fact.feature == feature else self._crossed(p, after[0])
        last = before[-1]
        if last.span.fact.feature == feature:
            return None
        earlier = [q for q in self.spans if q.end <= p.start]
        at = earlier.index(last)
        j = sum(q.span.fact.quantity == quantity for q in earlier[at + 1 :])  # its place among the numbers after
        group = []
        for q in reversed(earlier[: at + 1]):
            if q.span.fact.quantity == quantity:
                break
            if is_name(q):
                group.insert(0, q)
        if len(group) > 1 and j < len(group) and group[j].span.fact.feature == feature:
            return None
        return self._crossed(p, last)

    def _sizes_compared(self, p: Part) -> bool:
        """``p`` stands in the list of numbers after 'A mattered more than B' (a block naming no feature): the sizes
        compared, which a value is not."""
        before = [q for q in self.names if q.end <= p.start]
        return (
            len(before) >= 2
            and not any(q.block == p.block for q in self.names)
            and bool(
                MORE.search(self.text[before[-2].end : before[-1].start])
                or LESS.search(self.text[before[-2].end : before[-1].start])
            )
        )

    def _crossed(self, p: Part, other: Part) -> Claim:
        """Which name a value is said of is a binding by position: it may verify, never contradict (a list whose
        line breaks were lost would read each value as the next name's)."""
        return Claim(
            "number",
            p.span.text,
            "unchecked",
            f"{p.span.text} is {p.span.fact.feature}'s {p.span.fact.quantity}, written next to "
            f"{other.span.fact.feature}'s name: print it beside its own feature",
            "tracked.binding",
        )

    def trend_word(self, p: Part) -> tuple[bool, int]:
        """(a trend word stands right before ``p``, the sign it says: +1 'rose', -1 'fell', 0 'changed' or the
        trend's own tracked word, which its fact checks). A literal one counts only for a signal of a window (a
        feature with a change over it), and not when a score is its subject ('the margin grew by 8.8')."""
        prev = [r for r in self.spans if r.end <= p.start]
        if prev and (
            prev[-1].span.fact.quantity == "trend" or getattr(prev[-1].span.fact, "of", None) == "value_change"
        ):
            if re.fullmatch(
                r"\s*(?:by\s*)?(?:(?:about|around|roughly|some|nearly|almost|just)\s*)?",
                self.text[prev[-1].end : p.start],
            ):
                return True, 0
        f = p.span.fact
        if self.truth.get(Span(0, 0, "", replace(f, quantity="value_change"))) in (None, MISSING):
            return False, 0
        m = TREND_BEFORE.search(self.before(p, 24))
        before = SEGMENT.split(self.text[max(0, p.start - 80) : p.start])[-1]
        if m is None or (f.quantity != "value_change" and SCORE_SUBJECT.search(before)):
            return False, 0  # (a signal's own change is one whatever its label: 'the gap to the lead fell 10 m')
        return True, 1 if m.group("up") else -1 if m.group("down") else 0

    def trend(self, p: Part) -> Claim | None:
        """A number right after a trend word ('fell 4.1 dB', literal or a trend's own tracked word) is a signal's
        change over its window, and an 'up' or 'down' word has the change's sign."""
        q = p.span.fact.quantity
        after_word, said = self.trend_word(p)
        if not after_word:
            return None
        if q not in TREND_FITS:
            what = q.replace("_", " ")
            return Claim(
                "number",
                p.span.text,
                "contradicted",
                f"the {what}, written as a change over the window",
                "tracked.trend",
            )
        change = self.truth.get(p.span)
        if isinstance(change, float) and change * said < 0:
            return Claim(
                "direction",
                f"{self.before(p, 24).strip()} {p.span.text}",
                "contradicted",
                f"{p.span.fact.feature} changed by {change:+.4g} over its window",
                "tracked.trend",
            )
        return None

    def sign(self, p: Part) -> Claim | None:
        """A value printed with another sign than it has, and no word around it that carries the sign."""
        f = p.span.fact
        expected = self.truth.get(p.span)
        printed = number(p.span.text)
        if not isinstance(expected, (int, float)) or printed is None or expected >= 0 or printed < 0:
            return None
        if abs(float(expected)) < 1e-9 or SIGN_BEFORE.search(self.before(p, 30)) or SIGN_AFTER.match(self.after(p)):
            return None
        return Claim(
            "number",
            p.span.text,
            "contradicted",
            f"{f.feature}'s value is {float(expected):.4g}: written without its sign",
            "tracked.sign",
        )

    def label(self, p: Part) -> Claim | None:
        """'score=' / 'margin of' / 'average' right before a number of another quantity."""
        q = p.span.fact.quantity
        if q not in NUMERIC | {"value_text"}:
            return None
        before = SEGMENT.split(self.before(p, 24))[-1]  # ('+0.46 to the margin, 16.8 %': the share's own segment)
        if DIFFERENCE.match(self.after(p, 20)):  # 'its score was 2.34 higher': a difference, not the score
            return None
        if q in TREND_FITS and self.trend_word(p)[0]:  # 'fell by 4.1 dB': the trend rule judges it
            return None
        for pattern, group in LABELS:
            if pattern.search(before):
                if q in LABEL_FITS[group]:
                    return None
                return Claim(
                    "number",
                    p.span.text,
                    "contradicted",
                    f"written as the {group}, but it is the {q.replace('_', ' ')}",
                    "tracked.label",
                )
        if BASE_AFTER.match(self.after(p, 30)) and q not in LABEL_FITS["base"]:
            return Claim(
                "number",
                p.span.text,
                "contradicted",
                f"written as the background's average, but it is the {q.replace('_', ' ')}",
                "tracked.label",
            )
        if q in ("value", "value_text") and (AS_CONTRIBUTION.match(self.after(p, 30)) or self._sizes_compared(p)):
            return Claim(
                "number",
                p.span.text,
                "contradicted",
                f"{p.span.fact.feature}'s value, written as its contribution",
                "tracked.label",
            )
        if q == "contribution" and (m := VIEW_AFTER.search(self.after(p, 30))):
            said = "margin" if m.group(1) else "score"
            if said != view_of(p.span.fact.view):
                return Claim(
                    "number",
                    p.span.text,
                    "contradicted",
                    f"a contribution to the {view_of(p.span.fact.view)}, written as one to the {said}",
                    "tracked.view",
                )
        return None

    def role(self, p: Part) -> Claim | None:
        """A score printed beside the other action (the words naming an action's role are declared with ``role``)."""
        if self.truth.output != "actions" or self.truth.actions.get("chosen") == self.truth.actions.get("runner_up"):
            return None
        return self._score_role(p) if p.span.fact.quantity == "score" else None

    def _score_role(self, p: Part) -> Claim | None:
        """A score is the score of the action its words give it to: a 'runner-up' or 'chosen' label right before it,
        else the action right before it ('turn (score 3.05)', 'turn | score 3.05'), else the one right after 'for'
        ('3.99 for B'). Only such adjacency contradicts; an action further back in its block (a binding by position)
        leaves a mismatch unchecked."""
        role, before = p.span.fact.role, self.before(p, 40)
        said = "runner_up" if _RUNNER_LABEL.search(before) else "chosen" if _CHOSEN_LABEL.search(before) else None
        near = said is not None
        if said is None:
            earlier = [q for q in self.spans if q.end <= p.start]
            later = [q for q in self.spans if q.start >= p.end]
            if earlier and earlier[-1].span.fact.quantity in ("action", "role"):
                between = self.text[earlier[-1].end : p.start]
                near = bool(_SCORE_NEXT.fullmatch(between) or CELL_SCORE.fullmatch(between))
                if near or (earlier[-1].block == p.block and SCORE_OF_BEFORE.match(between)):
                    said = earlier[-1].span.fact.role
            if said is None and later and later[0].span.fact.quantity == "action":
                if SCORE_FOR_AFTER.match(self.text[p.end : later[0].start]):
                    said, near = later[0].span.fact.role, True
            if said is None:  # (pairing scores with actions in order is a binding by position)
                said, near = self._respective_role(p), False
        if said is None or said == role:
            return None
        return Claim(
            "number",
            p.span.text,
            "contradicted" if near else "unchecked",
            f"{p.span.text} is the {role.replace('_', '-')}'s score, written "
            + ("as" if near else "after")
            + f" the {said.replace('_', '-')}'s",
            "tracked.role",
        )

    def _respective_role(self, p: Part) -> str | None:
        """'A rather than B: ... (x vs y)': two scores after two actions of different roles pair in order."""
        actions = [q for q in self.spans if q.span.fact.quantity == "action"]
        scores = [q for q in self.spans if q.span.fact.quantity == "score"]
        roles = [q.span.fact.role for q in actions]
        if len(scores) != 2 or len(actions) != 2 or len(set(roles)) != 2 or scores[0].start < actions[-1].end:
            return None
        return roles[scores.index(p)]

    def base(self, p: Part) -> Claim | None:
        """A background average in a sentence with no word that says it is one."""
        if BASE_WORDS.search(literal(self.text, self.parts, 0, len(self.text))):
            return None
        return Claim(
            "number",
            p.span.text,
            "contradicted",
            f"{p.span.text} is the {p.span.fact.quantity.replace('_', ' ')} (the background's average), written "
            "with no word that says so",
            "tracked.label",
        )
