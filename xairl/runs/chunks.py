"""States read chunk by chunk, however many there are: a .npy file in slices, Parquet by row group, CSV by block
(through pyarrow), arrays and .npz/.json files whole, then sliced. Chunks start at multiples of the chunk size, so a
chunk is the same rows whoever reads it: the streaming engine, a resumed run or a Ray worker that reads only its own.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np

from xairl.errors import InputError
from xairl.policies.policy import Policy
from xairl.runs.files import atomic_write
from xairl.runs.inputs import check_columns, npy_header, read_states

CHUNK = 50_000  # states per chunk: a few MB of results, and bounded memory whatever the attributor


def count_states(source, policy: Policy) -> int | None:
    """Rows in a states source (an array, .npy, .parquet; None for a CSV, which is counted as it is read)."""
    if not isinstance(source, (str, Path)):
        return len(policy.check_states(source)) if not hasattr(source, "shape") else int(source.shape[0])
    path = Path(source)
    if path.suffix.lower() == ".npy":
        return len(_NpyRows(path))
    if path.suffix.lower() == ".parquet":
        return int(_parquet_file(path, policy).metadata.num_rows)
    if path.suffix.lower() == ".csv":
        return None
    return len(read_states(path, policy.feature_names, policy.observation))


def count_rows(source, policy: Policy) -> int:
    """Rows in a states source, a CSV file's counted by reading it through (block by block)."""
    if isinstance(source, (str, Path)) and not Path(source).is_file():
        raise InputError(f"{source}: no such file; give a .npy, .parquet, .csv, .npz or .json file of states.")
    n = count_states(source, policy)
    if n is None:
        _, batches = _table_batches(Path(source), policy, CHUNK, 0)
        n = sum(len(b) for b in batches)
    return n


def state_chunks(source, policy: Policy, chunk_size: int = CHUNK, start: int = 0) -> Iterator[tuple[int, np.ndarray]]:
    """(first row, checked float32 states) for each chunk of ``chunk_size`` rows from row ``start`` on.

    :param source: an array (any form the policy's observation takes), or a file: .npy (read by slice; a Fortran-
        order file through a memory map), .parquet (by record batch from the row group that holds ``start``; one
        column per feature, named as the features), .csv (by block; a header naming the features), or .npz/.json
        (read whole, then chunked).
    """
    if chunk_size < 1 or start < 0:
        raise InputError(f"chunk size must be at least 1 and the first row at least 0, got {chunk_size} and {start}.")
    path = Path(source) if isinstance(source, (str, Path)) else None
    suffix = path.suffix.lower() if path else ""
    if path is not None and not path.is_file():
        raise InputError(f"{path}: no such file; give a .npy, .parquet, .csv, .npz or .json file of states.")
    if suffix in (".parquet", ".csv"):
        first, batches = _table_batches(path, policy, chunk_size, start - start % chunk_size)
        yield from _rechunk(batches, policy, chunk_size, start, str(path), first)
        return
    rows = (
        _NpyRows(path)
        if suffix == ".npy"
        else read_states(path, policy.feature_names, policy.observation)
        if path is not None
        else policy.check_states(source)
    )
    n = len(rows)
    for a in range(start - start % chunk_size, n, chunk_size):
        what = f"{path or 'states'}: rows {a}..{min(a + chunk_size, n) - 1}"
        yield a, policy.check_states(np.asarray(rows[a : a + chunk_size]), what)


class _NpyRows:
    """The rows of a .npy file, read slice by slice with plain file reads: the system's page cache holds the file,
    not this process (a memory map would count every page read towards its resident memory, 320 MB at 10^7 states
    of 8 floats)."""

    def __init__(self, path: Path):
        try:
            with path.open("rb") as fh:
                self.shape, fortran, self.dtype = npy_header(fh)
                self.offset = fh.tell()
        except (ValueError, OSError, EOFError) as exc:
            raise InputError(f"{path}: cannot read it as .npy ({' '.join(str(exc).split())[:120]}).") from None
        if self.dtype.hasobject or not self.shape:
            raise InputError(
                f"{path}: holds {'Python objects' if self.dtype.hasobject else 'a single number'}, not rows of states."
            )
        self.path, self.fortran = path, fortran
        self.row = int(np.prod(self.shape[1:], dtype=np.int64))
        if path.stat().st_size - self.offset < len(self) * self.row * self.dtype.itemsize:
            raise InputError(f"{path}: shorter than its header says (shape {self.shape}); it is truncated.")

    def __len__(self) -> int:
        return int(self.shape[0])

    def __getitem__(self, rows: slice) -> np.ndarray:
        a, b, _ = rows.indices(len(self))
        if self.fortran:  # column-major: rows are not contiguous; the memory map reads them
            return np.array(np.load(self.path, mmap_mode="r", allow_pickle=False)[a:b])
        with self.path.open("rb") as fh:
            fh.seek(self.offset + a * self.row * self.dtype.itemsize)
            return np.fromfile(fh, self.dtype, count=max(b - a, 0) * self.row).reshape(max(b - a, 0), *self.shape[1:])


def _unreadable(path: Path, exc: Exception) -> InputError:
    return InputError(f"{path}: cannot read it ({' '.join(str(exc).split())[:160]}).")


def _parquet_file(path: Path, policy: Policy):
    """The opened Parquet file, checked to hold one column per feature; one-line InputError otherwise."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        pf = pq.ParquetFile(path)
    except (pa.ArrowException, OSError) as exc:
        raise _unreadable(path, exc) from None
    try:
        check_columns(pf.schema_arrow, policy.feature_names)
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None
    return pf


def _table_batches(path: Path, policy: Policy, chunk_size: int, start: int) -> tuple[int, Iterator[np.ndarray]]:
    """Record batches of a Parquet or CSV file as float64 arrays, the features' columns in the policy's order, and
    the row the first batch starts at: a Parquet file is read from the row group that holds row ``start``."""
    import pyarrow as pa

    names = list(policy.feature_names)
    if path.suffix.lower() == ".parquet":
        pf = _parquet_file(path, policy)
        first, skip, groups = 0, 0, pf.metadata.num_row_groups
        while skip < groups and first + pf.metadata.row_group(skip).num_rows <= start:
            first, skip = first + pf.metadata.row_group(skip).num_rows, skip + 1
        batches = pf.iter_batches(batch_size=chunk_size, row_groups=range(skip, groups), columns=names)
    else:
        from pyarrow import csv

        try:
            first, batches = (
                0,
                iter(
                    csv.open_csv(
                        path,
                        convert_options=csv.ConvertOptions(
                            include_columns=names, column_types={f: pa.float64() for f in names}
                        ),
                    )
                ),
            )
        except (pa.ArrowException, OSError) as exc:
            raise _unreadable(path, exc) from None

    def arrays() -> Iterator[np.ndarray]:
        try:
            for batch in batches:
                yield (
                    np.column_stack([batch.column(f).to_numpy(zero_copy_only=False) for f in names])
                    if batch.num_rows
                    else np.empty((0, len(names)))
                )
        except (pa.ArrowException, OSError) as exc:
            raise _unreadable(path, exc) from None

    return first, arrays()


def _rechunk(
    batches: Iterator[np.ndarray], policy: Policy, chunk_size: int, start: int, what: str, first: int = 0
) -> Iterator[tuple[int, np.ndarray]]:
    """Batches of any size, the first starting at row ``first`` -> chunks of ``chunk_size`` rows (the last may be
    shorter) starting at multiples of ``chunk_size``, from the chunk that holds row ``start`` on."""
    target, buffered, held = start - start % chunk_size, [], 0
    for batch in batches:
        if first < target:  # rows before the first chunk wanted
            cut = min(target - first, len(batch))
            batch, first = batch[cut:], first + cut
        if not len(batch):
            continue
        buffered.append(batch)
        held += len(batch)
        while held >= chunk_size:
            rows = np.concatenate(buffered)
            yield first, policy.check_states(rows[:chunk_size], f"{what}: rows {first}..{first + chunk_size - 1}")
            buffered, held, first = [rows[chunk_size:]], held - chunk_size, first + chunk_size
    if held:
        rows = np.concatenate(buffered)
        yield first, policy.check_states(rows, f"{what}: rows {first}..{first + len(rows) - 1}")


def stage_parquet(source, policy: Policy, path: Path, chunk_size: int = CHUNK) -> int:
    """``source`` (any states :func:`state_chunks` reads) rewritten as a Parquet file of one row group per chunk, so
    that a reader of one chunk (a Ray worker) reads only its own rows; written whole or not at all. Returns its rows.
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    names, n, writer = list(policy.feature_names), 0, None
    with atomic_write(path, "wb") as fh:
        try:
            for _, x in state_chunks(source, policy, chunk_size):
                table = pa.table({f: x[:, j] for j, f in enumerate(names)})
                writer = writer or pq.ParquetWriter(fh, table.schema, compression="zstd")
                writer.write_table(table, row_group_size=chunk_size)
                n += len(x)
        finally:
            if writer is not None:
                writer.close()
        if not n:
            raise InputError(f"{source}: holds no state to explain.")
    return n
