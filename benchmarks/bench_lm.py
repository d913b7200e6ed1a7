"""local_lm (issue 66, "Done when"): the language model chooses the template's wordings. For the toy policy
(``explain_action``) and the reference UAV policy (``uav-dqn``, ``handover``), on ``--states`` decisions each:

- **first try, every sentence chosen**: the narrative's source is ``local_lm`` (not the template's fallback) and the
  model chose the wording of every sentence (``extras["chosen"]``: sentences it chose, sentences offering a choice,
  sentences); also the share where it chose every sentence that offers a choice;
- **false**: narratives shown with a status other than verified (a choice the verifier did not pass);
- **garbled**: narratives whose text has a form fault (:func:`xairl.narrators.battery.malformed`: a tracked value
  glued to a word, a doubled space, a space before punctuation, ...);
- **worded together**: 16 decisions narrated alone, then prepared 8 at a time as the CLI does
  (:func:`xairl.narrators.prepare`: each step's choices of all 8 in one batched forward pass); the ratio of times,
  and whether the texts are the same;
- **audiences**: the share of decisions worded differently for ``operator`` and ``researcher``, each verified;
- **latency**: warm seconds a sentence on one thread (median, 90th percentile); **cold start**: a fresh process's
  first narrative less its second of the same decision, after a template narrative (so: the import of
  transformers, the model's load, the prompt's encoding), after the model's cached copy exists, and apart the import of transformers' model code alone.

``--out`` writes every decision's texts for each audience beside the template's, for reading by hand.

Run (about 3 minutes on 2 cores; nothing is downloaded):
    HF_HUB_OFFLINE=1 .venv/bin/python benchmarks/bench_lm.py [--states 40] [--out /tmp/lm.md]
"""

import argparse
import os
import statistics
import subprocess
import sys
import time

os.environ.setdefault("HF_HUB_OFFLINE", "1")

import xairl  # noqa: E402
from xairl.narrators.battery import malformed  # noqa: E402
from xairl.templates.tracking import Rendered  # noqa: E402

POLICIES = (("toy", "explain_action"), ("uav-dqn", "handover"))
AUDIENCES = (None, "operator", "researcher")

COLD = """
import time, xairl
p = xairl.get_policy('toy')
e = xairl.explain(p, p.background(2, seed=5), background=p.background(20))
kw = dict(narrator='local_lm', policy=p, robustness=False, options={'threads': 1})
xairl.narrate(e, 0, policy=p, robustness=False)  # (xairl's own first-use costs: the template, the verifier)
t0 = time.perf_counter(); xairl.narrate(e, 0, **kw); t1 = time.perf_counter(); xairl.narrate(e, 0, **kw)
print(t1 - t0 - (time.perf_counter() - t1))
"""
#: what importing transformers' model code costs a fresh process that has imported xairl and torch
IMPORT = """
import time, xairl, torch
t = time.perf_counter()
from transformers.models.llama import modeling_llama
print(time.perf_counter() - t)
"""


def fresh(code: str) -> float:
    return float(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout)


def run(name: str, template: str, states: int, pages: list[str]) -> dict:
    policy = xairl.get_policy(name)
    exp = xairl.explain(policy, policy.background(states, seed=7), background=policy.background(60))
    kw = {"narrator": "local_lm", "policy": policy, "template": template, "robustness": False}
    for audience in AUDIENCES:  # (each audience's prompt is encoded once, before the timed runs)
        xairl.narrate(exp, 0, **kw, options={"threads": 1, "audience": audience})
    every = offered = false = garbled = differ = 0
    per_sentence = []
    for i in range(states):
        texts = {}
        for audience in AUDIENCES:
            t = time.perf_counter()
            n = xairl.narrate(exp, i, **kw, options={"threads": 1, "audience": audience})
            seconds = time.perf_counter() - t
            chose, choosing, sentences = n.extras.get("chosen", (0, 0, 0))
            false += n.status != "verified"
            garbled += malformed(Rendered(n.text, n.provenance)) is not None
            texts[audience] = n.text
            if audience is None:
                per_sentence.append(seconds / max(sentences, 1))
                every += n.source == "local_lm" and chose == sentences
                offered += n.source == "local_lm" and chose == choosing
        differ += texts["operator"] != texts["researcher"]
        plain = xairl.narrate(exp, i, policy=policy, template=template, robustness=False).text
        pages.append(
            f"### {name}, decision {i}\n\n**template:** {plain}\n\n"
            + "\n\n".join(f"**{a or 'no audience'}:** {t}" for a, t in texts.items())
            + "\n"
        )
    per_sentence.sort()
    return {
        "policy": name,
        "states": states,
        "every": every,
        "offered": offered,
        "false": false,
        "garbled": garbled,
        "differ": differ,
        "median": statistics.median(per_sentence),
        "p90": per_sentence[int(0.9 * (len(per_sentence) - 1))],
    }


def together(name: str, template: str, n: int = 16, batch: int = 8) -> tuple[float, bool]:
    """(time alone / time prepared `batch` at a time, the same texts) on ``n`` decisions."""
    from xairl.narrators import prepare

    policy = xairl.get_policy(name)
    exp = xairl.explain(policy, policy.background(n, seed=3), background=policy.background(60))
    kw = {"narrator": "local_lm", "options": {"threads": 1}}
    how = {"policy": policy, "robustness": False, "template": template}
    xairl.narrate(exp, 0, **kw, **how)
    t = time.perf_counter()
    alone = [xairl.narrate(exp, i, **kw, **how).text for i in range(n)]
    seconds = time.perf_counter() - t
    t, texts = time.perf_counter(), []
    for start in range(0, n, batch):
        prepare(exp, [(i, how) for i in range(start, min(start + batch, n))], **kw)
        texts += [xairl.narrate(exp, i, **kw, **how).text for i in range(start, min(start + batch, n))]
    return seconds / (time.perf_counter() - t), texts == alone


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--states", type=int, default=40)
    ap.add_argument("--out", default=None, help="Markdown file with every text, for reading by hand")
    args = ap.parse_args()
    pages: list[str] = []
    rows = [run(name, template, args.states, pages) for name, template in POLICIES]
    batched = {name: together(name, template) for name, template in POLICIES}
    cold, imports = [fresh(COLD) for _ in range(3)], [fresh(IMPORT) for _ in range(3)]
    print(
        "| policy | decisions | first try, every sentence chosen | every offered choice | false | garbled "
        "| operator != researcher | s a sentence (median, p90) |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        n = r["states"]
        print(
            f"| {r['policy']} | {n} | {r['every']}/{n} ({100 * r['every'] / n:.0f} %) | {r['offered']}/{n} "
            f"| {r['false']}/{3 * n} | {r['garbled']}/{3 * n} | {r['differ']}/{n} | {r['median']:.2f}, {r['p90']:.2f} |"
        )
    for name, (ratio, same) in batched.items():
        print(f"{name}: 16 decisions worded 8 at a time {ratio:.2f}x as fast as alone; the same texts: {same}")
    print(
        f"cold start (a fresh process's first narrative less its second of the same decision, cached model): "
        f"{statistics.median(cold):.2f} s median of {', '.join(f'{c:.2f}' for c in cold)}; of which importing "
        f"transformers' model code {statistics.median(imports):.2f} s"
    )
    if args.out:
        with open(args.out, "w") as fh:
            fh.write("# local_lm wordings by audience\n\n" + "\n".join(pages))
        print(f"texts: {args.out}")


if __name__ == "__main__":
    main()
