"""Mutations of a template for benchmarks/bench_templates.py: regex edits of its first phrasings (what the
template narrator renders) in six categories (numbers, directions, swaps, invented features, actions, signs of
values), and paraphrases that keep the meaning."""

from __future__ import annotations

import re
from collections import defaultdict
from pathlib import Path

import yaml

_NUMF = r"(?=\s*\)?\s*\|\s*(?:abs\s*\|\s*)?(?:num|signed)\b)"  # followed by a number filter (maybe via |abs)
_VAR = r"(?<![\w.\]])([a-z_]\w*(?:\[\d+\])?)"


def _blocks(s: str):
    """[(start, end)] of every {{ ... }} expression."""
    return [(m.start(), m.end()) for m in re.finditer(r"\{\{.*?\}\}", s, re.S)]


def _in_expr(s: str, pos: int) -> bool:
    return any(a <= pos < b for a, b in _blocks(s))


def _binding(s: str, pos: int, var: str):
    """How ``var`` is bound at ``pos``: ('loop', LIST), ('set', EXPR) or None (innermost definition before pos)."""
    stack, sets = [], {}
    for m in re.finditer(r"\{%-?\s*(for\s+(\w+)\s+in\s+(.+?)|endfor|set\s+(\w+)\s*=\s*(.+?))\s*-?%\}", s[:pos]):
        if m.group(2):
            stack.append((m.group(2), m.group(3).strip()))
        elif m.group(1) == "endfor":
            if stack:
                stack.pop()
        elif m.group(4):
            sets[m.group(4)] = m.group(5).strip()
    for v, lst in reversed(stack):
        if v == var:
            return ("loop", lst)
    if var in sets:
        return ("set", sets[var])
    return None


def _neighbour(expr: str) -> str | None:
    """A feature expression's neighbour in its list: L[k] -> L[k+1] (or itself when there is none)."""
    m = re.fullmatch(r"(\w+)\[(\d+)\]", expr)
    if m:
        lst, k = m.group(1), int(m.group(2))
        return f"({lst}[{k + 1}] if {lst}|length > {k + 1} else {expr})"
    if expr == "concession":
        return "(reasons[0] if reasons else concession)"
    return None


def _at(s: str, m: re.Match, new: str, group: int = 0) -> str:
    return s[: m.start(group)] + new + s[m.end(group) :]


def _spread(items: list, cap: int) -> list:
    """Up to ``cap`` items, taken in turn from each kind of edit (so that every kind is tried), in order."""
    if len(items) <= cap:
        return items
    groups: dict[str, list] = defaultdict(list)
    for it in items:
        groups[_operator(it[0])].append(it)
    chosen, queues = [], [list(g) for g in groups.values()]
    while len(chosen) < cap and any(queues):
        for q in queues:
            if q and len(chosen) < cap:
                chosen.append(q.pop(0))
    return chosen


def mutate_numbers(s: str):
    out = []
    for m in re.finditer(_VAR + r"\.contribution" + _NUMF, s):  # a feature's value printed as its contribution
        if _in_expr(s, m.start()):
            out.append((f"value-for-contribution@{m.start()}", _at(s, m, f"{m.group(1)}.value")))
    for m in re.finditer(_VAR + r"\.(contribution|share)" + _NUMF, s):  # a neighbour's number of the same kind
        var, what = m.group(1), m.group(2)
        b = _binding(s, m.start(), var)
        if b and b[0] == "loop":
            new = f"({b[1]}[loop.index] if not loop.last else {b[1]}[0]).{what}"
        else:
            nb = _neighbour(b[1] if b else var)
            if nb is None:
                continue
            new = f"{nb}.{what}"
        out.append((f"neighbour-{what}@{m.start()}", _at(s, m, new)))
    for old, new in (
        ("score", "runner_up_score"),
        ("runner_up_score", "score"),
        ("q_margin", "base_margin"),
        ("base_margin", "q_margin"),
        ("base_value", "score"),
        ("score", "base_value"),
    ):
        for m in re.finditer(rf"(?<![\w.]){old}(?=\s*\|\s*(?:num|signed))", s):
            out.append((f"{old}->{new}@{m.start()}", _at(s, m, new)))
    for m in re.finditer(r"\{\{[^{}]*?\|\s*(num|signed)\s*\}\}", s):  # a literal number for a filter's output
        out.append((f"literal@{m.start()}", _at(s, m, "+3.17" if m.group(1) == "signed" else "3.17")))
    return out


_PAIRS = (
    ("raised", "lowered"),
    ("lowered", "raised"),
    ("increased", "decreased"),
    ("decreased", "increased"),
    ("added", "took away"),
    ("took away", "added"),
)


def mutate_directions(s: str):
    out = []
    for a, b in _PAIRS:
        for m in re.finditer(rf"\b{a}\b", s):
            out.append((f"{a}->{b}@{m.start()}", _at(s, m, b)))
    # 'up' / 'down' as a direction (quoted for a filter's branch, or after pushed / pulled / moved ... it), not "made up"
    for m in re.finditer(r"'(up|down)'|(?<=\bit )(up|down)\b|(?<=ed )(up|down)\b(?! to)", s):
        word = m.group(1) or m.group(2) or m.group(3)
        if re.search(r"\bmade $", s[: m.start()]):
            continue
        flip = "down" if word == "up" else "up"
        out.append((f"{word}->{flip}@{m.start()}", _at(s, m, f"'{flip}'" if m.group(1) else flip)))
    action_ref = r"(?=\s*\{\{\s*(?:action|runner_up|doing|other)\b|')"
    for m in re.finditer(r"\b(toward|towards|against)\b" + action_ref, s):
        new = "against" if m.group(1).startswith("toward") else "toward"
        out.append((f"{m.group(1)}->{new}@{m.start()}", _at(s, m, new)))
    for m in re.finditer(r"(?:\(|\barguing |\bargued )(for)\b", s):
        out.append((f"for->against@{m.start()}", _at(s, m, "against", 1)))
    for m in re.finditer(r"\{\{\s*(\w+)\.direction\s*\}\}", s):  # a tracked direction word written flipped
        v = m.group(1)
        out.append(
            (f"direction@{m.start()}", _at(s, m, f"{{{{ 'against' if {v}.direction == 'toward' else 'toward' }}}}"))
        )
    for m in re.finditer(r"(favou?r\w*|in favou?r of|side was|on) \{\{\s*(action|runner_up)\b", s):  # whom it favoured
        other = "runner_up" if m.group(2) == "action" else "action"
        new = _at(s, m, other, 2)
        if not re.search(r"\{\{\s*(action|runner_up)\s*\}\} over \{\{\s*\1\s*\}\}", new):  # not "X over X"
            out.append((f"favoured-{m.group(2)}@{m.start()}", new))
    for m in re.finditer(r"\b(action|runner_up) if ([^{}%]*?) else (runner_up|action)\b", s):
        if m.group(1) != m.group(3):
            out.append((f"branches@{m.start()}", _at(s, m, f"{m.group(3)} if {m.group(2)} else {m.group(1)}")))
    return out


def mutate_swaps(s: str):
    out = []
    for m in re.finditer(_VAR + r"\.contribution" + _NUMF, s):  # pairwise swaps of a loop's numbers
        var = m.group(1)
        b = _binding(s, m.start(), var)
        if b and b[0] == "loop":
            lst = b[1]
            new = (
                f"({lst}[loop.index] if loop.index0 is even and not loop.last else "
                f"({lst}[loop.index0 - 1] if loop.index0 is odd else {var})).contribution"
            )
            out.append((f"loop-pairs@{m.start()}", _at(s, m, new)))
    singles = []  # two singletons of one list, each printed: their numbers crossed
    for m in re.finditer(_VAR + r"\.contribution" + _NUMF, s):
        b = _binding(s, m.start(), m.group(1))
        expr = b[1] if b and b[0] == "set" else (m.group(1) if b is None else None)
        if expr and re.fullmatch(r"\w+\[\d+\]", expr):
            singles.append((m, expr))
    for i in range(len(singles)):
        for j in range(i + 1, len(singles)):
            (m1, e1), (m2, e2) = singles[i], singles[j]
            if e1 != e2 and e1.split("[")[0] == e2.split("[")[0]:
                t = s[: m2.start()] + f"{m1.group(1)}.contribution" + s[m2.end() :]
                t = t[: m1.start()] + f"{m2.group(1)}.contribution" + t[m1.end() :]
                out.append((f"cross-{e1}-{e2}@{m1.start()}", t))
    sc = [m for m in re.finditer(r"(?<![\w.])(score|runner_up_score)(?=\s*\|\s*num)", s)]
    if {m.group(1) for m in sc} == {"score", "runner_up_score"}:  # the two actions' scores crossed
        t = s
        for m in reversed(sc):
            t = _at(t, m, "runner_up_score" if m.group(1) == "score" else "score")
        out.append(("scores-crossed", t))
    return out


def mutate_actions(s: str):
    out = []
    if not re.search(r"\b(chose|chosen|choose|picked|preferred|beat|won|went with|executing|Why|kept|handed)\b", s):
        return out
    refs = list(re.finditer(r"\{\{\s*(action|runner_up)\b", s))
    if {m.group(1) for m in refs} == {"action", "runner_up"}:
        t = s
        for m in reversed(refs):
            t = _at(t, m, "runner_up" if m.group(1) == "action" else "action", 1)
        out.append(("both-swapped", t))
    first = next((m for m in refs if m.group(1) == "action"), None)
    if first is not None:
        out.append((f"chosen-named-runner-up@{first.start()}", _at(s, first, "runner_up", 1)))
    for m in re.finditer(r"extras\.(target_candidate|runner_up_candidate)\b", s):
        other = "runner_up_candidate" if m.group(1) == "target_candidate" else "target_candidate"
        out.append((f"candidate@{m.start()}", _at(s, m, other, 1)))
    return out


def mutate_signs(s: str):
    out = []
    for m in re.finditer(_VAR + r"\.value_text\b(?!\s*\|)", s):
        if re.search(r"\bif\s*$", s[: m.start()]):
            continue  # the condition `if f.value_text`, not a print
        v = m.group(1)
        out.append((f"value_text-unsigned@{m.start()}", _at(s, m, f"({v}.value_text|replace('-', ''))")))
        out.append(
            (
                f"value-abs@{m.start()}",
                _at(s, m, f"({v}.value|abs|num if {v}.value is number and {v}.value < 0 else {v}.value_text)"),
            )
        )
    for m in re.finditer(_VAR + r"\.value(?=\s*\|\s*num)", s):
        out.append((f"value-abs@{m.start()}", _at(s, m, f"{m.group(1)}.value|abs")))
    return out


INVENTED = (
    "The feature wind_speed contributed +0.50 toward this action.",
    "{{ action|cap }} also got +0.50 from the feature wind_speed.",
)


def paraphrase(s: str):
    out = []
    for a, b in (("raised", "increased"), ("lowered", "decreased"), ("chose", "picked"), ("came from", "was due to")):
        for m in re.finditer(rf"\b{a}\b", s):
            out.append((f"{a}->{b}@{m.start()}", _at(s, m, b)))
    for m in re.finditer(r"\bby (?=\{\{)", s):
        out.append((f"by-about@{m.start()}", _at(s, m, "by about ")))
    return out


_REFERS = re.compile(r"\b(it|its|this|that|these|those|them|then|also|the gap|next)\b", re.I)


def mutants(spec: dict, cap: int) -> dict[str, list[tuple[str, dict]]]:
    """{category: [(label, mutated spec)]}, and 'paraphrase'; each edit on one first phrasing."""
    sentences = [list(v) if isinstance(v, list) else [v] for v in spec["sentences"]]
    found: dict[str, list] = defaultdict(list)

    def with_first(k: int, new: str) -> dict:
        ss = [list(v) for v in sentences]
        ss[k][0] = new
        return {**spec, "sentences": ss}

    ops = {
        "numbers": mutate_numbers,
        "directions": mutate_directions,
        "swaps": mutate_swaps,
        "actions": mutate_actions,
        "signs": mutate_signs,
        "paraphrase": paraphrase,
    }
    for cat, op in ops.items():
        for k, v in enumerate(sentences):
            for label, new in op(v[0]):
                if new != v[0]:
                    found[cat].append((f"s{k + 1}:{label}", with_first(k, new)))
    for j, line in enumerate(INVENTED):
        found["invented"].append((f"appended-{j + 1}", {**spec, "sentences": [*sentences, [line]]}))
    for k in range(len(sentences) - 1):  # two neighbouring sentences that do not refer back, in the other order
        a, b = sentences[k][0], sentences[k + 1][0]
        if not _REFERS.search(re.sub(r"\{[{%].*?[}%]\}", " ", a + " " + b)):
            ss = [list(v) for v in sentences]
            ss[k], ss[k + 1] = ss[k + 1], ss[k]
            found["paraphrase"].append((f"order-s{k + 1}-s{k + 2}", {**spec, "sentences": ss}))
    return {c: _spread(v, cap) for c, v in found.items()}


def write_spec(spec: dict, folder: Path) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{spec['name']}.yaml"
    path.write_text(yaml.safe_dump(spec, sort_keys=False, allow_unicode=True, width=100_000))
    return path


def _operator(label: str) -> str:
    """A mutation's kind of edit: its label without the sentence and the position."""
    return re.sub(r"@\d+$", "", re.sub(r"^s\d+:", "", label))
