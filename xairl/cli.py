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


def _parse_options(pairs: Sequence[str]) -> dict:
    """``["n_steps=32", "method=riemann_left"]`` -> dict; values are read as JSON when they parse, else as text."""
    opts: dict = {}
    for pair in pairs:
        key, sep, raw = pair.partition("=")
        if not sep or not key.strip():
            raise InputError(f"option '{pair}' is not key=value; write e.g. -o n_steps=32.")
        try:
            opts[key.strip()] = json.loads(raw)
        except ValueError:
            opts[key.strip()] = raw
    return opts


def cmd_plugins(args) -> int:
    for plugin, kinds in sorted(plugins.summary().items()):
        print(plugin)
        for kind, names in sorted(kinds.items()):
            print(f"  {kind}: {', '.join(sorted(names))}")
        if not kinds:
            print("  (registers nothing)")
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


def cmd_explain(args) -> int:
    import numpy as np

    from .attributors import explain
    from .inputs import read_states

    policy = plugins.get_policy(args.policy)
    method = plugins.get_attributor(args.method)  # unknown names fail before any file is read
    options = method(_parse_options(args.option)).options
    if args.states:
        states = read_states(args.states, policy.feature_names)
    else:
        states = policy.background(args.n, seed=args.seed + 1)
    bg = read_states(args.background, policy.feature_names) if args.background else policy.background(
        args.background_size, seed=args.seed)
    exp = explain(policy, states, background=bg, method=args.method, options=options.model_dump())
    if args.format == "jsonl":
        for rec in exp.records():
            print(rec.model_dump_json())
        return 0
    chosen = exp.for_chosen()
    for i, rec in enumerate(exp.records()):
        order = np.argsort(-np.abs(chosen[i]))[: args.top]
        scores = ", ".join(f"{a}={v:.3f}" for a, v in rec.scores.items())
        print(f"state {i}: chose {rec.chosen} (runner-up {rec.runner_up}); scores {scores}")
        for j in order:
            f = exp.feature_names[j]
            print(f"    {f:<24} = {exp.states[i, j]:>10.4g}   contribution {chosen[i, j]:+.4f}")
        print(f"    base {exp.base_values[i, exp.chosen[i]]:.4f}, additivity gap "
              f"{exp.additivity_gap[i, exp.chosen[i]]:.2e} ({exp.method})")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="xairl", description="Explain what a reinforcement-learning policy decided "
                                     "and why.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    p = sub.add_parser("plugins", help="list installed plugins and what each registers")
    p.set_defaults(run=cmd_plugins)
    p = sub.add_parser("attributors", help="list attribution methods and their options")
    p.add_argument("--json", action="store_true", help="print names and JSON schemas of the options")
    p.set_defaults(run=cmd_attributors)
    p = sub.add_parser("explain", help="explain a registered policy's decisions on states from a file")
    p.add_argument("--policy", default="toy", help="registered policy name (see `xairl plugins`); default: toy")
    p.add_argument("--states", help="states to explain: .csv with a header naming the features, .npy or .json; "
                   "default: --n states from the policy's sampler")
    p.add_argument("--background", help="background states file (default: the policy's sampler)")
    p.add_argument("--background-size", type=int, default=100, help="background states drawn from the sampler")
    p.add_argument("--n", type=int, default=5, help="states to sample when --states is not given")
    p.add_argument("--seed", type=int, default=0, help="seed of the sampled states and background")
    p.add_argument("--method", default="deep_shap", help="attribution method (see `xairl attributors`)")
    p.add_argument("-o", "--option", action="append", default=[], metavar="KEY=VALUE",
                   help="an option of the method, validated against its schema; repeatable")
    p.add_argument("--format", choices=("table", "jsonl"), default="table", help="output format")
    p.add_argument("--top", type=int, default=5, help="features shown per state in the table")
    p.set_defaults(run=cmd_explain)
    commands = plugins.registry("command")
    for name in commands.names():
        entry = commands.entry(name)
        entry.load()(sub.add_parser(name, help=entry.description))
    return parser


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
