"""Streaming a large run through the CLI (issue 28): `xairl explain --format parquet` on N states of an 8-64-64-4 MLP
(CleanRL style, given as file.py:attr) x 100 background, deep_shap. Prints states/s and peak RSS of the CLI process,
bytes per state on disk for Parquet and for JSON lines, and ratios against the issue's targets (50,000 states/s on 2
cores, peak RSS <= 1 GB, Parquet <= 1/3 of JSON lines, peak RSS at 10x the states within 10 % of 1x).

Run: .venv/bin/python benchmarks/bench_stream.py [--states 1000000] [--scale 10] [--chunk-size 50000]
(--scale 10 also runs 10x the states, for the flat-memory check; it takes ten times as long.)
"""

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

POLICY = Path(__file__).with_name("fleet_mlp.py")  # make_policy: the 8-64-64-4 MLP


def run(cmd: list[str]) -> tuple[float, float]:
    """Wall seconds and peak RSS (MB) of one command in a fresh process."""
    t = time.perf_counter()
    pid = os.fork()
    if pid == 0:  # the child: the command, its RSS counted apart from this process's
        os.execv(cmd[0], cmd)
    _, status, usage = os.wait4(pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"failed: {' '.join(cmd)}")
    return time.perf_counter() - t, usage.ru_maxrss / 1024


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--states", type=int, default=1_000_000)
    ap.add_argument("--scale", type=int, default=1, help="also run this many times the states (10 for the issue)")
    ap.add_argument("--chunk-size", type=int, default=50_000)
    args = ap.parse_args()
    import numpy as np

    xairl = str(Path(sys.executable).with_name("xairl"))
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        rng = np.random.default_rng(0)
        np.save(tmp / "bg.npy", rng.normal(size=(100, 8)).astype(np.float32))
        common = [xairl, "explain", "--policy", f"{POLICY}:make_policy", "--background", str(tmp / "bg.npy")]
        peaks = {
            n: throughput(common, tmp, n, args.chunk_size, rng) for n in sorted({args.states, args.states * args.scale})
        }
        small = min(peaks)
        if len(peaks) > 1:
            big = max(peaks)
            print(f"peak RSS at {big} states / at {small}: {peaks[big] / peaks[small]:.3f} (target <= 1.10)")
        bytes_per_state(common, tmp, rng)
    print(f"(this process's own peak: {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB)")


def throughput(common: list[str], tmp: Path, n: int, chunk_size: int, rng) -> float:
    """States a second, peak RSS and Parquet bytes a state of ``xairl explain`` on ``n`` states, printed; the RSS."""
    import numpy as np

    states = np.lib.format.open_memmap(tmp / f"s{n}.npy", mode="w+", dtype=np.float32, shape=(n, 8))
    for a in range(0, n, 1_000_000):  # written in pieces: the benchmark itself stays small too
        states[a : a + 1_000_000] = rng.normal(size=(min(1_000_000, n - a), 8))
    states.flush()
    del states
    out = tmp / f"out{n}"
    secs, rss = run(
        [*common, "--states", str(tmp / f"s{n}.npy"), "--out", str(out), "--format", "parquet"]
        + ["--chunk-size", str(chunk_size)]
    )
    disk = sum(p.stat().st_size for p in (out / "explanations.parquet").glob("part-*.parquet"))
    print(
        f"{n} states: {secs:.1f} s, {n / secs:,.0f} states/s (target 50,000: {n / secs / 50_000:.2f}x), "
        f"peak RSS {rss:.0f} MB (target 1024: {rss / 1024:.2f}x), Parquet {disk / n:.1f} bytes/state"
    )
    (tmp / f"s{n}.npy").unlink()
    return rss


def bytes_per_state(common: list[str], tmp: Path, rng, sample: int = 10_000) -> None:
    """JSON lines against Parquet of the same explanations, on ``sample`` states (bytes a state do not depend on n)."""
    import numpy as np

    np.save(tmp / "few.npy", rng.normal(size=(sample, 8)).astype(np.float32))
    few = [*common, "--states", str(tmp / "few.npy")]
    jsonl = subprocess.run([*few, "--format", "jsonl"], capture_output=True, check=True).stdout
    subprocess.run([*few, "--out", str(tmp / "few"), "--format", "parquet"], capture_output=True, check=True)
    pq = sum(p.stat().st_size for p in (tmp / "few" / "explanations.parquet").glob("part-*.parquet")) / sample
    print(
        f"bytes per state, {sample} states: JSON lines {len(jsonl) / sample:.0f}, Parquet {pq:.0f}: "
        f"Parquet / JSON lines = {pq / (len(jsonl) / sample):.3f} (target <= 0.333)"
    )


if __name__ == "__main__":
    main()
