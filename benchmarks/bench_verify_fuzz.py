"""The verifier on hostile text: every case of a seeded fuzz run must be read in under 100 ms (issue 51).

Cases are sentences built from an explanation's names (repeated, adjacent, in lists), digit runs of every length
(1 to 5,000 digits, with commas, points, signs, currencies and units), runs of spaces and punctuation, list words
('and', 'as well as'), brackets, direction words and headers ('Raising it: A, B'): the family of the issue's
`speed 999...9 ! battery raised it.`, whose `_JOIN` pattern took 4x the time per 2 more digits. Explanations: one
output and three outputs, plain names, names with digits and brackets, and 60 features.

    .venv/bin/python benchmarks/bench_verify_fuzz.py                 # 5,000 cases, exits 1 if one took >= 100 ms
    .venv/bin/python benchmarks/bench_verify_fuzz.py --cases 500 --seed 3 --limit-ms 100

Then a second family, number-dense text (a table's worth of numbers in one sentence: 50 to 400 in a row), whose time
is bounded per 1,000 characters: a clause reads its first 40 numbers (the rest are unchecked, 'number.too-many').

A case over half the limit is run twice more and its best time kept: the machine's load (other processes, a garbage
collection) is not the verifier's work; its first time is printed too. The unit tests bound the same work without a
clock (``tests/test_hardening_verify.py`` counts a pattern's backtracking steps).
"""

from __future__ import annotations

import argparse
import pathlib
import random
import statistics
import sys
import time

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
import xairl  # noqa: E402
from xairl.verification import verify  # noqa: E402


def _explanation(names, actions=("out",), seed=0):
    rng = np.random.default_rng(seed)
    v = rng.normal(size=(1, len(names), len(actions)))
    return xairl.Explanation(
        values=v,
        base_values=np.zeros((1, len(actions))),
        outputs=v.sum(axis=1),
        states=rng.normal(size=(1, len(names))),
        feature_names=tuple(names),
        action_names=tuple(actions),
        method="given",
        output="value" if len(actions) == 1 else "actions",
    )


EXPLANATIONS = [
    _explanation(["speed", "battery", "load"]),
    _explanation(["speed", "battery", "wind"], actions=("turn", "recharge", "stay"), seed=1),
    _explanation(["sensors[0]", "rsrp_1", "obs[1,32,35]", "battery_level"], seed=2),
    _explanation([f"f_{i}" for i in range(60)], seed=3),
]
WORDS = [
    "and",
    "or",
    "as well as",
    "together with",
    "both",
    "the",
    "its",
    "of",
    "at",
    "plus",
    "raised",
    "lowered",
    "raised it",
    "pushed toward",
    "lowered the score",
    "by",
    "about",
    "not",
    "without",
    "would be higher",
    "Raising it:",
    "more than",
    "twice",
    "because",
    "toward",
    "the most",
    "average",
    "is categorized as",
    "predicted probability",
    "points",
    "in total",
    "vs",
    "from",
    "to",
    "%",
    "!",
    "?",
    "(",
    ")",
    ":",
    ";",
    "-",
    "+",
    "$",
    "\0",
    "'s",
    "\u2212",
    "\u00a0",
]
SEPARATORS = [" ", ",", ".", "!", "-", "(", ")", "'", ":", "%", "/", "\t", ", ", " ,", "( ", " !", "\0"]


def _digits(rng: random.Random) -> str:
    n = rng.choice([1, 2, 3, 5, 12, 20, 24, 30, 40, 64, 100, 400, 1000, 5000])
    run = "".join(rng.choice("0123456789") for _ in range(n)) if rng.random() < 0.5 else "9" * n
    if rng.random() < 0.3:  # commas and points inside the run
        run = "".join(c + (rng.choice(",.") if rng.random() < 0.3 else "") for c in run)
    return (
        rng.choice(["", "", "+", "-", "$", "-$"])
        + run
        + rng.choice(["", "", " ", "%", " km", "kmh", " and", " pts", "e5"])
    )


def _run(rng: random.Random) -> str:
    """Spaces or punctuation, of any length: no words, so no more claims, whatever the length."""
    return rng.choice(SEPARATORS) * rng.choice([2, 10, 50, 200, 600, 2000])


def case(rng: random.Random, names: list[str]) -> str:
    """One hostile sentence: the issue's shape, or 2 to 12 pieces, each a name (up to 4 times over, adjacent),
    digits, a run of separators, a few numbers in a row ('9 9 9') or a word."""
    if rng.random() < 0.25:  # the shape: a name, digits, a stop, a name, a direction word
        return f"{rng.choice(names)} {_digits(rng)} {rng.choice(SEPARATORS)} {rng.choice(names)} raised it."
    pieces = []
    for _ in range(rng.randint(2, 12)):
        kind = rng.random()
        if kind < 0.3:
            pieces.append(rng.choice(["", " ", ", ", " and "]).join([rng.choice(names)] * rng.choice([1, 1, 2, 4])))
        elif kind < 0.55:
            pieces.append(_digits(rng))
        elif kind < 0.65:
            pieces.append(_run(rng))
        elif kind < 0.7:
            pieces.append(rng.choice(NUMBER_RUNS) * rng.randint(2, 8))
        else:
            pieces.append(rng.choice(WORDS))
    return rng.choice(["", " ", "\n- "]).join(pieces) + rng.choice(["", ".", " !", "\u00a0"])


NUMBER_RUNS = ["9 ", "9,", "1.5 ", "(2) ", "9 and "]


def table_case(rng: random.Random, names: list[str]) -> str:
    """A table's worth of numbers in prose: 1 to 4 runs of 50 to 400 numbers among names and a direction word. Their
    time is reported per 1,000 characters (a clause reads its first 40 numbers: the work grows with the text)."""
    pieces = [rng.choice(NUMBER_RUNS) * rng.choice([50, 150, 400]) for _ in range(rng.randint(1, 4))]
    pieces.insert(rng.randrange(len(pieces) + 1), f"{rng.choice(names)} raised it by")
    return " ".join(pieces) + "."


def _best_ms(text: str, exp, limit_ms: float) -> tuple[float, float, str]:
    """(best time, first time, status) of up to three readings; a reading under half the limit is not repeated."""
    took = []
    for _attempt in range(3):
        t = time.perf_counter()
        result = verify(text, exp, 0)
        took.append((time.perf_counter() - t) * 1000)
        if took[-1] < limit_ms / 2:
            break
    return min(took), took[0], result.status


def tables(rng: random.Random, cases: int, limit_per_k: float) -> int:
    """The number-dense family: each case within ``limit_per_k`` ms per 1,000 characters (a case under 1,000
    characters: within ``limit_per_k`` ms); returns how many were not."""
    rows = []  # (ms, characters, budget)
    for _ in range(cases):
        exp = EXPLANATIONS[rng.randrange(len(EXPLANATIONS))]
        text = table_case(rng, list(exp.feature_names))
        budget = limit_per_k * max(1.0, len(text) / 1000)
        rows.append((_best_ms(text, exp, budget)[0], len(text), budget))
    worst = max(rows, key=lambda r: r[0] / r[2])
    per_k = [ms / n * 1000 for ms, n, _ in rows if n >= 1000]
    print(
        f"tables: {cases} cases of {min(r[1] for r in rows)} to {max(r[1] for r in rows)} characters; max "
        f"{max(r[0] for r in rows):.1f} ms; over 1,000 characters, per 1,000: median {statistics.median(per_k):.1f} ms, "
        f"max {max(per_k):.1f} ms; nearest its budget: {worst[0]:.1f} ms for {worst[1]} characters (budget "
        f"{worst[2]:.0f} ms: {limit_per_k:.0f} ms per 1,000 characters, at least {limit_per_k:.0f} ms)"
    )
    return sum(ms >= budget for ms, _, budget in rows)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=5000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--limit-ms", type=float, default=100.0)
    parser.add_argument("--tables", type=int, default=200, help="cases of the number-dense family")
    parser.add_argument("--table-limit-ms", type=float, default=100.0, help="per 1,000 characters")
    args = parser.parse_args(argv)
    rng = random.Random(args.seed)
    verify("Speed raised it by 0.4.", EXPLANATIONS[0], 0)  # warm: spaCy's model, the vocabularies' regexes
    for exp in EXPLANATIONS:
        verify(f"{exp.feature_names[0]} raised it.", exp, 0)
    firsts, times, worst = [], [], (0.0, "", "")
    statuses = {"verified": 0, "contradicted": 0, "unchecked": 0}
    start = time.perf_counter()
    for _ in range(args.cases):
        exp = EXPLANATIONS[rng.randrange(len(EXPLANATIONS))]
        text = case(rng, list(exp.feature_names))
        best, first, status = _best_ms(text, exp, args.limit_ms)
        firsts.append(first)
        times.append(best)
        statuses[status] += 1
        if best > worst[0]:
            worst = (best, text, ",".join(exp.feature_names[:4]))
    total = time.perf_counter() - start
    ms, text, names = worst
    shown = text if len(text) <= 160 else f"{text[:100]!r}...{text[-40:]!r} ({len(text)} chars)"
    print(f"{len(times)} cases in {total:.1f} s (seed {args.seed}); statuses {statuses}")
    print(
        f"per case: median {statistics.median(times):.2f} ms, p99 {np.percentile(times, 99):.1f} ms, "
        f"max {max(times):.1f} ms (first runs: max {max(firsts):.1f} ms); limit {args.limit_ms:.0f} ms"
    )
    print(f"worst case: {ms:.1f} ms over [{names}]: {shown if len(text) > 160 else repr(shown)}")
    over = sum(t >= args.limit_ms for t in times)
    if over:
        print(f"FAIL: {over} case(s) took {args.limit_ms:.0f} ms or more")
    dense = tables(rng, args.tables, args.table_limit_ms)
    if dense:
        print(f"FAIL: a number-dense case took {args.table_limit_ms:.0f} ms or more per 1,000 characters")
    return int(bool(over or dense))


if __name__ == "__main__":
    sys.exit(main())
