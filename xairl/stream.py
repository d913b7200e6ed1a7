"""Explaining more states than fit in memory: states read in chunks, explained chunk by chunk, each chunk written as
a Parquet file of its own as soon as it is done, and global figures from running sums and a uniform sample.

    for start, exp in xairl.explain_chunks(policy, "states.npy", background=bg, chunk_size=50_000): ...
    xairl.explain_to_parquet(policy, "states.npy", "out/", background=bg)      # resumable: resume=True
    exp = xairl.read_parquet("out/explanations.parquet")                      # back as one Explanation

The output folder holds ``explanations.parquet/`` (a Parquet dataset, one ``part-<first row>.parquet`` per chunk:
``pandas.read_parquet`` and ``pyarrow.dataset`` read the folder as one table), ``run.json`` (what ran: the source,
the chunk size, the method and its options, hashes of the policy and the background; ``resume`` refuses another
run) and ``summary.json`` (mean |contribution| per feature over all states). Each part is written to a hidden
``.part`` file and renamed when complete, so an interrupted run leaves only whole chunks, and ``resume`` explains
exactly the chunks that are missing.

A part is trusted by its contents, not its name: its metadata holds the run it belongs to (a hash of ``run.json``'s
record), its first row, its number of rows, and a SHA-256 of its columns and metadata. ``resume`` reads every part
first: a damaged one (a flipped bit, cut short, rows other than its name says) is explained again; a whole part of
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
import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .chunks import CHUNK, count_states, state_chunks
from .errors import InputError, one_line
from .explanation import Explanation
from .files import write_text
from .policy import Policy, model_hash

SAMPLE = 1_000  # states kept (uniformly, by reservoir sampling) for the figures of a streamed run
DATASET = "explanations.parquet"
PART = re.compile(r"part-(\d{12})\.parquet")  # a part's name: its first row


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
    from .attributors import explain

    bg = policy.background() if background is None else policy.check_states(background, "background")
    for first, x in state_chunks(states, policy, chunk_size, start):
        yield first, explain(policy, x, background=bg, method=method, options=options)


# ---- writing ---------------------------------------------------------------------------------------------------
def _part_name(first: int) -> str:
    return f"part-{first:012d}.parquet"


def write_part(folder: Path, first: int, exp: Explanation, meta: dict) -> Path:
    """One chunk as ``folder/part-<first>.parquet``, written whole or not at all."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from .files import atomic_write

    n, f, a = exp.values.shape

    def fixed(arr: np.ndarray, width: int, kind) -> pa.Array:
        return pa.FixedSizeListArray.from_arrays(pa.array(np.ascontiguousarray(arr).reshape(-1), kind), width)

    decides = exp.output == "actions"
    columns = {
        "index": pa.array(np.arange(first, first + n, dtype=np.int64)),
        "state": fixed(exp.states.astype(np.float32), f, pa.float32()),
        "values": fixed(exp.values.astype(np.float32), f * a, pa.float32()),
        "base_values": fixed(exp.base_values, a, pa.float64()),
        "outputs": fixed(exp.outputs, a, pa.float64()),
        "additivity_gap": fixed(exp.additivity_gap, a, pa.float64()),
        "chosen": pa.array(exp.chosen if decides else np.full(n, -1), pa.int32()),
        "runner_up": pa.array(exp.runner_up if decides else np.full(n, -1), pa.int32()),
    }
    if exp.available is not None:  # the action mask: chosen and runner-up are taken among available actions
        columns["available"] = fixed(exp.available, a, pa.bool_())
    meta = {**meta, "first": first, "rows": n}
    table = pa.table(columns)
    meta["sha256"] = _checksum(table, meta)
    table = table.replace_schema_metadata({"xairl": json.dumps(meta)})
    path = folder / _part_name(first)
    with atomic_write(path, "wb") as fh:
        pq.write_table(table, fh, compression="zstd")
    return path


def _checksum(table, meta: dict) -> str:
    """SHA-256 of a part's columns (names, types, values) and of its metadata other than this checksum."""
    import pyarrow as pa

    digest = hashlib.sha256(json.dumps({k: v for k, v in meta.items() if k != "sha256"}, sort_keys=True).encode())
    for name in table.column_names:
        column = table.column(name).combine_chunks()
        while pa.types.is_fixed_size_list(column.type):
            column = column.flatten()
        digest.update(f"\0{name}:{column.type}\0".encode())
        digest.update(column.to_numpy(zero_copy_only=False).tobytes())
    return digest.hexdigest()


def check_part(path: Path, first: int, rows: int, run: str) -> tuple[str, str]:
    """("ok", ""), ("bad", why) for a damaged part (explain its chunk again) or ("foreign", why) for a whole part of
    another run: is ``path`` rows ``first..first + rows - 1`` of run ``run``, as written?"""
    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        table = pq.read_table(path)
        meta = json.loads(table.schema.metadata[b"xairl"])
        whole = meta.pop("sha256") == _checksum(table, meta)
    except (
        pa.ArrowException,
        OSError,
        KeyError,
        ValueError,
        TypeError,
        AttributeError,
        RecursionError,
        MemoryError,
    ) as exc:
        return "bad", f"unreadable: {one_line(exc, 80)}"
    if not whole:
        return "bad", "its checksum does not match its contents"
    if meta.get("run") != run:
        return "foreign", "a part written by another run (other states, policy, background, method or chunk size)"
    index = table.column("index").to_numpy()
    if meta.get("first") != first or not np.array_equal(index, np.arange(first, first + rows)):
        return "bad", f"it holds {len(index)} row(s) from {meta.get('first')}, not rows {first}..{first + rows - 1}"
    return "ok", ""


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


def run_identity(
    policy: Policy, source, background: np.ndarray, method: str, options: dict, chunk_size: int
) -> dict[str, Any]:
    """What makes two runs the same run (``resume`` continues only that)."""
    if isinstance(source, (str, Path)):
        stat = Path(source).stat()
        where = {"source": str(Path(source).resolve()), "source_bytes": stat.st_size, "source_mtime": stat.st_mtime}
    else:
        where = {"source": "array", "source_sha256": hashlib.sha256(np.ascontiguousarray(source).tobytes()).hexdigest()}
    return {
        **where,
        "chunk_size": chunk_size,
        "method": method,
        "options": options,
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
    from .attributors import explain
    from .display import progress

    run = start_run(policy, states, out, background, method, options, chunk_size, resume)
    summary = RunningSummary()
    bar = progress(
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
                write_part(run.parts, first, exp, run.meta)
            summary.add(first, read_parquet(run.parts / _part_name(first)))  # as written: resumed runs sum the same
            bar.update(len(x))
    return finish_run(run, summary, states)


@dataclass
class Run:
    """A run's folder, once checked: its validated options, background, identity, the parts' metadata, and the
    first rows of the chunks an interrupted run already wrote whole (a damaged part's chunk is not among them)."""

    out: Path
    options: dict
    background: np.ndarray
    identity: dict
    meta: dict
    done: set[int]

    @property
    def parts(self) -> Path:
        return self.out / DATASET


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
    from .chunks import count_rows
    from .plugins import get_attributor

    out = Path(out)
    options = get_attributor(method)(options).options.model_dump()
    bg = policy.background() if background is None else policy.check_states(background, "background")
    identity = run_identity(policy, states, bg, method, options, chunk_size)
    meta = part_meta(policy, method, options, identity)
    done = _existing_run(out, identity, resume, meta["run"], lambda: count_rows(states, policy))
    try:
        (out / DATASET).mkdir(parents=True, exist_ok=True)
        write_text(out / "run.json", json.dumps(identity, indent=2))
    except OSError as exc:
        raise InputError(
            f"cannot write the run into {out} ({exc.strerror or one_line(exc)}); give a folder you can write to."
        ) from None
    return Run(out, options, bg, identity, meta, done)


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


def _existing_run(out: Path, identity: dict, resume: bool, run: str, total) -> set[int]:
    """First rows of the chunks an earlier run completed and that are whole (empty for a new folder); refuses
    another run's folder, and any file in the dataset that is not a part of this run, by name."""
    import logging

    folder = out / DATASET
    try:
        files = sorted(p for p in folder.iterdir() if not p.name.startswith((".", "_"))) if folder.is_dir() else []
    except OSError as exc:
        raise InputError(f"cannot read {folder} ({exc.strerror}); give a folder you can read and write.") from None
    parts = [p for p in files if PART.fullmatch(p.name)]
    if not files and not (out / "run.json").exists():
        return set()
    if not resume and (parts or (out / "run.json").exists()):
        raise InputError(
            f"{out} already holds a run ({len(parts)} chunk(s) written); pass --resume to continue it, "
            "or give another folder."
        )
    earlier = _record(out / "run.json")
    if earlier is not None and earlier != json.loads(json.dumps(identity)):
        changed = sorted(k for k in identity if earlier.get(k) != json.loads(json.dumps(identity))[k])
        raise InputError(
            f"{out} holds another run (it differs in {', '.join(changed) or 'run.json'}); resume needs "
            "the same states, policy, background, method, options and chunk size (if they are the same, "
            "run.json was damaged: delete it and resume; every part is checked against this run)."
        )
    n, chunk = (total() if files else 0), identity["chunk_size"]
    strays = [
        p
        for p in files
        if not PART.fullmatch(p.name) or int(p.name[5:17]) % chunk or int(p.name[5:17]) >= n or not p.is_file()
    ]
    if strays:
        raise _not_ours(
            strays,
            f"no chunk of this run is named so: its chunks are part-<first row>.parquet, the "
            f"first rows multiples of {chunk} below {n}",
            folder,
        )
    done = set()
    for path in parts:
        first = int(path.name[5:17])
        verdict, why = check_part(path, first, min(chunk, n - first), run)
        if verdict == "foreign":
            raise _not_ours([path], why, folder)
        if verdict == "ok":
            done.add(first)
        else:  # written over when its chunk is explained again
            logging.getLogger("xairl").warning(f"xairl: {path}: damaged ({why}); its rows are explained again.")
    return done


def _record(path: Path) -> dict | None:
    """The run recorded in ``run.json`` (None without one); one line when it is not a record xairl wrote."""
    if not path.exists():
        return None
    try:
        record = json.loads(path.read_text())
        what = "a JSON " + {str: "string", int: "number", float: "number", bool: "boolean"}.get(type(record), "list")
        what = "JSON null" if record is None else what
    except OSError as exc:
        record, what = None, exc.strerror or one_line(exc, 80)
    except RecursionError:
        record, what = None, "JSON nested too deeply"
    except ValueError:
        record, what = None, "not JSON"
    if not isinstance(record, dict):
        raise InputError(
            f"{path}: not the record of a run ({what}); delete it and --resume again (each part is "
            "checked against this run), or give another folder."
        )
    return record


def _not_ours(paths: list[Path], why: str, folder: Path) -> InputError:
    more = f" ({len(paths) - 1} more file(s) there are not parts of this run either)" if len(paths) > 1 else ""
    return InputError(
        f"{paths[0]}: not a part of this run ({why}); delete it or move it out of {folder} and run again{more}."
    )
