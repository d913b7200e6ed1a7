"""Where a text names a feature, an action or a categorical value.

A feature is recognised by its name in any spelling (``gill_size``, "gill-size", "gill size", "GillSize"), its
description, its aliases, and by any run of their words that belongs to that feature alone ("kitchen" for
``kitchen_quality``). A run shared by several features ("quality" for ``overall_quality`` and ``kitchen_quality``)
is an *ambiguous* mention: a claim about it counts only when it holds, or fails, for every feature it may mean.
Actions are recognised by name, alias and verb forms ("recharged", "handing over to candidate 1"); a head word shared
by several actions ("handover") means the chosen or runner-up one among them. Categorical values are recognised by
their labels ("CollgCr", "self-employed" and "self-employment"); labels of one or two letters only next to their
feature's name. What each name may be written as is built once per explanation by :mod:`.vocabulary`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from xairl.policies.region_names import REGION_RE
from xairl.verification.prose.vocabulary import Vocabulary, region_key, split_words


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


#: a label given to its feature after it: "the mother's job, which is categorized as 'other'"
_ASSIGNED = re.compile(
    r"[\s,]*(?:(?:which|that)\s*)?(?:(?:is|was|being)\s*)?(?:categori[sz]ed|classified|listed|coded|"
    r"recorded|labell?ed|given)\s+as\s+(?:an?\s+)?[\"'“‘]?",
    re.IGNORECASE,
)


def find_mentions(text: str, vocab: Vocabulary) -> tuple[list[Mention], str]:
    """Mentions in ``text`` (longest surface first, no overlaps) and the text with them masked by NUL characters,
    so that digits inside names ('rsrp_1', 'candidate 2') are not read as numbers."""
    taken = bytearray(len(text))
    found: list[Mention] = []
    folded = text.lower().replace("ı", "i").replace("ſ", "s")  # the two letters a case-blind 'i' and 's' match
    # a region by its extent or its grid reference, first: 'patch F6 of frame 2' is one name, not 'patch F6' and more
    # ('patch F6 of frame 7', of no frame, is no mention of 'patch F6' either: left unmasked for unknown_regions)
    unknown = bytearray(len(text))
    for m in REGION_RE.finditer(text) if vocab.regions else ():
        keys = vocab.regions.get(region_key(m.group(0)))
        span = taken if keys else unknown
        if not any(taken[m.start() : m.end()]):
            found += [Mention(m.start(), m.end(), "feature", keys)] if keys else []
            span[m.start() : m.end()] = b"\1" * (m.end() - m.start())
    for pattern, kind, keys, label, form, needle in vocab.entries:
        if needle not in folded:
            continue  # the regex cannot match: much cheaper to know than to run it
        for m in pattern.finditer(text):
            if kind == "label" and _IDIOM.search(text, max(0, m.start() - 16), m.start()):
                continue  # 'on its own' is no housing label
            if not any(taken[m.start() : m.end()]) and not any(unknown[m.start() : m.end()]):
                found.append(Mention(m.start(), m.end(), kind, keys, label, form))
                taken[m.start() : m.end()] = b"\1" * (m.end() - m.start())
    features = [m for m in found if m.kind == "feature"]
    for f, labels in vocab.short_labels.items():  # 'Y', 'Ex', 'other': only right next to their feature
        near = [m for m in features if f in m.keys]
        for label, surface in labels:
            for m in re.finditer(rf"(?<![\w]){surface}(?![\w])", text, 0 if len(label) <= 2 else re.IGNORECASE):
                if any(
                    abs(m.start() - n.end) <= 14
                    or abs(n.start - m.end()) <= 14
                    or _ASSIGNED.fullmatch(text, n.end, m.start())
                    for n in near
                ) and not any(taken[m.start() : m.end()]):
                    found.append(Mention(m.start(), m.end(), "label", (f,), label))
                    taken[m.start() : m.end()] = b"\1" * (m.end() - m.start())
    found = sorted(found, key=lambda m: m.start)
    for m in dict.fromkeys(_modifiers(text, found)):  # 'corner kicks', 'attempts on goal': one name, not two
        found.remove(m)
        taken[m.start : m.end] = bytes(m.end - m.start)
    merged: list[Mention] = []
    for m in found:  # 'the abnormal sale condition' (Condition of sale): two words of one name, one mention
        last = merged[-1] if merged else None
        if (
            last is not None
            and m.kind == last.kind == "feature"
            and m.keys == last.keys
            and text[last.end : m.start] == " "
        ):
            merged[-1] = Mention(last.start, m.end, "feature", m.keys, "", last.form)
            taken[last.end : m.start] = b"\1"
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
        if (
            prev.kind == m.kind == "feature"
            and prev.form == ""
            and m.form == "part"
            and prev.keys != m.keys
            and re.fullmatch(r" |\s+(?:on|of|per)\s+", text[prev.end : m.start])
        ):
            out.append(m)
        elif (
            prev.kind == m.kind == "feature"
            and prev.form == "part"
            and not set(prev.keys) & set(m.keys)
            and text[prev.end : m.start] == " "
            and " " not in text[prev.start : prev.end]
        ):
            out.append(prev)  # 'the 19-vehicle queue': a queue, not the emergency vehicle
    return out


_ORDINALS = frozenset({"second", "third", "fourth", "fifth", "2nd", "3rd", "4th", "5th"})
_IDIOM = re.compile(r"\b(?:on|of)\s+(?:its|their|his|her|my|our|your)\s+$", re.IGNORECASE)
_QUALIFIER_STOP = re.compile(
    r"[,.;:!?()\[\]]|\b(?:the|a|an|and|or|of|with|by|to|was|is|were|are|than|from|while|"
    r"for|at|as|on|in|its|their|his|her|that|which)\b",
    re.IGNORECASE,
)


#: a qualifier after an ambiguous name: a preposition and a noun phrase of up to three words ('on the east approach')
_AFTER_QUALIFIER = re.compile(
    r"\s+(?:on|to|in|at|of|from|for)\s+(?:the\s+)?((?:[^\W\d_]+\s+){0,2}[^\W\d_]+)\b", re.IGNORECASE
)


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
        qual = [w for w in split_words(text[lo : m.start]) if w in known]
        if (
            not qual
            and out
            and out[-1].kind == "feature"
            and re.fullmatch(r"\s*(?:and|or|&|,)\s*", text[out[-1].end : m.start])
        ):  # "candidate 1's RSRP and RSRQ"
            qual = [w for w in split_words(text[out[-1].start : out[-1].end]) if w in known]
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
        qualifier = text[lo : m.start]
        first = min(lo + len(qualifier) - len(qualifier.lstrip()), m.start)  # where the qualifying words begin
        while out and out[-1].kind == "feature" and out[-1].start >= first:
            out.pop()  # 'serving BS's' in 'the serving BS's weak RSRP'
        out.append(Mention(first, m.end, "feature", keys))
    return out
