"""`xairl prompts check` (issue 52, done-when 4): the battery's time per template, under 10 s each, and what it
reports on the built-in templates and on the custom set 1 (``data/templates/custom``): a correct template should be
reported nothing, a ``wrong_*`` one with the line that is wrong.

    .venv/bin/python benchmarks/bench_prompts_check.py            # every plugin installed is in the battery
    .venv/bin/python benchmarks/bench_prompts_check.py --show     # also every line reported
"""

from __future__ import annotations

import argparse
import os
import pathlib
import platform
import sys
import time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
from xairl.narrators import battery_cases, check_template  # noqa: E402
from xairl.registry.plugins import prompt_dirs  # noqa: E402
from xairl.templates import prompts  # noqa: E402

CUSTOM = pathlib.Path(__file__).parent / "data" / "templates" / "custom"


def templates() -> list[pathlib.Path]:
    plugin = [p for _, d in prompt_dirs() for p in sorted(pathlib.Path(d).glob("*.yaml"))]
    custom = [p for p in sorted(CUSTOM.glob("*.yaml")) if p.name != "MANIFEST.yaml"]
    return sorted(prompts.builtin_dir().glob("*.yaml")) + plugin + custom


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--show", action="store_true", help="print every line the check reports")
    args = ap.parse_args()
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}")
    t0 = time.perf_counter()
    loaded = battery_cases.plugin_policies()  # (the first template would otherwise pay the plugins' loading)
    print(f"plugin policies: {[n for n, p, _ in loaded if p is not None]} loaded in {time.perf_counter() - t0:.2f} s")
    print(f"{'template':<44} {'cases':>5} {'renders':>7} {'seconds':>7} {'problems':>8} {'notes':>5}")
    slowest, missed = 0.0, []
    for path in templates():
        said: list[str] = []
        t = time.perf_counter()
        lines = check_template(path, notes=True, verbose=said.append)
        seconds = time.perf_counter() - t
        summary = said[0] if said else ""
        cases = summary.split(" cases")[0].split()[-1] if summary else "-"
        renders = summary.split(" renderings")[0].split()[-1] if summary else "-"
        problems = [x for x in lines if not x.startswith("note:")]
        name = f"{path.parent.name}/{path.name}"
        print(f"{name:<44} {cases:>5} {renders:>7} {seconds:>7.2f} {len(problems):>8} {len(lines) - len(problems):>5}")
        slowest = max(slowest, seconds)
        if path.stem.startswith("wrong_") and not problems:
            missed.append(path.stem)
        if args.show:
            for x in lines:
                print(f"    {x}")
    print(f"slowest template: {slowest:.2f} s (goal < 10 s); wrong templates reported nothing: {missed or 'none'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
