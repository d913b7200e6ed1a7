"""What the local language model adds over the template: ``template`` vs ``local_lm`` mode=choose vs mode=rewrite.

For each policy (the toy policy with ``explain_action`` and the reference UAV policy ``uav-dqn`` with ``handover``)
and each narrator, over the same states:

- verified 1st: share of narratives whose own text verified (before any template fallback);
- shown != tpl: share where the text shown to the user differs from the template narrator's text;
- own != tpl: the same for the model's own text, shown or rejected (rewrite: what the model wrote);
- edit (words): mean word-level edit distance between the shown text and the template's text (and the same for
  the model's own text), with the template text's mean length for scale;
- sent. changed: mean share of the template's sentences that do not appear unchanged in the shown text;
- warm latency: median (p90) seconds per narrative with the model already loaded (``xairl.narrate`` end to end);
- cold start: a new process that imports xairl, loads the model from its converted copy and narrates once (measured
  once, in a subprocess); the first use ever also converts the packaged GGUF file (timed in this process when
  the model cache is empty, which it is by default: a fresh temporary cache).

Then two example pairs (template vs rewrite) so a reader sees what changes.

Run (about 10 minutes on 2 busy cores; nothing is downloaded):
    HF_HUB_OFFLINE=1 .venv/bin/python benchmarks/bench_lm_modes.py [--states 20] [--rewrite-states N]
        [--policies toy:explain_action,uav-dqn:handover] [--model-cache DIR] [--threads N]
``--rewrite-states`` (default: ``--states``) narrows the slow rewrite mode to the first N states (0: skip it).
``--threads`` sets torch's CPU threads for the model (default: torch's choice, all cores); on a shared machine
``--threads 1`` is several times faster for rewrite (greedy generation); the figures in the module doc of
xairl/narrators/local_lm.py give both.
"""

import argparse
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile
import textwrap
import time

os.environ.setdefault("HF_HUB_OFFLINE", "1")
os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")

import numpy as np  # noqa: E402

import xairl  # noqa: E402

COLD = (
    "import time; t0 = time.perf_counter(); import xairl; from xairl.narrators import local_lm; "
    "t1 = time.perf_counter(); local_lm.load_model(); t2 = time.perf_counter(); "
    "p = xairl.get_policy({policy!r}); e = xairl.explain(p, p.background(1, seed=5), background=p.background(50)); "
    "t3 = time.perf_counter(); n = xairl.narrate(e, 0, narrator='local_lm', policy=p, template={template!r}, "
    "options={options!r}); t4 = time.perf_counter(); print(t1 - t0, t2 - t1, t4 - t3, t4 - t0 - (t3 - t2))"
)
SENTENCE = re.compile(r"(?<=[.!?])\s+(?=[A-Z0-9])")


def word_edits(a: str, b: str) -> int:
    """Levenshtein distance between the word sequences of ``a`` and ``b`` (insert, delete, substitute a word)."""
    x, y = a.split(), b.split()
    row = list(range(len(y) + 1))
    for i, wx in enumerate(x, 1):
        prev, row[0] = row[0], i
        for j, wy in enumerate(y, 1):
            prev, row[j] = row[j], min(row[j] + 1, row[j - 1] + 1, prev + (wx != wy))
    return row[-1]


def sentences_changed(template: str, text: str) -> float:
    """Share of the template's sentences that are not, unchanged, a sentence of ``text``."""
    ours = SENTENCE.split(template.strip())
    theirs = set(SENTENCE.split(text.strip()))
    return sum(s not in theirs for s in ours) / max(len(ours), 1)


def run_policy(name: str, template: str, n_states: int, n_rewrite: int, threads: int | None):
    policy = xairl.get_policy(name)
    exp = xairl.explain(policy, policy.background(n_states, seed=21), background=policy.background(100))
    extra = {"threads": threads} if threads else {}
    rows, pairs = [], []
    template_texts = []
    for label, narrator, options, count in (
        ("template", "template", None, n_states),
        ("local_lm choose", "local_lm", {"mode": "choose", **extra}, n_states),
        ("local_lm rewrite", "local_lm", {"mode": "rewrite", **extra}, n_rewrite),
    ):
        if not count:
            continue
        times, first, shown_diff, own_diff, edit, own_edit, sent, words = [], [], [], [], [], [], [], []
        for i in range(count):
            t0 = time.perf_counter()
            n = xairl.narrate(exp, i, narrator=narrator, policy=policy, template=template, options=options)
            times.append(time.perf_counter() - t0)
            assert n.verified, n  # what is shown always verifies (the template is the fallback)
            if narrator == "template":
                template_texts.append(n.text)
            base = template_texts[i]
            own = n.rejected if n.rejected is not None else n.text
            first.append(n.source == narrator)
            shown_diff.append(n.text != base)
            own_diff.append(own != base)
            edit.append(word_edits(base, n.text))
            own_edit.append(word_edits(base, own))
            sent.append(sentences_changed(base, n.text))
            words.append(len(base.split()))
            if options and options["mode"] == "rewrite":
                pairs.append((name, i, base, own, n.source == narrator))
        t = np.array(times)
        rows.append(
            (
                name,
                label,
                count,
                np.mean(first),
                np.mean(shown_diff),
                np.mean(own_diff),
                np.mean(edit),
                np.mean(own_edit),
                np.mean(words),
                np.mean(sent),
                np.median(t),
                np.percentile(t, 90),
            )
        )
    return rows, pairs


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--states", type=int, default=20)
    ap.add_argument("--rewrite-states", type=int, default=None, help="states for mode=rewrite (default: --states)")
    ap.add_argument("--policies", default="toy:explain_action,uav-dqn:handover", help="policy:template,...")
    ap.add_argument("--model-cache", default=None, help="converted-model cache (default: a fresh temporary one)")
    ap.add_argument("--threads", type=int, default=None, help="torch CPU threads for the model")
    args = ap.parse_args()
    n_rewrite = args.states if args.rewrite_states is None else min(args.rewrite_states, args.states)
    cache = args.model_cache or tempfile.mkdtemp(prefix="xairl-models-")
    os.environ["XAIRL_MODEL_CACHE"] = cache
    try:
        run(args, cache, n_rewrite)
    finally:
        if not args.model_cache:
            shutil.rmtree(cache, ignore_errors=True)  # the converted copy (~520 MB) of a fresh temporary cache


def run(args, cache: str, n_rewrite: int) -> None:
    policies = [tuple(p.split(":")) for p in args.policies.split(",")]
    print(
        f"machine: {platform.machine()}, {os.cpu_count()} cores (load {os.getloadavg()[0]:.1f}); "
        f"{args.states} states per policy, rewrite on the first {n_rewrite}; model cache {cache}"
    )

    from xairl.narrators import local_lm

    had_copy = any(os.scandir(cache))
    t0 = time.perf_counter()
    local_lm.load_model()  # the first use ever converts the packaged GGUF to a cached safetensors copy
    first_use = time.perf_counter() - t0
    code = COLD.format(
        policy=policies[0][0], template=policies[0][1], options={"threads": args.threads} if args.threads else {}
    )
    cold = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    imp, load, one, total = map(float, cold[-4:])
    print(f"first use in this process ({'cached copy' if had_copy else 'GGUF conversion + load'}): {first_use:.1f} s")
    print(
        f"cold start, new process: import xairl {imp:.1f} s + model load (imports transformers) {load:.1f} s + "
        f"first narrative {one:.1f} s = {total:.1f} s to the first local_lm narrative"
    )

    rows, pairs = [], []
    for name, template in policies:
        r, p = run_policy(name, template, args.states, n_rewrite, args.threads)
        rows += r
        pairs += p

    head = (
        "policy",
        "narrator",
        "n",
        "verified 1st",
        "shown!=tpl",
        "own!=tpl",
        "edit shown",
        "edit own",
        "tpl words",
        "sent.changed",
        "warm median",
        "p90",
    )
    print()
    print(
        f"{head[0]:<8} {head[1]:<17} {head[2]:>3} {head[3]:>12} {head[4]:>10} {head[5]:>8} {head[6]:>10} "
        f"{head[7]:>8} {head[8]:>9} {head[9]:>12} {head[10]:>11} {head[11]:>7}"
    )
    for name, label, n, first, sd, od, ed, oed, words, sent, med, p90 in rows:
        print(
            f"{name:<8} {label:<17} {n:>3} {100 * first:>11.0f}% {100 * sd:>9.0f}% {100 * od:>7.0f}% {ed:>10.1f} "
            f"{oed:>8.1f} {words:>9.0f} {100 * sent:>11.0f}% {med:>10.2f}s {p90:>6.2f}s"
        )
    print(
        "(verified 1st: the narrator's own text verified; shown/own != tpl: the shown text / the model's own text"
        " differs from the template's; edit: mean word-level edit distance to the template's text)"
    )

    # two example pairs: a verified rewrite if there is one, and a rejected one; else the first two
    good = [p for p in pairs if p[4]]
    bad = [p for p in pairs if not p[4]]
    examples = (good[:1] + bad[:1]) if good and bad else pairs[:2]
    for name, i, base, own, ok in examples:
        print(
            f"\n--- {name}, state {i}: rewrite {'verified, shown' if ok else 'rejected, template shown instead'} "
            f"({word_edits(base, own)} word edits)"
        )
        print(textwrap.fill("template: " + base, 116, subsequent_indent="          "))
        print(textwrap.fill("rewrite:  " + own, 116, subsequent_indent="          "))


if __name__ == "__main__":
    main()
