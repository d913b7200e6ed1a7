"""8 processes x 1,000 concurrent writes to one feedback store; then a writer killed mid-run. Counts lost records.

Run: .venv/bin/python benchmarks/stress_feedback.py [--procs 8] [--writes 1000]
"""

import argparse
import multiprocessing as mp
import os
import signal
import sqlite3
import tempfile
import time
from pathlib import Path


def writer(path, n, tag):
    from xairl.narrators.base import Narrative
    from xairl.outputs.feedback import FeedbackStore

    store = FeedbackStore(path)
    for i in range(n):
        store.record(Narrative(f"{tag}-{i}", (), True, 0.5, {}, "template", "t", i))


def run(procs: int, writes: int, path: Path) -> tuple[int, float]:
    from xairl.outputs.feedback import FeedbackStore

    FeedbackStore(path)
    ctx = mp.get_context("spawn")
    ps = [ctx.Process(target=writer, args=(path, writes, f"p{k}")) for k in range(procs)]
    t0 = time.perf_counter()
    for p in ps:
        p.start()
    for p in ps:
        p.join()
        assert p.exitcode == 0, p.exitcode
    return len({r.text for r in FeedbackStore(path).records()}), time.perf_counter() - t0


def killed_writer(path: Path) -> tuple[int, str]:
    from xairl.outputs.feedback import FeedbackStore

    ctx = mp.get_context("spawn")
    p = ctx.Process(target=writer, args=(path, 100_000, "victim"))
    p.start()
    time.sleep(3.0)
    os.kill(p.pid, signal.SIGKILL)
    p.join()
    rows = FeedbackStore(path).records()
    ok = sqlite3.connect(path).execute("PRAGMA integrity_check").fetchone()[0]
    return len(rows), ok


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--procs", type=int, default=8)
    ap.add_argument("--writes", type=int, default=1000)
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as d:
        n, secs = run(a.procs, a.writes, Path(d) / "fb.sqlite")
        want = a.procs * a.writes
        print(
            f"{a.procs} processes x {a.writes} writes: {n}/{want} distinct records stored, {want - n} lost, "
            f"{secs:.1f} s ({want / secs:.0f} writes/s)"
        )
        rows, integrity = killed_writer(Path(d) / "killed.sqlite")
        print(
            f"writer killed with SIGKILL after 3 s: store readable, {rows} complete records, integrity_check: "
            f"{integrity}"
        )
