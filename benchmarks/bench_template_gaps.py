"""How much of a template the language model may choose (issue 66: "at least two wordings in most gaps").

A gap is the literal text between two tracked values of a rendering (or before the first, after the last) that holds
a word. For each template (the built-ins, or the files given), rendered on `xairl prompts check`'s battery of
decisions (a template that reads a plugin's ``extras`` on the plugin policies' decisions only): the share of gaps
inside a ``pick(...)`` (with two or more wordings), and the share where the sentence offers another phrasing or a
pick.

Run: .venv/bin/python benchmarks/bench_template_gaps.py [TEMPLATE.yaml ...]   (any template file: a plugin's too,
rendered on the decisions of the policies that plugin registers)
"""

import re
import sys
from pathlib import Path

from xairl.facts import decision_facts, global_facts
from xairl.narrators.battery import cases, uses_extras
from xairl.templates import prompts
from xairl.templates.tracking import track_decision, track_global, untangle


def gaps(rendered, phrasings: int) -> list[tuple[bool, bool]]:
    """(inside a pick, a pick or another phrasing) for each gap with a word."""
    draft = rendered.draft
    if draft is None:
        text, spans = str(rendered), rendered.spans
    else:  # each pick's first wording between two bell characters, to find it among the gaps
        marked = "".join(p if k % 2 == 0 else "\x07" + p[0] + "\x07" for k, p in enumerate(draft.parts))
        text, spans = untangle(marked, list(draft.record))
    cuts = [0] + [x for s in spans for x in (s.start, s.end)] + [len(text)]
    out = []
    for a, b in zip(cuts[::2], cuts[1::2]):
        gap = text[a:b]
        if re.search(r"[A-Za-z]{2,}", gap.replace("\x07", "")):
            out.append(("\x07" in gap, "\x07" in gap or phrasings > 1))
    return out


def main() -> None:
    print("| template | gaps with a word | in a pick | in a pick or a sentence with another phrasing |")
    print("|---|---|---|---|")
    paths = [Path(p) for p in sys.argv[1:]] or sorted(prompts.builtin_dir().glob("*.yaml"))
    for path in paths:
        tpl = prompts.parse(path)
        outputs = tpl.spec.outputs if tpl.spec.kind == "decision" else ("actions", "continuous", "value")
        plugin, found = uses_extras(tpl), []
        for case in cases(outputs, tpl.spec.kind)[0]:
            if plugin and case.policy.facts_hook is None:  # (it reads a plugin's extras: its policies' decisions)
                continue
            if case.index is None:
                context = track_global(global_facts(case.explanation, case.policy, k=3).context())
            else:
                context = track_decision(decision_facts(case.explanation, case.index, case.policy, 3).context())
            for options in tpl.render_variants(context):
                found += [g for r in options if r for g in gaps(r, sum(map(bool, options)))]
        n = len(found)
        picks, either = sum(p for p, _ in found), sum(e for _, e in found)
        print(f"| {path.stem} | {n} | {picks} ({100 * picks / n:.0f} %) | {either} ({100 * either / n:.0f} %) |")


if __name__ == "__main__":
    main()
