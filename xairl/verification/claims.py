"""Claim words a text writes itself: the closed lists of :file:`lexicon.yaml` (``claims:``), names of the policy's
features and actions, and identifier-like tokens.

A template writes every claim word through a tracked filter (``dir``, ``level``, ``rank``, ``cmp``, ``role`` of
:mod:`xairl.templates.prompts`): the word is then the author's, and its fact says which way, so checking it is a
lookup. A claim word left in the template's literal text is *undeclared*: ``xairl prompts check`` names it with the
filter to use, and at render time its sentence is unchecked. :func:`claim_words` finds them in the literal text (the
caller blanks the tracked spans with spaces, so offsets hold).

A phrasing that prints a counterfactual fact (``{{ counterfactual.… }}``, facts whose quantity starts with
:data:`COUNTERFACTUAL`) is checked by re-running the policy on the changed state: its literal words ("had … been …,
the policy would have chosen …") are that check's to judge, and no claim word is looked for in it
(:func:`checked_by_counterfactual`).
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import yaml

#: the lexicon every word list of :mod:`xairl.verification` comes from
LEXICON = Path(__file__).with_name("lexicon.yaml")
#: the kinds of claim word, in the lexicon's order; a name or identifier is kind 'name'
KINDS = ("direction", "level", "rank", "comparison", "negation", "cause", "role")
#: the prefix of a counterfactual fact's quantity (:func:`xairl.templates.tracking.track_counterfactual`), and the
#: template variable that holds them
COUNTERFACTUAL, COUNTERFACTUAL_VARIABLE = "cf_", "counterfactual"
NAME_USE = "{{ f.label }} (or {{ f.name }}) for a feature, {{ action }} or {{ runner_up }} for an action"
IDENTIFIER_USE = "{{ f.label }} or {{ action }} from the facts (a name no fact holds is an invented one)"

# An identifier: letters or digits joined by an underscore ('cell_load', 'rsrp_1'), or camelCase with two lowercase
# letters before a capital ('cellLoad'; units such as 'dBm', 'kHz' or 'mWh' are not identifiers)
_IDENTIFIER = re.compile(
    r"(?<!\w)(?:[A-Za-z][A-Za-z0-9]*_[A-Za-z0-9_]*[A-Za-z0-9]|[a-z][a-z0-9]+[A-Z][A-Za-z0-9]*)(?!\w)"
)


@dataclass(frozen=True)
class ClaimWord:
    """A claim word written as literal text: ``word`` at ``start:end``, its ``kind`` (one of :data:`KINDS`, or
    'name' for a feature's or action's name, label or an identifier-like token), and ``use``: the declaration to
    write instead (``dir('raised', 'lowered')``, ``{{ f.label }}``)."""

    start: int
    end: int
    word: str
    kind: str
    use: str


@dataclass(frozen=True)
class Lexicon:
    """The ``claims:`` section: each word (normalised: lower case, single spaces, straight apostrophes) with its
    kind and the filter to use, the filler words that are never claims, and one pattern for them all."""

    words: dict[str, tuple[str, str]]
    filler: frozenset[str]
    pattern: re.Pattern


def normalise(word: str) -> str:
    """Lower case, single spaces, straight apostrophes: the form the lexicon is keyed by."""
    return " ".join(word.replace("\u2019", "'").lower().split())


def _alternation(words: Iterable[str]) -> str:
    """A whole-word pattern of ``words``, longest first (so 'because of' wins over 'because'), across any spaces
    and either apostrophe."""
    parts = sorted(set(words), key=len, reverse=True)
    escaped = (r"\s+".join(re.escape(w).replace("'", "['\u2019]") for w in p.split()) for p in parts)
    return r"(?<!\w)(?:" + "|".join(escaped) + r")(?!\w)"


@lru_cache(maxsize=4)
def lexicon(path: Path = LEXICON) -> Lexicon:
    """The claim words of the lexicon at ``path``, read and compiled once."""
    data = yaml.safe_load(Path(path).read_text(encoding="utf-8"))["claims"]
    words: dict[str, tuple[str, str]] = {}
    for kind in KINDS:
        for word, use in (data.get(kind) or {}).items():
            if not isinstance(word, str):  # YAML reads a bare no, on or false as a boolean
                raise ValueError(f"{path}: claim word {word!r} ({kind}) is not a string; quote it.")
            key = normalise(word)
            if key in words:
                raise ValueError(f"{path}: claim word {word!r} is listed twice ({words[key][0]} and {kind}).")
            words[key] = (kind, str(use))
    if not all(isinstance(w, str) for w in data.get("filler") or ()):
        raise ValueError(f"{path}: a filler word is not a string; quote it.")
    filler = frozenset(normalise(w) for w in data.get("filler") or ())
    if clash := sorted(filler & set(words)):
        raise ValueError(f"{path}: {', '.join(clash)} listed both as claim words and as filler.")
    return Lexicon(words, filler, re.compile(_alternation(words), re.IGNORECASE))


@lru_cache(maxsize=64)
def _names(names: tuple[str, ...]) -> re.Pattern | None:
    """One pattern of the policy's names and labels (filler words left out: an action called 'value' does not make
    every 'value' a claim)."""
    filler = lexicon().filler
    kept = [n for n in (normalise(x) for x in names) if n and n not in filler]
    return re.compile(_alternation(kept), re.IGNORECASE) if kept else None


def claim_words(text: str, names: Iterable[str] = ()) -> list[ClaimWord]:
    """The claim words written in ``text`` (literal words only: blank the tracked spans with spaces first), in
    order and not overlapping (the longest match wins where two overlap).

    :param names: the policy's features' and actions' names and labels (multi-word labels too); a literal one is a
        claim of kind 'name', as is any identifier-like token ('cell_load', 'cellLoad').
    """
    lex = lexicon()
    found: list[tuple[int, int, str, str]] = []
    for m in lex.pattern.finditer(text):
        kind, use = lex.words[normalise(m.group())]
        found.append((m.start(), m.end(), kind, use))
    key = names if isinstance(names, tuple) else tuple(dict.fromkeys(str(n) for n in names))  # (a tuple: as given)
    pattern = _names(key)
    if pattern is not None:
        found += [(m.start(), m.end(), "name", NAME_USE) for m in pattern.finditer(text)]
    found += [(m.start(), m.end(), "name", IDENTIFIER_USE) for m in _IDENTIFIER.finditer(text)]
    found.sort(key=lambda f: (f[0], f[0] - f[1]))
    out: list[ClaimWord] = []
    for start, end, kind, use in found:
        if out and start < out[-1].end:
            continue
        out.append(ClaimWord(start, end, text[start:end], kind, use))
    return out


def checked_by_counterfactual(spans: Iterable) -> bool:
    """Whether a rendered sentence with these tracked ``spans`` (:class:`xairl.templates.tracking.Span`) prints a
    counterfactual fact: it is checked by re-running the policy, and its literal words are not scanned."""
    return any(str(getattr(s.fact, "quantity", "")).startswith(COUNTERFACTUAL) for s in spans)
