"""``xairl explain``: a policy's decisions on states from a file or its sampler, printed as a table or JSON lines,
narrated, written as a report (``--out``), or streamed chunk by chunk into Parquet (``--format parquet``, and
``--out`` alone above STREAM_ABOVE states: what an operator explaining a large log needs, memory bounded, a progress
bar, resumable)."""

from __future__ import annotations

import argparse
import json
import re

from xairl.cli.args import (
    MARKS,
    count,
    feedback_arguments,
    make_dir,
    narration_arguments,
    out_dir,
    parse_options,
    report_request,
    streaming_arguments,
)
from xairl.cli.counterfactual import asked, block, counterfactual_arguments, said, search, summaries
from xairl.errors import InputError
from xairl.registry import plugins

#: above this many states, ``--out DIR`` without a --format streams them into DIR/explanations.parquet (200,000 toy
#: states as one JSON-lines file: 207 MB built in memory, 1.18 GB peak RSS, written at the end with no progress bar;
#: streamed: 25 MB of Parquet, 550 MB peak RSS)
STREAM_ABOVE = 50_000


def cmd_explain(args) -> int:
    from xairl.attributors import explain
    from xairl.runs.inputs import read_states

    policy = plugins.load_policy(args.policy, parse_options(args.policy_arg), _state_shape(args.states))
    method = plugins.get_attributor(args.method)  # unknown names fail before any file is read
    options = method(parse_options(args.option)).options
    if args.out:  # before anything is read: a folder that cannot be made fails at once
        make_dir(args.out)
    states = _choose_format(args, policy)
    asked(args, policy)  # a bad --counterfactual-target, or --counterfactual with Parquet: one line, exit 2
    if args.narrate and args.narrator == "local_lm":  # the model loads while the states are explained
        from xairl.narrators.local_lm import preload

        preload(parse_options(args.narrator_option).get("model"))
    if args.format == "parquet" and not args.out:
        raise InputError("--format parquet writes a folder: give it with --out DIR.")
    if args.engine == "ray" and args.format != "parquet":
        raise InputError("--engine ray streams into a folder: add --format parquet --out DIR.")
    if args.states and args.format == "parquet":
        states = None  # streamed from the file, chunk by chunk
    elif args.states and states is None:
        states = read_states(args.states, policy.feature_names, policy.observation)
    elif not args.states:
        states = policy.background(args.n, seed=args.seed + 1)
    bg = (
        read_states(args.background, policy.feature_names, policy.observation, "background")
        if args.background
        else policy.background(args.background_size, seed=args.seed)
    )
    if args.format == "parquet":
        return _stream(args, policy, args.states or states, bg, options.model_dump())
    exp = explain(policy, states, background=bg, method=args.method, options=options.model_dump())
    if args.out:
        return _write_report(args, exp, policy, bg)
    raw = search(args, policy, exp, bg)  # --counterfactual: each decision's, in one batch
    found = summaries(raw, policy)
    if args.narrate:
        return _print_narratives(args, exp, policy, bg, raw)
    if args.format == "jsonl":
        for i, rec in enumerate(exp.records()):
            print(
                rec.model_dump_json() if found is None else json.dumps({**rec.model_dump(), "counterfactual": found[i]})
            )
        return 0
    return _print_table(exp, args.top, args.view, found)


def _choose_format(args, policy):
    """Sets ``args.format`` when none was given: with ``--out``, parquet (streamed) for more than STREAM_ABOVE
    states, or with ``--resume`` or ``--engine ray``; table otherwise. Returns the states when it had to read them
    whole to count them (.npz, .json), else None."""
    import sys
    from pathlib import Path

    from xairl.runs.chunks import count_rows
    from xairl.runs.inputs import read_states

    if args.format is not None:
        return None
    args.format, states, n = "table", None, args.n
    if not args.out:
        return None
    if args.states and Path(args.states).suffix.lower() in (".npy", ".parquet", ".csv"):
        n = count_rows(args.states, policy)
    elif args.states:
        states = read_states(args.states, policy.feature_names, policy.observation)
        n = len(states)
    if n > STREAM_ABOVE or args.resume or args.engine == "ray":
        args.format = "parquet"
    if n > STREAM_ABOVE:
        print(
            f"xairl: {n} states: streaming them into {Path(args.out) / 'explanations.parquet'} chunk by chunk, as "
            f"--format parquet does (resumable with --resume); --format jsonl writes one explanations.jsonl "
            f"instead, in memory.",
            file=sys.stderr,
        )
    return states


def _print_table(exp, top: int, view: str, found=None) -> int:
    """Each state's strongest contributions, labelled with what they add up to: the margin over the runner-up
    (why this action and not the next best; the narratives' view) or the chosen action's score."""
    import numpy as np

    decides = exp.output == "actions"
    if exp.decides:
        print(
            "contributions to the margin: score(chosen) - score(runner-up)"
            if view == "margin"
            else "contributions to the chosen action's score"
        )
    values, expected, value = exp.contributions(view)
    for i, rec in enumerate(exp.records()):
        scores = ", ".join(f"{a}={v:.3f}" for a, v in rec.scores.items())
        print(
            f"state {i}: chose {rec.chosen} (runner-up {rec.runner_up}); scores {scores}"
            if decides
            else f"state {i}: {exp.output} {scores}"
        )
        for a in [int(exp.chosen[i])] if decides else range(exp.values.shape[2]):
            contrib = values[i] if decides else exp.values[i, :, a]
            if not decides:
                print(f"  {exp.action_names[a]}:")
            for j in np.argsort(-np.abs(contrib), kind="stable")[:top]:
                print(f"    {exp.feature_names[j]:<24} = {exp.states[i, j]:>10.4g}   contribution {contrib[j]:+.4f}")
            if exp.decides and view == "margin":
                print(f"    expected margin {expected[i]:.4f} -> margin {value[i]:.4f} ({exp.method})")
            else:
                print(
                    f"    base {exp.base_values[i, a]:.4f}, additivity gap {exp.additivity_gap[i, a]:.2e} ({exp.method})"
                )
        if found is not None:
            print(block(found[i]))
    return 0


def _state_shape(path):
    """The shape of one state in a .npy file (what a bare torch module given as --policy takes), from its header;
    else None."""
    from xairl.runs.inputs import npy_header

    if not path or not str(path).lower().endswith(".npy"):
        return None
    try:
        with open(path, "rb") as fh:
            shape = npy_header(fh)[0]
    except Exception:  # a peek only: read_states reports whatever is wrong with the file
        return None
    return shape[1:] if len(shape) > 1 else shape


def _write_report(args, exp, policy, bg) -> int:
    """explanations.jsonl, figures and report.html for any policy (``--out DIR``)."""
    from pathlib import Path

    from xairl.outputs.report import ReportContent, write_report

    req = report_request(
        args, Path(args.out), dict(exp.options), len(exp.values), progress=False,
        counterfactual_target=args.counterfactual_target, max_changes=args.max_changes,
    )  # fmt: skip
    content = ReportContent(
        title=f"xairl: {policy.name}", policy=policy, background=bg, datasets=[("states", exp.states)]
    )
    path = write_report(req, content, explained={"states": exp})
    print(f"report: {path.resolve()}")
    return 0


def _stream(args, policy, states, bg, options: dict) -> int:
    """``--format parquet``: explained chunk by chunk into DIR/explanations.parquet (resumable), with a progress bar
    on a terminal, and a report whose figures show a uniform sample of the states."""
    import time
    from pathlib import Path

    from xairl.outputs.report import ReportContent, table_html, write_report
    from xairl.runs.stream import explain_to_parquet

    out = Path(args.out)
    t0 = time.time()
    common = dict(background=bg, method=args.method, options=options, chunk_size=args.chunk_size, resume=args.resume)
    if args.engine == "ray":
        from xairl.runs.scale import explain_on_ray

        summary = explain_on_ray(policy, states, out, **common, workers=args.workers, address=args.ray_address)
    else:
        summary = explain_to_parquet(policy, states, out, **common)
    seconds = time.time() - t0
    means = summary.to_dict(policy.feature_names)["mean_abs_contribution"]
    order = sorted(policy.feature_names, key=lambda f: -means["margin"][f])
    table = table_html(
        ["feature", "mean |contribution| to the margin", "to the chosen score"],
        [[f, f"{means['margin'][f]:.4g}", f"{means['chosen_score'][f]:.4g}"] for f in order],
    )
    req = report_request(args, out, options, summary.n, progress=False, records=False)
    content = ReportContent(
        title=f"xairl: {policy.name}",
        policy=policy,
        background=bg,
        datasets=[("states", summary.sample_explanation().states)],
        tables=[(f"Mean |contribution| over all {summary.n} states", table)],
        notes=[
            f"{summary.n} states explained in {seconds:.1f} s ({summary.n / max(seconds, 1e-9):.0f}"
            f" states/s) into {out / 'explanations.parquet'}; the figures show a uniform "
            f"sample of {len(summary.sample)} of them."
        ],
    )
    path = write_report(req, content, explained={"states": summary.sample_explanation()})
    print(f"explanations: {(out / 'explanations.parquet').resolve()} ({summary.n} states)\nreport: {path.resolve()}")
    return 0


#: decisions the CLI words together (a narrator that batches them, local_lm, scores their choices in one pass)
BATCH = 8


def _print_narratives(args, exp, policy, bg, raw=None) -> int:
    from xairl.explanations.evidence import verdict_text
    from xairl.narrators import narrate, prepare
    from xairl.outputs.feedback import FeedbackStore

    store = None if args.no_record else FeedbackStore(args.feedback_db)
    options = parse_options(args.narrator_option)
    if args.examples_from_feedback and store is not None:
        options.setdefault("examples", store.examples())
    found = summaries(raw, policy)
    how = {"template": args.template, "policy": policy, "background": bg, "robustness": not args.no_robustness}
    how["prompt_dirs"] = tuple(args.prompts)
    for i in range(len(exp.values)):
        if i % BATCH == 0:  # the next decisions worded together (local_lm: one forward pass per step for all)
            batch = range(i, min(i + BATCH, len(exp.values)))
            prepare(exp, [(j, how | said(raw, j)) for j in batch], narrator=args.narrator, options=options)
        n = narrate(
            exp,
            i,
            narrator=args.narrator,
            options=options,
            **how,
            **said(raw, i),  # the template's counterfactual sentence, checked by a re-run
        )
        if found is not None and n.evidence is not None:  # the review page shows it beside the narrative
            n.evidence["counterfactual"] = found[i]
        if store is not None:
            store.record(n, policy=policy)
        if args.format == "jsonl":
            print(
                json.dumps(
                    {
                        "index": i,
                        "text": n.text,
                        "verified": n.verified,
                        "verdict": n.status,
                        "coverage": n.coverage,
                        "account": n.account,
                        "confidence": n.confidence,
                        "components": n.components,
                        "source": n.source,
                        "template": n.template,
                        "sentences": [{"text": t, "status": st} for t, st in n.sentences],
                        **({"counterfactual": found[i]} if found is not None else {}),
                    }
                )
            )
            continue
        parts = ", ".join(f"{k} {v:.2f}" for k, v in n.components.items() if v is not None)
        print(f"state {i} [{verdict_text(n.status, n.coverage)}, confidence {n.confidence:.2f}: {parts}; {n.source}]")
        print(marked_rows(n.text, n.sentences))
        if n.account:
            print(f"    account: {n.account}")
        if found is not None:
            print(block(found[i]))
    return 0


#: a list item's bullet or number at the start of a row: the sentences after it on its line are indented past it
_ITEM = re.compile(r"(?:[-\u2022*]|\d{1,2}[.)])\s+")


def marked_rows(text: str, sentences) -> str:
    """The terminal's narrative: each sentence on a row after its mark (MARKS), aligned. The text's line breaks stay:
    a sentence that starts a line of a list gets its bullet back, the sentences after it on that line are indented
    under the item's words, a blank line stays a blank row, and a sentence's own lines (a text without sentences)
    are indented under its first."""
    from xairl.explanations.evidence import sentence_lines

    if not sentences:
        return "\n".join(f"    {line}" for line in text.splitlines())
    rows, indent = [], ""
    for j, (breaks, bullet, s, status) in enumerate(sentence_lines(text, sentences)):
        if breaks or j == 0:
            rows += [""] if breaks > 1 else []
            s = f"{bullet} {s}" if bullet else s
            item = _ITEM.match(s)
            indent = " " * (item.end() if item else 0)
        else:
            s = indent + s
        first, *more = s.splitlines() or [""]
        rows.append(f"    {MARKS.get(status, status):<13} {first}")
        rows += [f"{'':18}{indent}{line}" for line in more]
    return "\n".join(rows)


def explain_parser(p: argparse.ArgumentParser) -> None:
    _input_arguments(p)
    p.add_argument("--method", default="deep_shap", help="attribution method (see `xairl attributors`)")
    p.add_argument(
        "-o",
        "--option",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="an option of the method, validated against its schema; repeatable",
    )
    p.add_argument(
        "--format",
        choices=("table", "jsonl", "parquet"),
        default=None,
        help="table or jsonl on the terminal; parquet: streamed chunk by chunk into --out DIR (any number "
        f"of states, resumable with --resume). Default: table, or parquet with --out above {STREAM_ABOVE:,} "
        "states",
    )
    streaming_arguments(p)
    p.add_argument("--top", type=count(1), default=5, help="features shown per state in the table")
    p.add_argument(
        "--view",
        choices=("margin", "score"),
        default="margin",
        help="what the terminal table's contributions add up to for a decision: the margin over the "
        "runner-up (default; the narratives' view) or the chosen action's score (reports and narratives "
        "show the margin beside the score)",
    )
    narration_arguments(p)
    counterfactual_arguments(p)
    feedback_arguments(p)
    p.set_defaults(run=cmd_explain)


def _input_arguments(p: argparse.ArgumentParser) -> None:
    """--policy, --policy-arg, --out, --states, --background, --background-size, --n, --seed: what is explained,
    against what, and where it goes."""
    p.add_argument(
        "--policy",
        default="toy",
        help="registered policy name (see `xairl plugins`), or with nothing "
        "installed package.module:attr or path/file.py:attr (a Policy, a torch module, or a function "
        "returning one, called with the --policy-arg values); default: toy. A module:attr or file.py:attr "
        "imports and runs that code, as any Python entry point does: give only code you trust",
    )
    p.add_argument(
        "--policy-arg",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="argument of a module:attr policy function, e.g. --policy-arg checkpoint=my_q.pt",
    )
    p.add_argument(
        "--out",
        type=out_dir,
        default=None,
        metavar="DIR",
        help="write explanations.jsonl, figures and report.html into DIR instead of printing; more than "
        f"{STREAM_ABOVE:,} states (or --resume, or --engine ray) are streamed into "
        "DIR/explanations.parquet instead, as with --format parquet, and the report shows a sample of them "
        "(--format jsonl keeps one JSON-lines file, built in memory)",
    )
    p.add_argument(
        "--states",
        help="states to explain: .csv with a header naming the features, .npy "
        "(n, *obs_shape), .npz (dict observations) or .json; "
        "default: --n states from the policy's sampler",
    )
    p.add_argument("--background", help="background states file (default: the policy's sampler)")
    p.add_argument(
        "--background-size", type=count(1, 1_000_000), default=100, help="background states drawn from the sampler"
    )
    p.add_argument("--n", type=count(1, 10_000_000), default=5, help="states to sample when --states is not given")
    p.add_argument("--seed", type=count(0, 2**32 - 1), default=0, help="seed of the sampled states and background")
