"""The command line's argument types and shared arguments: numbers in a range, paths checked before anything runs,
``key=value`` options, and argparse errors as one line (exit status 2 through :func:`xairl.cli.main`)."""

from __future__ import annotations

import argparse
import json
from collections.abc import Sequence

from xairl.errors import InputError


class Parser(argparse.ArgumentParser):
    """argparse with its errors as one line and exit status 2 through :func:`main` (not usage text)."""

    def error(self, message: str):
        raise InputError(f"{self.prog}: {message}; see `{self.prog} --help`.")


def count(low: int, high: int | None = None):
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
def new_file(path) -> str | None:
    """A file to write whose folder exists (an existing file is replaced)."""
    if path.is_dir():
        return f"{_short(str(path))} is a folder; give a file name"
    if not path.parent.is_dir():
        return f"the folder {_short(str(path.parent))} does not exist; create it first"
    return None


@_path
def out_dir(path) -> str | None:
    """A folder to write into, new or existing (missing folders above it are created, as mkdir -p does)."""
    if path.exists() and not path.is_dir():
        return f"{_short(str(path))} is a file, not a folder; give a folder for the report"
    above = next((p for p in path.absolute().parents if p.exists()), None)
    if above is not None and not above.is_dir():
        return f"{_short(str(above))} is a file, so no folder can be made under it"
    return None


def make_dir(path: str, what: str = "--out"):
    """Creates the folder ``path`` (mkdir -p) and checks a file can be written in it, before any work is done; one
    line when the system refuses (``/proc/...``, a read-only disk, no permission)."""
    import tempfile
    from pathlib import Path

    try:
        Path(path).mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=path):
            pass
    except OSError as exc:
        raise InputError(
            f"{what} {_short(str(path))}: cannot write there ({exc.strerror or exc}); give a folder you can write to."
        ) from None
    return Path(path)


def key_value(flag: str, example: str):
    """An argparse type: ``KEY=VALUE`` text, checked when the command line is read (``flag`` and ``example`` name
    the option in the message). ``-n 3`` is thus an error that says what ``-n`` is, not a narrator option that a
    run without --narrate never reads."""

    def parse(text: str) -> str:
        key, sep, _ = text.partition("=")
        if sep and key.strip():
            return text
        count = f"; to explain {text.strip()} states, write --n {text.strip()}" if text.strip().isdigit() else ""
        raise argparse.ArgumentTypeError(f"{_short(text)!r} is not key=value; write e.g. {flag} {example}{count}")

    parse.__name__ = "KEY=VALUE"
    return parse


def parse_options(pairs: Sequence[str]) -> dict:
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


def report_request(args, out, options: dict, n_states: int, **more):
    """The :class:`xairl.plugin.ReportRequest` of a command's report options (``--method``, ``--narrate``,
    ``--narrator``, ``--template``, ``--prompts``, ``--seed``, ``--no-robustness``), for ``n_states`` states."""
    from pathlib import Path

    from xairl.outputs.report import ReportRequest

    return ReportRequest(
        out=Path(out),
        method=args.method,
        options=options,
        narrate=args.narrate,
        narrator=args.narrator,
        narrator_options=parse_options(args.narrator_option),
        template=args.template,
        prompt_dirs=args.prompts,
        seed=args.seed,
        n_states=n_states,
        robustness=not args.no_robustness,
        **more,
    )


def narration_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--narrate", action="store_true", help="explain decisions in words, checked against the numbers")
    p.add_argument("--narrator", default="template", help="template (default), local_lm, or a plugin's narrator")
    p.add_argument("--template", default=None, help="template name or .yaml path (default explain_action)")
    p.add_argument(
        "--prompts", action="append", default=[], metavar="DIR", help="extra template folder, searched first"
    )
    p.add_argument(
        "-n",
        "--narrator-option",
        action="append",
        type=key_value("-n", "audience=operator"),
        default=[],
        metavar="KEY=VALUE",
        help="a narrator option, e.g. -n audience=operator (local_lm) or -n model=PATH",
    )
    p.add_argument(
        "--no-robustness",
        action="store_true",
        help="confidence without the agreement and stability "
        "components (saves three extra explanations per narrated state)",
    )


#: how each sentence's status is shown: an unchecked sentence is said to be unchecked, never passed as verified
MARKS = {"verified": "verified", "contradicted": "CONTRADICTED", "unchecked": "unchecked", "none": "(no claim)"}


def feedback_arguments(p: argparse.ArgumentParser) -> None:
    """--feedback-db, --no-record, --examples-from-feedback: where the narratives shown are recorded for review."""
    p.add_argument(
        "--feedback-db", type=new_file, default=None, help="SQLite store of shown narratives (default: in the user dir)"
    )
    p.add_argument("--no-record", action="store_true", help="do not record the narratives for review")
    p.add_argument(
        "--examples-from-feedback",
        action="store_true",
        help="give the local LM the operators' latest accepted or corrected narratives as examples",
    )


def streaming_arguments(p: argparse.ArgumentParser) -> None:
    """--chunk-size, --resume, --engine, --workers, --ray-address: a streamed run (--format parquet)."""
    p.add_argument(
        "--chunk-size",
        type=count(1, 10_000_000),
        default=50_000,
        help="states per chunk with --format parquet (memory grows with it)",
    )
    p.add_argument(
        "--resume",
        action="store_true",
        help="with --format parquet (or --out alone): continue an interrupted run in --out",
    )
    p.add_argument(
        "--engine",
        choices=("local", "ray"),
        default="local",
        help="with --format parquet: this process (local) or Ray workers (pip install 'xairl[scale]')",
    )
    p.add_argument("--workers", type=count(1, 100_000), default=2, help="Ray workers (one CPU each; default 2)")
    p.add_argument(
        "--ray-address",
        default=None,
        metavar="ADDRESS",
        help="a running Ray cluster (e.g. auto or ray://host:10001); default: Ray started on this machine",
    )
