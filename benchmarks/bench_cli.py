"""`xairl explain` end to end for a policy given as module:attr (nothing installed): 10,000 states x 100
background of a CleanRL-style MLP (4-120-84-2), JSONL + figures + report.html. Goal (issue 12): <= 6 s.

Run: .venv/bin/python benchmarks/bench_cli.py [--states 10000] [--repeats 3]
"""

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--states", type=int, default=10_000)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    xairl = str(Path(sys.executable).with_name("xairl"))
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        subprocess.run(
            [
                sys.executable,
                str(ROOT / "examples" / "bring_your_own.py"),
                "--out",
                str(out),
                "--states",
                str(args.states),
            ],
            check=True,
            capture_output=True,
        )
        cmd = [
            xairl,
            "explain",
            "--policy",
            f"{ROOT / 'examples' / 'bring_your_own.py'}:make_policy",
            "--policy-arg",
            f"checkpoint={out / 'my_q.pt'}",
            "--states",
            str(out / "states.npy"),
            "--background",
            str(out / "background.npy"),
            "--out",
            str(out / "report"),
        ]
        times = []
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            subprocess.run(cmd, check=True, capture_output=True)
            times.append(time.perf_counter() - t0)
        lines = sum(1 for _ in open(out / "report" / "explanations.jsonl"))
    best, median = min(times), sorted(times)[len(times) // 2]
    print(
        f"xairl explain --policy file.py:attr --out DIR, {args.states} states x 100 background, MLP 4-120-84-2: "
        f"median {median:.2f} s (best {best:.2f} s) over {args.repeats} runs, {lines} JSONL lines; goal 6 s: "
        f"{'met' if median <= 6 else 'NOT met'} (ratio {median / 6:.2f} of the budget)"
    )


if __name__ == "__main__":
    main()
