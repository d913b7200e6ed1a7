"""Templates rendered on tracked facts and verified by provenance (issue 52, "Done when" items 1, 2 and 5).

1. Custom template sets: set 1 (benchmarks/data/templates/custom, frozen) and set 2 (.../heldout, held out, reported
   apart), on six policy kinds (a flat MLP, a dict observation, an image CNN narrated in regions, a continuous action
   with two dimensions, a value, the UAV plugin's DQN), 10 decisions each, with ``xairl.narrate(..., template=NAME,
   prompt_dirs=[DIR], robustness=False)``. A correct template's rendering should be verified; a wrong template's
   rendering is wrong only where its text differs from its TWIN's (benchmarks/data/templates/twins/<set>/<file>: the
   same wording with the error fixed), and it should then be caught (not verified). The twins should verify.
2. The built-in templates (prompts/*.yaml; the UAV plugin's ``handover`` on the UAV kind only) on every kind whose
   output they declare (``global_summary``: once per kind, index None). Mutation corpora of set 1's correct
   templates and of the built-ins: each template's first phrasings edited by regexes (numbers, directions, swaps,
   invented features, actions, signs of values), a mutated rendering counted where its text differs from the
   original's on that decision (for the signs: where a printed value is negative); and paraphrases that keep the
   meaning, counted where the original rendering is verified.
5. Time to verify an own narrative with provenance, per sentence (``xairl.verify(text, exp, i, policy,
   provenance=n.provenance)``, warm), median and 95th percentile per kind, and the reader's time on the same texts
   without provenance (goal: at most 2 ms per sentence on 2 cores).

A template that raises a TemplateError on a kind (e.g. it needs a plugin's extras) is 'not applicable' there.
Run: OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_templates.py [--decisions 10] [--sets custom,heldout,builtin]
     [--kinds flat,dict,image,continuous,value,uav] [--workers 2] [--quick] [--out /tmp/bench_templates.json]
"""

from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import os
import platform
import re
import shutil
import tempfile
import time
from collections import defaultdict
from pathlib import Path

import numpy as np
import torch
import yaml

import xairl
from xairl import prompts as xprompts
from xairl.errors import XairlError
from xairl.toy import toy_background, toy_policy

HERE = Path(__file__).resolve().parent
DATA = HERE / "data" / "templates"
KINDS = ("flat", "dict", "image", "continuous", "value", "uav")
OUTPUT_OF = {"flat": "actions", "dict": "actions", "image": "actions", "uav": "actions"} | {
    "continuous": "continuous",
    "value": "value",
}
CATEGORIES = ("numbers", "directions", "swaps", "invented", "actions", "signs")
MAX_EXAMPLES = 5

# ---------------------------------------------------------------------------------------------------------------
# The six policy kinds (small seeded torch nets; nothing imported from tests/)


def _seeded(net: torch.nn.Module, seed: int, scale: float = 0.5) -> torch.nn.Module:
    gen = torch.Generator().manual_seed(seed)
    with torch.no_grad():
        for p in net.parameters():
            p.copy_(torch.randn(p.shape, generator=gen) * scale)
    return net.eval()


class DictNet(torch.nn.Module):
    """A dict observation {"vec": (4,), "aux": (3,)}: two linear encoders summed, a ReLU, a head of 3 actions."""

    def __init__(self):
        super().__init__()
        self.vec, self.aux = torch.nn.Linear(4, 12), torch.nn.Linear(3, 12)
        self.act, self.head = torch.nn.ReLU(), torch.nn.Linear(12, 3)

    def forward(self, obs):
        return self.head(self.act(self.vec(obs["vec"]) + self.aux(obs["aux"])))


def build_kind(kind: str, n: int):
    """(policy, states, background) of one kind, seeded."""
    rng = np.random.default_rng(7)
    if kind == "flat":
        return toy_policy(), toy_background(n, seed=1), toy_background(100, seed=0)
    if kind == "dict":
        policy = xairl.Policy(
            _seeded(DictNet(), 1),
            feature_names=["speed", "heading", "gap_front", "gap_rear", "fuel", "load", "cabin_temp"],
            action_names=["accelerate", "brake", "coast"],
            observation={"vec": (4,), "aux": (3,)},
            name="dict",
        )
        s = rng.normal(size=(n + 100, 7)).astype(np.float32)
        return policy, s[:n], s[n:]
    if kind == "image":  # 3x32x32 frames: narrated in regions (patches of one channel)
        net = torch.nn.Sequential(
            torch.nn.Conv2d(3, 4, 4, 2),
            torch.nn.ReLU(),
            torch.nn.Conv2d(4, 8, 3, 2),
            torch.nn.ReLU(),
            torch.nn.Flatten(),
            torch.nn.Linear(8 * 7 * 7, 4),
        )
        policy = xairl.Policy(
            _seeded(net, 4, 0.3), observation=(3, 32, 32), action_names=["noop", "fire", "left", "right"], name="cnn"
        )
        frames = rng.random((n + 50, 3, 32, 32), dtype=np.float32)
        return policy, frames[:n], frames[n:]
    if kind in ("continuous", "value"):
        m = 2 if kind == "continuous" else 1
        net = _seeded(torch.nn.Sequential(torch.nn.Linear(6, 16), torch.nn.Tanh(), torch.nn.Linear(16, m)), 1 + m)
        policy = xairl.Policy(
            net,
            feature_names=["altitude", "airspeed", "pitch", "roll", "gust", "payload"],
            action_names=["steer", "throttle"] if m == 2 else None,
            output=kind,
            name=kind,
        )
        s = rng.normal(size=(n + 100, 6)).astype(np.float32)
        return policy, s[:n], s[n:]
    if kind == "uav":  # as `xairl explain --policy uav-dqn` loads it: the plugin's registered policy, its sampler
        policy = xairl.get_policy("uav-dqn")
        return policy, policy.background(n, seed=1), policy.background(100, seed=0)
    raise ValueError(kind)


# Filled in the parent before the workers fork (so they share the explanations)
STATE: dict = {}


def setup(kinds, n):
    for kind in kinds:
        policy, states, bg = build_kind(kind, n)
        t = time.perf_counter()
        exp = xairl.explain(policy, states, background=bg)
        STATE[kind] = (policy, exp, time.perf_counter() - t)


# ---------------------------------------------------------------------------------------------------------------
# Rendering (one job = one template on one decision of one kind)


def _claim(c) -> list:
    return [c.kind, c.text, c.status, c.rule, c.detail]


def render(job):
    """job: (key, dir or None, name, kind, index) -> (key, kind, index, result dict)."""
    key, folder, name, kind, index = job
    policy, exp, _ = STATE[kind]
    try:
        n = xairl.narrate(
            exp, index, template=name, policy=policy, prompt_dirs=[folder] if folder else [], robustness=False
        )
    except xprompts.TemplateError as exc:
        return key, kind, index, {"na": str(exc)[:300]}
    except XairlError as exc:
        return key, kind, index, {"error": f"{type(exc).__name__}: {str(exc)[:300]}"}
    except Exception as exc:  # a crash of xairl itself: reported, not counted
        return key, kind, index, {"error": f"CRASH {type(exc).__name__}: {str(exc)[:300]}"}
    return (
        key,
        kind,
        index,
        {
            "text": n.text,
            "verified": bool(n.verified),
            "sentences": [list(s) for s in n.sentences],
            "claims": [_claim(c) for c in n.claims],
            "negative_value": any(
                s.fact.quantity in ("value", "value_text") and _negative(s.fact.value) for s in n.provenance
            ),
        },
    )


def _negative(v) -> bool:
    if isinstance(v, (int, float)):
        return v < 0
    return isinstance(v, str) and v.lstrip().startswith(("-", "\u2212"))


def run_jobs(jobs, workers):
    out = {}
    if workers <= 1:
        for job in jobs:
            key, kind, index, res = render(job)
            out[(key, kind, index)] = res
        return out
    ctx = mp.get_context("fork")
    with ctx.Pool(workers) as pool:
        for key, kind, index, res in pool.imap_unordered(render, jobs, chunksize=8):
            out[(key, kind, index)] = res
    return out


# ---------------------------------------------------------------------------------------------------------------
# Templates


def read_template(path: Path) -> dict:
    return yaml.safe_load(path.read_text())


def template_kinds(spec: dict, kinds) -> list[str]:
    outs = spec.get("outputs") or ["actions", "continuous", "value"]
    return [k for k in kinds if OUTPUT_OF[k] in outs]


def builtin_templates(kinds) -> list[dict]:
    """The built-ins (prompts/*.yaml) and the UAV plugin's handover (on the UAV kind only)."""
    found = []
    for path in sorted(xprompts.builtin_dir().glob("*.yaml")):
        spec = read_template(path)
        found.append({"name": spec["name"], "path": path, "spec": spec, "kinds": template_kinds(spec, kinds)})
    from xairl.plugins import prompt_dirs

    for _, folder in prompt_dirs():
        for path in sorted(Path(folder).glob("*.yaml")):
            spec = read_template(path)
            if spec["name"] == "handover":
                found.append(
                    {"name": "handover", "path": path, "spec": spec, "kinds": [k for k in kinds if k == "uav"]}
                )
    return found


def set_templates(name: str, kinds) -> list[dict]:
    folder = DATA / name
    manifest = yaml.safe_load((folder / "MANIFEST.yaml").read_text())
    out = []
    for t in manifest["templates"]:
        path = folder / t["file"]
        spec = read_template(path)
        twin = DATA / "twins" / name / t["file"]
        out.append(
            {
                "name": spec["name"],
                "path": path,
                "spec": spec,
                "correct": bool(t["correct"]),
                "kinds": template_kinds(spec, kinds),
                "twin": twin if not t["correct"] else None,
                "error": t.get("error"),
            }
        )
    return out


def decisions_of(spec: dict, n: int):
    return [None] if spec.get("kind") == "global" else list(range(n))


# ---------------------------------------------------------------------------------------------------------------
# Mutations: regex edits of a template's first phrasings (what the template narrator renders)

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


# ---------------------------------------------------------------------------------------------------------------
# Summaries


def _bad_claims(res) -> list:
    return [c for c in res.get("claims", []) if c[2] == "contradicted"]


def _example(tname, kind, index, res, extra=None) -> dict:
    ex = {
        "template": tname,
        "kind": kind,
        "decision": index,
        "text": res.get("text"),
        "sentences": [s for s in res.get("sentences", []) if s[1] != "verified"],
        "contradicted": _bad_claims(res),
    }
    if extra:
        ex.update(extra)
    return ex


def summarise_set(set_name, templates, results, twins, n, kinds):
    """Per template and kind: verified/rendered (correct), caught/wrong (wrong), n/a; the twins' own verification."""
    rows, misses, false_rejections, twin_rows = [], [], [], []
    for t in templates:
        for kind in kinds:
            if kind not in t["kinds"]:
                continue
            row = {"template": t["name"], "kind": kind, "correct": t["correct"], "rendered": 0, "na": 0, "errors": 0}
            row.update({"verified": 0} if t["correct"] else {"wrong": 0, "caught": 0, "same_as_twin": 0})
            trow = {"template": t["name"], "kind": kind, "rendered": 0, "verified": 0, "na": 0}
            for i in decisions_of(t["spec"], n):
                res = results[((set_name, t["name"]), kind, i)]
                if "na" in res or "error" in res:
                    row["na" if "na" in res else "errors"] += 1
                    row.setdefault("message", res.get("na") or res.get("error"))
                    continue
                row["rendered"] += 1
                if t["correct"]:
                    row["verified"] += res["verified"]
                    if not res["verified"]:
                        false_rejections.append(_example(t["name"], kind, i, res))
                    continue
                twin = twins[((set_name + "-twin", t["name"]), kind, i)]
                if "text" in twin:
                    trow["rendered"] += 1
                    trow["verified"] += twin["verified"]
                    if not twin["verified"]:
                        false_rejections.append(_example(t["name"] + " (twin)", kind, i, twin))
                else:
                    trow["na"] += 1
                if "text" not in twin or twin["text"] == res["text"]:
                    row["same_as_twin"] += 1
                    continue
                row["wrong"] += 1
                row["caught"] += not res["verified"]
                if res["verified"]:
                    misses.append(_example(t["name"], kind, i, res, {"twin_text": twin["text"]}))
            rows.append(row)
            if not t["correct"]:
                twin_rows.append(trow)
    correct = [r for r in rows if r["correct"]]
    wrong = [r for r in rows if not r["correct"]]
    summary = {
        "correct_verified": sum(r["verified"] for r in correct),
        "correct_rendered": sum(r["rendered"] for r in correct),
        "wrong_caught": sum(r["caught"] for r in wrong),
        "wrong_renderings": sum(r["wrong"] for r in wrong),
        "twins_verified": sum(r["verified"] for r in twin_rows),
        "twins_rendered": sum(r["rendered"] for r in twin_rows),
        "not_applicable": sum(r["na"] for r in rows),
        "errors": sum(r["errors"] for r in rows),
        "failing_correct_templates": sorted({r["template"] for r in correct if r["verified"] < r["rendered"]}),
        "templates_with_missed_wrong": sorted({r["template"] for r in wrong if r["caught"] < r["wrong"]}),
        "twins_not_verified": sorted({r["template"] for r in twin_rows if r["verified"] < r["rendered"]}),
    }
    return {
        "rows": rows,
        "twins": twin_rows,
        "summary": summary,
        "false_rejections": false_rejections,
        "misses": misses,
    }


def summarise_builtins(templates, results, n, kinds):
    rows, false_rejections = [], []
    for t in templates:
        for kind in t["kinds"]:
            row = {"template": t["name"], "kind": kind, "rendered": 0, "verified": 0, "na": 0, "errors": 0}
            for i in decisions_of(t["spec"], n):
                res = results[(("builtin", t["name"]), kind, i)]
                if "na" in res or "error" in res:
                    row["na" if "na" in res else "errors"] += 1
                    row.setdefault("message", res.get("na") or res.get("error"))
                    continue
                row["rendered"] += 1
                row["verified"] += res["verified"]
                if not res["verified"]:
                    false_rejections.append(_example(t["name"], kind, i, res))
            rows.append(row)
    return {
        "rows": rows,
        "summary": {
            "verified": sum(r["verified"] for r in rows),
            "rendered": sum(r["rendered"] for r in rows),
            "failing": sorted({r["template"] for r in rows if r["verified"] < r["rendered"]}),
        },
        "false_rejections": false_rejections,
    }


# ---------------------------------------------------------------------------------------------------------------
# Timing (item 5)


def timing(kinds, templates, n, repeats=2):
    """Per kind: ms per sentence of verify with provenance and of the reader alone, over the kind's narratives."""
    out = {}
    for kind in kinds:
        policy, full, _ = STATE[kind]
        views, note = [full], None
        if full.output == "continuous":  # verify() on the whole continuous explanation: does it take the text?
            try:
                nar = xairl.narrate(full, 0, policy=policy, robustness=False)
                xairl.verify(nar.text, full, 0, policy, provenance=nar.provenance)
            except XairlError as exc:  # then each dimension on its own (as narrate verifies them)
                note = f"verify(text, exp, ...) on the 2-dimension explanation: {type(exc).__name__}: {exc}"
                views = [full.output_slice(j) for j in range(full.values.shape[2])]
        narratives = []
        for exp in views:
            for t in templates:
                if kind not in t["kinds"] or t["spec"].get("kind") == "global":
                    continue
                folder = str(t["path"].parent)
                for i in range(n):
                    try:
                        nar = xairl.narrate(
                            exp, i, template=t["name"], policy=policy, prompt_dirs=[folder], robustness=False
                        )
                    except XairlError:
                        continue
                    narratives.append((exp, i, nar))
        if not narratives:
            continue
        e0, i0, n0 = narratives[0]
        xairl.verify(n0.text, e0, i0, policy, provenance=n0.provenance)  # warm
        xairl.verify(n0.text, e0, i0, policy)
        prov, reader, agree = [], [], 0
        for exp, i, nar in narratives:
            k = max(1, len(nar.sentences))
            best_p = best_r = float("inf")
            for _ in range(repeats):
                t0 = time.perf_counter()
                v = xairl.verify(nar.text, exp, i, policy, provenance=nar.provenance)
                best_p = min(best_p, time.perf_counter() - t0)
                t0 = time.perf_counter()
                xairl.verify(nar.text, exp, i, policy)
                best_r = min(best_r, time.perf_counter() - t0)
            agree += bool(v.ok) == bool(nar.verified)
            prov.append(1000 * best_p / k)
            reader.append(1000 * best_r / k)
        out[kind] = {
            "narratives": len(narratives),
            "sentences": sum(max(1, len(nar.sentences)) for _, _, nar in narratives),
            "provenance_median_ms": float(np.median(prov)),
            "provenance_p95_ms": float(np.percentile(prov, 95)),
            "reader_median_ms": float(np.median(reader)),
            "reader_p95_ms": float(np.percentile(reader, 95)),
            "ratio_median": float(np.median(prov) / np.median(reader)),
            "verify_agrees_with_narrate": agree,
            "note": note,
        }
    return out


# ---------------------------------------------------------------------------------------------------------------


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--decisions", type=int, default=10)
    ap.add_argument("--sets", default="custom,heldout,builtin")
    ap.add_argument("--kinds", default=",".join(KINDS))
    ap.add_argument("--workers", type=int, default=min(2, os.cpu_count() or 1))
    ap.add_argument("--max-mutants", type=int, default=4, help="mutants per template and category (sites spread)")
    ap.add_argument("--no-mutations", action="store_true")
    ap.add_argument("--no-timing", action="store_true")
    ap.add_argument("--quick", action="store_true", help="3 decisions, 2 mutants per template and category")
    ap.add_argument("--out", default="/tmp/bench_templates.json")
    args = ap.parse_args()
    if args.quick:
        args.decisions, args.max_mutants = min(args.decisions, 3), min(args.max_mutants, 2)
    torch.set_num_threads(1)
    kinds = [k for k in args.kinds.split(",") if k]
    sets = [s for s in args.sets.split(",") if s]
    n = args.decisions
    started = time.perf_counter()
    print(
        f"machine: {platform.machine()}, {os.cpu_count()} cores, OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS')}, "
        f"torch {torch.__version__}, {args.workers} workers; {n} decisions per kind; kinds {', '.join(kinds)}"
    )
    setup(kinds, n)
    for kind in kinds:
        policy, exp, t = STATE[kind]
        print(
            f"  {kind:<11} {policy.name:<10} output={exp.output:<10} features={len(policy.feature_names):<5} "
            f"method={exp.method} explain {t:.2f}s"
        )

    tsets = {s: set_templates(s, kinds) for s in sets if s != "builtin"}
    builtins = builtin_templates(kinds) if "builtin" in sets else []
    report: dict = {
        "machine": {"arch": platform.machine(), "cores": os.cpu_count(), "torch": torch.__version__},
        "decisions": n,
        "kinds": kinds,
        "sets": {},
    }

    # Timing first, alone on the machine (item 5)
    if not args.no_timing:
        timed = [t for t in tsets.get("custom", []) if t["correct"]] + builtins
        report["timing"] = timing(kinds, timed, n)

    # Jobs: every template of the sets, the twins, the built-ins
    jobs = []
    for s, templates in tsets.items():
        for t in templates:
            for kind in t["kinds"]:
                for i in decisions_of(t["spec"], n):
                    jobs.append(((s, t["name"]), str(t["path"].parent), t["name"], kind, i))
                    if t["twin"] is not None:
                        jobs.append(((s + "-twin", t["name"]), str(t["twin"].parent), t["name"], kind, i))
    for t in builtins:
        for kind in t["kinds"]:
            for i in decisions_of(t["spec"], n):
                jobs.append((("builtin", t["name"]), None, t["name"], kind, i))

    tmp = Path(tempfile.mkdtemp(prefix="bench_templates_"))
    mutant_meta = {}  # key -> (source, template, category, label)
    if not args.no_mutations:
        sources = [("custom", t) for t in tsets.get("custom", []) if t["correct"]] + [("builtin", t) for t in builtins]
        for src, t in sources:
            for cat, items in mutants(t["spec"], args.max_mutants).items():
                for j, (label, spec) in enumerate(items):
                    key = ("mutant", src, t["name"], cat, j)
                    folder = tmp / f"{src}-{t['name']}-{cat}-{j}"
                    write_spec(spec, folder)
                    mutant_meta[key] = (src, t, cat, label)
                    for kind in t["kinds"]:
                        for i in decisions_of(t["spec"], n):
                            jobs.append((key, str(folder), t["name"], kind, i))
    print(f"renderings: {len(jobs)} ({len(mutant_meta)} mutated templates)", flush=True)
    t0 = time.perf_counter()
    results = run_jobs(jobs, args.workers)
    render_s = time.perf_counter() - t0
    shutil.rmtree(tmp, ignore_errors=True)

    # Sets 1 and 2
    for s, templates in tsets.items():
        twins = {k: v for k, v in results.items() if k[0][0] == s + "-twin"}
        report["sets"][s] = summarise_set(s, templates, results, twins, n, kinds)
    if builtins:
        report["sets"]["builtin"] = summarise_builtins(builtins, results, n, kinds)

    # Mutations
    if mutant_meta:
        report["mutations"] = summarise_mutations(mutant_meta, results, n)

    report["seconds"] = {"render_and_verify": render_s, "total": time.perf_counter() - started}
    print_report(report, tsets)
    Path(args.out).write_text(json.dumps(report, indent=1, default=str))
    print(f"\nJSON: {args.out}; {report['seconds']['total']:.0f} s in all ({render_s:.0f} s rendering)")


def summarise_mutations(meta, results, n):
    cats = {c: {"mutated": 0, "caught": 0, "templates": 0, "unchanged": 0, "na": 0} for c in CATEGORIES}
    para = {"rendered": 0, "rejected": 0, "templates": 0, "unchanged": 0, "na": 0, "original_not_verified": 0}
    misses, rejections = defaultdict(list), []
    per_template = defaultdict(lambda: defaultdict(lambda: [0, 0]))
    for key, (src, t, cat, label) in meta.items():
        tally = para if cat == "paraphrase" else cats[cat]
        tally["templates"] += 1
        for kind in t["kinds"]:
            for i in decisions_of(t["spec"], n):
                res = results[(key, kind, i)]
                orig = results[((src, t["name"]), kind, i)]
                if "text" not in res or "text" not in orig:
                    tally["na"] += 1
                    continue
                if res["text"] == orig["text"]:
                    tally["unchanged"] += 1
                    continue
                if cat == "paraphrase":
                    if not orig["verified"]:
                        tally["original_not_verified"] += 1
                        continue
                    tally["rendered"] += 1
                    if not res["verified"]:
                        tally["rejected"] += 1
                        rejections.append(_example(t["name"], kind, i, res, {"mutation": label, "source": src}))
                    continue
                if cat == "signs" and not orig.get("negative_value"):
                    tally["unchanged"] += 1
                    continue
                tally["mutated"] += 1
                tally["caught"] += not res["verified"]
                op = tally.setdefault("by_operator", {}).setdefault(_operator(label), [0, 0])
                op[0] += not res["verified"]
                op[1] += 1
                pt = per_template[f"{src}:{t['name']}"][cat]
                pt[0] += not res["verified"]
                pt[1] += 1
                if res["verified"]:
                    misses[cat].append(
                        _example(
                            t["name"],
                            kind,
                            i,
                            res,
                            {
                                "mutation": label,
                                "source": src,
                                "original": orig["text"],
                                "claims": _changed_claims(res, orig),
                            },
                        )
                    )
    return {
        "categories": cats,
        "paraphrases": para,
        "per_template": {k: {c: v for c, v in d.items()} for k, d in per_template.items()},
        "miss_counts": {c: len(v) for c, v in misses.items()},
        "misses": {c: _diverse(v, MAX_EXAMPLES) for c, v in misses.items()},
        "all_misses": {c: v for c, v in misses.items()},
        "paraphrase_rejections": _diverse(rejections, MAX_EXAMPLES),
        "all_paraphrase_rejections": rejections,
    }


def _operator(label: str) -> str:
    """A mutation's kind of edit: its label without the sentence and the position."""
    return re.sub(r"@\d+$", "", re.sub(r"^s\d+:", "", label))


def _changed_claims(res, orig) -> list:
    """The claims of the sentences that differ from the original rendering's (all claims when none is found)."""
    before = {s for s, _ in orig.get("sentences", [])}
    changed = [s for s, _ in res.get("sentences", []) if s not in before]
    claims = [c for c in res.get("claims", []) if any(c[1] and c[1] in s for s in changed)]
    return (claims or res.get("claims", []))[:12]


def _diverse(items, k):
    """Up to k examples: one per kind of edit first, then one per template, then the rest."""
    seen_op, seen_t, first, second, rest = set(), set(), [], [], []
    for ex in items:
        op, t = _operator(ex.get("mutation") or ""), ex["template"]
        if op not in seen_op:
            first.append(ex)
        elif t not in seen_t:
            second.append(ex)
        else:
            rest.append(ex)
        seen_op.add(op)
        seen_t.add(t)
    return (first + second + rest)[:k]


def _pct(a, b):
    return f"{a}/{b}" + (f" ({100 * a / b:.1f} %)" if b else "")


def print_report(report, tsets):
    kinds = report["kinds"]
    if "timing" in report:
        print("\nItem 5: verifying an own narrative with provenance, ms per sentence (goal: <= 2 ms)")
        print(
            f"  {'kind':<11} {'narr.':>5} {'sent.':>6} {'median':>7} {'p95':>7} | {'reader med':>10} {'p95':>7} | ratio"
        )
        for kind, r in report["timing"].items():
            print(
                f"  {kind:<11} {r['narratives']:>5} {r['sentences']:>6} {r['provenance_median_ms']:>7.2f} "
                f"{r['provenance_p95_ms']:>7.2f} | {r['reader_median_ms']:>10.2f} {r['reader_p95_ms']:>7.2f} | "
                f"{r['ratio_median']:.2f}  (verify(provenance).ok == narrate.verified: "
                f"{r['verify_agrees_with_narrate']}/{r['narratives']})"
            )
            if r.get("note"):
                print(f"    note ({kind}): {r['note'][:200]}; timed per dimension (Explanation.output_slice)")
    for s, res in report["sets"].items():
        title = {"custom": "Set 1 (custom, frozen)", "heldout": "Set 2 (HELD OUT)", "builtin": "Built-in templates"}
        print(f"\n{title.get(s, s)}")
        if s == "builtin":
            for r in res["rows"]:
                na = f"  n/a {r['na']}: {r['message'][:100]}" if r["na"] else ""
                err = f"  ERRORS {r['errors']}: {r['message'][:100]}" if r["errors"] else ""
                print(f"  {r['template']:<28} {r['kind']:<11} verified {r['verified']}/{r['rendered']}{na}{err}")
            sm = res["summary"]
            print(f"  => built-ins verified {_pct(sm['verified'], sm['rendered'])}; failing: {sm['failing']}")
            continue
        header = "  " + f"{'template':<36}" + "".join(f"{k:>12}" for k in kinds)
        print(header + "   (correct: verified/rendered; wrong: caught/wrong)")
        by = {(r["template"], r["kind"]): r for r in res["rows"]}
        for t in tsets[s]:
            cells = []
            for k in kinds:
                r = by.get((t["name"], k))
                if r is None:
                    cells.append("-")
                elif r["rendered"] == 0 and (r["na"] or r["errors"]):
                    cells.append("n/a" if r["na"] else "ERR")
                elif t["correct"]:
                    cells.append(f"{r['verified']}/{r['rendered']}")
                else:
                    cells.append(f"{r['caught']}/{r['wrong']}")
            mark = "" if t["correct"] else " [wrong]"
            print("  " + f"{t['name'] + mark:<36}" + "".join(f"{c:>12}" for c in cells))
        for r in res["rows"]:
            if r["na"] or r["errors"]:
                print(
                    f"    n/a {r['template']} on {r['kind']} ({r['na']} n/a, {r['errors']} errors): {r['message'][:160]}"
                )
        tw = {(r["template"], r["kind"]): r for r in res["twins"]}
        if tw:
            print(
                "  twins (corrected copies of the wrong templates) verified: "
                + ", ".join(f"{t}/{k} {r['verified']}/{r['rendered']}" for (t, k), r in tw.items())
            )
        sm = res["summary"]
        print(
            f"  => correct renderings verified {_pct(sm['correct_verified'], sm['correct_rendered'])}; wrong renderings "
            f"caught {_pct(sm['wrong_caught'], sm['wrong_renderings'])}; twins verified "
            f"{_pct(sm['twins_verified'], sm['twins_rendered'])}; n/a {sm['not_applicable']}, errors {sm['errors']}"
        )
        print(
            f"     failing correct templates: {sm['failing_correct_templates']}; wrong templates with misses: "
            f"{sm['templates_with_missed_wrong']}; twins not verified: {sm['twins_not_verified']}"
        )
        if s != "heldout":  # the held-out set's texts are not printed
            for ex in res["false_rejections"][:MAX_EXAMPLES]:
                _print_example("FALSE REJECTION", ex)
            for ex in res["misses"][:MAX_EXAMPLES]:
                _print_example("MISSED WRONG", ex)
    if s := report.get("sets", {}).get("builtin"):
        for ex in s["false_rejections"][:MAX_EXAMPLES]:
            _print_example("BUILT-IN FALSE REJECTION", ex)
    if "mutations" in report:
        m = report["mutations"]
        print("\nMutation corpora (set 1's correct templates and the built-ins): caught / mutated renderings")
        for c, r in m["categories"].items():
            print(
                f"  {c:<11} {_pct(r['caught'], r['mutated']):>24}   ({r['templates']} mutated templates; "
                f"{r['unchanged']} renderings unchanged, {r['na']} n/a)"
            )
        p = m["paraphrases"]
        print(
            f"  paraphrases rejected {_pct(p['rejected'], p['rendered'])} ({p['templates']} paraphrased templates; "
            f"{p['unchanged']} unchanged, {p['na']} n/a, {p['original_not_verified']} on decisions whose original "
            "was not verified, not counted)"
        )
        print("  by kind of edit (caught/mutated):")
        for c, r in m["categories"].items():
            ops = ", ".join(f"{o} {a}/{b}" for o, (a, b) in sorted(r.get("by_operator", {}).items()))
            print(f"    {c:<11} {ops}")
        for c, exs in m["misses"].items():
            print(f"\n  misses: {c} ({m['miss_counts'][c]} in all)")
            for ex in exs:
                _print_example("MISS", ex)
        if m["paraphrase_rejections"]:
            print(f"\n  paraphrases rejected ({len(m['all_paraphrase_rejections'])} in all)")
            for ex in m["paraphrase_rejections"]:
                _print_example("REJECTED PARAPHRASE", ex)


def _print_example(what, ex):
    head = f"    {what}: {ex['template']} on {ex['kind']}, decision {ex['decision']}"
    if ex.get("mutation"):
        head += f", mutation {ex.get('source')}:{ex['mutation']}"
    print(head)
    print(f"      text: {ex['text']}")
    if ex.get("original"):
        print(f"      original: {ex['original']}")
    if ex.get("twin_text"):
        print(f"      twin: {ex['twin_text']}")
    for s, st in ex.get("sentences", [])[:4]:
        print(f"      [{st}] {s[:300]}")
    for c in ex.get("contradicted", [])[:4]:
        print(f"      contradicted {c[0]} {c[1]!r} rule={c[3]}: {c[4][:200]}")
    for c in ex.get("claims", [])[:8]:
        print(f"      claim {c[0]} {c[1]!r} {c[2]} rule={c[3]}: {c[4][:160]}")


if __name__ == "__main__":
    main()
