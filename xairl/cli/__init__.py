"""The ``xairl`` command. ``main(argv) -> int``; user errors print one line and return 2, never a traceback.

Only argparse and the plugin registry are imported here; torch and shap load inside the commands that need them.
``args`` holds the argument types shared by the commands, ``explain`` the biggest command with its four outputs.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections.abc import Sequence

from xairl.cli.args import (
    Parser,
    count,
    make_dir,
    narration_arguments,
    new_file,
    out_dir,
    parse_options,
    report_request,
)
from xairl.cli.explain import explain_parser, marked_rows
from xairl.errors import InputError, XairlError
from xairl.registry import plugins


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
            kind = spec.get("type") or "|".join(
                str(a.get("type", a.get("const", a.get("enum", "?")))) for a in spec.get("anyOf", [])
            )
            if "enum" in spec:
                kind = "|".join(spec["enum"])
            print(f"    -o {key}=  {kind}, default {spec.get('default')!r}: {spec.get('description', '')}")
    return 0


def cmd_report(args) -> int:
    from xairl.explanations.display import heartbeat
    from xairl.outputs.report import write_report

    report = plugins.registry("report").load(args.plugin)(parse_options(args.option))
    method_options = plugins.get_attributor(args.method)(parse_options(args.method_option)).options.model_dump()
    req = report_request(args, args.out, method_options, args.n)
    make_dir(req.out)  # one line, before any work, where the folder cannot be made (--out /proc/x)
    with heartbeat(f"building the {args.plugin} report's content"):  # a plugin's minutes, said every 10 s
        content = report.build(req)
    path = write_report(req, content)
    print(f"report: {path.resolve()}")
    return 0


def cmd_prompts(args) -> int:
    from xairl.templates import prompts

    if args.action == "list":
        for name, path in sorted(prompts.available(args.prompts).items()):
            tpl = prompts.parse(path)
            print(f"{name:<18} {tpl.spec.kind:<9} {path}\n    {tpl.spec.description}")
        return 0
    if not args.target:
        raise InputError(
            f"`xairl prompts {args.action}` needs a template {'name' if args.action == 'show' else 'path'}."
        )
    if args.action == "show":
        tpl = prompts.load(args.target, args.prompts)
        print(f"# {tpl.path}")
        print(tpl.path.read_text(), end="")
        return 0
    from xairl.narrators import check_template

    lines = check_template(args.target, notes=True, verbose=print if args.verbose else None)
    problems = [p for p in lines if not p.startswith("note:")]
    for p in lines:
        print(p)
    notes = f", {len(lines) - len(problems)} note(s)" if len(lines) > len(problems) else ""
    print(f"{args.target}: {'ok' if not problems else f'{len(problems)} problem(s)'}{notes}")
    return 0 if not problems else 1


#: ``xairl verify``'s exit status by verdict (2 stays a user error)
VERIFY_EXIT = {"verified": 0, "contradicted": 1, "partly checked": 3}


def cmd_verify(args) -> int:
    """Check a text against an explanation; with --trace, every claim with the words it was read from and the
    reading (rule) that bound it."""
    from xairl.cli.records import read_explanation
    from xairl.explanations.evidence import verdict_text
    from xairl.templates.prompts import bidi_visible
    from xairl.verification import verify

    text = args.text if args.text != "-" else sys.stdin.read()
    exp, index = read_explanation(args.explanation, args.index)
    result = verify(text, exp, index)
    for sentence in result.sentences:
        print(f"[{sentence.status}] {bidi_visible(sentence.text)}")  # shown as read, not reordered
        for c in sentence.claims if args.trace else ():
            print(f"    {c.status:<12} {c.kind:<9} {c.text!r:<28} {c.rule or '-':<22} {c.detail}")
    if args.trace:  # what each reading that fired reads, from its entry in the rules' table
        from xairl.verification.prose.rules import by_id

        BY_ID = by_id()

        fired = sorted({c.rule for c in result.claims if c.rule in BY_ID})
        print(
            "rules:" if fired else "rules: none fired",
            *(f"  {r}: a {BY_ID[r].claim} bound by {BY_ID[r].binding}" for r in fired),
            sep="\n",
        )
    print(f"verdict: {verdict_text(result.status, result.coverage)}{'; ' + result.note if result.note else ''}")
    if result.account:
        print(f"account: {result.account}")
    return VERIFY_EXIT[result.status]


def cmd_review(args) -> int:
    from xairl.explanations.evidence import verdict_text
    from xairl.outputs.feedback import FeedbackStore

    store = FeedbackStore(args.db)
    if args.serve:
        from xairl.outputs.review import serve

        serve(store, args.port)
        return 0
    if args.export:
        from xairl.runs.files import atomic_write

        with atomic_write(args.export) as fh:
            n = store.export_corrections(fh)
        print(f"wrote {n} correction(s) to {args.export}")
        return 0
    pending = store.records("pending")
    print(f"{len(pending)} narrative(s) to review in {store.path}")
    for r in pending:
        bad = sum(c["status"] != "verified" for c in r.claims)
        print(
            f"\n#{r.id} [{r.template}, {r.source}, confidence {r.confidence:.2f}, "
            f"{verdict_text(r.verdict, r.coverage)}{f': {bad} claim(s) not verified' if bad else ''}]"
        )
        if r.account:
            print(f"    account: {r.account}")
        marked = (r.evidence or {}).get("sentences") or []
        print(marked_rows(r.text, marked))
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


#: the top-level help's examples: one line per task a newcomer comes with
EXAMPLES = """examples:
  xairl explain                                   the example policy's decisions on 5 sampled states
  xairl explain --policy uav-dqn --narrate        the UAV reference policy's decisions, in verified words
  xairl explain --policy my_pkg.pol:make_policy --states s.npy --background bg.npy --out report/
                                                  your own policy: an HTML report with figures
  xairl explain --states big.npy --format parquet --out run/    any number of states, streamed, resumable
  xairl verify "The buffer raised the score by 0.4." --explanation exp.json --trace
  xairl report --plugin uav-handover -o real=ukm --out out/report    the paper's report, with real flights
  xairl <command> --help                          each command's options and examples
"""


#: each command's examples, shown under its --help
COMMAND_EXAMPLES = {
    "explain": """examples:
  xairl explain --n 3 --top 4                     three sampled states of the example policy, 4 features each
  xairl explain --policy uav-dqn --view score     contributions to the chosen action's score, not the margin
  xairl explain --policy pol.py:make_policy --states s.csv --background bg.csv --narrate
  xairl explain --policy my_pkg.policies:make_policy --states s.npy --out report/   an HTML report
  xairl explain --states big.npy --background bg.npy --format parquet --out run/ [--resume] [--engine ray]
""",
    "verify": """examples:
  (the --explanation file is what Explanation.to_json() writes in Python, or xairl explain --out's JSON lines)
  xairl verify "Speed lowered the score by 0.52." --explanation report/explanations.jsonl --index 2
  xairl verify "Speed lowered the score by 0.52." --explanation exp.json --index 0 --trace
  echo "..." | xairl verify - --explanation exp.json

it prints each sentence's status, then the verdict and the account:
  verdict: verified | contradicted | partly checked (coverage 62 %)
  account: what the text's features account for of the margin (or score), and what it leaves out
exit status: 0 verified (every claim checked, and true), 1 contradicted (a claim is false), 3 partly checked
(nothing false, but not every claim could be checked), 2 a usage error (a missing file, a bad --index)
""",
    "report": """examples:
  xairl report --plugin uav-handover --out out/report                 Table I and SHAP on simulated flights
  xairl report --plugin uav-handover -o real=ukm --narrate --out out/report    with the real UKM flights
""",
    "review": """examples:
  xairl review                                    review recorded narratives in the terminal
  xairl review --serve --port 8765                the review page, with each narrative's evidence
  xairl review --export corrections.jsonl
""",
    "prompts": """examples:
  xairl prompts list
  xairl prompts show explain_action
  xairl prompts check my_template.yaml
""",
}


def _command(sub, name: str, **kwargs) -> argparse.ArgumentParser:
    """A subcommand's parser, with its examples under --help when it has some."""
    if name in COMMAND_EXAMPLES:
        kwargs.update(epilog=COMMAND_EXAMPLES[name], formatter_class=argparse.RawDescriptionHelpFormatter)
    return sub.add_parser(name, **kwargs)


def version_line() -> str:
    """``xairl 0.1.0`` and the installed plugins' distributions with their versions."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        own = version("xairl")
    except PackageNotFoundError:  # running from a source tree that was never installed
        own = "unknown (not installed)"
    extra = [f"{dist} {ver}" for dist, ver in plugins.distributions()]
    return f"xairl {own}" + (f" (plugins: {', '.join(extra)})" if extra else "")


def _verify_parser(p: argparse.ArgumentParser) -> None:
    """``xairl verify``'s arguments."""
    p.add_argument("text", help="the text to check, or - to read it from standard input")
    p.add_argument(
        "--explanation",
        required=True,
        metavar="FILE",
        help="the explanation: the JSON Explanation.to_json() writes, or the explanations.jsonl of "
        "xairl explain --out (or its --format jsonl lines)",
    )
    p.add_argument(
        "--index",
        type=count(0),
        default=None,
        help="which state the text is about: of an explanation (default 0), or which record (line) of a JSON-lines "
        "file, from 0 (needed when it holds more than one)",
    )
    p.add_argument("--trace", action="store_true", help="every claim: status, kind, words, rule, reason")
    p.set_defaults(run=cmd_verify)


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="xairl",
        description="Explain what a reinforcement-learning policy decided and why.",
        epilog=EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=version_line())
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    p = sub.add_parser("plugins", help="list installed plugins and what each registers")
    p.set_defaults(run=cmd_plugins)
    p = sub.add_parser("attributors", help="list attribution methods and their options")
    p.add_argument("--json", action="store_true", help="print names and JSON schemas of the options")
    p.set_defaults(run=cmd_attributors)
    explain_parser(_command(sub, "explain", help="explain a registered policy's decisions on states from a file"))
    _report_parser(_command(sub, "report", help="write a plugin's report (HTML, JSONL, figures) into a folder"))
    p = _command(sub, "prompts", help="list, show or check prompt templates")
    p.add_argument("action", choices=("list", "show", "check"))
    p.add_argument("target", nargs="?", help="template name (show) or .yaml path (check)")
    p.add_argument("--prompts", action="append", default=[], metavar="DIR", help="extra template folder")
    p.add_argument(
        "-v", "--verbose", action="store_true", help="check: say how many cases the battery rendered, and in what time"
    )
    p.set_defaults(run=cmd_prompts)
    _verify_parser(
        _command(
            sub,
            "verify",
            help="check a text's claims against an explanation: verified (exit 0), contradicted (1) or partly checked (3)",
        )
    )
    p = _command(
        sub,
        "review",
        help="accept, reject or correct recorded narratives in the terminal, or in a local "
        "web page with the evidence (--serve)",
    )
    p.add_argument("--db", type=new_file, default=None, help="feedback store (default: in the user dir)")
    p.add_argument("--serve", action="store_true", help="serve the review page on http://127.0.0.1:PORT/")
    p.add_argument(
        "--port", type=count(0, 65535), default=8765, help="port of the review page (default 8765; 0: any free port)"
    )
    p.add_argument(
        "--export", type=new_file, metavar="FILE", help="write the corrections as JSON lines instead of reviewing"
    )
    p.set_defaults(run=cmd_review)
    commands = plugins.registry("command")
    for name in commands.names():
        entry = commands.entry(name)
        entry.load()(sub.add_parser(name, help=entry.description))
    return parser


def _report_parser(p: argparse.ArgumentParser) -> None:
    p.add_argument("--plugin", required=True, help="the report's name (see `xairl plugins`), e.g. uav-handover")
    p.add_argument(
        "-o",
        "--option",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="an option of the plugin's report, validated against its schema (e.g. -o real=PATH)",
    )
    p.add_argument("--out", type=out_dir, default="xairl-report", help="report folder (default xairl-report)")
    p.add_argument("--n", type=count(1, 1_000_000), default=500, help="states explained per dataset")
    p.add_argument("--seed", type=count(0, 2**32 - 1), default=0, help="seed of everything the report samples")
    p.add_argument("--method", default="deep_shap", help="attribution method (see `xairl attributors`)")
    p.add_argument(
        "-m",
        "--method-option",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="an option of the attribution method; repeatable",
    )
    narration_arguments(p)
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
    except BrokenPipeError:  # the reader stopped early (`xairl ... | head`): nothing more to say, as other tools
        sys.stdout = open(os.devnull, "w")  # (Python's flush at exit would raise again)  # noqa: SIM115
        return 141
    except Exception as exc:  # a bug of ours or a plugin's: one line, the traceback only on request
        if os.environ.get("XAIRL_DEBUG"):
            raise
        print(
            f"xairl: internal error: {type(exc).__name__}: {exc} (set XAIRL_DEBUG=1 for the traceback; please "
            "report it)",
            file=sys.stderr,
        )
        return 1
