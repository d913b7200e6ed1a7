"""Resume fuzz (issue 51, "done when"): a whole streamed run of the toy policy (50 states, 5 parts of 10) is damaged
one to three ways at a time (a flipped bit, a truncated part, a part with rows cut, a deleted part, two parts under
each other's names, a stray copy under a name that is no chunk's, another run's whole part; run.json made no record
in one case in ten), then resumed. Each case must end with every state exactly once and the values of an undamaged
run, or in one line naming a file that is no part of the run; deleting the named file and resuming again must then
end whole. Damage alone must never be refused. Prints the tally per kind of damage.

Run: .venv/bin/python benchmarks/fuzz_resume.py [--cases 1000] [--seed 51] [--engine ray]
(``tests/test_hardening_stream.py`` runs 210 cases of it with the local engine.)
"""

from __future__ import annotations

import argparse
import collections
import pathlib
import random
import shutil
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
from tests.resume_fuzz import KINDS, make_runs, one_case  # noqa: E402
from xairl.runs.stream import explain_to_parquet  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=51)
    ap.add_argument("--engine", choices=("local", "ray"), default="local")
    args = ap.parse_args()
    engine = explain_to_parquet
    if args.engine == "ray":
        import ray

        from xairl.runs.scale import explain_on_ray

        ray.init(
            num_cpus=2,
            include_dashboard=False,
            log_to_driver=False,
            logging_level="ERROR",
            _node_ip_address="127.0.0.1",
        )

        def engine(*a, **k):
            return explain_on_ray(*a, workers=2, **{key: v for key, v in k.items() if key != "progress"})

    import logging

    logging.getLogger("xairl").setLevel(logging.ERROR)  # the notes on damaged parts: one per case
    rng, tally, failures = random.Random(args.seed), collections.Counter(), []
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        reference, run = make_runs(root, engine)
        for case in range(args.cases):
            try:
                done = one_case(case, root, reference, run, rng, engine)
            except AssertionError as exc:
                failures.append(f"case {case}: {' '.join(str(exc).split())[:300]}")
                shutil.rmtree(root / f"case{case}", ignore_errors=True)
                continue
            end = "refused by name, then whole" if done["refusals"] else "whole at once"
            tally["all", end] += 1
            for kind in set(done["kinds"]) | ({"run.json"} if done["record"] else set()):
                tally[kind, end] += 1
    seconds = time.perf_counter() - t0
    print(f"{args.cases} cases ({args.engine} engine, seed {args.seed}) in {seconds:.1f} s")
    for kind in ("all", *KINDS, "run.json"):
        print(
            f"  {kind:<9} whole at once {tally[kind, 'whole at once']:>5}   refused by name, then whole "
            f"{tally[kind, 'refused by name, then whole']:>5}"
        )
    print(f"  violations: {len(failures)}", *failures[:10], sep="\n    ")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
