"""The ``xairl`` command. ``main(argv) -> int``; user errors print one line and return 2, never a traceback.

Only argparse and the plugin registry are imported here; torch and shap load inside the commands that need them.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
from typing import Sequence

from . import plugins
from .errors import InputError, XairlError


class _Parser(argparse.ArgumentParser):
    """argparse with its errors as one line and exit status 2 through :func:`main` (not usage text)."""

    def error(self, message: str):
        raise InputError(f"{self.prog}: {message}; see `{self.prog} --help`.")


def _count(low: int, high: int | None = None):
    """An argparse type: an integer in ``low..high``."""
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{_short(text)!r} is not a whole number") from None
        if value < low or (high is not None and value > high):
            bound = f"at least {low}" if high is None else f"between {low} and {high}"
            raise argparse.ArgumentTypeError(f"{value} must be {bound}")
        return value

    parse.__name__ = "number"
    return parse


def _short(text: str, limit: int = 80) -> str:
    return text if len(text) <= limit else text[:limit] + "..."


def _path(check):
    """An argparse type from ``check(path) -> problem or None``; a path the system refuses is a problem too."""
    def parse(text: str) -> str:
        from pathlib import Path

        try:
            problem = check(Path(text)) if text else "an empty path"
        except (OSError, ValueError) as exc:  # a name too long, a NUL byte
            problem = f"cannot use {_short(text)!r} ({getattr(exc, 'strerror', None) or exc})"
        if problem:
            raise argparse.ArgumentTypeError(problem)
        return text

    parse.__name__ = "path"
    return parse


@_path
def _new_file(path) -> str | None:
    """A file to write whose folder exists (an existing file is replaced)."""
    if path.is_dir():
        return f"{_short(str(path))} is a folder; give a file name"
    if not path.parent.is_dir():
        return f"the folder {_short(str(path.parent))} does not exist; create it first"
    return None


@_path
def _out_dir(path) -> str | None:
    """A folder to write into, new or existing (missing folders above it are created, as mkdir -p does)."""
    if path.exists() and not path.is_dir():
        return f"{_short(str(path))} is a file, not a folder; give a folder for the report"
    above = next((p for p in path.absolute().parents if p.exists()), None)
    if above is not None and not above.is_dir():
        return f"{_short(str(above))} is a file, so no folder can be made under it"
    return None


def _parse_options(pairs: Sequence[str]) -> dict:
    """``["n_steps=32", "method=riemann_left"]`` -> dict; values are read as JSON when they parse, else as text."""
    opts: dict = {}
    for pair in pairs:
        key, sep, raw = pair.partition("=")
        if not sep or not key.strip():
            raise InputError(f"option '{pair}' is not key=value; write e.g. -o n_steps=32.")
        try:
            opts[key.strip()] = json.loads(raw, parse_constant=lambda c: c)  # NaN/Infinity stay text: refused later
        except (ValueError, RecursionError):
            opts[key.strip()] = raw
    return opts


def cmd_plugins(args) -> int:
    summary, failed = plugins.summary(), plugins.failures()
    for plugin in sorted(set(summary) | set(failed)):
        print(plugin)
        if plugin in failed:
            print(f"  LEFT OUT: {failed[plugin]}")
            continue
        for kind, names in sorted(summary[plugin].items()):
            print(f"  {kind}: {', '.join(sorted(names))}")
        if not summary[plugin]:
            print("  (registers nothing)")
    if os.environ.get(plugins.LOAD_ENV) is not None:
        print(f"(only the plugins named in ${plugins.LOAD_ENV} were loaded)")
    return 0


def cmd_attributors(args) -> int:
    reg = plugins.registry("attributor")
    rows = []
    for name in reg.names():
        entry = reg.entry(name)
        schema = entry.load().Options.model_json_schema()
        rows.append({"name": name, "plugin": entry.plugin, "description": entry.description, "options": schema})
    if args.json:
        print(json.dumps(rows, indent=2))
        return 0
    for row in rows:
        print(f"{row['name']}  ({row['plugin']}): {row['description']}")
        for key, spec in row["options"].get("properties", {}).items():
            kind = spec.get("type") or "|".join(str(a.get("type", a.get("const", a.get("enum", "?"))))
                                                for a in spec.get("anyOf", []))
            if "enum" in spec:
                kind = "|".join(spec["enum"])
            print(f"    -o {key}=  {kind}, default {spec.get('default')!r}: {spec.get('description', '')}")
    return 0


def cmd_report(args) -> int:
    from pathlib import Path

    from .report import ReportRequest, write_report

    report = plugins.registry("report").load(args.plugin)(_parse_options(args.option))
    method_options = plugins.get_attributor(args.method)(_parse_options(args.method_option)).options.model_dump()
    req = ReportRequest(out=Path(args.out), method=args.method, options=method_options, narrate=args.narrate,
                        narrator=args.narrator, narrator_options=_parse_options(args.narrator_option),
                        template=args.template, prompt_dirs=args.prompts, seed=args.seed, n_states=args.n,
                        robustness=not args.no_robustness)
    req.out.mkdir(parents=True, exist_ok=True)
    path = write_report(req, report.build(req))
    print(f"report: {path.resolve()}")
    return 0


def cmd_explain(args) -> int:
    import numpy as np

    from .attributors import explain
    from .inputs import read_states

    policy = plugins.load_policy(args.policy, _parse_options(args.policy_arg), _state_shape(args.states))
    method = plugins.get_attributor(args.method)  # unknown names fail before any file is read
    options = method(_parse_options(args.option)).options
    if args.format == "parquet" and not args.out:
        raise InputError("--format parquet writes a folder: give it with --out DIR.")
    if args.engine == "ray" and args.format != "parquet":
        raise InputError("--engine ray streams into a folder: add --format parquet --out DIR.")
    if args.states and args.format == "parquet":
        states = None  # streamed from the file, chunk by chunk
    elif args.states:
        states = read_states(args.states, policy.feature_names, policy.observation)
    else:
        states = policy.background(args.n, seed=args.seed + 1)
    bg = read_states(args.background, policy.feature_names, policy.observation, "background") if args.background else \
        policy.background(args.background_size, seed=args.seed)
    if args.format == "parquet":
        return _stream(args, policy, args.states or states, bg, options.model_dump())
    exp = explain(policy, states, background=bg, method=args.method, options=options.model_dump())
    if args.out:
        return _write_report(args, exp, policy, bg)
    if args.narrate:
        return _print_narratives(args, exp, policy, bg)
    if args.format == "jsonl":
        for rec in exp.records():
            print(rec.model_dump_json())
        return 0
    decides = exp.output == "actions"
    for i, rec in enumerate(exp.records()):
        scores = ", ".join(f"{a}={v:.3f}" for a, v in rec.scores.items())
        print(f"state {i}: chose {rec.chosen} (runner-up {rec.runner_up}); scores {scores}" if decides else
              f"state {i}: {exp.output} {scores}")
        for a in ([int(exp.chosen[i])] if decides else range(exp.values.shape[2])):
            contrib = exp.values[i, :, a]
            if not decides:
                print(f"  {exp.action_names[a]}:")
            for j in np.argsort(-np.abs(contrib))[: args.top]:
                print(f"    {exp.feature_names[j]:<24} = {exp.states[i, j]:>10.4g}   contribution {contrib[j]:+.4f}")
            print(f"    base {exp.base_values[i, a]:.4f}, additivity gap {exp.additivity_gap[i, a]:.2e} ({exp.method})")
    return 0


def _state_shape(path):
    """The shape of one state in a .npy file (what a bare torch module given as --policy takes), else None."""
    import numpy as np

    if not path or not str(path).lower().endswith(".npy"):
        return None
    try:
        shape = np.load(path, mmap_mode="r", allow_pickle=False).shape
    except Exception:  # a peek only: read_states reports whatever is wrong with the file
        return None
    return shape[1:] if len(shape) > 1 else shape


def _write_report(args, exp, policy, bg) -> int:
    """explanations.jsonl, figures and report.html for any policy (``--out DIR``)."""
    from pathlib import Path

    from .report import ReportContent, ReportRequest, write_report

    req = ReportRequest(out=Path(args.out), method=args.method, options=dict(exp.options), narrate=args.narrate,
                        narrator=args.narrator, narrator_options=_parse_options(args.narrator_option),
                        template=args.template, prompt_dirs=args.prompts, seed=args.seed, n_states=len(exp.values),
                        robustness=not args.no_robustness, progress=False)
    content = ReportContent(title=f"xairl: {policy.name}", policy=policy, background=bg,
                            datasets=[("states", exp.states)])
    path = write_report(req, content, explained={"states": exp})
    print(f"report: {path.resolve()}")
    return 0


def _stream(args, policy, states, bg, options: dict) -> int:
    """``--format parquet``: explained chunk by chunk into DIR/explanations.parquet (resumable), with a progress bar
    on a terminal, and a report whose figures show a uniform sample of the states."""
    import time
    from pathlib import Path

    from .report import ReportContent, ReportRequest, table_html, write_report
    from .stream import explain_to_parquet

    out = Path(args.out)
    t0 = time.time()
    if args.engine == "ray":
        from .scale import explain_on_ray

        summary = explain_on_ray(policy, states, out, background=bg, method=args.method, options=options,
                                 chunk_size=args.chunk_size, resume=args.resume, workers=args.workers,
                                 address=args.ray_address)
    else:
        summary = explain_to_parquet(policy, states, out, background=bg, method=args.method, options=options,
                                     chunk_size=args.chunk_size, resume=args.resume)
    seconds = time.time() - t0
    means = summary.to_dict(policy.feature_names)["mean_abs_contribution"]
    order = sorted(policy.feature_names, key=lambda f: -means["margin"][f])
    table = table_html(["feature", "mean |contribution| to the margin", "to the chosen score"],
                       [[f, f"{means['margin'][f]:.4g}", f"{means['chosen_score'][f]:.4g}"] for f in order])
    req = ReportRequest(out=out, method=args.method, options=options, narrate=args.narrate, narrator=args.narrator,
                        narrator_options=_parse_options(args.narrator_option), template=args.template,
                        prompt_dirs=args.prompts, seed=args.seed, n_states=summary.n,
                        robustness=not args.no_robustness, progress=False, records=False)
    content = ReportContent(title=f"xairl: {policy.name}", policy=policy, background=bg,
                            datasets=[("states", summary.sample_explanation().states)],
                            tables=[(f"Mean |contribution| over all {summary.n} states", table)],
                            notes=[f"{summary.n} states explained in {seconds:.1f} s ({summary.n / max(seconds, 1e-9):.0f}"
                                   f" states/s) into {out / 'explanations.parquet'}; the figures show a uniform "
                                   f"sample of {len(summary.sample)} of them."])
    path = write_report(req, content, explained={"states": summary.sample_explanation()})
    print(f"explanations: {(out / 'explanations.parquet').resolve()} ({summary.n} states)\nreport: {path.resolve()}")
    return 0


def _print_narratives(args, exp, policy, bg) -> int:
    from .feedback import FeedbackStore
    from .narrators import narrate

    store = None if args.no_record else FeedbackStore(args.feedback_db)
    options = _parse_options(args.narrator_option)
    if args.examples_from_feedback and store is not None:
        options.setdefault("examples", store.examples())
    for i in range(len(exp.values)):
        n = narrate(exp, i, narrator=args.narrator, template=args.template, policy=policy, background=bg,
                    robustness=not args.no_robustness,
                    options=options, prompt_dirs=args.prompts, store=store)
        if args.format == "jsonl":
            print(json.dumps({"index": i, "text": n.text, "verified": n.verified, "confidence": n.confidence,
                              "components": n.components, "source": n.source, "template": n.template,
                              "sentences": [{"text": t, "status": st} for t, st in n.sentences]}))
            continue
        mark = "verified" if n.verified else "NOT VERIFIED"
        parts = ", ".join(f"{k} {v:.2f}" for k, v in n.components.items() if v is not None)
        print(f"state {i} [{mark}, confidence {n.confidence:.2f}: {parts}; {n.source}]")
        print("\n".join(f"    {_MARKS[status]:<13} {text}" for text, status in n.sentences) or f"    {n.text}")
    return 0


#: how each sentence's status is shown: an unchecked sentence is said to be unchecked, never passed as verified
_MARKS = {"verified": "verified", "contradicted": "CONTRADICTED", "unchecked": "unchecked"}


def cmd_prompts(args) -> int:
    from . import prompts

    if args.action == "list":
        for name, path in sorted(prompts.available(args.prompts).items()):
            tpl = prompts.parse(path)
            print(f"{name:<18} {tpl.spec.kind:<9} {path}\n    {tpl.spec.description}")
        return 0
    if not args.target:
        raise InputError(f"`xairl prompts {args.action}` needs a template {'name' if args.action == 'show' else 'path'}.")
    if args.action == "show":
        tpl = prompts.load(args.target, args.prompts)
        print(f"# {tpl.path}")
        print(tpl.path.read_text(), end="")
        return 0
    from .narrators import check_template

    problems = check_template(args.target)
    for p in problems:
        print(p)
    print(f"{args.target}: {'ok' if not problems else f'{len(problems)} problem(s)'}")
    return 0 if not problems else 1


def cmd_verify(args) -> int:
    """Check a text against an explanation; with --trace, every claim with the words it was read from and the
    reading (rule) that bound it."""
    from .explanation import Explanation
    from .narrators.verify import verify

    text = args.text if args.text != "-" else sys.stdin.read()
    try:
        with open(args.explanation, "rb") as fh:
            raw = fh.read()
    except OSError as exc:
        raise InputError(f"cannot read --explanation {args.explanation}: {exc.strerror}; give the JSON that "
                         f"Explanation.to_json() writes.") from None
    try:
        exp = Explanation.from_json(raw)
    except InputError as exc:
        raise InputError(f"--explanation {args.explanation}: {exc}") from None
    try:
        exp.check_index(args.index)
    except InputError as exc:
        raise InputError(f"--index {args.index}: {exc}") from None
    result = verify(text, exp, args.index)
    for sentence in result.sentences:
        print(f"[{sentence.status}] {sentence.text}")
        for c in sentence.claims if args.trace else ():
            print(f"    {c.status:<12} {c.kind:<9} {c.text!r:<28} {c.rule or '-':<22} {c.detail}")
    print(f"accurate: {'yes' if result.accurate else 'no'}; ok: {'yes' if result.ok else 'no'} "
          f"(coverage {result.coverage:.0%}){'; ' + result.note if result.note else ''}")
    return 0 if result.accurate else 1


def cmd_review(args) -> int:
    from .feedback import FeedbackStore

    store = FeedbackStore(args.db)
    if args.serve:
        from .review import serve

        serve(store, args.port)
        return 0
    if args.export:
        from .files import atomic_write

        with atomic_write(args.export) as fh:
            n = store.export_corrections(fh)
        print(f"wrote {n} correction(s) to {args.export}")
        return 0
    pending = store.records("pending")
    print(f"{len(pending)} narrative(s) to review in {store.path}")
    for r in pending:
        bad = [c for c in r.claims if c["status"] != "verified"]
        print(f"\n#{r.id} [{r.template}, {r.source}, confidence {r.confidence:.2f}, "
              f"{'verified' if r.verified else f'{len(bad)} unverified claim(s)'}]")
        marked = (r.evidence or {}).get("sentences") or []
        print("\n".join(f"    {_MARKS.get(st, st):<13} {t}" for t, st in marked) or f"    {r.text}")
        while True:
            try:
                answer = input("[a]ccept  [r]eject  [c]orrect  [s]kip  [q]uit > ").strip().lower()[:1]
            except EOFError:
                return 0
            if answer == "q":
                return 0
            if answer == "s":
                break
            if answer in ("a", "r"):
                store.review(r.id, "accepted" if answer == "a" else "rejected")
                break
            if answer == "c":
                try:
                    text = input("corrected text > ").strip()
                except EOFError:
                    return 0
                if text:
                    store.review(r.id, "corrected", text)
                    break
    return 0


def _narration_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--narrate", action="store_true", help="explain decisions in words, checked against the numbers")
    p.add_argument("--narrator", default="template", help="template (default), local_lm, or a plugin's narrator")
    p.add_argument("--template", default=None, help="template name or .yaml path (default explain_action)")
    p.add_argument("--prompts", action="append", default=[], metavar="DIR", help="extra template folder, searched first")
    p.add_argument("-n", "--narrator-option", action="append", default=[], metavar="KEY=VALUE",
                   help="a narrator option, e.g. -n mode=rewrite or -n model=PATH")
    p.add_argument("--no-robustness", action="store_true", help="confidence without the agreement and stability "
                   "components (saves three extra explanations per narrated state)")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="xairl", description="Explain what a reinforcement-learning policy decided "
                                     "and why.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    p = sub.add_parser("plugins", help="list installed plugins and what each registers")
    p.set_defaults(run=cmd_plugins)
    p = sub.add_parser("attributors", help="list attribution methods and their options")
    p.add_argument("--json", action="store_true", help="print names and JSON schemas of the options")
    p.set_defaults(run=cmd_attributors)
    _explain_parser(sub.add_parser("explain", help="explain a registered policy's decisions on states from a file"))
    _report_parser(sub.add_parser("report", help="write a plugin's report (HTML, JSONL, figures) into a folder"))
    p = sub.add_parser("prompts", help="list, show or check prompt templates")
    p.add_argument("action", choices=("list", "show", "check"))
    p.add_argument("target", nargs="?", help="template name (show) or .yaml path (check)")
    p.add_argument("--prompts", action="append", default=[], metavar="DIR", help="extra template folder")
    p.set_defaults(run=cmd_prompts)
    p = sub.add_parser("verify", help="check a text's claims against an explanation (exit 1 when one is "
                       "contradicted)")
    p.add_argument("text", help="the text to check, or - to read it from standard input")
    p.add_argument("--explanation", required=True, metavar="FILE", help="the explanation, as Explanation.to_json() "
                   "writes it")
    p.add_argument("--index", type=_count(0), default=0, help="which state of the explanation the text is about")
    p.add_argument("--trace", action="store_true", help="every claim: status, kind, words, rule, reason")
    p.set_defaults(run=cmd_verify)
    p = sub.add_parser("review", help="accept, reject or correct recorded narratives in the terminal, or in a local "
                       "web page with the evidence (--serve)")
    p.add_argument("--db", type=_new_file, default=None, help="feedback store (default: in the user dir)")
    p.add_argument("--serve", action="store_true", help="serve the review page on http://127.0.0.1:PORT/")
    p.add_argument("--port", type=_count(0, 65535), default=8765, help="port of the review page (default 8765; 0: "
                   "any free port)")
    p.add_argument("--export", type=_new_file, metavar="FILE", help="write the corrections as JSON lines instead of reviewing")
    p.set_defaults(run=cmd_review)
    commands = plugins.registry("command")
    for name in commands.names():
        entry = commands.entry(name)
        entry.load()(sub.add_parser(name, help=entry.description))
    return parser


def _explain_parser(p: argparse.ArgumentParser) -> None:
    p.add_argument("--policy", default="toy", help="registered policy name (see `xairl plugins`), or with nothing "
                   "installed package.module:attr or path/file.py:attr (a Policy, a torch module, or a function "
                   "returning one, called with the --policy-arg values); default: toy. A module:attr or file.py:attr "
                   "imports and runs that code, as any Python entry point does: give only code you trust")
    p.add_argument("--policy-arg", action="append", default=[], metavar="KEY=VALUE",
                   help="argument of a module:attr policy function, e.g. --policy-arg checkpoint=my_q.pt")
    p.add_argument("--out", type=_out_dir, default=None, metavar="DIR",
                   help="write explanations.jsonl, figures and report.html into DIR instead of printing")
    p.add_argument("--states", help="states to explain: .csv with a header naming the features, .npy "
                   "(n, *obs_shape), .npz (dict observations) or .json; "
                   "default: --n states from the policy's sampler")
    p.add_argument("--background", help="background states file (default: the policy's sampler)")
    p.add_argument("--background-size", type=_count(1, 1_000_000), default=100, help="background states drawn from the sampler")
    p.add_argument("--n", type=_count(1, 10_000_000), default=5, help="states to sample when --states is not given")
    p.add_argument("--seed", type=_count(0, 2 ** 32 - 1), default=0, help="seed of the sampled states and background")
    p.add_argument("--method", default="deep_shap", help="attribution method (see `xairl attributors`)")
    p.add_argument("-o", "--option", action="append", default=[], metavar="KEY=VALUE",
                   help="an option of the method, validated against its schema; repeatable")
    p.add_argument("--format", choices=("table", "jsonl", "parquet"), default="table",
                   help="table or jsonl on the terminal; parquet: streamed chunk by chunk into --out DIR (any number "
                   "of states, resumable with --resume)")
    p.add_argument("--chunk-size", type=_count(1, 10_000_000), default=50_000, help="states per chunk with --format "
                   "parquet (memory grows with it)")
    p.add_argument("--resume", action="store_true", help="with --format parquet: continue an interrupted run in --out")
    p.add_argument("--engine", choices=("local", "ray"), default="local", help="with --format parquet: this process "
                   "(local) or Ray workers (pip install 'xairl[scale]'; states from a .npy file)")
    p.add_argument("--workers", type=_count(1, 100_000), default=2, help="Ray workers (one CPU each; default 2)")
    p.add_argument("--ray-address", default=None, metavar="ADDRESS", help="a running Ray cluster (e.g. auto or "
                   "ray://host:10001); default: Ray started on this machine")
    p.add_argument("--top", type=_count(1), default=5, help="features shown per state in the table")
    _narration_arguments(p)
    p.add_argument("--feedback-db", type=_new_file, default=None, help="SQLite store of shown narratives (default: in the user dir)")
    p.add_argument("--no-record", action="store_true", help="do not record the narratives for review")
    p.add_argument("--examples-from-feedback", action="store_true",
                   help="give the local LM the operators' latest accepted or corrected narratives as examples")
    p.set_defaults(run=cmd_explain)


def _report_parser(p: argparse.ArgumentParser) -> None:
    p.add_argument("--plugin", required=True, help="the report's name (see `xairl plugins`), e.g. uav-handover")
    p.add_argument("-o", "--option", action="append", default=[], metavar="KEY=VALUE",
                   help="an option of the plugin's report, validated against its schema (e.g. -o real=PATH)")
    p.add_argument("--out", type=_out_dir, default="xairl-report", help="report folder (default xairl-report)")
    p.add_argument("--n", type=_count(1, 1_000_000), default=500, help="states explained per dataset")
    p.add_argument("--seed", type=_count(0, 2 ** 32 - 1), default=0, help="seed of everything the report samples")
    p.add_argument("--method", default="deep_shap", help="attribution method (see `xairl attributors`)")
    p.add_argument("-m", "--method-option", action="append", default=[], metavar="KEY=VALUE",
                   help="an option of the attribution method; repeatable")
    _narration_arguments(p)
    p.set_defaults(run=cmd_report)


def main(argv: Sequence[str] | None = None) -> int:
    try:
        parser = build_parser()
        args = parser.parse_args(argv)
        if not getattr(args, "run", None):
            parser.print_help()
            return 0
        return int(args.run(args) or 0)
    except XairlError as exc:
        print(f"xairl: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("xairl: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # a bug of ours or a plugin's: one line, the traceback only on request
        if os.environ.get("XAIRL_DEBUG"):
            raise
        print(f"xairl: internal error: {type(exc).__name__}: {exc} (set XAIRL_DEBUG=1 for the traceback; please "
              "report it)", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
