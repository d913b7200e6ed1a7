"""A backtracking regex matcher that counts its steps, for tests that bound a pattern's work without a clock.

It walks the tree Python's own parser gives (``re._parser``) the way Python's engine does (greedy repeats try one
more first, alternatives in order, lookarounds and atomic groups), so a pattern that backtracks catastrophically here
does so in ``re`` too; a run stops with :class:`TooManySteps` once it has spent its budget. The steps are
deterministic: the same pattern and text always take the same number, on any machine and under any load. Character
classes are read approximately (Unicode categories by ``str`` methods), which changes no count that matters here.
"""

from __future__ import annotations

import re
import sys

try:
    from re import _constants as C  # Python 3.11+
    from re import _parser as P
except ImportError:  # Python 3.10
    import sre_constants as C  # type: ignore[no-redef]
    import sre_parse as P  # type: ignore[no-redef]

_CATEGORIES = {
    C.CATEGORY_DIGIT: str.isdecimal,
    C.CATEGORY_SPACE: str.isspace,
    C.CATEGORY_WORD: lambda ch: ch.isalnum() or ch == "_",
    C.CATEGORY_NOT_DIGIT: lambda ch: not ch.isdecimal(),
    C.CATEGORY_NOT_SPACE: lambda ch: not ch.isspace(),
    C.CATEGORY_NOT_WORD: lambda ch: not (ch.isalnum() or ch == "_"),
}
_ATOMIC = getattr(C, "ATOMIC_GROUP", None)
_POSSESSIVE = getattr(C, "POSSESSIVE_REPEAT", None)


class TooManySteps(Exception):
    """The match took more steps than its budget."""


class StepCounter:
    """Counts the steps of matching one compiled pattern. :param budget: steps before :class:`TooManySteps`."""

    def __init__(self, pattern: re.Pattern, budget: int = 1_000_000):
        self.pattern, self.budget, self.steps = pattern, budget, 0
        self.tree = list(P.parse(pattern.pattern, pattern.flags))
        self.text, self.found = "", False

    # -- the public ways to run it: each returns the steps it took (and raises TooManySteps past the budget)
    def match(self, text: str, pos: int = 0) -> int:
        return self._run(text, [pos])

    def search(self, text: str) -> int:
        return self._run(text, range(len(text) + 1))

    def _run(self, text: str, starts) -> int:
        self.text, self.steps, self.found = text, 0, False
        limit = sys.getrecursionlimit()
        sys.setrecursionlimit(max(limit, 50_000))
        try:
            for start in starts:
                if self._seq(self.tree, 0, start, {}, self.pattern.flags, lambda p, caps: True):
                    self.found = True
                    break
        finally:
            sys.setrecursionlimit(limit)
        return self.steps

    # -- the engine: continuation passing, each call one step
    def _tick(self) -> None:
        self.steps += 1
        if self.steps > self.budget:
            raise TooManySteps(f"more than {self.budget} steps")

    def _char(self, op, av, ch: str, flags: int) -> bool:
        fold = flags & re.IGNORECASE
        if op == C.ANY:
            return ch != "\n" or bool(flags & re.DOTALL)
        if op in (C.LITERAL, C.NOT_LITERAL):
            same = ch == chr(av) or (fold and ch.lower() == chr(av).lower())
            return same == (op == C.LITERAL)
        negate, found = False, False
        for kind, value in av:  # IN: a class
            if kind == C.NEGATE:
                negate = True
            elif kind == C.LITERAL:
                found = found or ch == chr(value) or bool(fold and ch.lower() == chr(value).lower())
            elif kind in (C.RANGE, getattr(C, "RANGE_UNI_IGNORE", C.RANGE)):
                lo, hi = value
                found = found or any(lo <= ord(c) <= hi for c in ({ch, ch.lower(), ch.upper()} if fold else {ch}))
            elif kind == C.CATEGORY:
                found = found or _CATEGORIES[value](ch)
        return found != negate

    def _at(self, code, pos: int, flags: int) -> bool:
        text = self.text

        def word(i):
            return 0 <= i < len(text) and (text[i].isalnum() or text[i] == "_")

        if code in (C.AT_BEGINNING, C.AT_BEGINNING_STRING):
            return pos == 0 or (code == C.AT_BEGINNING and flags & re.MULTILINE and text[pos - 1] == "\n")
        if code == C.AT_END:
            return (
                pos == len(text)
                or (pos == len(text) - 1 and text[pos] == "\n")
                or bool(flags & re.MULTILINE and pos < len(text) and text[pos] == "\n")
            )
        if code == C.AT_END_STRING:
            return pos == len(text)
        if code == C.AT_BOUNDARY:
            return word(pos - 1) != word(pos)
        if code == C.AT_NON_BOUNDARY:
            return word(pos - 1) == word(pos)
        raise NotImplementedError(code)

    def _seq(self, items, i: int, pos: int, caps: dict, flags: int, k) -> bool:
        self._tick()
        if i == len(items):
            return k(pos, caps)
        op, av = items[i]

        def nxt(p, c):
            return self._seq(items, i + 1, p, c, flags, k)

        if op in (C.LITERAL, C.NOT_LITERAL, C.ANY, C.IN):
            return pos < len(self.text) and self._char(op, av, self.text[pos], flags) and nxt(pos + 1, caps)
        if op == C.AT:
            return self._at(av, pos, flags) and nxt(pos, caps)
        if op == C.BRANCH:
            return any(self._seq(list(alt), 0, pos, caps, flags, nxt) for alt in av[1])
        if op == C.SUBPATTERN:
            group, add, remove, sub = av
            inner = (flags | add) & ~remove

            def close(p, c):
                return nxt(p, {**c, group: (pos, p)} if group else c)

            return self._seq(list(sub), 0, pos, caps, inner, close)
        if op in (C.MAX_REPEAT, C.MIN_REPEAT, _POSSESSIVE):
            return self._repeat(op, av, pos, caps, flags, nxt)
        if op == _ATOMIC:
            end = self._first(list(av), pos, caps, flags)
            return end is not None and nxt(*end)
        if op in (C.ASSERT, C.ASSERT_NOT):
            direction, sub = av
            if direction < 0:  # a lookbehind: its width is fixed
                width = sub.getwidth()[0]
                start = pos - width
                found = start >= 0 and self._seq(list(sub), 0, start, caps, flags, lambda p, c: p == pos)
            else:
                found = self._seq(list(sub), 0, pos, caps, flags, lambda p, c: True)
            return found == (op == C.ASSERT) and nxt(pos, caps)
        if op == C.GROUPREF:
            if av not in caps:
                return False
            said = self.text[caps[av][0] : caps[av][1]]
            return self.text.startswith(said, pos) and nxt(pos + len(said), caps)
        raise NotImplementedError(op)

    def _first(self, sub, pos: int, caps: dict, flags: int):
        found = []
        self._seq(sub, 0, pos, caps, flags, lambda p, c: found.append((p, c)) or True)
        return found[0] if found else None

    def _repeat(self, op, av, pos: int, caps: dict, flags: int, nxt) -> bool:
        lo, hi, sub = av
        sub = list(sub)
        hi = float("inf") if hi == C.MAXREPEAT else hi

        def more(count, p, c):
            self._tick()
            if op == C.MIN_REPEAT and count >= lo and nxt(p, c):
                return True
            if count < hi and self._seq(
                sub, 0, p, c, flags, lambda q, d: (q != p or count < lo) and more(count + 1, q, d)
            ):
                return True
            return op != C.MIN_REPEAT and count >= lo and nxt(p, c)

        if op == _POSSESSIVE:
            ends = []
            self._repeat(C.MAX_REPEAT, av, pos, caps, flags, lambda p, c: ends.append((p, c)) or True)
            return bool(ends) and nxt(*ends[0])
        return more(0, pos, caps)


def steps(pattern: re.Pattern, text: str, how: str = "search", budget: int = 1_000_000) -> int:
    """Steps of ``pattern.search(text)`` (or ``match``); raises :class:`TooManySteps` past ``budget``."""
    counter = StepCounter(pattern, budget)
    return counter.search(text) if how == "search" else counter.match(text)
