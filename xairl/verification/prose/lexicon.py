"""The reader's word lists (xairl/verification/lexicon.yaml), loaded once: the one place a hedge, a direction verb, a rank word
or a negation is listed. Verbs are listed in their base form; :func:`forms` makes the rest."""

from __future__ import annotations

import functools
from pathlib import Path

import yaml

#: the one lexicon of the verification package (xairl/verification/lexicon.yaml)
LEXICON = Path(__file__).parent.parent / "lexicon.yaml"
_VERB_LISTS = ("up", "down", "phrasal", "output_up", "output_down", "outweigh", "give", "choose", "win")


def forms(word: str) -> set[str]:
    """A verb's base form and its -s, -ed and -ing forms (raise: raises, raised, raising; cut: cuts, cutting)."""
    if not word.isalpha() or len(word) < 3:
        return {word}
    vowels = "aeiou"
    double = len(word) <= 4 and word[-1] in "bdgmnpt" and word[-2] in vowels and word[-3] not in vowels
    consonant_y = word.endswith("y") and word[-2] not in vowels
    if consonant_y:
        return {word, word[:-1] + "ies", word[:-1] + "ied", word + "ing"}
    third = word + "es" if word.endswith(("sh", "ch", "s", "x")) else word + "s"
    if word.endswith("e") and not word.endswith("ee"):
        return {word, third, word + "d", word[:-1] + "ing"}
    stem = word + word[-1] if double else word
    return {word, third, stem + "ed", stem + "ing"}


#: the lexicon's sections that are not the reader's (provenance's words, the claim words of templates)
OTHER_SECTIONS = ("names", "own", "claims")


@functools.cache
def lexicon() -> dict:
    """The word lists, verbs with their forms; ``ordinals`` a word -> rank map."""
    raw = yaml.safe_load(LEXICON.read_text(encoding="utf-8"))
    out = {}
    for key, words in raw.items():
        if key in OTHER_SECTIONS:
            continue
        if key == "closed_classes":
            out[key] = [frozenset(str(w).lower() for w in group) for group in words]
        elif key == "tag_pos":
            out[key] = {str(k): str(v) for k, v in words.items()}
        elif isinstance(words, dict):
            out[key] = {str(k).lower(): int(v) for k, v in words.items()}
        else:
            bad = [w for w in words if not isinstance(w, str)]
            if bad:
                raise ValueError(
                    f"lexicon.yaml: '{key}' holds {bad}, not words: quote them (YAML reads yes/no/off as booleans)"
                )
            words = [w.lower() for w in words]
            out[key] = sorted({f for w in words for f in forms(w)}) if key in _VERB_LISTS else words
    out["closed_words"] = sorted({w for group in out.get("closed_classes", ()) for w in group})
    return out
