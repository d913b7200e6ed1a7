"""Where a text names a feature, an action or a categorical value.

A feature is recognised by its name in any spelling (``gill_size``, "gill-size", "gill size", "GillSize"), its
description, its aliases, and by any run of their words that belongs to that feature alone ("kitchen" for
``kitchen_quality``). A run shared by several features ("quality" for ``overall_quality`` and ``kitchen_quality``)
is an *ambiguous* mention: a claim about it counts only when it holds, or fails, for every feature it may mean.
Actions are recognised by name, alias and verb forms ("recharged", "handing over to candidate 1"); a head word shared
by several actions ("handover") means the chosen or runner-up one among them. Categorical values are recognised by
their labels ("CollgCr", "self-employed" and "self-employment"); labels of one or two letters only next to their
feature's name.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

from ...explanation import Explanation
from ...observation import REGION_RE
from ...policy import Policy
from .book import legend
from .lexicon import ABBREVIATIONS, BASE_FORM as _BASE_FORM, GENERIC, IRREGULAR as _IRREGULAR, STOP  # noqa: F401


@dataclass(frozen=True)
class Mention:
    """A span naming something: kind 'feature', 'action' or 'label'; ``keys`` the features or actions it may mean
    (several: ambiguous); ``label`` the categorical value named (kind 'label'); ``form`` 'past' for a verb in the
    past tense ("recharged": a statement of what was chosen)."""

    start: int
    end: int
    kind: str
    keys: tuple[str, ...]
    label: str = ""
    form: str = ""


def split_words(name: str) -> list[str]:
    """'GillSize' / 'gill_size' / 'gill-size' / 'rsrp_1' -> ['gill', 'size'] / ... / ['rsrp', '1']."""
    spaced = re.sub(r"(?<=[a-z0-9])(?=[A-Z])|[_\-./]+", " ", name)
    return re.findall(r"[a-z0-9]+", spaced.lower())


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
    """Every surface of an explanation's names, longest first: (regex, kind, keys, label, form)."""

    entries: list[tuple[re.Pattern, str, tuple[str, ...], str, str]]
    #: feature -> [(label, pattern)] of labels named only right next to their feature: 1-2 characters ('Y', 'Ex') or
    #: plain words ('other', 'at_home')
    short_labels: dict[str, list[tuple[str, str]]]
    words: dict[str, frozenset[str]]  # feature -> the words of its name, description and aliases (qualifiers)
    #: words of the features' own names ('quality' of ``kitchen_quality``) and their stems ('scor~' of 'scoring'), and
    #: the set of content words of each description of two or more ('mother', 'job'): a phrase with one such word, or
    #: with all the words of one such set ('the mother having a job'), may be a vague mention of a feature, not a
    #: thing the model lacks
    name_words: frozenset = frozenset()


def vocabulary(exp: Explanation, policy: Policy | None, clean) -> Vocabulary:
    phrases: dict[str, set[str]] = {}
    exact: dict[str, set[str]] = {}
    feature_words: dict[str, frozenset[str]] = {}
    described_words: list[frozenset[str]] = []  # the content words of each description ('mother's job': mother, job)
    groups = [g for g in (policy.reason_groups if policy else {}) if g not in exp.feature_names]
    for f in [*exp.feature_names, *groups]:
        info = policy.features.get(f) if policy else None
        described = (info.description if clean(info.description) else _head(info.description)) if info else ""
        described_words.append(frozenset(w for w in split_words(_head(described)) if w not in STOP and len(w) >= 3))
        forms = [f, " ".join(split_words(f))] + ([described, _head(described), *info.aliases] if info else [])
        feature_words[f] = frozenset(w for form in forms if form for w in split_words(form) if w not in STOP)
        name_words = split_words(f)
        if len(name_words) == 2 and not any(w.isdigit() for w in name_words):  # 'year built' -> 'build year'
            forms.append(" ".join(_BASE_FORM.get(w, w) for w in reversed(name_words)))
        for form in forms:
            if form and clean(form):
                exact.setdefault(_phrase(form), set()).add(f)
        spelled = [" ".join(ABBREVIATIONS[w] if w in ABBREVIATIONS else w for w in name_words)]  # 'distance to ...'
        spelled = spelled if spelled[0] != " ".join(name_words) else []
        feature_words[f] |= frozenset(w for form in spelled for w in form.split() if w not in STOP)
        for form in [f] + ([_head(described)] if described else []) + spelled:
            if clean(form) and not REGION_RE.match(f.removeprefix("the ")):  # a region: only by its whole name
                for run in _runs(form, f):
                    phrases.setdefault(run, set()).add(f)
    shared: dict[str, set[str]] = {}
    for f in [*exp.feature_names, *groups]:
        for w in split_words(f):
            if w in GENERIC and len(w) >= 4:
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
    entries += [(name, kind, (name,), "", "literal") for kind, names in (("feature", exp.feature_names),
                                                                          ("action", exp.action_names))
                for name in names if name.strip() and clean(name)]  # 'sensors[0]', '速度', '?' as written
    entries = [e for e in entries if e[0].split()]
    entries.sort(key=lambda e: -len(e[0]))
    names = {w for f in feature_words for w in split_words(f) if len(w) >= 3 and not w.isdigit()}
    names |= {stem(w) for w in names} | {ws for ws in described_words if len(ws) >= 2}
    compiled = [(_literal(p), kind, keys, label, "") if form == "literal" else (_pattern(p, kind), kind, keys, label,
                                                                                 form)
                for p, kind, keys, label, form in entries]
    return Vocabulary(compiled + _acronyms(exp.feature_names), short, feature_words, frozenset(names))


def _runs(form: str, f: str) -> list[str]:
    """The runs of words of feature ``f``'s name or description ``form`` that may name it: every run of two words or
    more, single words unless generic, short, a number, or the instance the form is about ('the applicant's age', 'age
    of the patient': not 'applicant', 'patient'; in a description, or a name that is a phrase)."""
    lowered = form.lower()
    owners = set(re.findall(r"(\w+)'s\b", lowered)) | set(re.findall(r"\bof (?:the |a |an )?(\w+)$", lowered)) | \
        _INSTANCES
    words = [w for w in split_words(form) if w not in STOP]
    out = []
    for i in range(len(words)):
        for j in range(i + 1, len(words) + 1):
            run = words[i:j]
            if not any(re.search(r"[a-z]", w) for w in run):
                continue  # '2 2' of 'obs[0,2,2]' would name a pixel by any number '22'
            if len(run) == 1 and (run[0] in GENERIC or len(run[0]) < 3 or run[0].isdigit() or (
                    run[0] in owners and (form != f or len(words) >= 3)) or (
                    form != f and len(run[0]) < 5 and run[0] not in split_words(f))):
                continue
            out.append(" ".join(run))
    return out


#: a label given to its feature after it: "the mother's job, which is categorized as 'other'"
_ASSIGNED = re.compile(r"[\s,]*(?:which|that)?\s*(?:is|was|being)?\s*(?:categori[sz]ed|classified|listed|coded|"
                       r"recorded|labell?ed|given)\s+as\s+(?:an?\s+)?[\"'“‘]?", re.IGNORECASE)
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


def _head(description: str) -> str:
    """A description without its legend ('weekly study time (1: <2 hours, ...)': 'weekly study time'), for a text
    that names it without (or a legend that is not clean, see :func:`~.book.clean_surface`)."""
    return re.split(r"\s*[(:;\[]", description or "", maxsplit=1)[0].strip()


def _acronyms(features) -> list:
    """'DTI' for ``debt_to_income``: the capital initials of a name of three words or more, matched as written (so
    that 'NOR' of ``number_of_rooms`` is not the word 'nor'); only an acronym one feature has."""
    owners: dict[str, list[str]] = {}
    for f in features:
        words = split_words(f)
        if len(words) >= 3 and not any(w.isdigit() for w in words):
            owners.setdefault("".join(w[0] for w in words).upper(), []).append(f)
    return [(re.compile(rf"(?<![\w]){acr}s?(?![\w])"), "feature", (fs[0],), "", "") for acr, fs in owners.items()
            if len(fs) == 1]


def _phrase(text: str) -> str:
    return " ".join(w for w in re.findall(r"[a-z0-9']+", re.sub(r"(?<=[a-z0-9])(?=[A-Z])|[_\-]+", " ", text).lower())
                    if w != "the") if text else ""


#: the endings a label's stem takes ('retir~': retired, retirement, retiree; not 'cours~' in 'coursework')
_STEM_ENDING = r"(?:e|es|ed|ing|ment|ments|ement|ements|ee|ees|er|ers|s|y|ies|ied|ion|ions|ive|al)?"


def _pattern(phrase: str, kind: str) -> re.Pattern:
    """Words in order, separated by spaces, hyphens, underscores or nothing; plural 's' and possessive allowed."""
    parts = [re.escape(w) for w in phrase.split()]
    if kind == "label":  # a stem ('~') takes an inflection (_STEM_ENDING), a whole word a plural
        body = r"[\s_\-]*".join(p.replace("\\~", "").replace("~", "") + _STEM_ENDING if "~" in p else
                                  p + "(?:s|es|ing|ed|er|ers)?" for p in parts)
    else:  # a plural name also in the singular ('Corners': 'a corner')
        last = phrase.split()[-1]
        if len(last) > 4 and last.endswith("s") and not last.endswith(("ss", "us", "is")):
            parts[-1] = re.escape(last[:-2] if last.endswith(("sses", "xes", "ches", "shes")) else last[:-1])
        body = r"(?:'s|')?(?:[\s_\-(),]+(?:the\s+)?|)".join(parts) + r"(?:s|es)?(?:'s|')?\)?"
    return re.compile(rf"(?<![\w]){body}(?![\w])(?![.,]\d)", re.IGNORECASE)  # not 'RSRQ (-3' of 'RSRQ (-3.2 dB)'


def _literal(name: str) -> re.Pattern:
    """A name exactly as written, whatever its digits, brackets or script ('obs[1,32,35]', '速度'), not inside a
    longer word or name; a name of punctuation only ('?', '-') only between spaces (or a bracket or comma after it),
    so that it is not every minus sign."""
    if not re.search(r"[^\W_]", name):
        return re.compile(rf"(?<![^\s(]){re.escape(name)}(?=[\s,;:)]|$)")
    return re.compile(rf"(?<![\w\[]){re.escape(name)}(?![\w\]])", re.IGNORECASE)


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


def named_features(mentions: list[Mention]) -> list[Mention]:
    """The mentions a claim can be about: features and categorical values (not actions)."""
    return [m for m in mentions if m.kind in ("feature", "label")]


def find_mentions(text: str, vocab: Vocabulary) -> tuple[list[Mention], str]:
    """Mentions in ``text`` (longest surface first, no overlaps) and the text with them masked by NUL characters,
    so that digits inside names ('rsrp_1', 'candidate 2') are not read as numbers."""
    taken = bytearray(len(text))
    found: list[Mention] = []
    for pattern, kind, keys, label, form in vocab.entries:
        for m in pattern.finditer(text):
            if kind == "label" and _IDIOM.search(text, max(0, m.start() - 16), m.start()):
                continue  # 'on its own' is no housing label
            if not any(taken[m.start():m.end()]):
                found.append(Mention(m.start(), m.end(), kind, keys, label, form))
                taken[m.start():m.end()] = b"\1" * (m.end() - m.start())
    features = [m for m in found if m.kind == "feature"]
    for f, labels in vocab.short_labels.items():  # 'Y', 'Ex', 'other': only right next to their feature
        near = [m for m in features if f in m.keys]
        for label, surface in labels:
            for m in re.finditer(rf"(?<![\w]){surface}(?![\w])", text, 0 if len(label) <= 2 else re.IGNORECASE):
                if any(abs(m.start() - n.end) <= 14 or abs(n.start - m.end()) <= 14 or _ASSIGNED.fullmatch(
                        text, n.end, m.start()) for n in near) and not any(taken[m.start():m.end()]):
                    found.append(Mention(m.start(), m.end(), "label", (f,), label))
                    taken[m.start():m.end()] = b"\1" * (m.end() - m.start())
    found = sorted(found, key=lambda m: m.start)
    for m in _modifiers(text, found):  # 'corner kicks', 'attempts on goal': one name, not two
        found.remove(m)
        taken[m.start:m.end] = bytes(m.end - m.start)
    merged: list[Mention] = []
    for m in found:  # 'the abnormal sale condition' (Condition of sale): two words of one name, one mention
        last = merged[-1] if merged else None
        if last is not None and m.kind == last.kind == "feature" and m.keys == last.keys and \
                text[last.end:m.start] == " ":
            merged[-1] = Mention(last.start, m.end, "feature", m.keys, "", last.form)
            taken[last.end:m.start] = b"\1"
        else:
            merged.append(m)
    found = _narrow(text, merged, vocab.words)
    masked = "".join("\0" if t else ch for ch, t in zip(text, taken))
    return found, masked


def _modifiers(text: str, found: list[Mention]) -> list[Mention]:
    """A word of a longer feature name that only completes another feature's whole name: the head of a compound right
    after it ('corner kicks': Corners, not Free Kicks) or the object of 'on'/'of'/'per' after it ('attempts on goal':
    Attempts, not Goal Scored); or that only qualifies the name right after it ('vehicle queue': a queue)."""
    out = []
    for prev, m in zip(found, found[1:]):
        if prev.kind == m.kind == "feature" and prev.form == "" and m.form == "part" and prev.keys != m.keys and \
                re.fullmatch(r" |\s+(?:on|of|per)\s+", text[prev.end:m.start]):
            out.append(m)
        elif prev.kind == m.kind == "feature" and prev.form == "part" and not set(prev.keys) & set(m.keys) and \
                text[prev.end:m.start] == " " and " " not in text[prev.start:prev.end]:
            out.append(prev)  # 'the 19-vehicle queue': a queue, not the emergency vehicle
    return out


#: what a model's input describes: a word of a feature's description, never a feature on its own
_INSTANCES = frozenset({"patient", "applicant", "borrower", "customer", "client", "person", "student", "team", "player",
                        "user", "house", "home", "property", "uav", "drone", "vehicle", "agent"})
#: words that make a label too plain to be recognised away from its feature ('the other features', 'at home')
_PLAIN_LABEL_WORDS = frozenset({"other", "others", "none", "unknown", "yes", "no", "home", "at", "true", "false", "na",
                                "missing", "not", "applicable", "some"})
_ORDINALS = frozenset({"second", "third", "fourth", "fifth", "2nd", "3rd", "4th", "5th"})
_IDIOM = re.compile(r"\b(?:on|of)\s+(?:its|their|his|her|my|our|your)\s+$", re.IGNORECASE)
_QUALIFIER_STOP = re.compile(r"[,.;:!?()\[\]]|\b(?:the|a|an|and|or|of|with|by|to|was|is|were|are|than|from|while|"
                             r"for|at|as|on|in|its|their|his|her|that|which)\b", re.IGNORECASE)


#: a qualifier after an ambiguous name: a preposition and a noun phrase of up to three words ('on the east approach')
_AFTER_QUALIFIER = re.compile(r"\s+(?:on|to|in|at|of|from|for)\s+(?:the\s+)?((?:[^\W\d_]+\s+){0,2}[^\W\d_]+)\b",
                              re.IGNORECASE)


def _meant(keys: tuple[str, ...], qual: list[str], words: dict[str, frozenset[str]]) -> tuple[str, ...]:
    """The meanings of an ambiguous name whose words hold every qualifying word; a meaning with an ordinal the
    qualifier lacks goes ('the strongest neighbour' is not 'the second strongest neighbour')."""
    meant = tuple(k for k in keys if qual and set(qual) <= words.get(k, frozenset()))
    plain = tuple(k for k in meant if not (words.get(k, frozenset()) & _ORDINALS) - set(qual))
    return plain or meant


def _narrow(text: str, found: list[Mention], words: dict[str, frozenset[str]]) -> list[Mention]:
    """An ambiguous name narrowed by the words that qualify it in its noun phrase: 'the serving cell's poor RSRQ'
    means the one RSRQ whose name or description has 'serving'; 'candidate 1's excellent RSRQ' the one of candidate
    1. Only words that belong to some of the meanings count ('poor', 'cell' do not); mentions inside the qualifier
    ('serving BS's') become part of the narrowed name. Nothing is guessed: without such words the name stays
    ambiguous."""
    out: list[Mention] = []
    inside: set[int] = set()  # mentions inside a qualifier after an ambiguous name: part of the narrowed name
    for m in found:
        if id(m) in inside:
            continue
        if m.kind != "feature" or len(m.keys) < 2:
            out.append(m)
            continue
        start = max(0, m.start - 40)
        stops = list(_QUALIFIER_STOP.finditer(text, start, m.start))
        lo = stops[-1].end() if stops else start
        if not stops and start > 0:
            lo = text.find(" ", start) + 1
        known = set().union(*(words.get(k, frozenset()) for k in m.keys))
        qual = [w for w in split_words(text[lo:m.start]) if w in known]
        if not qual and out and out[-1].kind == "feature" and \
                re.fullmatch(r"\s*(?:and|or|&|,)\s*", text[out[-1].end:m.start]):  # "candidate 1's RSRP and RSRQ"
            qual = [w for w in split_words(text[out[-1].start:out[-1].end]) if w in known]
            lo = m.start
        keys = _meant(m.keys, qual, words)
        if not keys or len(keys) == len(m.keys):
            after = _AFTER_QUALIFIER.match(text, m.end)  # 'the queue on the east approach': queue_east
            qual = [w for w in split_words(after.group(1)) if w in known] if after else []
            keys = _meant(m.keys, qual, words)
            if keys and len(keys) < len(m.keys):
                inside |= {id(n) for n in found if m.end < n.start < after.end()}  # 'approach' of approach_speed
                out.append(Mention(m.start, after.end(), "feature", keys))
            else:
                out.append(m)
            continue
        qualifier = text[lo:m.start]
        first = min(lo + len(qualifier) - len(qualifier.lstrip()), m.start)  # where the qualifying words begin
        while out and out[-1].kind == "feature" and out[-1].start >= first:
            out.pop()  # 'serving BS's' in 'the serving BS's weak RSRP'
        out.append(Mention(first, m.end, "feature", keys))
    return out
