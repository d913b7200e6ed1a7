"""The rules on a sentence's literal words: direction words, level words, rank words and comparisons, each judged
against the tracked facts of the feature it is said of."""

from __future__ import annotations

import re

import numpy as np

from xairl.verification.own.lexicon import (
    CHANGE_NEXT,
    CHOSEN_SIDE,
    EXTRA_DIRECTIONS,
    LESS,
    LEVEL,
    MORE,
    NEGATED,
    NOT_RANK,
    NUMERIC,
    ORDINAL,
    SIDE,
    SIDE_OF,
    SIGNED_CONTEXT,
    SUPERLATIVE,
)
from xairl.verification.own.parts import Part
from xairl.verification.own.truth import view_of
from xairl.verification.prose.checks import DIRECTION_RE
from xairl.verification.result import Claim


class WordRules:
    """Mixed into :class:`xairl.verification.own.spans.Sentence`: the rules that read literal words."""

    def directions(self) -> list[Claim]:
        """Each direction word of the literal text against the sign of the feature it is said of."""
        out = []
        for p in self.parts:
            if p.span is not None:  # (a tracked direction word is checked by its fact: truth.check_fact)
                continue
            words = self.text[p.start : p.end]
            found = [(m, 1 if m.group("pos") else -1) for m in DIRECTION_RE.finditer(words)]
            found += [(m, -1 if m.group("neg") else 0) for m in EXTRA_DIRECTIONS.finditer(words)]
            if self._between_numbers(p) and re.fullmatch(r"\W*\w+\W*", words):
                continue  # '-0.97 against +0.88', '3.05 vs 0.71': a comparison of two numbers
            prev = next((q for q in reversed(self.spans) if q.end <= p.start), None)
            if prev is not None and prev.end == p.start and prev.span.fact.quantity == "action":
                side = SIDE_OF.match(words)  # 'the feature most on B's side': for B
                target = self._said_of(p) if side else None
                if target is not None:
                    polarity = -1 if prev.span.fact.role == "runner_up" else 1
                    out.append(self._judge(side.group(0), polarity, target, prev))
            nxt = next((q for q in self.spans if q.start >= p.end), None)
            for m, polarity in found:
                if (
                    nxt is not None
                    and nxt.span.fact.quantity == "value_change"
                    and CHANGE_NEXT.fullmatch(words[m.end() :])
                ):
                    continue  # 'went down by 2.0 dB': a signal's change over its window (its trend rule), no push
                action = self._action_after(p, m.end())
                if action is None and SIDE.fullmatch(m.group(0)) and not CHOSEN_SIDE.match(words, m.end()):
                    continue  # 'favoured a handover to BS 2': a side the words name without a tracked action
                if polarity == 0:  # 'for': a direction only toward a named action
                    if action is None:
                        continue
                    polarity = 1
                if action is not None and action.span.fact.role == "runner_up":
                    polarity = -polarity  # 'favoured B', 'against B': for or against the runner-up
                if NEGATED.search(self.text[max(0, p.start + m.start() - 30) : p.start + m.start()]):
                    polarity = -polarity
                target = self._said_of(p)
                if target is not None:
                    out.append(self._judge(m.group(0), polarity, target, action))
        return out

    def _action_after(self, p: Part, at: int) -> Part | None:
        """The tracked action right after a word at ``at`` of literal part ``p`` ('toward B', 'favoured B')."""
        rest = self.text[p.start + at : p.end]
        if not re.fullmatch(r"\W*(?:the\s+|a\s+|an\s+)?(?:action\s+)?", rest):
            return None
        nxt = next((q for q in self.spans if q.start >= p.end), None)
        if nxt is None or nxt.span.fact.quantity != "action" or re.match(r"['’]s\b", self.text[nxt.end : nxt.end + 3]):
            return None  # ('the most important feature for A's score': a possessive, not a side)
        return nxt

    def _between_numbers(self, p: Part) -> bool:
        before = [q for q in self.spans if q.end <= p.start]
        after = [q for q in self.spans if q.start >= p.end]
        return bool(before and after) and all(
            q.span.fact.quantity in NUMERIC and before[-1].end == p.start and after[0].start == p.end
            for q in (before[-1], after[0])
        )

    def _said_of(self, p: Part) -> Part | None:
        """The feature a direction word of literal part ``p`` is said of: the only name of its segment, else the
        nearest name before it in the sentence, else the first after it in its segment."""
        own = [q for q in self.names if q.segment == p.segment]
        if len({q.span.fact.feature for q in own}) == 1:
            return own[0]
        before = [q for q in self.names if q.end <= p.start]
        if before:
            return before[-1]
        after = [q for q in self.names if q.start >= p.end and q.segment == p.segment]
        return after[0] if after else None

    def _judge(self, word: str, polarity: int, target: Part, action: Part | None) -> Claim:
        name = target.span.fact.feature
        view = "margin" if action is not None and action.span.fact.role == "runner_up" else target.span.fact.view
        fact = self.feature_fact(name, view)
        contribution = None
        if fact is not None:
            contribution = fact.contribution if hasattr(fact, "contribution") else fact.get("mean")
        if contribution is None or contribution == 0:
            return Claim(
                "direction", word, "unchecked", f"{name}: no contribution to judge '{word}' by", "tracked.direction"
            )
        ok = (contribution > 0) == (polarity > 0)
        return Claim(
            "direction",
            word,
            "verified" if ok else "contradicted",
            f"'{word}' is said of {name}, whose contribution is {contribution:+.4g}",
            "tracked.direction",
        )

    def levels(self) -> list[Claim]:
        """A level word the template or model wrote ('wind (normal)', 'a high load') against the level of the one
        feature its segment names (or whose value it follows)."""
        out = []
        for p in self.parts:
            if p.span is not None:
                continue
            for m in LEVEL.finditer(self.text[p.start : p.end]):
                prev = next((q for q in reversed(self.spans) if q.end <= p.start), None)
                own = {q.span.fact.feature: q for q in self.names if q.segment == p.segment}
                right_after = prev is not None and not re.search(r"\w", self.text[prev.end : p.start + m.start()])
                if right_after and prev.span.fact.quantity in ("value", "value_text"):  # '(0.40, low)'
                    name = prev.span.fact.feature
                elif len(own) == 1:
                    name = next(iter(own))
                else:
                    continue
                fact = self.feature_fact(name, None)
                level = getattr(fact, "level", "unknown")
                said = (
                    "typical"
                    if m.group(0).lower() in ("normal", "typical", "moderate", "average")
                    else m.group(0).lower()
                )
                status = "unchecked" if level == "unknown" else "verified" if said == level else "contradicted"
                out.append(Claim("magnitude", m.group(0), status, f"{name}'s level is {level}", "tracked.level"))
        return out

    def ranks(self) -> list[Claim]:
        """A superlative or ordinal in a segment that names one feature: that feature's rank."""
        out = []
        segments = {p.segment for p in self.parts}
        for seg in segments:
            words = "".join(
                self.text[p.start : p.end] if p.span is None else "X" for p in self.parts if p.segment == seg
            )
            names = {q.span.fact.feature: q for q in self.names if q.segment == seg}
            if len(names) != 1 or NOT_RANK.search(words) and not SUPERLATIVE.search(NOT_RANK.sub("", words)):
                continue
            said = (
                1
                if SUPERLATIVE.search(NOT_RANK.sub("", words))
                else next((r for r, pattern in ORDINAL.items() if pattern.search(words)), None)
            )
            if said is None:
                continue
            ((name, q),) = names.items()
            fact = self.feature_fact(name, q.span.fact.view)
            if fact is None or not hasattr(fact, "rank"):
                continue
            signed = bool(DIRECTION_RE.search(words) or SIGNED_CONTEXT.search(words))
            ok = fact.rank == said or (signed and self._signed_rank(name, q.span.fact.view) == said)
            out.append(
                Claim(
                    "rank",
                    f"{name}: {words.strip()[:60]}",
                    "verified" if ok else "contradicted",
                    f"said to rank {said}; {name} ranks {fact.rank}",
                    "tracked.rank",
                )
            )
        return out

    def _signed_rank(self, name: str, view: str | None) -> int:
        views = [v.get(view_of(view)) for v in self.truth.features.values()]
        mine = self.feature_fact(name, view)
        same = sorted(
            (
                abs(f.contribution)
                for f in views
                if f is not None and f.rank and np.sign(f.contribution) == np.sign(mine.contribution)
            ),
            reverse=True,
        )
        return 1 + sum(s > abs(mine.contribution) for s in same)

    def comparisons(self) -> list[Claim]:
        """'A mattered more than B' (two names in one segment, the comparison between them)."""
        out = []
        for a, b in zip(self.names, self.names[1:]):
            if a.segment != b.segment or a.span.fact.feature == b.span.fact.feature:
                continue
            between = self.text[a.end : b.start]
            sign = 1 if MORE.search(between) else -1 if LESS.search(between) else 0
            fa, fb = (
                self.feature_fact(a.span.fact.feature, a.span.fact.view),
                self.feature_fact(b.span.fact.feature, b.span.fact.view),
            )
            if not sign or fa is None or fb is None or not hasattr(fa, "contribution"):
                continue
            x, y = abs(fa.contribution), abs(fb.contribution)
            ok = x >= y - 1e-12 if sign > 0 else x <= y + 1e-12
            out.append(
                Claim(
                    "magnitude",
                    f"{a.span.text}{between}{b.span.text}",
                    "verified" if ok else "contradicted",
                    f"|{a.span.fact.feature}| = {x:.4g}, |{b.span.fact.feature}| = {y:.4g}",
                    "tracked.comparison",
                )
            )
        return out
