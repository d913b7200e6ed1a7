"""The resume fuzz's cases (run by ``tests/test_hardening_stream.py`` and, with more cases, by
``benchmarks/fuzz_resume.py``): a streamed run of the toy policy damaged one to three ways at a time, then resumed;
each case's checks."""

from __future__ import annotations

import json
import random
import shutil
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from xairl.errors import InputError
from xairl.runs.stream import DATASET, explain_to_parquet, read_parquet
from xairl.toy import toy_policy

POLICY = toy_policy()
N, CHUNK = 50, 10  # five parts
STATES = POLICY.background(N, seed=5)
BG = POLICY.background(10)
KINDS = ("flip", "truncate", "short", "delete", "swap", "stray", "foreign")
RECORDS = ("[1, 2]", "3", '"run"', "null", "[" * 5000 + "]" * 5000, "{")  # run.json made no record of a run


def part(first: int) -> str:
    return f"part-{first:012d}.parquet"


def make_runs(root: Path, engine=explain_to_parquet):
    """``root/run`` (the run to damage), ``root/other`` (another background: foreign parts), the undamaged values and
    the run's id."""
    engine(POLICY, STATES, root / "run", background=BG, chunk_size=CHUNK, progress=False)
    engine(POLICY, STATES, root / "other", background=BG[:7], chunk_size=CHUNK, progress=False)
    run = json.loads(pq.read_schema(root / "run" / DATASET / part(0)).metadata[b"xairl"]).get("run")
    return read_parquet(root / "run" / DATASET), run


def mutate(kind: str, parts: Path, other: Path, rng: random.Random) -> str | None:
    """Damages the dataset folder ``parts`` one way; returns the name of a file it leaves there that is no part of
    the run (to be refused by name), or None."""
    names = sorted(p.name for p in parts.glob("part-*.parquet"))
    if not names:
        return None
    victim = parts / rng.choice(names)
    if kind == "flip":  # one bit, anywhere in the file
        data = bytearray(victim.read_bytes())
        data[rng.randrange(len(data))] ^= 1 << rng.randrange(8)
        victim.write_bytes(bytes(data))
    elif kind == "truncate":
        victim.write_bytes(victim.read_bytes()[: rng.randrange(victim.stat().st_size)])
    elif kind == "short":  # fewer rows, the metadata kept (unless an earlier damage left it unreadable)
        try:
            table = pq.read_table(victim)
        except (pa.ArrowException, OSError):
            return None
        pq.write_table(table.slice(0, rng.randrange(table.num_rows)), victim)
    elif kind == "delete":
        victim.unlink()
    elif kind == "swap" and len(names) > 1:  # two parts, each under the other's name
        a, b = (parts / name for name in rng.sample(names, 2))
        a.rename(parts / "swap.tmp"), b.rename(a), (parts / "swap.tmp").rename(b)
    elif kind == "stray":  # a copy under a name that is no chunk's: misaligned, past the end, or no part's name
        misaligned = rng.randrange(1, N)
        name = rng.choice(
            [
                part(misaligned + (misaligned % CHUNK == 0)),
                part(N + CHUNK * rng.randrange(3)),
                "part-7.parquet",
                "extra.parquet",
                "notes.txt",
            ]
        )
        shutil.copy(victim, parts / name)
        return name
    elif kind == "foreign":  # another run's part, whole, under one of this run's names
        first = rng.randrange(0, N, CHUNK)
        shutil.copy(other / part(first), parts / part(first))
        return part(first)
    return None


def not_a_part_of_the_run(path: Path, run: str) -> bool:
    """run.json when it is no record of a run, a file whose name is no chunk's, or another run's whole part."""
    from xairl.runs.parts import PART, check_part

    if path.name == "run.json":
        try:
            return not isinstance(json.loads(path.read_text()), dict)
        except (ValueError, RecursionError):
            return True
    if not PART.fullmatch(path.name) or int(path.name[5:17]) % CHUNK or int(path.name[5:17]) >= N:
        return True
    return check_part(path, int(path.name[5:17]), CHUNK, run)[0] == "foreign"


def one_case(case: int, root: Path, reference, run: str, rng: random.Random, engine=explain_to_parquet) -> dict:
    """Damages a copy of ``root/run``, resumes it (deleting each file refused by name) and checks the outcome;
    AssertionError on a violation. Returns what was done and how it ended."""
    out = root / f"case{case}"
    shutil.copytree(root / "run", out)
    chosen = [KINDS[case % len(KINDS)]] + rng.sample(KINDS, rng.randrange(3))
    named = {mutate(kind, out / DATASET, root / "other" / DATASET, rng) for kind in chosen} - {None}
    record = case % 10 == 9
    if record:
        (out / "run.json").write_text(rng.choice(RECORDS))
    refusals = []
    for _ in range(8):
        try:
            summary = engine(POLICY, STATES, out, background=BG, chunk_size=CHUNK, progress=False, resume=True)
        except InputError as exc:
            message = str(exc)
            assert "\n" not in message and (
                "not a part of this run (" in message or "run.json: not the record of a run (" in message
            ), message
            refused = next(p for p in [out / "run.json", *(out / DATASET).iterdir()] if f"{p}: not " in message)
            assert not_a_part_of_the_run(refused, run), message
            refusals.append(refused.name)
            refused.unlink()
            continue
        assert summary.n == N, summary.n
        index = pq.read_table(out / DATASET, columns=["index"]).column("index").to_numpy()
        assert np.array_equal(np.sort(index), np.arange(N)), f"case {case} {chosen}: a state missing or twice"
        assert np.array_equal(read_parquet(out / DATASET).values, reference.values), f"case {case} {chosen}: values"
        break
    else:
        raise AssertionError(f"case {case} ({chosen}) still refused after 8 resumes: {refusals}")
    assert named or record or not refusals, f"case {case} {chosen}: damage alone was refused: {refusals}"
    shutil.rmtree(out)
    return {"kinds": chosen, "refusals": refusals, "named": sorted(named), "record": record}
