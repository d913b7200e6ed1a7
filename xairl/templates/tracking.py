"""Tracked rendering: every value a template takes from the facts keeps the fact it came from.

The facts a template sees are wrapped (:func:`track`): a name, an action or a label is a :class:`TrackedStr`, a number
a :class:`TrackedFloat` or :class:`TrackedInt`, each holding its :class:`Fact`; compared, tested or computed with,
they are the plain values. Printed while a rendering records (:func:`recording`), they write their text between
invisible markers (Unicode's private use area) saying which fact they are, which survive any string built around
them. :func:`untangle` takes them out: the clean text and a :class:`Span` per printed value, with its fact and the
template's transformation (``neg``, ``abs``, ``round``, ``scale``). The verifier checks a span by its fact.
"""

from __future__ import annotations

import contextvars
import math
import re
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, replace

#: start of a marker, its id (hex digits as private-use characters), end of the id, end of the span
_OPEN, _MID, _CLOSE, _DIGIT = "\ue000", "\ue001", "\ue002", 0xE010
_MARK = re.compile(f"{_OPEN}([\ue010-\ue01f]+){_MID}([^{_OPEN}{_MID}{_CLOSE}]*){_CLOSE}")
_STRAY = re.compile(f"[{_OPEN}-\ue004\ue010-\ue01f]")  # (a choice point's too: xairl.templates.choices)
_RECORD: contextvars.ContextVar[list | None] = contextvars.ContextVar("xairl_tracking", default=None)


@dataclass(frozen=True)
class Fact:
    """What a tracked value is.

    :param quantity: 'name' (a feature's name or label), 'value' (its value; 'value_text' as written with its unit,
        'fill' as a percentage of its capacity, 'level' its level word), 'contribution', 'share', 'rank',
        'direction', 'action', 'score', 'margin', 'base_value', 'base_margin', 'gap', 'comparison' (a domain fact's
        text; 'comparison_value' its number), 'extra' (a plugin's named value), 'mean_abs', 'mean' (a global
        summary's), 'n_states', 'method', 'index', 'unit', 'kind', 'target'; a counterfactual's 'cf_<field>'
        (:func:`track_counterfactual`); a claim word's 'direction', 'level', 'rank', 'rank_same_way', 'comparison' or
        'role', with ``of`` set (each filter of :mod:`xairl.templates.claim_filters` says its fact's shape).
    :param feature: the feature (or group) it is about; for 'extra' the key; else None.
    :param view: 'score' (the chosen action's score, or the output), 'margin' (over the runner-up) or None.
    :param role: for an action and its score: 'chosen' or 'runner_up'; for a claim word, see ``quantity``.
    :param value: the fact's value when it was rendered.
    :param of: for a claim word, the quantity of the tracked value its filter read ('contribution', 'margin',
        'level', 'rank', 'action', 'cf_action', ...); None for a value printed as it is.
    """

    quantity: str
    feature: str | None = None
    view: str | None = None
    role: str | None = None
    value: object = None
    of: str | None = None
    #: a claim filter's words are the same whatever the fact ('dir("raised", "raised")'): the word declares nothing
    alike: bool = False


@dataclass(frozen=True)
class Span:
    """A tracked value as printed: ``text`` at ``start:end`` of the clean text, its ``fact``, and the ``transform``
    the template applied to the value before printing it ('' none; else ``neg``, ``abs``, ``round``, ``scale:K``,
    joined by '+', in the order applied)."""

    start: int
    end: int
    text: str
    fact: Fact
    transform: str = ""

    def shifted(self, offset: int) -> Span:
        return replace(self, start=self.start + offset, end=self.end + offset)


def _mark(text: str, fact: Fact, transform: str) -> str:
    """``text`` between markers when a rendering records, else ``text``."""
    record = _RECORD.get()
    if record is None:
        return text
    record.append((fact, transform))
    digits = "".join(chr(_DIGIT + int(d, 16)) for d in f"{len(record) - 1:x}")
    return f"{_OPEN}{digits}{_MID}{_STRAY.sub('', text)}{_CLOSE}"


def _then(transform: str, step: str) -> str:
    return f"{transform}+{step}" if transform else step


class TrackedStr(str):
    """A string fact: equal to, and compared as, its text; printed with its markers. Case and strip methods keep
    the fact."""

    fact: Fact

    def __new__(cls, value: str, fact: Fact):
        obj = super().__new__(cls, value)
        obj.fact = fact
        return obj

    def __str__(self) -> str:
        return _mark(str.__str__(self), self.fact, "")

    def __html__(self) -> str:
        return str(self)

    def __format__(self, spec: str) -> str:
        return _mark(str.__format__(str.__str__(self), spec), self.fact, "")

    def _same(self, text: str) -> TrackedStr:
        return TrackedStr(text, self.fact)

    def lower(self):
        return self._same(str.lower(self))

    def upper(self):
        return self._same(str.upper(self))

    def title(self):
        return self._same(str.title(self))

    def capitalize(self):
        return self._same(str.capitalize(self))

    def strip(self, chars=None):
        return self._same(str.strip(self, chars))

    def __reduce__(self):
        return str, (str.__str__(self),)


class TrackedFloat(float):
    """A number fact: a float in every computation; negation, abs, rounding and scaling keep the fact (with the
    transformation); anything else gives a plain float, which the verifier reads like any other number."""

    fact: Fact
    transform: str

    def __new__(cls, value: float, fact: Fact, transform: str = ""):
        obj = super().__new__(cls, value)
        obj.fact, obj.transform = fact, transform
        return obj

    def printed(self, text: str) -> str:
        """``text`` (this number as a filter wrote it) with its markers."""
        return _mark(text, self.fact, self.transform)

    def __str__(self) -> str:
        return self.printed(float.__repr__(self))

    def __format__(self, spec: str) -> str:
        return self.printed(float.__format__(float(self), spec))

    def _keep(self, value: float, step: str) -> TrackedFloat:
        return TrackedFloat(value, self.fact, _then(self.transform, step))

    def __neg__(self):
        return self._keep(-float(self), "neg")

    def __pos__(self):
        return self

    def __abs__(self):
        return self._keep(abs(float(self)), "abs")

    def __round__(self, ndigits=None):
        out = round(float(self), ndigits)
        return out if ndigits is None else self._keep(out, f"round:{int(ndigits)}")

    def __mul__(self, other):
        if isinstance(other, (TrackedFloat, TrackedInt)):  # a product of two facts is neither of them
            return float(self) * float(other)
        if isinstance(other, (int, float)) and not isinstance(other, bool) and math.isfinite(other):
            return self._keep(float(self) * other, f"scale:{float(other):g}")
        return float.__mul__(self, other)

    __rmul__ = __mul__

    def __truediv__(self, other):
        if isinstance(other, (TrackedFloat, TrackedInt)):  # a ratio of two facts is neither of them
            return float(self) / float(other) if other else float.__truediv__(self, other)
        if isinstance(other, (int, float)) and not isinstance(other, bool) and other:
            return self._keep(float(self) / other, f"scale:{1 / float(other):g}")
        return float.__truediv__(self, other)

    def __reduce__(self):
        return float, (float(self),)


class TrackedInt(int):
    """An integer fact (a rank, a count, an id): an int in every computation, printed with its markers."""

    fact: Fact

    def __new__(cls, value: int, fact: Fact):
        obj = super().__new__(cls, value)
        obj.fact = fact
        return obj

    transform = ""

    def printed(self, text: str) -> str:
        return _mark(text, self.fact, "")

    def __str__(self) -> str:
        return self.printed(int.__repr__(self))

    def __format__(self, spec: str) -> str:
        return self.printed(int.__format__(int(self), spec))

    def __reduce__(self):
        return int, (int(self),)


def tracked(value, fact: Fact):
    """``value`` wrapped with its fact (a bool, None or a container is returned as it is)."""
    if isinstance(value, bool) or value is None:
        return value
    if isinstance(value, str):
        return TrackedStr(value, replace(fact, value=value))
    if isinstance(value, int):
        return TrackedInt(value, replace(fact, value=value))
    if isinstance(value, float):
        return TrackedFloat(value, replace(fact, value=value))
    return value


@contextmanager
def collecting(var: contextvars.ContextVar) -> Iterator[list]:
    """Within it, ``var`` holds a fresh list (what a rendering collects); yields that list."""
    token = var.set(record := [])
    try:
        yield record
    finally:
        var.reset(token)


def recording():
    """Within it, tracked values print with their markers; yields the (fact, transform) list for :func:`untangle`."""
    return collecting(_RECORD)


def untangle(marked: str, record: list) -> tuple[str, tuple[Span, ...]]:
    """(clean text, spans) of a text rendered under :func:`recording`; a marker the template broke (sliced, reversed)
    is dropped and its text is left untracked."""
    out, spans, pos = [], [], 0
    for m in _MARK.finditer(marked):
        out.append(_STRAY.sub("", marked[pos : m.start()]))
        start = sum(map(len, out))
        text = m.group(2)
        n = int("".join(f"{ord(c) - _DIGIT:x}" for c in m.group(1)), 16)
        if text and n < len(record):
            fact, transform = record[n]
            spans.append(Span(start, start + len(text), text, fact, transform))
        out.append(text)
        pos = m.end()
    out.append(_STRAY.sub("", marked[pos:]))
    return "".join(out), tuple(spans)


def strip_markers(text: str) -> str:
    """``text`` without any marker."""
    return _STRAY.sub("", text)


class Rendered(str):
    """A rendered phrasing: its clean text, with the :class:`Span` of every tracked value it printed."""

    spans: tuple[Span, ...]
    draft = None  #: its choice points (xairl.templates.choices.Draft) when the template offers wordings

    def __new__(cls, text: str, spans: tuple[Span, ...] = ()):
        obj = super().__new__(cls, text)
        obj.spans = spans
        return obj

    def __reduce__(self):
        return Rendered, (str.__str__(self), self.spans)


def joined(parts: list[tuple[str, tuple[Span, ...]]], separators: list[str]) -> Rendered:
    """Rendered texts joined by ``separators`` (one fewer), their spans shifted to their places."""
    text, spans = "", []
    for n, (part, part_spans) in enumerate(parts):
        if n:
            text += separators[n - 1]
        spans += [s.shifted(len(text)) for s in part_spans]
        text += part
    return Rendered(text, tuple(spans))


def locate(text: str, sentences: list[list[Rendered]]) -> tuple[Span, ...]:
    """The spans of ``text`` where it repeats phrasings of ``sentences`` in order (what a narrator composed from the
    template's phrasings): each sentence's longest phrasing found after the previous one lends its spans; words
    found in no phrasing carry none (the verifier reads them like outside prose)."""
    spans, cursor = [], 0
    for variants in sentences:
        best = None
        for v in sorted((v for v in variants if v), key=len, reverse=True):
            at = text.find(v, cursor)
            if at >= 0 and (best is None or at < best[0]):
                best = (at, v)
        if best is not None:
            at, v = best
            spans += [s.shifted(at) for s in getattr(v, "spans", ())]
            cursor = at + len(v)
    return tuple(spans)


_FEATURE_FIELDS = {
    "name": "name",
    "label": "name",
    "value": "value",
    "value_text": "value_text",
    "unit": "unit",
    "contribution": "contribution",
    "share": "share",
    "direction": "direction",
    "level": "level",
    "level_text": "level",
    "rank": "rank",
    "rank_same_way": "rank_same_way",
    "kind": "kind",
    "fill": "fill",
    "change": "value_change",
    "trend": "trend",
    "window": "window",
    "change_unit": "change_unit",
    "steps": "steps",
    "mean_abs": "mean_abs",
    "mean": "mean",
    "high_values": "direction_high",
    "low_values": "direction_low",
}


def _feature(d: Mapping, view: str | None) -> dict:
    name = str(d.get("name", ""))
    return {k: tracked(v, Fact(_FEATURE_FIELDS[k], name, view)) if k in _FEATURE_FIELDS else v for k, v in d.items()}


def track_decision(context: Mapping) -> dict:
    """A decision template's variables (:meth:`xairl.facts.DecisionFacts.context`) with every fact tracked."""
    c = dict(context)
    out = {
        "index": tracked(c["index"], Fact("index")),
        "action": tracked(c["action"], Fact("action", role="chosen")),
        "runner_up": tracked(c["runner_up"], Fact("action", role="runner_up")),
        "score": tracked(c["score"], Fact("score", view="score", role="chosen")),
        "runner_up_score": tracked(c["runner_up_score"], Fact("score", view="score", role="runner_up")),
        "q_margin": tracked(c["q_margin"], Fact("margin", view="margin")),
        "base_value": tracked(c["base_value"], Fact("base_value", view="score", role="chosen")),
        "base_margin": tracked(c["base_margin"], Fact("base_margin", view="margin")),
        "additivity_gap": tracked(c["additivity_gap"], Fact("gap")),
        "method": tracked(c["method"], Fact("method")),
        "top": [_feature(f, "score") for f in c["top"]],
        "margin_top": [_feature(f, "margin") for f in c["margin_top"]],
        "reasons": [_feature(f, "margin") for f in c["reasons"]],
        "concession": None if c["concession"] is None else _feature(c["concession"], "margin"),
        "identifiers": [_feature(f, "score") for f in c["identifiers"]],
        "trends": [
            _feature(f, "margin" if c["output"] == "actions" and c["runner_up"] != c["action"] else "score")
            for f in c.get("trends", ())
        ],
        "both_ways": [
            _feature(f, "margin" if c["output"] == "actions" and c["runner_up"] != c["action"] else "score")
            for f in c.get("both_ways", ())
        ],
        "comparisons": [
            {
                "text": tracked(d["text"], Fact("comparison", feature=str(d["text"]), value=d["value"])),
                "value": tracked(d["value"], Fact("comparison_value", feature=str(d["text"]))),
                "unit": d["unit"],
            }
            for d in c["comparisons"]
        ],
        "extras": {k: tracked(v, Fact("extra", feature=str(k))) for k, v in c["extras"].items()},
        "counterfactual": track_counterfactual(c.get("counterfactual")),
    }
    return c | out


def track_counterfactual(cf: Mapping | None) -> dict | None:
    """A counterfactual fact (:class:`xairl.counterfactual_facts.CounterfactualFact` as a dict), tracked: each
    change's fields as 'cf_<field>' of its feature, with role 'change:<n>' (which change), the rest as 'cf_<field>'."""
    if cf is None:
        return None
    changes = [
        {k: tracked(v, Fact(f"cf_{k}", str(d["name"]), role=f"change:{n}")) for k, v in d.items()}
        for n, d in enumerate(cf["changes"])
    ]
    return {k: tracked(v, Fact(f"cf_{k}")) for k, v in cf.items() if k != "changes"} | {"changes": changes}


def track_global(context: Mapping) -> dict:
    """A global template's variables (:meth:`xairl.facts.GlobalFacts.context`) with every fact tracked."""
    c = dict(context)
    view = c.get("view")
    return c | {
        "n_states": tracked(c["n_states"], Fact("n_states")),
        "method": tracked(c["method"], Fact("method")),
        "ranking": [_feature(f, view) for f in c["ranking"]],
        "target": tracked(c["target"], Fact("target", view=view)),
    }
