"""The wordings a template offers between its facts: ``{{ pick('came from', 'was due to') }}``.

A template's sentence may leave some of its words open: ``pick`` lists wordings that say the same thing, and a
rendering holds a *choice point* there (an invisible marker, like a tracked value's). The template narrator shows
the first wording of every choice; the language-model narrator chooses among them (:mod:`xairl.narrators.wording`),
so its text is always a sentence the template can write, with every tracked value in place. A wording may print
tracked values and claim filters (``pick(f|dir('gave', 'cost') ~ ' it', ...)``); a literal claim word in one is
flagged by ``xairl prompts check`` as anywhere else, and every wording is rendered and verified there.

:class:`Draft` is a rendering with its choice points: :meth:`Draft.render` writes it with given choices, and
:meth:`Draft.pieces` gives the clean words of its fixed stretches and wordings, for a model to score.
"""

from __future__ import annotations

import contextvars
import re
from collections.abc import Sequence
from dataclasses import dataclass

from xairl.templates.tracking import Rendered, collecting, strip_markers, untangle

#: start and end of a choice point's marker; its number is written as tracking writes a span's id
_OPEN, _CLOSE, _DIGIT = "\ue003", "\ue004", 0xE010
_POINT = re.compile(f"{_OPEN}([\ue010-\ue01f]+){_CLOSE}")
#: the most wordings one choice may offer, and the longest a wording may be (the model scores each on every use)
MAX_WORDINGS = 6
MAX_WORDING = 200
_CHOICES: contextvars.ContextVar[list | None] = contextvars.ContextVar("xairl_choices", default=None)


class ChoiceError(ValueError):
    """A ``pick`` the template cannot make (the sandbox reports it with the template's file and line)."""


def pick(*wordings) -> str:
    """The template's global ``pick``: a choice among ``wordings`` (the first is the template's own). Outside a
    rendering that keeps choices it prints the first."""
    texts = [str(w) for w in wordings]
    if not texts:
        raise ChoiceError("pick() needs at least one wording")
    if len(texts) > MAX_WORDINGS:
        raise ChoiceError(f"pick() offers {len(texts)} wordings; at most {MAX_WORDINGS}")
    if any(len(strip_markers(t)) > MAX_WORDING for t in texts):
        raise ChoiceError(f"a pick() wording is longer than {MAX_WORDING} characters; pick among short wordings")
    if any(_OPEN in t for t in texts):
        raise ChoiceError("pick() inside pick(); offer the combined wordings in one pick()")
    record = _CHOICES.get()
    if record is None:
        return texts[0]
    record.append(texts)
    return f"{_OPEN}{''.join(chr(_DIGIT + int(d, 16)) for d in f'{len(record) - 1:x}')}{_CLOSE}"


def capitalised(text: str, cap) -> str | None:
    """``text`` is a choice point's marker first (``{{ pick(...)|cap }}``): ``cap`` is applied to each of its
    wordings, and the marker is returned; None when ``text`` does not start with one."""
    m = _POINT.match(text)
    record = _CHOICES.get()
    if m is None or record is None:
        return None
    n = _number(m.group(1))
    record[n] = [cap(w) for w in record[n]]
    return text


def choosing():
    """Within it, ``pick`` leaves a choice point; yields the list of each point's wordings."""
    return collecting(_CHOICES)


def _number(digits: str) -> int:
    return int("".join(f"{ord(c) - _DIGIT:x}" for c in digits), 16)


def _collapsed(text: str) -> str:
    """Spaces collapsed within each line, as the sandbox leaves a rendering (an empty wording leaves none double)."""
    lines = (" ".join(line.split()) for line in text.splitlines())
    return "\n".join(line for line in lines if line)


@dataclass(frozen=True)
class Draft:
    """A rendering with its choice points: ``parts`` alternates fixed marked text and a point's wordings (marked),
    starting and ending with fixed text; ``record`` is the tracked values' record (:func:`untangle`)."""

    parts: tuple
    record: tuple

    @classmethod
    def of(cls, marked: str, choices: list, record: list) -> Draft:
        parts: list = []
        pos = 0
        for m in _POINT.finditer(marked):
            parts += [marked[pos : m.start()], tuple(choices[_number(m.group(1))])]
            pos = m.end()
        return cls((*parts, marked[pos:]), tuple(record))

    @property
    def points(self) -> list[tuple[str, ...]]:
        """Each choice point's wordings, in order."""
        return self.parts[1::2]

    def render(self, choices: Sequence[int] | int = 0) -> Rendered:
        """The text with wording ``choices[k]`` at point k (an int: that wording at every point, or a point's last
        where it offers fewer), with the spans of its tracked values."""
        points = self.points
        if isinstance(choices, int):
            choices = [min(choices, len(p) - 1) for p in points]
        marked = "".join(part if k % 2 == 0 else part[choices[k // 2]] for k, part in enumerate(self.parts))
        return Rendered(*untangle(_collapsed(marked), list(self.record)))

    def pieces(self) -> tuple[list[str], list[tuple[str, ...]]]:
        """(the clean text of each fixed stretch, one more than the points; each point's clean wordings)."""
        return [strip_markers(p) for p in self.parts[::2]], [tuple(map(strip_markers, p)) for p in self.points]

    @property
    def wordings(self) -> int:
        """The most wordings any point offers (1 without a choice)."""
        return max(map(len, self.points), default=1)
