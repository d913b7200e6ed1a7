"""The surfaces of an explanation's names, built once per explanation: each feature's name in any spelling, its
description, aliases and runs of their words; actions by name, alias and verb form; categorical labels and legend
meanings. :mod:`.names` finds them in a text."""

from __future__ import annotations

import functools
import re
from collections.abc import Mapping
from dataclasses import dataclass, field

from xairl.explanations.explanation import Explanation
from xairl.policies.policy import Policy
from xairl.policies.region_names import REGION_RE
from xairl.verification.prose.book import legend
from xairl.verification.prose.shorthands import acronyms, description_head, needle, shorthands, split_words
from xairl.verification.prose.words import ABBREVIATIONS, GENERIC, SPAN, STOP, SYNONYMS, UNIT_PARTS
from xairl.verification.prose.words import BASE_FORM as _BASE_FORM
from xairl.verification.prose.words import IRREGULAR as _IRREGULAR

#: what a model's input describes: a word of a feature's description, never a feature on its own
_INSTANCES = frozenset(
    {
        "patient",
        "applicant",
        "borrower",
        "customer",
        "client",
        "person",
        "student",
        "team",
        "player",
        "user",
        "house",
        "home",
        "property",
        "uav",
        "drone",
        "vehicle",
        "agent",
    }
)
#: words that make a label too plain to be recognised away from its feature ('the other features', 'at home')
_PLAIN_LABEL_WORDS = frozenset(
    {
        "other",
        "others",
        "none",
        "unknown",
        "yes",
        "no",
        "home",
        "at",
        "true",
        "false",
        "na",
        "missing",
        "not",
        "applicable",
        "some",
    }
)


@functools.lru_cache(maxsize=65536)
def stem(word: str) -> str:
    """A crude English stem, enough for labels ('renting' -> 'rent', 'self-employment' -> 'self employ'); a word
    left whole is returned as is."""
    w = word.lower()
    for suffix in ("ment", "ing", "ed", "es", "s", "e"):
        if w.endswith(suffix) and not w.endswith("ss") and len(w) - len(suffix) >= 4:
            return w[: -len(suffix)] + "~"
    return w


@dataclass
class Vocabulary:
    """Every surface of an explanation's names, longest first: (regex, kind, keys, label, form, needle)."""

    #: ``needle``: lowercase text every match holds, looked for before the regex runs ('' where none is known)
    entries: list[tuple[re.Pattern, str, tuple[str, ...], str, str, str]]
    #: feature -> [(label, pattern)] of labels named only right next to their feature: 1-2 characters ('Y', 'Ex') or
    #: plain words ('other', 'at_home')
    short_labels: dict[str, list[tuple[str, str]]]
    words: dict[str, frozenset[str]]  # feature -> the words of its name, description and aliases (qualifiers)
    #: words of the features' own names ('quality' of ``kitchen_quality``) and their stems ('scor~' of 'scoring'), and
    #: the set of content words of each description of two or more ('mother', 'job'): a phrase with one such word, or
    #: with all the words of one such set ('the mother having a job'), may be a vague mention of a feature, not a
    #: thing the model lacks
    name_words: frozenset = frozenset()
    #: an image's regions by their other names (:func:`region_key` of the phrase -> the regions it may mean)
    regions: dict[str, tuple[str, ...]] = field(default_factory=dict)


def vocabulary(exp: Explanation, policy: Policy | None, clean) -> Vocabulary:
    groups = [g for g in (policy.reason_groups if policy else {}) if g not in exp.feature_names]
    phrases, exact, feature_words, described_words = _feature_forms([*exp.feature_names, *groups], policy, clean)
    shared: dict[str, set[str]] = {}
    for f in [*exp.feature_names, *groups]:
        for w in split_words(f):
            if w in GENERIC and len(w) >= 4 and w not in SPAN:
                shared.setdefault(w, set()).add(f)
    for w, keys in shared.items():  # 'quality' of overall_quality and kitchen_quality: named, but not which
        if len(keys) > 1 and w not in phrases and w not in exact:
            phrases[w] = keys
    for phrase in [p for p in phrases if p.endswith("s") and p[:-1] in phrases]:  # 'condition' and 'conditions'
        phrases[phrase] = phrases[phrase[:-1]] = phrases[phrase] | phrases[phrase[:-1]]
    if exp.output != "actions":  # 'the probability of diabetes': the output's words are not a part of a feature's
        for w in {w for a in exp.action_names for w in split_words(a)}:
            phrases.pop(w, None)
    entries = []
    for phrase, keys in {**phrases, **exact}.items():
        keys = exact.get(phrase, keys)  # a word or run of a longer name is a 'part' ('kicks' of Free Kicks)
        entries.append((phrase, "feature", tuple(sorted(keys)), "", "" if phrase in exact else "part"))
    entries += _action_entries(exp, policy, clean)
    label_entries, short = _label_entries(exp, clean)
    entries += label_entries + _legend_entries(exp, policy)
    entries += [
        (name, kind, (name,), "", "literal")
        for kind, names in (("feature", exp.feature_names), ("action", exp.action_names))
        for name in names
        if name.strip() and clean(name)
    ]  # 'sensors[0]', '速度', '?' as written
    entries = [e for e in entries if e[0].split()]
    entries.sort(key=lambda e: -len(e[0]))
    names = {w for f in feature_words for w in split_words(f) if len(w) >= 3 and not w.isdigit()}
    names |= {
        level.split()[-1].lower()
        for f in feature_words
        if (info := policy.features.get(f) if policy else None)
        for level in (info.low, info.high)
        if len(level.split()) > 1
    }  # '(-27.5 dB, poor quality)'
    names |= {stem(w) for w in names} | {ws for ws in described_words if len(ws) >= 2}
    compiled = []
    for p, kind, keys, label, form in entries:
        pattern, needle = _literal(p) if form == "literal" else _pattern(p, kind)
        compiled.append((pattern, kind, keys, label, "" if form == "literal" else form, needle))
    return Vocabulary(
        compiled + acronyms(exp.feature_names, exp.categories) + shorthands(exp.feature_names),
        short,
        feature_words,
        frozenset(names),
        _region_aliases(exp),
    )


def _feature_forms(names, policy: Policy | None, clean):
    """The ways each feature (or group) in ``names`` is written: (phrases: a run of words naming part of it ->
    features, exact: a whole name -> features, each feature's words, each description's content words ('mother's
    job': mother, job))."""
    phrases: dict[str, set[str]] = {}
    exact: dict[str, set[str]] = {}
    feature_words: dict[str, frozenset[str]] = {}
    described_words: list[frozenset[str]] = []
    for f in names:
        info = policy.features.get(f) if policy else None
        described = (
            (info.description if clean(info.description) else description_head(info.description)) if info else ""
        )
        described_words.append(
            frozenset(w for w in split_words(description_head(described)) if w not in STOP and len(w) >= 3)
        )
        forms = [f, " ".join(split_words(f))] + (
            [described, description_head(described), *info.aliases] if info else []
        )
        feature_words[f] = frozenset(w for form in forms if form for w in split_words(form) if w not in STOP)
        name_words = split_words(f)
        if len(name_words) == 2 and not any(w.isdigit() for w in name_words):  # 'year built' -> 'build year'
            forms.append(" ".join(_BASE_FORM.get(w, w) for w in reversed(name_words)))
        for form in forms:
            if form and clean(form):
                exact.setdefault(_phrase(form), set()).add(f)
        spelled = _spellings(name_words)
        feature_words[f] |= frozenset(w for form in spelled for w in form.split() if w not in STOP)
        for form in [f] + ([description_head(described)] if described else []) + spelled:
            if clean(form) and not REGION_RE.match(f.removeprefix("the ")):  # a region: only by its whole name
                for run in _runs(form, f):
                    phrases.setdefault(run, set()).add(f)
    return phrases, exact, feature_words, described_words


def _regions(exp: Explanation) -> dict[str, str]:
    """The explanation's image regions (name -> extent, as :func:`xairl.in_regions` keeps them), a frame stack's
    regions over its frames and each frame's patch of them (:func:`.window.per_signal`); none for pixels."""
    extents = (exp.extras or {}).get("regions")
    names = [*exp.feature_names, *((exp.extras or {}).get("window") or {}).get("slots", {}).get("names", ())]
    return {f: str(extents[f]) for f in names if f in extents} if isinstance(extents, Mapping) else {}


def region_key(phrase: str) -> str:
    """A region phrase (:data:`xairl.policies.region_names.REGION_RE`) in one spelling, to look it up: 'The 8×8 patch at rows
    16-23 and columns 40 to 47 in channel 1' -> '8x8 patch at rows 16 to 23 columns 40 to 47 of channel 1'."""
    key = re.sub(r"\s*(?:\bto\b|-|–|\bthrough\b)\s*", " to ", phrase.lower().replace("×", "x").replace(",", " "))
    key = re.sub(r"\b(?:spanning|covering|over)\b", "at", re.sub(r"\bin\b", "of", key))
    key = re.sub(r"\brow\b", "rows", re.sub(r"\bcolumn\b", "columns", key))
    return " ".join(w for w in key.split() if w not in ("the", "and"))


def _region_aliases(exp: Explanation) -> dict[str, tuple[str, ...]]:
    """Other names of each region (:func:`region_key` -> regions): its extent ('the 12x12 patch at rows 60 to 71,
    columns 60 to 71 of frame 2'), a frame said as a channel or a channel as a frame ('patch F6 of channel 2'), and its
    grid reference alone ('patch F6' in an image of several frames: an ambiguous mention of that patch of each
    frame). Looked up per region phrase of a text (:func:`.names.find_mentions`): one regex for all of them, not one
    per alias (hundreds of patterns, compiled again on every call once they overflow ``re``'s cache)."""
    other = {" of frame ": " of channel ", " of channel ": " of frame "}
    out: dict[str, set[str]] = {}
    for f, extent in _regions(exp).items():
        for form in (f, extent):
            swapped = next((form.replace(a, b) for a, b in other.items() if a in form), form)
            for alias in {form, swapped}:
                out.setdefault(region_key(alias), set()).add(f)
                if (m := REGION_RE.search(alias)) and m.group(0) != alias.removeprefix("the "):  # ' of KEY' left out
                    out.setdefault(region_key(m.group(0)), set()).add(f)
        ref = f.split(" of ", 1)[0]
        if ref != f and ref not in exp.feature_names:  # (a region over frames is named by its reference alone)
            out.setdefault(region_key(ref), set()).add(f)
    return {k: tuple(sorted(v)) for k, v in out.items()}


def _spellings(name_words: list[str]) -> list[str]:
    """Other spellings of a name's words: abbreviations written out ('dist_to_charger_m': 'distance to charger m')
    and each word swapped for a synonym ('battery_pct': 'charge pct'; 'hr_mean_6h': 'pulse mean 6h')."""
    spelled = " ".join(ABBREVIATIONS.get(w, w) for w in name_words)
    out = [spelled] if spelled != " ".join(name_words) else []
    return out + [
        " ".join(w if k != i else other for k, w in enumerate(words))
        for words in {tuple(name_words), *(tuple(s.split()) for s in out)}
        for i, w in enumerate(words)
        for other in SYNONYMS.get(w, ())
    ]


def _runs(form: str, f: str) -> list[str]:
    """The runs of words of feature ``f``'s name or description ``form`` that may name it: every run of two words or
    more, single words unless generic, a unit or statistic (``UNIT_PARTS``: 'min', 'avg'), short, a number, or the
    instance the form is about ('the applicant's age', 'age of the patient': not 'applicant', 'patient'; in a
    description, or a name that is a phrase)."""
    lowered = form.lower()
    owners = (
        set(re.findall(r"(\w+)'s\b", lowered)) | set(re.findall(r"\bof (?:the |a |an )?(\w+)$", lowered)) | _INSTANCES
    )
    words = [w for w in split_words(form) if w not in STOP]
    out = []
    for i in range(len(words)):
        for j in range(i + 1, len(words) + 1):
            run = words[i:j]
            if not any(re.search(r"[a-z]", w) for w in run):
                continue  # '2 2' of 'obs[0,2,2]' would name a pixel by any number '22'
            if len(run) == 1 and (
                run[0] in GENERIC
                or run[0] in UNIT_PARTS
                or len(run[0]) < 3
                or run[0].isdigit()
                or (run[0] in owners and (form != f or len(words) >= 3))
                or (form != f and len(run[0]) < 5 and run[0] not in split_words(f))
            ):
                continue
            out.append(" ".join(run))
    return out


#: legend meanings too common to name a feature's code
_COMMON_MEANINGS = {"yes", "no", "none", "true", "false", "low", "high", "other", "unknown", "never", "always"}


def _legend_entries(exp: Explanation, policy: Policy | None) -> list:
    """The meaning of a flag's one-entry legend, when it is one word ('sex (1 = male)': 'male'), named as its value
    (the words of a longer legend, 'bank' of '1 bank, 2 stores, 3 none', are too often said of other things)."""
    out = []
    for f in exp.feature_names:
        info = policy.features.get(f) if policy else None
        meanings = legend(info.description if info else "").values()
        for meaning in meanings if len(meanings) == 1 else ():
            if re.fullmatch(r"[A-Za-z]{4,}", meaning) and meaning.lower() not in _COMMON_MEANINGS | STOP:
                out.append((meaning.lower(), "label", (f,), meaning, "legend"))
    return out


def _label_entries(exp: Explanation, clean) -> tuple[list, dict[str, list[tuple[str, str]]]]:
    """Vocabulary entries of categorical labels (a stem of each word; a one-hot column's name 'work_type_children'),
    and the labels named only right next to their feature: 1-2 characters ('Y', 'Ex') or plain words ('other')."""
    entries, short = [], {}
    for f, labels in (exp.categories or {}).items():
        for label in labels:
            if len(label) <= 2:
                short.setdefault(f, []).append((label, re.escape(label)))
            elif all(w in _PLAIN_LABEL_WORDS for w in split_words(label)):  # 'other', 'at_home': plain words
                short.setdefault(f, []).append((label, r"[\s_\-]+".join(map(re.escape, split_words(label)))))
            elif clean(label):
                entries.append((" ".join(stem(w) for w in split_words(label)), "label", (f,), label, ""))
            if clean(label):  # a one-hot column's name: 'work_type_children', 'smoking_status=never smoked'
                entries.append((f"{_phrase(f)} {_phrase(label)}", "label", (f,), label, "one-hot"))
    return entries, short


def _phrase(text: str) -> str:
    return (
        " ".join(
            w
            for w in re.findall(r"[a-z0-9']+", re.sub(r"(?<=[a-z0-9])(?=[A-Z])|[_\-]+", " ", text).lower())
            if w != "the"
        )
        if text
        else ""
    )


#: the endings a label's stem takes ('retir~': retired, retirement, retiree; not 'cours~' in 'coursework')
_STEM_ENDING = r"(?:e|es|ed|ing|ment|ments|ement|ements|ee|ees|er|ers|s|y|ies|ied|ion|ions|ive|al)?"


def _pattern(phrase: str, kind: str) -> tuple[re.Pattern, str]:
    """Words in order, separated by spaces, hyphens, underscores or nothing; plural 's' and possessive allowed. With
    the needle: the first word as it must appear."""
    words = phrase.split()
    if kind == "label":  # a stem ('~') takes an inflection (_STEM_ENDING), a whole word a plural
        endings = [_STEM_ENDING if "~" in w else "(?:s|es|ing|ed|er|ers)?" for w in words]
        words = [w.replace("~", "") for w in words]
        body = r"[\s_\-]*".join(re.escape(w) + ending for w, ending in zip(words, endings))
    else:  # a plural name also in the singular ('Corners': 'a corner')
        last = words[-1]
        if len(last) > 4 and last.endswith("s") and not last.endswith(("ss", "us", "is")):
            words[-1] = last[:-2] if last.endswith(("sses", "xes", "ches", "shes")) else last[:-1]
        body = (
            r"(?:'s|')?(?:[\s_\-(),]+(?:the\s+|(?:of|to|in|for)[\s_\-]+)?|)".join(map(re.escape, words))
            + r"(?:s|es)?(?:'s|')?\)?"
        )  # ('state-of-charge' of the run 'state charge' of soc_pct's spelling)
    pattern = re.compile(rf"(?<![\w]){body}(?![\w])(?![.,]\d)", re.IGNORECASE)  # not 'RSRQ (-3' of 'RSRQ (-3.2 dB)'
    return pattern, needle(words[0])


def _literal(name: str) -> tuple[re.Pattern, str]:
    """A name exactly as written, whatever its digits, brackets or script ('obs[1,32,35]', '速度'), not inside a
    longer word or name; a name of punctuation only ('?', '-') only between spaces (or a bracket or comma after it),
    so that it is not every minus sign. With the needle: the name."""
    if not re.search(r"[^\W_]", name):
        return re.compile(rf"(?<![^\s(]){re.escape(name)}(?=[\s,;:)]|$)"), needle(name)
    return re.compile(rf"(?<![\w\[]){re.escape(name)}(?![\w\]])", re.IGNORECASE), needle(name)


def _inflect(head: str) -> list[tuple[str, str]]:
    """(surface, form) for an action's head phrase: itself, and the verb forms of its first word."""
    first, _, rest = head.partition(" ")
    rest = f" {rest}" if rest else ""
    base = first[:-1] if first.endswith("e") else first
    out = [(head, ""), (f"{first}s{rest}", ""), (f"{base}ing{rest}", "")]
    past = _IRREGULAR.get(first, f"{base}ed")
    out.append((f"{past}{rest}", "past"))
    if first == "stay":
        out.append((f"stayed{rest}", "past"))
    if first.endswith("over") and len(first) > 4:  # handover -> hand over
        out += _inflect(f"{first[:-4]} over{rest}")
    return out


def _action_entries(exp: Explanation, policy: Policy | None, clean) -> list:
    heads: dict[str, set[str]] = {}
    full: list[tuple[str, str, str]] = []
    for a in exp.action_names:
        forms = {a, " ".join(split_words(a)), *(policy.action_aliases.get(a, ()) if policy else ())}
        for form in forms:
            if not form or not clean(form):
                continue
            phrase = re.sub(r"^(a|an|the)\s+", "", _phrase(form))
            words = phrase.split()
            for surface, kind in _inflect(phrase):
                full.append((surface, a, kind))
            for extra in (f"go {phrase}", f"goes {phrase}", f"going {phrase}"):
                full.append((extra, a, ""))
            full.append((f"went {phrase}", a, "past"))
            cut = next((i for i, w in enumerate(words) if w == "to" or any(c.isdigit() for c in w)), len(words))
            if 0 < cut < len(words):
                heads.setdefault(" ".join(words[:cut]), set()).add(a)
    owners: dict[tuple[str, str], set[str]] = {}
    for surface, a, form in full:  # a surface that several actions share ('switch cells') is one shared mention
        owners.setdefault((surface, form), set()).add(a)
    out = [(s, "action", tuple(sorted(acts)), "", form) for (s, form), acts in owners.items()]
    for head, acts in heads.items():
        if len(acts) > 1:
            for surface, form in _inflect(head):
                out.append((surface, "action", tuple(sorted(acts)), "", form))
    return out
