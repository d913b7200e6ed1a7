"""Explaining more states than fit in memory: states read in chunks, explained chunk by chunk, each chunk written as
a Parquet file of its own as soon as it is done, and global figures from running sums and a uniform sample.

    for start, exp in xairl.explain_chunks(policy, "states.npy", background=bg, chunk_size=50_000): ...
    xairl.explain_to_parquet(policy, "states.npy", "out/", background=bg)      # resumable: resume=True
    exp = xairl.read_parquet("out/explanations.parquet")                      # back as one Explanation

The output folder holds ``explanations.parquet/`` (a Parquet dataset, one ``part-<first row>.parquet`` per chunk:
``pandas.read_parquet`` and ``pyarrow.dataset`` read the folder as one table), ``run.json`` (what ran: the source
and a SHA-256 of its contents, the chunk size, the method and its options, hashes of the policy and the background,
and the SHA-256 of each part's bytes as written; ``resume`` refuses another run, or states whose contents changed)
and ``summary.json`` (mean |contribution| per feature over all states). Each part is written to a hidden
``.part`` file and renamed when complete, so an interrupted run leaves only whole chunks, and ``resume`` explains
exactly the chunks that are missing.

A part (:mod:`xairl.runs.parts`) is trusted by its contents, not its name: its metadata holds the run it belongs to (a hash of ``run.json``'s
record), its first row, its number of rows, and a SHA-256 of its columns and metadata. ``resume`` reads every part
first: a damaged one (a flipped bit, its footer's statistics changed, cut short, rows other than its name says, or
bytes other than run.json recorded) is explained again; a whole part of
another run, or a file that is no part of this run (``part-...07``, a chunk past the end), is refused by name before
anything is explained, so the dataset holds every state exactly once.

Columns of a part: ``index`` (the state's row in the source), ``state`` (F float32), ``values`` (F x A float32,
feature-major: ``values.reshape(F, A)``), ``base_values``, ``outputs`` and ``additivity_gap`` (A float64 each), and
``chosen`` and ``runner_up`` (action indices, -1 when nothing is chosen). The schema's metadata (key ``xairl``)
holds the names, the method, its options and the policy's hash.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from xairl.errors import InputError, one_line
from xairl.explanations.explanation import Explanation
from xairl.policies.policy import Policy, model_hash
from xairl.runs.chunks import CHUNK, count_states, state_chunks
from xairl.runs.files import write_text
from xairl.runs.parts import DATASET, RECORDED, existing_parts, file_sha256, part_name, write_part

SAMPLE = 1_000  # states kept (uniformly, by reservoir sampling) for the figures of a streamed run


# ---- explaining ------------------------------------------------------------------------------------------------
def explain_chunks(
    policy: Policy,
    states,
    background=None,
    method: str = "deep_shap",
    options: dict | None = None,
    chunk_size: int = CHUNK,
    start: int = 0,
) -> Iterator[tuple[int, Explanation]]:
    """(first row, Explanation) for each chunk of ``states`` (an array or a file, see :func:`state_chunks`), in
    order; memory stays that of one chunk whatever the number of states."""
    from xairl.attributors import explain

    bg = policy.background() if background is None else policy.check_states(background, "background")
    for first, x in state_chunks(states, policy, chunk_size, start):
        yield first, explain(policy, x, background=bg, method=method, options=options)


def read_parquet(path: str | Path) -> Explanation:
    """A written dataset (the ``explanations.parquet`` folder or one part) as one Explanation, rows in index order
    (for runs that fit in memory; stream larger ones with pyarrow.dataset)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    path = Path(path)
    parts = sorted(path.glob("part-*.parquet")) if path.is_dir() else [path]
    if not parts:
        raise InputError(f"{path}: no explanation parts in it; write them with xairl.explain_to_parquet.")
    try:
        table = pa.concat_tables([pq.read_table(p) for p in parts])
        meta = json.loads(table.schema.metadata[b"xairl"])
    except (pa.ArrowException, OSError, KeyError, ValueError) as exc:
        raise InputError(f"{path}: not an xairl Parquet dataset ({' '.join(str(exc).split())[:120]}).") from None
    table = table.sort_by("index")
    twice = np.flatnonzero(np.diff(table.column("index").to_numpy()) == 0)
    if len(twice):  # pandas and pyarrow would read the folder with the row twice
        raise InputError(
            f"{path}: row {table.column('index')[int(twice[0])]} is in two parts: a copy or another run's "
            "part is there (xairl explain --resume names it)."
        )
    f, a = len(meta["feature_names"]), len(meta["action_names"])

    def rows(name: str, width: int) -> np.ndarray:
        return table.column(name).combine_chunks().flatten().to_numpy().reshape(-1, width).astype(np.float64)

    available = rows("available", a).astype(bool) if "available" in table.column_names else None
    return Explanation(
        values=rows("values", f * a).reshape(-1, f, a),
        base_values=rows("base_values", a),
        outputs=rows("outputs", a),
        states=rows("state", f),
        feature_names=tuple(meta["feature_names"]),
        action_names=tuple(meta["action_names"]),
        method=meta["method"],
        options=meta["options"],
        output=meta["output"],
        observation=meta.get("observation"),
        available=available,
        categories=meta.get("categories"),
    )


@dataclass
class RunningSummary:
    """Figures of a streamed run without a second pass: sums of |contribution| per feature (to the chosen score and
    to the margin over the runner-up), and a uniform sample of ``size`` states (reservoir sampling, seeded)."""

    size: int = SAMPLE
    seed: int = 0
    n: int = 0
    abs_chosen: np.ndarray | None = None
    abs_margin: np.ndarray | None = None
    sample: list = field(default_factory=list)  # (row, Explanation of one state)

    def add(self, first: int, exp: Explanation) -> None:
        chosen, margin = np.abs(exp.for_chosen()).sum(axis=0), np.abs(exp.margin()).sum(axis=0)
        self.abs_chosen = chosen if self.abs_chosen is None else self.abs_chosen + chosen
        self.abs_margin = margin if self.abs_margin is None else self.abs_margin + margin
        m = len(exp.values)
        # Algorithm R: state number t (1-based) replaces a random slot j < t when j < size; the draws are seeded per
        # chunk, so a resumed run keeps the same sample
        slots = np.random.default_rng([self.seed, first]).integers(0, np.arange(self.n + 1, self.n + m + 1))
        slots = np.where(np.arange(self.n, self.n + m) < self.size, np.arange(self.n, self.n + m), slots)
        for i in np.flatnonzero(slots < self.size):
            entry = (first + int(i), _rows(exp, int(i)))
            if slots[i] < len(self.sample):
                self.sample[slots[i]] = entry
            else:
                self.sample.append(entry)
        self.n += m

    def sample_explanation(self) -> Explanation | None:
        """The sampled states as one Explanation, in row order."""
        if not self.sample:
            return None
        parts = [e for _, e in sorted(self.sample, key=lambda p: p[0])]
        first = parts[0]
        return Explanation(
            **{
                **first.__dict__,
                **{
                    k: np.concatenate([getattr(p, k) for p in parts])
                    for k in ("values", "base_values", "outputs", "states")
                },
                "available": None if first.available is None else np.concatenate([p.available for p in parts]),
            }
        )

    def to_dict(self, feature_names) -> dict:
        mean = {"chosen_score": self.abs_chosen / max(self.n, 1), "margin": self.abs_margin / max(self.n, 1)}
        return {
            "states": self.n,
            "sampled_for_figures": len(self.sample),
            "mean_abs_contribution": {k: dict(zip(feature_names, v.tolist())) for k, v in mean.items()},
        }


def _rows(exp: Explanation, i: int) -> Explanation:
    """State ``i`` alone, copied: a view would keep its whole chunk in memory as long as the sample holds it."""
    s = slice(i, i + 1)
    return Explanation(
        **{
            **exp.__dict__,
            "values": exp.values[s].copy(),
            "base_values": exp.base_values[s].copy(),
            "outputs": exp.outputs[s].copy(),
            "states": exp.states[s].copy(),
            "available": None if exp.available is None else exp.available[s].copy(),
        }
    )


#: options that say how a run is shown or bounded, not what it computes: a resumed run may change them
NOT_IDENTITY = frozenset({"progress", "max_evaluations", "max_rows"})


def run_identity(
    policy: Policy, source, background: np.ndarray, method: str, options: dict, chunk_size: int
) -> dict[str, Any]:
    """What makes two runs the same run (``resume`` continues only that). A file of states is known by its contents:
    a file rewritten with the same size and time is another run's states."""
    if isinstance(source, (str, Path)):
        where = {"source": str(Path(source).resolve()), "source_sha256": file_sha256(Path(source))}
    else:
        where = {"source": "array", "source_sha256": hashlib.sha256(np.ascontiguousarray(source).tobytes()).hexdigest()}
    return {
        **where,
        "chunk_size": chunk_size,
        "method": method,
        "options": {k: v for k, v in options.items() if k not in NOT_IDENTITY},
        "policy": policy.name,
        "policy_hash": model_hash(policy.module),
        "background_sha256": hashlib.sha256(np.ascontiguousarray(background).tobytes()).hexdigest(),
    }


def explain_to_parquet(
    policy: Policy,
    states,
    out: str | Path,
    background=None,
    method: str = "deep_shap",
    options: dict | None = None,
    chunk_size: int = CHUNK,
    resume: bool = False,
    progress: bool | None = None,
) -> RunningSummary:
    """Explain ``states`` chunk by chunk into ``out`` (layout in the module doc), with a progress bar on a terminal
    (``progress=None``: only when stderr is one). ``resume=True`` continues an interrupted run of the same
    states, policy, background, method, options and chunk size; without it, a folder that already holds a run is
    refused (nothing is overwritten)."""
    from xairl.attributors import explain
    from xairl.explanations.display import (
        progress as progress_bar,  # (progress: the parameter saying whether to show it)
    )

    run = start_run(policy, states, out, background, method, options, chunk_size, resume)
    summary = RunningSummary()
    bar = progress_bar(
        total=count_states(states, policy),
        unit="states",
        desc=f"explaining ({method})",
        disable=False if progress else None if progress is None else True,
        smoothing=0.1,
    )
    with bar:
        for first, x in state_chunks(states, policy, chunk_size):
            if first not in run.done:  # (a whole chunk from an interrupted run is not explained again)
                exp = explain(policy, x, background=run.background, method=method, options=run.options)
                run.record(first, write_part(run.parts, first, exp, run.meta))
            summary.add(first, read_parquet(run.parts / part_name(first)))  # as written: resumed runs sum the same
            bar.update(len(x))
    return finish_run(run, summary, states)


@dataclass
class Run:
    """A run's folder, once checked: its validated options, background, identity, the parts' metadata, and the
    first rows of the chunks an interrupted run already wrote whole (a damaged part's chunk is not among them), with
    the SHA-256 of their bytes."""

    out: Path
    options: dict
    background: np.ndarray
    identity: dict
    meta: dict
    done: dict[int, str]

    @property
    def parts(self) -> Path:
        return self.out / DATASET

    def record(self, first: int, sha256: str) -> None:
        """Notes in run.json the SHA-256 of a part just written whole: resume keeps a part only when its bytes match."""
        self.done[first] = sha256
        self.save()

    def save(self) -> None:
        """run.json: the run's identity and the SHA-256 of each part written whole, by name."""
        recorded = {part_name(f): self.done[f] for f in sorted(self.done)}
        write_text(self.out / "run.json", json.dumps({**self.identity, RECORDED: recorded}, indent=2))


def start_run(
    policy: Policy,
    states,
    out: str | Path,
    background,
    method: str,
    options: dict | None,
    chunk_size: int,
    resume: bool,
) -> Run:
    """Checks the folder (a new run, or the same run with ``resume``, every part it holds verified) and records the
    run in ``run.json``; shared by the local and the Ray engine."""
    from xairl.registry.plugins import get_attributor
    from xairl.runs.chunks import count_rows

    out = Path(out)
    attributor = get_attributor(method)(options)
    options = attributor.options.model_dump()
    bg = policy.background() if background is None else policy.check_states(background, "background")
    # the largest chunk's cost, before anything is written: a refused run leaves no folder to resume
    attributor.check_cost(policy, min(chunk_size, count_rows(states, policy)), len(bg))
    identity = run_identity(policy, states, bg, method, options, chunk_size)
    meta = part_meta(policy, method, options, identity)
    done = existing_parts(out, identity, resume, meta["run"], lambda: count_rows(states, policy))
    run = Run(out, options, bg, identity, meta, done)
    try:
        (out / DATASET).mkdir(parents=True, exist_ok=True)
        run.save()
    except OSError as exc:
        raise InputError(
            f"cannot write the run into {out} ({exc.strerror or one_line(exc)}); give a folder you can write to."
        ) from None
    return run


def finish_run(run: Run, summary: RunningSummary, states) -> RunningSummary:
    """Writes ``summary.json``; a run without a single state is an error."""
    if not summary.n:
        raise InputError(f"{states if isinstance(states, (str, Path)) else 'the states'} holds no state to explain.")
    write_text(run.out / "summary.json", json.dumps(summary.to_dict(run.meta["feature_names"]), indent=2))
    return summary


def part_meta(policy: Policy, method: str, options: dict, identity: dict) -> dict:
    """The metadata every part carries (key ``xairl`` of its Parquet schema; each part adds its first row, its
    number of rows and its checksum)."""
    return {
        "feature_names": list(policy.feature_names),
        "action_names": list(policy.action_names),
        "method": method,
        "options": options,
        "output": policy.output,
        "policy": policy.name,
        "policy_hash": identity["policy_hash"],
        "observation": policy.observation.to_dict(),
        "categories": {f: list(i.categories) for f, i in policy.features.items() if i.categories} or None,
        "run": hashlib.sha256(json.dumps(identity, sort_keys=True).encode()).hexdigest()[:16],
    }
