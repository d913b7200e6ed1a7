"""Read any text back against an Explanation: numbers, feature names, directions, ranks and actions.

Each claim found is verified, contradicted or unsupported; a text is ``ok`` only when every claim is verified.
How claims are tied to features: the text is split into clauses (sentences, then ';'); a number belongs to the
feature named last before it in its clause, unless words around it name a decision-level quantity ("margin of",
"above", "vs", "score"); direction and rank words belong to the nearest feature mention (preferring the one before). Feature and
action mentions are masked before numbers are read, so digits inside names ('rsrp_1') are not numbers.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from ..explanation import Explanation
from ..policy import Policy
from .facts import decision_facts, global_facts

POSITIVE = ("toward", "towards", "supports", "supported", "supporting", "raises", "raised", "raising", "increases",
            "increased", "pushes up", "pushed up", "in favour of", "in favor of", "favours", "favoured", "favors",
            "favored")
NEGATIVE = ("against", "opposes", "opposed", "opposing", "lowers", "lowered", "lowering", "decreases", "decreased",
            "pushes down", "pushed down", "reduces", "reduced", "away from")
ORDINALS = {"most important": 1, "main": 1, "biggest": 1, "largest": 1, "strongest": 1, "first": 1, "top": 1,
            "second": 2, "2nd": 2, "third": 3, "3rd": 3, "fourth": 4, "4th": 4, "fifth": 5, "5th": 5}
_ORD = "|".join(sorted(map(re.escape, ORDINALS), key=len, reverse=True))
RANK_RE = re.compile(rf"\b(?:({_ORD})(?:\s+most\s+important|\s+largest|\s+biggest|\s+strongest)?\s+"
                     r"(feature|factor|driver|reason|contributor|influence)(s?)\b|(mattered|matters|counted) most)")
CHOICE_RE = re.compile(r"\b(chose|chooses|choose|picked|picks|selected|selects|decided on|decided to|preferred|"
                       r"prefers|opted for)\s*$")
CHOSEN_AFTER_RE = re.compile(r"^\s+(was|is|got)\s+(chosen|picked|selected|preferred)")
NUMBER_RE = re.compile(r"(?<![\w.])([+\-\u2212]?\d+(?:\.\d+)?)(\s*%)?")
IDENT_RE = re.compile(r"\b[A-Za-z][A-Za-z0-9]*(?:_[A-Za-z0-9]+)+\b")
MARGIN_WORDS = re.compile(r"\b(rather than|instead of|runner-up|runner up)\b")


@dataclass(frozen=True)
class Claim:
    kind: str       # number | feature | direction | rank | action
    text: str
    status: str     # verified | contradicted | unsupported
    detail: str = ""


@dataclass(frozen=True)
class Verification:
    claims: tuple[Claim, ...]

    @property
    def ok(self) -> bool:
        return all(c.status == "verified" for c in self.claims)

    def problems(self) -> list[Claim]:
        return [c for c in self.claims if c.status != "verified"]


@dataclass
class _Feature:
    values: list[float] = field(default_factory=list)      # numbers that must keep their sign
    contribs: dict[str, float] = field(default_factory=dict)  # context -> contribution (sign or magnitude)
    shares: list[float] = field(default_factory=list)
    ranks: dict[str, int] = field(default_factory=dict)       # context -> rank


@dataclass
class FactBook:
    """Everything a text may claim about one decision (or, with ``index=None``, about all states)."""

    features: dict[str, _Feature]
    surfaces: list[tuple[str, str, str]]  # (lowercase surface, kind, key)
    numbers: list[float]
    chosen: str | None
    runner_up: str | None
    global_view: bool = False
    by_unit: dict[str, list[float]] = field(default_factory=dict)  # domain comparisons, by their unit


_CLAIMY = re.compile(r"[+\-\u2212]\d|\d\.\d|%|\b(" + "|".join(map(re.escape, POSITIVE + NEGATIVE)) + r")\b|"
                    + RANK_RE.pattern, re.IGNORECASE)


def clean_surface(text: str) -> bool:
    """May this name or description hide its words from the verifier? Not if it carries claims itself (a signed or
    decimal number, a percentage, a direction or rank word): text from data files or plugins cannot smuggle claims."""
    return not _CLAIMY.search(text)


def _surfaces(exp: Explanation, policy: Policy | None) -> list[tuple[str, str, str]]:
    out = []
    for f in exp.feature_names:
        info = policy.features.get(f) if policy else None
        names = {f, f.replace("_", " ")} | ({info.description, *info.aliases} if info else set())
        out += [(n.lower(), "feature", f) for n in names if n]
    for a in exp.action_names:
        names = {a, a.replace("_", " "), *(policy.action_aliases.get(a, ()) if policy else ())}
        out += [(n.lower(), "action", a) for n in names if n]
    return sorted({o for o in out if clean_surface(o[0])}, key=lambda s: -len(s[0]))


def fact_book(exp: Explanation, index: int | None, policy: Policy | None = None) -> FactBook:
    feats = {f: _Feature() for f in exp.feature_names}
    if index is None:
        g = global_facts(exp, policy, k=len(exp.feature_names))
        for r in g.ranking:
            e = feats[r["name"]]
            e.values.append(r["mean_abs"])
            e.ranks["chosen"] = e.ranks["margin"] = r["rank"]
            if r["high_values"] != "mixed":
                e.contribs["chosen"] = e.contribs["margin"] = 1.0 if r["high_values"] == "toward" else -1.0
        return FactBook(feats, _surfaces(exp, policy), [g.n_states], None, None, global_view=True)
    d = decision_facts(exp, index, policy, k=len(exp.feature_names))
    for ctx, facts in (("chosen", d.top), ("margin", d.margin_top)):
        for ff in facts:
            e = feats[ff.name]
            e.values = [ff.value]
            e.contribs[ctx] = ff.contribution
            e.shares.append(ff.share)
            e.ranks[ctx] = ff.rank
    numbers = [d.score, d.runner_up_score, d.q_margin, d.base_value, d.additivity_gap]
    numbers += [c.value for c in d.comparisons]
    numbers += [float(v) for v in d.extras.values() if isinstance(v, (int, float)) and not isinstance(v, bool)]
    by_unit: dict[str, list[float]] = {}
    for c in d.comparisons:
        if c.unit:
            by_unit.setdefault(c.unit, []).append(c.value)
    runner_up = None if d.runner_up == d.action else d.runner_up  # a single available action: no alternative
    return FactBook(feats, _surfaces(exp, policy), numbers, d.action, runner_up, by_unit=by_unit)


def _matches(written: str, value: float, magnitude_ok: bool = False) -> bool:
    s = written.replace("\u2212", "-")
    x = float(s)
    decimals = len(s.split(".")[1]) if "." in s else 0
    tol = 0.5 * 10 ** -decimals + 1e-9 + 1e-6 * abs(value)
    if abs(x - value) <= tol:
        return True
    return magnitude_ok and s[0] not in "+-" and abs(x - abs(value)) <= tol


def _mentions(clause: str, book: FactBook) -> tuple[list["Mention"], str]:
    """Known feature/action mentions (start, end, kind, key) and the clause with them masked."""
    low = clause.lower()
    taken = [False] * len(clause)
    found = []
    for surface, kind, key in book.surfaces:
        for m in re.finditer(rf"(?<![\w]){re.escape(surface)}(?![\w])", low):
            if not any(taken[m.start():m.end()]):
                found.append((m.start(), m.end(), kind, key))
                taken[m.start():m.end()] = [True] * (m.end() - m.start())
    masked = "".join("\0" if t else ch for ch, t in zip(clause, taken))
    return sorted(found), masked


def _nearest(pos: int, feats: list["Mention"]) -> str | None:
    before = [f for f in feats if f[1] <= pos]
    if before:
        return before[-1][3]
    after = [f for f in feats if f[0] >= pos]
    return after[0][3] if after else None


def verify(text: str, explanation: Explanation, index: int | None = 0, policy: Policy | None = None) -> Verification:
    """Check every claim of ``text`` against the explanation of state ``index`` (``None``: the global view).

    :param policy: optional, for feature descriptions/aliases and domain facts the text may cite.
    """
    book = fact_book(explanation, index, policy)
    claims: list[Claim] = []
    for sentence in re.split(r"(?<=[.!?])\s+", text.strip()):
        sent_feats, sent_masked = _mentions(sentence, book)
        actions = [m for m in sent_feats if m[2] == "action"]
        margin_sentence = bool(MARGIN_WORDS.search(sentence.lower())) or any(
            m[3] == book.runner_up for m in actions)
        for start, end, _, key in actions:
            claims.append(_check_action(sentence, start, end, key, book))
        for clause in sentence.split(";"):
            _check_clause(clause, book, margin_sentence, claims)
        for ident in IDENT_RE.findall(sent_masked):
            claims.append(Claim("feature", ident, "contradicted", "not a feature or action of this explanation"))
    return Verification(tuple(claims))


def _check_action(sentence: str, start: int, end: int, key: str, book: FactBook) -> Claim:
    text = sentence[start:end]
    if book.global_view:
        return Claim("action", text, "unsupported", "a global summary names no particular action")
    is_choice = bool(CHOICE_RE.search(sentence[:start])) or bool(CHOSEN_AFTER_RE.match(sentence[end:]))
    if key == book.chosen:
        return Claim("action", text, "verified", "the chosen action")
    if is_choice:
        return Claim("action", text, "contradicted", f"the policy chose {book.chosen}, not {key}")
    if key == book.runner_up:
        return Claim("action", text, "verified", "the runner-up action")
    others = f" and {book.runner_up} (runner-up)" if book.runner_up else " (no other action was available)"
    return Claim("action", text, "contradicted", f"only {book.chosen} (chosen){others} is explained here")


def _feature_number(written: str, pct: bool, before: str, e: _Feature, key: str,
                    ctx: str) -> tuple[str, str, str | None]:
    """A number tied to a feature, read by its form: 'N%' is a share; '+N' or 'by N' a contribution (by N may
    drop the sign) to the sentence's context (the chosen action, or the margin over the runner-up); any other
    number is the feature's value, or a contribution written with its minus sign."""
    if pct:
        if any(_matches(written, v) for v in e.shares):
            return "verified", f"{key}: share", None
        return "contradicted", f"{written}% is not the share of {key}", None
    by = bool(re.search(r"\bby\s*$", before))
    signed = written[0] in "+-\u2212"
    if written[0] == "+" or by:
        c = e.contribs.get(ctx)
        if c is not None and _matches(written, c, magnitude_ok=by):
            return "verified", f"{key}: contribution ({ctx})", ctx
        return "contradicted", f"{written} is not the contribution of {key} ({ctx})", "final"
    if any(_matches(written, v) for v in e.values):
        return "verified", f"{key}: value", None
    if signed and ctx in e.contribs and _matches(written, e.contribs[ctx]):
        return "verified", f"{key}: contribution ({ctx})", ctx
    return "contradicted", f"{written} is not the value or a contribution of {key}", None


def _unit_slots(book: FactBook, after: str) -> list[float]:
    unit = re.match(r"\s*([a-zA-Z]+)\b", after)
    units = {u.lower(): v for u, v in book.by_unit.items()}
    return units.get(unit.group(1).lower(), []) if unit else []


def _cue_slots(book: FactBook, before: str, after: str) -> list[float] | None:
    """The decision-level quantity that the words around a number name (Q-margin, runner-up score, score), or
    None when they name none. These cues win over feature attachment."""
    if book.global_view or len(book.numbers) < 3:
        return None
    score, runner, margin = book.numbers[:3]
    if re.match(r"\s*(higher|above|more|ahead)\b", after) or re.search(r"margin( of)?\s*$", before):
        return [margin]
    if re.search(r"\bvs\.?\s*$|\bversus\s*$", before):
        return [runner]
    if re.match(r"\s*(vs\.?|versus)\s", after):
        return [score]
    if re.search(r"\bscor(e|ed|ing)\b[^0-9]*$", before) and not re.search(r"(higher|above|margin)", before):
        return [score]
    return None


def _free_slots(book: FactBook, after: str) -> list[float]:
    """What a number tied to no feature may stand for: a comparison in its unit, else any decision-level fact."""
    return _unit_slots(book, after) or book.numbers


Mention = tuple[int, int, str, str]  # (start, end, kind, key) of a feature or action named in a clause


def _check_clause(clause: str, book: FactBook, margin_sentence: bool, claims: list[Claim]) -> None:
    """Every claim of one clause: the features it names, then its numbers, directions and ranks."""
    found, masked = _mentions(clause, book)
    feats = [m for m in found if m[2] == "feature"]
    ctx_default = "margin" if margin_sentence else "chosen"
    claims += [Claim("feature", clause[start:end], "verified", key) for start, end, _, key in feats]
    matched_ctx: dict[str, str] = {}  # feature -> the context its numbers were verified in (directions follow it)
    for m in NUMBER_RE.finditer(masked):
        claims.append(_check_number(m, masked, feats, book, ctx_default, matched_ctx))
    claims += _check_directions(masked.lower(), feats, book, matched_ctx, ctx_default)
    claims += _check_ranks(masked.lower(), feats, book, ctx_default)


def _check_number(m: re.Match, masked: str, feats: list[Mention], book: FactBook, ctx_default: str,
                  matched_ctx: dict[str, str]) -> Claim:
    """A number: a decision-level quantity when the words around it say so, else a fact of the feature named
    before it, else (unless written as a contribution or share) a domain comparison or decision-level fact."""
    written, pct = m.group(1), bool(m.group(2))
    text = m.group(0).strip()
    before = masked[max(0, m.start() - 24):m.start()].lower()
    after = masked[m.end():m.end() + 12].lower()
    cue = _cue_slots(book, before, after)
    if cue is not None:  # "margin of 4.9", "5.4 above", "vs -11.8", "score -6.4"
        ok = any(_matches(written, v) for v in cue)
        return Claim("number", text, "verified" if ok else "contradicted",
                     "decision-level quantity named by the words around it")
    before_feats = [f for f in feats if f[1] <= m.start()]
    key = before_feats[-1][3] if before_feats else None
    status, detail, final = "unsupported", "matches no fact of this explanation", False
    if key is not None:
        status, detail, ctx = _feature_number(written, pct, before, book.features[key], key, ctx_default)
        final = ctx == "final"  # written as a contribution: no other fact may stand in for it
        if ctx and not final:
            matched_ctx.setdefault(key, ctx)
    if status != "verified" and not pct and not final:
        # a number tied to a feature may stand only for a domain comparison in the unit written after it
        wanted = _free_slots(book, after) if key is None else _unit_slots(book, after)
        if any(_matches(written, v) for v in wanted):
            status, detail = "verified", "a decision-level fact"
    return Claim("number", text, status, detail)


def _check_directions(low: str, feats: list[Mention], book: FactBook, matched_ctx: dict[str, str],
                      ctx_default: str) -> list[Claim]:
    """Direction words against the sign of the nearest feature's contribution (in the context its numbers used)."""
    out = []
    for words, polarity in ((POSITIVE, 1), (NEGATIVE, -1)):
        for w in words:
            for m in re.finditer(rf"\b{re.escape(w)}\b", low):
                key = _nearest(m.start(), feats)
                if key is None:
                    continue
                ctx = matched_ctx.get(key, ctx_default)
                c = book.features[key].contribs.get(ctx)
                if c is None or c == 0:
                    out.append(Claim("direction", w, "unsupported", f"no sign known for {key} ({ctx})"))
                elif np.sign(c) == polarity:
                    out.append(Claim("direction", w, "verified", f"{key} {ctx} contribution {c:+.3g}"))
                else:
                    out.append(Claim("direction", w, "contradicted", f"{key} pushes the other way ({c:+.3g})"))
    return out


def _check_ranks(low: str, feats: list[Mention], book: FactBook, ctx: str) -> list[Claim]:
    """Rank words ('most important', 'second factor', 'the top features were ...') against the ranking."""
    out = []
    for m in RANK_RE.finditer(low):
        rank = ORDINALS.get(m.group(1), 1) if m.group(1) else 1
        plural = bool(m.group(3))
        after = [f for f in feats if f[0] >= m.end()]
        targets = [f[3] for f in after] if plural else [_nearest(m.start(), feats)] if feats else []
        if not targets or targets == [None]:
            out.append(Claim("rank", m.group(0), "unsupported", "names no feature"))
            continue
        for key in targets:
            actual = book.features[key].ranks.get(ctx)
            limit_ok = actual is not None and (actual <= len(targets) if plural else actual == rank)
            out.append(Claim("rank", f"{m.group(0)}: {key}", "verified" if limit_ok else "contradicted",
                             f"{key} ranks {actual} ({ctx})"))
    return out
