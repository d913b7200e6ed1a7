"""The Ray engine (``pip install 'xairl[scale]'``): the streaming pipeline of :mod:`xairl.runs.stream`, its chunks spread
over Ray workers. Only this module imports Ray; the local engine never does.

Ray Data maps the chunks' first rows through an actor pool (``map_batches``): each actor holds the policy, the
background and the attributor, reads only its chunk's rows from the states, explains them and writes its Parquet
part, whole or not at all. The states are read where they are when each chunk can be read alone: a .npy file (by
slice) or a Parquet file (by row group) on a file system the workers share, or an array put in Ray's object store.
A CSV, .npz or .json file is first rewritten by the driver as a Parquet file of one row group per chunk, in the
output folder (which the workers write to, so they share it), and removed at the end. The chunks are those of the
local engine, so the parts are the same bits, ``run.json`` and ``resume`` work alike, and the summary is computed by
the driver from the written parts, in order.

:func:`narrate_on_ray` narrates many states of an Explanation on a pool of Ray actors, each holding one narrator
(a local language model is loaded once per actor), the narratives returned in order.

``ray.init()`` starts Ray on this machine with ``workers`` CPUs (loopback only); ``address`` joins a running cluster
(``ray://host:10001`` or ``auto``).
"""

from __future__ import annotations

import contextlib
from pathlib import Path

import numpy as np

from xairl.errors import InputError, XairlError
from xairl.policies.policy import Policy
from xairl.runs.chunks import CHUNK, count_states, stage_parquet, state_chunks
from xairl.runs.parts import part_name, write_part
from xairl.runs.stream import RunningSummary, finish_run, read_parquet, start_run

STAGED = ".states.parquet"  # a CSV, .npz or .json file's states, rewritten for the workers (then removed)


def _ray():
    try:
        import ray
    except ImportError:
        raise InputError("the Ray engine needs Ray: pip install 'xairl[scale]'.") from None
    return ray


def _start(ray, address: str | None, workers: int) -> bool:
    """Starts Ray unless it runs (this machine with ``workers`` CPUs on loopback, or the cluster at ``address``);
    True when started here (and so to be shut down here)."""
    if ray.is_initialized():
        return False
    ray.init(
        address=address,
        num_cpus=None if address else workers,
        include_dashboard=False,
        log_to_driver=False,
        logging_level="ERROR",
        configure_logging=False,
        **({} if address else {"_node_ip_address": "127.0.0.1"}),
    )
    return True


def _usable(ray, workers: int) -> int:
    """``workers`` actors of one CPU each, refused in one line when the Ray cluster cannot hold one of them (they
    would wait for ever); as many as its CPUs allow otherwise."""
    cpus = int(ray.cluster_resources().get("CPU", 0))
    if workers < 1 or cpus < 1:
        raise InputError(
            f"the Ray engine needs at least one worker and one CPU: asked for {workers} worker(s), the "
            f"cluster has {cpus} CPU(s)."
        )
    return min(workers, cpus)


@contextlib.contextmanager
def _unwrapped(ray):
    """A user's error raised in a worker (a bad template) comes out as itself, in one line, not as Ray's traceback of
    the worker. (Ray Data's own notices, its plan and timings, still reach the terminal: Ray sets up its loggers
    when a dataset runs.)"""
    try:
        yield
    except Exception as exc:  # Ray's task errors (a RayError that may also subclass the user's error) or Ray Data's
        cause = exc
        while cause is not None and (isinstance(cause, ray.exceptions.RayError) or not isinstance(cause, XairlError)):
            cause = getattr(cause, "cause", None) or cause.__cause__
        if cause is None:
            raise
        raise cause.with_traceback(None) from None


class _ChunkWorker:
    """A Ray actor: explains the chunks whose first rows it is given, each into its own part."""

    def __init__(
        self,
        policy: Policy,
        states,
        background: np.ndarray,
        method: str,
        options: dict,
        chunk_size: int,
        parts: str,
        meta: dict,
        threads: int,
    ):
        import ray
        import torch

        torch.set_num_threads(threads)  # one worker per core: no oversubscription
        if isinstance(states, ray.ObjectRef):  # an array in the object store, shared by the workers of a node
            states = ray.get(states)
        self.policy, self.states, self.bg = policy, states, background
        self.method, self.options, self.chunk_size = method, options, chunk_size
        self.parts, self.meta = Path(parts), meta

    def __call__(self, batch: dict) -> dict:
        """Each chunk explained and written, with the SHA-256 of its part's bytes for the driver to record in
        run.json; a user's error (NaN in the states, ...) is returned as its message, for the driver to report in one
        line (Ray Data would only pass on its traceback)."""
        from xairl.attributors import explain

        states = self.states if isinstance(self.states, str) else np.asarray(self.states)
        errors, digests = [], []
        for first in batch["first"].tolist():
            try:
                _, x = next(state_chunks(states, self.policy, self.chunk_size, start=first))
                exp = explain(self.policy, x, background=self.bg, method=self.method, options=self.options)
            except XairlError as exc:
                errors.append(str(exc))
                digests.append("")
                continue
            digests.append(write_part(self.parts, first, exp, self.meta))
            errors.append("")
        return {
            "first": batch["first"],
            "error": np.array(errors, dtype=object),
            "sha256": np.array(digests, dtype=object),
        }


def explain_on_ray(
    policy: Policy,
    states,
    out: str | Path,
    background=None,
    method: str = "deep_shap",
    options: dict | None = None,
    chunk_size: int = CHUNK,
    resume: bool = False,
    workers: int = 2,
    address: str | None = None,
    progress: bool | None = None,
) -> RunningSummary:
    """:func:`xairl.explain_to_parquet` on Ray: the same folder, the same parts (bit for bit), ``workers`` actors.

    :param states: a .npy or .parquet file (each worker reads its chunks: on a cluster, a path every node can read),
        a .csv, .npz or .json file (rewritten first as Parquet in ``out``), or an array.
    :param address: a running Ray cluster; None starts Ray on this machine with ``workers`` CPUs.
    """
    ray = _ray()
    from xairl.explanations.display import progress as bar

    source = str(Path(states).resolve()) if isinstance(states, (str, Path)) else policy.check_states(states)
    run = start_run(policy, states, out, background, method, options, chunk_size, resume)
    staged = isinstance(source, str) and Path(source).suffix.lower() not in (".npy", ".parquet")
    started = False
    try:
        if staged:  # no reading of one chunk alone: rewritten once, one row group per chunk
            source = str((run.out / STAGED).resolve())
            total = stage_parquet(states, policy, Path(source), chunk_size)
        else:
            total = count_states(states, policy)
        todo = [first for first in range(0, total, chunk_size) if first not in run.done]
        started = _start(ray, address, workers)
        ref = ray.put(source) if not isinstance(source, str) else source
        failed = _explain_chunks(ray, run, policy, ref, method, chunk_size, todo, workers) if todo else []
        if failed:  # the chunks written so far stay: fix the states and --resume
            raise InputError(failed[0])
    finally:
        if started:
            ray.shutdown()
        if staged:
            Path(source).unlink(missing_ok=True)
    summary = RunningSummary()
    for first in bar(range(0, total, chunk_size), desc="summing", unit="chunk", disable=not progress):
        summary.add(first, read_parquet(run.parts / part_name(first)))
    return finish_run(run, summary, states)


def _explain_chunks(ray, run, policy: Policy, states, method: str, chunk_size: int, todo, workers: int) -> list[str]:
    """The chunks starting at ``todo`` explained by a pool of actors, each part recorded in run.json as it arrives
    (an interrupted run resumes from every part it wrote); the workers' errors, in order."""
    with _unwrapped(ray):
        ray.data.DataContext.get_current().enable_progress_bars = False
        chunks = ray.data.from_items([{"first": f} for f in todo], override_num_blocks=len(todo)).map_batches(
            _ChunkWorker,
            batch_size=1,
            num_cpus=1,
            compute=ray.data.ActorPoolStrategy(size=_usable(ray, workers)),
            fn_constructor_kwargs={
                "policy": policy,
                "states": states,
                "background": run.background,
                "method": method,
                "options": run.options,
                "chunk_size": chunk_size,
                "parts": str(run.parts),
                "meta": run.meta,
                "threads": 1,
            },
        )
        failed = []
        for row in chunks.iter_rows():  # streamed
            if row["error"]:
                failed.append(row["error"])
            else:
                run.done[int(row["first"])] = row["sha256"]
                run.save()
    return failed


class _NarrationWorker:
    """A Ray actor: one narrator (a local language model is loaded once per actor) narrating states of one
    Explanation."""

    def __init__(self, explanation, narrator: str, kwargs: dict, threads: int):
        import torch

        torch.set_num_threads(threads)
        self.exp, self.narrator, self.kwargs = explanation, narrator, kwargs  # (Ray hands over the object itself)

    def narrate(self, index: int):
        from xairl.narrators import narrate

        return narrate(self.exp, index, narrator=self.narrator, **self.kwargs)


def narrate_on_ray(
    explanation,
    indices=None,
    narrator: str = "local_lm",
    workers: int = 2,
    address: str | None = None,
    threads: int = 1,
    **kwargs,
) -> list:
    """:func:`xairl.narrate` for many states of ``explanation`` on ``workers`` Ray actors (each loads the narrator
    once): the narratives of ``indices`` (default: every state), in their order. ``kwargs`` are
    :func:`xairl.narrate`'s (``policy``, ``background``, ``options``, ``template``, ...); ``store`` is not taken
    (record the returned narratives in the driver). ``threads``: torch threads per actor.
    """
    ray = _ray()
    if "store" in kwargs:
        raise InputError("narrate_on_ray records nothing: record its narratives with store.record in this process.")
    from xairl.registry.plugins import registry

    registry("narrator").load(narrator)  # an unknown name fails here, in one line, not in a worker
    n = len(explanation.values)
    indices = list(range(n)) if indices is None else [int(i) for i in indices]
    if any(not 0 <= i < n for i in indices):
        raise InputError(f"narrate_on_ray: indices must lie in 0..{n - 1} (the explanation's states).")
    started = _start(ray, address, workers)
    try:
        ref = ray.put(explanation)
        actor = ray.remote(num_cpus=1)(_NarrationWorker)
        pool = ray.util.ActorPool([actor.remote(ref, narrator, kwargs, threads) for _ in range(_usable(ray, workers))])
        with _unwrapped(ray):
            return list(pool.map(lambda a, i: a.narrate.remote(i), indices))
    finally:
        if started:
            ray.shutdown()
