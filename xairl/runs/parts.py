"""The parts of a streamed run: each chunk's Parquet file, carrying its run, its rows and a checksum, and the check
of a folder's parts before a run resumes (a damaged part is explained again; a file that is no part of this run is
refused by name). The checksum inside a part covers its columns and metadata, not the Parquet footer's statistics,
which filtered readers trust to skip row groups; so each part's bytes are also hashed as written, recorded in
``run.json`` (key ``parts``), and a part is kept on resume only when its bytes still match."""

from __future__ import annotations

import hashlib
import json
import logging
import re
from pathlib import Path

import numpy as np

from xairl.errors import InputError, one_line
from xairl.explanations.explanation import Explanation

DATASET = "explanations.parquet"
RECORDED = "parts"  # run.json's key of the SHA-256 of each part's bytes, by name, as written
PART = re.compile(r"part-(\d{12})\.parquet")  # a part's name: its first row


def part_name(first: int) -> str:
    return f"part-{first:012d}.parquet"


def write_part(folder: Path, first: int, exp: Explanation, meta: dict) -> str:
    """One chunk as ``folder/part-<first>.parquet``, written whole or not at all; returns the SHA-256 of its bytes
    (for run.json)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from xairl.runs.files import atomic_write

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
    sink = pa.BufferOutputStream()  # a chunk's part is a few MB: hashed whole, as it goes to disk
    pq.write_table(table, sink, compression="zstd")
    data = sink.getvalue()
    with atomic_write(folder / part_name(first), "wb") as fh:
        fh.write(data)
    return hashlib.sha256(data).hexdigest()


def file_sha256(path: Path) -> str:
    """SHA-256 of a file's bytes, read 1 MiB at a time."""
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        while block := fh.read(1 << 20):
            digest.update(block)
    return digest.hexdigest()


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


def existing_parts(out: Path, identity: dict, resume: bool, run: str, total) -> dict[int, str]:
    """First row -> SHA-256 of the chunks an earlier run completed and that are whole, their bytes as recorded in
    run.json (empty for a new folder); refuses another run's folder, states that changed since the run began, and
    any file in the dataset that is not a part of this run, by name."""
    folder = out / DATASET
    try:
        files = sorted(p for p in folder.iterdir() if not p.name.startswith((".", "_"))) if folder.is_dir() else []
    except OSError as exc:
        raise InputError(f"cannot read {folder} ({exc.strerror}); give a folder you can read and write.") from None
    parts = [p for p in files if PART.fullmatch(p.name)]
    if not files and not (out / "run.json").exists():
        return {}
    if not resume and (parts or (out / "run.json").exists()):
        raise InputError(
            f"{out} already holds a run ({len(parts)} chunk(s) written); pass --resume to continue it, "
            "or give another folder."
        )
    earlier = _record(out / "run.json")
    recorded = (earlier or {}).pop(RECORDED, None)
    recorded = recorded if isinstance(recorded, dict) else {}  # (none recorded: every part is explained again)
    _same_run(out, earlier, identity)
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
    return _whole_parts(parts, recorded, chunk, n, run, folder)


def _same_run(out: Path, earlier: dict | None, identity: dict) -> None:
    """Refuses a run.json that records another run (or the same states file with other contents)."""
    if earlier is not None and earlier != json.loads(json.dumps(identity)):
        changed = sorted(k for k in identity if earlier.get(k) != json.loads(json.dumps(identity))[k])
        if changed == ["source_sha256"]:  # the same file, other contents: resuming would mix old rows and new
            what = "the states array" if identity["source"] == "array" else identity["source"]
            raise InputError(
                f"{what} changed since the run in {out} began (its contents differ from the SHA-256 "
                f"in run.json); rerun without --resume into another folder, or delete {out} and run again."
            )
        raise InputError(
            f"{out} holds another run (it differs in {', '.join(changed) or 'run.json'}); resume needs "
            "the same states, policy, background, method, options and chunk size (if they are the same, "
            "run.json was damaged: delete it and resume; every part is checked against this run)."
        )


def _whole_parts(parts: list[Path], recorded: dict, chunk: int, n: int, run: str, folder: Path) -> dict[int, str]:
    """First row -> SHA-256 of each part that is whole and whose bytes are those recorded in run.json; a damaged or
    unrecorded part is left to be explained again (said in a warning), a foreign one refused by name."""
    done, unrecorded = {}, 0
    for path in parts:
        first = int(path.name[5:17])
        verdict, why = check_part(path, first, min(chunk, n - first), run)
        if verdict == "foreign":
            raise _not_ours([path], why, folder)
        if verdict == "ok" and path.name not in recorded:  # written by a run cut off before it recorded the part
            unrecorded += 1
            continue
        digest = file_sha256(path) if verdict == "ok" else ""
        if verdict == "ok" and digest != recorded[path.name]:  # the footer's statistics, say: filters would skip rows
            verdict, why = "bad", "its bytes differ from the SHA-256 recorded in run.json when it was written"
        if verdict == "ok":
            done[first] = digest
        else:  # written over when its chunk is explained again
            logging.getLogger("xairl").warning(f"xairl: {path}: damaged ({why}); its rows are explained again.")
    if unrecorded:
        logging.getLogger("xairl").warning(
            f"xairl: {unrecorded} part(s) in {folder} have no SHA-256 in run.json (a run cut off as it wrote them, or "
            "run.json deleted): their rows are explained again."
        )
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
            f"{path}: not the record of a run ({what}); delete it and --resume again (the parts are then "
            "explained again), or give another folder."
        )
    return record


def _not_ours(paths: list[Path], why: str, folder: Path) -> InputError:
    more = f" ({len(paths) - 1} more file(s) there are not parts of this run either)" if len(paths) > 1 else ""
    return InputError(
        f"{paths[0]}: not a part of this run ({why}); delete it or move it out of {folder} and run again{more}."
    )
