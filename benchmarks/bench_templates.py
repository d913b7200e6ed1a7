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
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import torch

import xairl
from xairl.errors import XairlError
from xairl.templates import prompts as xprompts
from xairl.toy import toy_background, toy_policy

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from benchmarks.template_mutations import mutants, write_spec  # noqa: E402
from benchmarks.template_report import (  # noqa: E402
    decisions_of,
    print_report,
    summarise_builtins,
    summarise_mutations,
    summarise_set,
)
from benchmarks.template_sets import KINDS, builtin_templates, set_templates  # noqa: E402

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

    jobs = template_jobs(tsets, builtins, n)
    tmp = Path(tempfile.mkdtemp(prefix="bench_templates_"))
    mutant_meta = {}  # key -> (source, template, category, label)
    if not args.no_mutations:
        jobs += mutant_jobs(tsets, builtins, args.max_mutants, n, tmp, mutant_meta)
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


def template_jobs(tsets: dict, builtins: list, n: int) -> list:
    """A rendering job for every template of the sets (and its twin), and every built-in, on each decision."""
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
    return jobs


def mutant_jobs(tsets: dict, builtins: list, max_mutants: int, n: int, tmp: Path, meta: dict) -> list:
    """The mutants of every correct custom template and every built-in, written under ``tmp``, a rendering job for
    each on each decision; ``meta`` gets each mutant's (source, template, category, label)."""
    jobs = []
    sources = [("custom", t) for t in tsets.get("custom", []) if t["correct"]] + [("builtin", t) for t in builtins]
    for src, t in sources:
        for cat, items in mutants(t["spec"], max_mutants).items():
            for j, (label, spec) in enumerate(items):
                key = ("mutant", src, t["name"], cat, j)
                folder = tmp / f"{src}-{t['name']}-{cat}-{j}"
                write_spec(spec, folder)
                meta[key] = (src, t, cat, label)
                for kind in t["kinds"]:
                    for i in decisions_of(t["spec"], n):
                        jobs.append((key, str(folder), t["name"], kind, i))
    return jobs


if __name__ == "__main__":
    main()
