"""Short names people write for an explanation's features: a description without its legend, the capital
initials of a long name ('DTI'), and shorthands of a name's words ('temp', 'avg')."""

from __future__ import annotations

import re

from xairl.verification.prose.words import GENERIC, STOP, UNIT_PARTS


def split_words(name: str) -> list[str]:
    """'GillSize' / 'gill_size' / 'gill-size' / 'rsrp_1' -> ['gill', 'size'] / ... / ['rsrp', '1']."""
    spaced = re.sub(r"(?<=[a-z0-9])(?=[A-Z])|[_\-./]+", " ", name)
    return re.findall(r"[a-z0-9]+", spaced.lower())


def needle(word: str) -> str:
    """Lowercase text a case-blind match of ``word`` holds; '' where the word is not ASCII (case folding beyond ASCII
    is left to the regex)."""
    return word.lower() if word.isascii() else ""


def description_head(description: str) -> str:
    """A description without its legend ('weekly study time (1: <2 hours, ...)': 'weekly study time'), for a text
    that names it without (or a legend that is not clean, see :func:`~.book.clean_surface`)."""
    return re.split(r"\s*[(:;\[]", description or "", maxsplit=1)[0].strip()


def acronyms(features, categories=None) -> list:
    """'DTI' for ``debt_to_income``: the capital initials of a name of three words or more, matched as written (so
    that 'NOR' of ``number_of_rooms`` is not the word 'nor'); only an acronym one feature has. And a label's word
    in capitals ('ECA' of ``inside_ECA``: 'without the ECA effect' names that label's feature)."""
    owners: dict[str, list[str]] = {}
    for f in features:
        words = split_words(f)
        if len(words) >= 3 and not any(w.isdigit() for w in words):
            owners.setdefault("".join(w[0] for w in words).upper(), []).append(f)
    out = [
        (re.compile(rf"(?<![\w]){acr}s?(?![\w])"), "feature", (fs[0],), "", "", needle(acr))
        for acr, fs in owners.items()
        if len(fs) == 1
    ]
    labelled: dict[str, list[tuple[str, str]]] = {}
    for f, labels in (categories or {}).items():
        for label in labels:
            words = re.split(r"[\s_\-/]+", label)
            for w in words if len(words) >= 2 else ():
                if re.fullmatch(r"[A-Z]{3,}", w):
                    labelled.setdefault(w, []).append((f, label))
    return out + [
        (re.compile(rf"(?<![\w]){w}(?![\w])"), "label", (fl[0][0],), fl[0][1], "", needle(w))
        for w, fl in labelled.items()
        if len(fl) == 1
    ]


#: a number right after a shorthand ('alc 9.4: -0.38', 'Wknd +3.2h'): the only place a shorthand names
_NUMBER_AFTER = (
    r"(?=\s*[:=]?\s*\(?\s*(?:[+\-−±]\s?[$€£]?\d|[$€£]?\d[\d.,]*\s*[a-z%]{0,3}\s*(?::\s*[+\-−±]?|"
    r"\(?[+\-−±])\s?\d))"
)
#: (a signed number, 'Wknd +3.2h', or a value and its push after a colon or with a sign, 'alc 9.4: -0.38', 'alc 13.6
#: +0.79'; not 'par 3 golf', '3 bed 2 bath', 'Cat 3 storms', 'In the US 3 of 10')


def shorthands(features) -> list:
    """Shorthands of compact logs, each only right before a number and only where one feature has it: the first 3
    or more letters of a name's word of 5 or more ('alc' of ``alcohol``, 'sulph' of ``sulphates``), a word of 4 or
    more without its vowels ('wknd' of ``weekend_flag``), the word with '-ing' ('mentoring' of ``mentor_meetings``),
    and the two capital initials of a name of two words ('VA' of ``volatile_acidity``), as written."""
    words = {w for f in features for w in split_words(f)} | STOP | GENERIC | _COMMON_SHORT
    owners: dict[str, set[str]] = {}
    for f in features:
        parts = split_words(f)
        for w in parts:
            if len(w) < 4 or not w.isalpha() or w in GENERIC or w in UNIT_PARTS:
                continue
            prefixes = (w[:k] for k in range(3, len(w))) if len(w) >= 5 else ()
            skeleton = w[0] + re.sub(r"[aeiou]", "", w[1:])
            for short in {*prefixes, skeleton, f"{w}ing", f"{w.removesuffix('e')}ing"}:
                if len(short) >= 3 and short not in words:
                    owners.setdefault(short, set()).add(f)
        if len(parts) == 2 and all(w.isalpha() for w in parts):
            owners.setdefault("".join(w[0] for w in parts).upper(), set()).add(f)
    groups: dict[tuple[str, str], list[str]] = {}  # one regex per feature and first three letters (fewer to compile)
    for short, fs in owners.items():
        if len(fs) == 1:
            groups.setdefault((next(iter(fs)), short if short.isupper() else short[:3]), []).append(short)
    out = []
    for (f, head), shorts in groups.items():
        body = "|".join(re.escape(x) for x in sorted(shorts, key=len, reverse=True))
        out.append(
            (
                re.compile(rf"(?<![\w])(?:{body})(?![\w]){_NUMBER_AFTER}", 0 if head.isupper() else re.IGNORECASE),
                "feature",
                (f,),
                "",
                "shorthand",
                needle(head),
            )
        )
    return out


#: English words a shorthand must not be, since they stand before numbers in any prose
_COMMON_SHORT = {
    "sum",
    "net",
    "top",
    "all",
    "add",
    "and",
    "for",
    "was",
    "are",
    "but",
    "not",
    "now",
    "one",
    "two",
    "six",
    "ten",
    "pos",
    "neg",
    "see",
    "set",
    "get",
    "out",
    "off",
    "its",
    "has",
    "had",
    "got",
    "put",
    "say",
    "let",
    "use",
    "cut",
    "max",
    "min",
    "avg",
    "day",
    "days",
    "week",
    "year",
    "hour",
    "than",
    "then",
    "with",
    "from",
    "over",
    "only",
    "just",
    "each",
    "some",
    "more",
    "less",
    "most",
    "down",
    "gave",
    "give",
    "lift",
    "push",
    "drag",
    "pull",
    "base",
    "mean",
    "total",
    "score",
    "value",
    "shift",
    "plus",
    "per",
    "par",
    "bed",
    "rev",
    "est",
    "cat",
    "mar",
    "month",
    "us",
}
