"""Streaming (issue 28): states read in chunks from .npy, Parquet and CSV, explained chunk by chunk into a Parquet
dataset, equal to explaining them at once; a run killed with kill -9 and resumed explains every state exactly once."""

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import xairl
from xairl.cli import main
from xairl.errors import InputError
from xairl.runs.chunks import _table_batches, stage_parquet, state_chunks
from xairl.runs.stream import explain_chunks, explain_to_parquet, read_parquet
from xairl.toy import FEATURES, toy_policy

POLICY = toy_policy()
STATES = POLICY.background(2_345, seed=3)
BG = POLICY.background(40)


@pytest.fixture(scope="module")
def reference():
    return xairl.explain(POLICY, STATES, background=BG)


def _sources(folder):
    np.save(folder / "s.npy", STATES)
    pq.write_table(
        pa.table(
            {f: STATES[:, j].astype(np.float64) for j, f in enumerate(reversed(FEATURES))}
            | {f: STATES[:, FEATURES.index(f)].astype(np.float64) for f in FEATURES}
        ),
        folder / "s.parquet",
        row_group_size=700,
    )
    (folder / "s.csv").write_text(
        ",".join(FEATURES[::-1]) + "\n" + "\n".join(",".join(repr(float(v)) for v in row[::-1]) for row in STATES)
    )
    return [folder / "s.npy", folder / "s.parquet", folder / "s.csv", STATES]


def test_every_source_gives_the_same_chunks(tmp_path):
    for source in _sources(tmp_path):
        chunks = list(state_chunks(source, POLICY, chunk_size=1000))
        assert [first for first, _ in chunks] == [0, 1000, 2000] and [len(c) for _, c in chunks] == [1000, 1000, 345]
        assert np.array_equal(np.concatenate([c for _, c in chunks]), STATES), source
        for start in (1000, 1999, 2000):  # Parquet: the row groups before the chunk (700 rows each) are not read
            later = list(state_chunks(source, POLICY, chunk_size=1000, start=start))
            assert [first for first, _ in later] == list(range(start - start % 1000, 2345, 1000)), (source, start)
            assert np.array_equal(np.concatenate([c for _, c in later]), STATES[start - start % 1000 :]), (
                source,
                start,
            )


def test_parquet_is_read_from_the_row_group_that_holds_the_first_row_wanted(tmp_path):
    parquet = _sources(tmp_path)[1]  # row groups of 700 rows
    assert [_table_batches(parquet, POLICY, 1000, start)[0] for start in (0, 699, 700, 2000)] == [0, 0, 700, 1400]


def test_staged_parquet_has_one_row_group_per_chunk(tmp_path):
    csv = _sources(tmp_path)[2]
    assert stage_parquet(csv, POLICY, tmp_path / "staged.parquet", chunk_size=1000) == 2345
    meta = pq.ParquetFile(tmp_path / "staged.parquet").metadata
    assert [meta.row_group(g).num_rows for g in range(meta.num_row_groups)] == [1000, 1000, 345]
    assert np.array_equal(next(state_chunks(tmp_path / "staged.parquet", POLICY, 1000, start=2000))[1], STATES[2000:])


def test_chunks_equal_one_explanation_of_all_states(reference):
    parts = list(explain_chunks(POLICY, STATES, background=BG, chunk_size=800))
    assert np.array_equal(np.concatenate([e.values for _, e in parts]), reference.values)


def test_parquet_dataset_round_trip_and_summary(tmp_path, reference):
    summary = explain_to_parquet(
        POLICY,
        tmp_path / "s.npy" if np.save(tmp_path / "s.npy", STATES) is None else None,
        tmp_path / "out",
        background=BG,
        chunk_size=1000,
        progress=False,
    )
    back = read_parquet(tmp_path / "out" / "explanations.parquet")
    assert np.array_equal(back.values, reference.values.astype(np.float32).astype(np.float64))
    assert np.array_equal(back.outputs, reference.outputs) and back.feature_names == reference.feature_names
    assert np.array_equal(back.chosen, reference.chosen)
    table = pq.read_table(tmp_path / "out" / "explanations.parquet")  # one table for pyarrow (and pandas)
    assert table.num_rows == len(STATES) and sorted(table.column("index").to_pylist()) == list(range(len(STATES)))
    meta = json.loads(table.schema.metadata[b"xairl"])
    assert meta["method"] == "deep_shap" and len(meta["policy_hash"]) == 16
    means = json.loads((tmp_path / "out" / "summary.json").read_text())["mean_abs_contribution"]["margin"]
    assert np.allclose([means[f] for f in FEATURES], np.abs(back.margin()).mean(axis=0))
    assert summary.n == len(STATES) and len(summary.sample) == 1000
    sample = summary.sample_explanation()
    assert len(np.unique(sample.states, axis=0)) == 1000  # a sample of distinct states, in row order


def test_a_folder_holding_a_run_is_not_overwritten_and_resume_checks_it_is_the_same_run(tmp_path):
    out = tmp_path / "out"
    explain_to_parquet(POLICY, STATES, out, background=BG, chunk_size=1000, progress=False)
    with pytest.raises(InputError, match="already holds a run .*--resume"):
        explain_to_parquet(POLICY, STATES, out, background=BG, chunk_size=1000, progress=False)
    with pytest.raises(InputError, match="differs in background_sha256"):
        explain_to_parquet(POLICY, STATES, out, background=BG[:20], chunk_size=1000, progress=False, resume=True)
    with pytest.raises(InputError, match="differs in method, options"):
        explain_to_parquet(
            POLICY, STATES, out, background=BG, method="exact", chunk_size=1000, progress=False, resume=True
        )


@pytest.mark.slow
def test_kill_9_then_resume_explains_every_state_exactly_once(tmp_path):
    states = tmp_path / "s.npy"
    np.save(states, POLICY.background(6_400, seed=9))  # 32 chunks of 200
    out = tmp_path / "out"
    argv = [
        sys.executable,
        "-m",
        "xairl.cli",
        "explain",
        "--states",
        str(states),
        "--out",
        str(out),
        "--format",
        "parquet",
        "--chunk-size",
        "200",
        "--method",
        "integrated_gradients",
        "-o",
        "n_steps=8",
        "--background-size",
        "20",
    ]
    proc = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    parts = out / "explanations.parquet"
    deadline = time.time() + 120
    while time.time() < deadline and len(list(parts.glob("part-*.parquet"))) < 3:
        time.sleep(0.01)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    done = len(list(parts.glob("part-*.parquet")))
    assert 3 <= done < 32, done  # killed mid-run
    assert not [p for p in parts.iterdir() if p.suffix == ".parquet" and not p.name.startswith("part-")]
    assert subprocess.run(argv, capture_output=True, text=True).returncode == 2  # a run is there: not overwritten
    rerun = subprocess.run(argv + ["--resume"], capture_output=True, text=True)
    assert rerun.returncode == 0, rerun.stderr
    index = pq.read_table(parts, columns=["index"]).column("index").to_numpy()
    assert len(index) == 6_400 and np.array_equal(np.sort(index), np.arange(6_400))  # each exactly once
    for junk in parts.glob(".*.part"):  # what the kill left: hidden, never under a final name
        junk.unlink()
    again = tmp_path / "again"
    explain_to_parquet(
        POLICY,
        states,
        again,
        background=POLICY.background(20, seed=0),
        method="integrated_gradients",
        options={"n_steps": 8},
        chunk_size=200,
        progress=False,
    )
    assert np.array_equal(read_parquet(parts).values, read_parquet(again / "explanations.parquet").values)


def test_cli_parquet_writes_a_report_of_a_sample_and_shows_progress_on_a_terminal(tmp_path, capsys):
    assert (
        main(["explain", "--n", "3000", "--out", str(tmp_path / "r"), "--format", "parquet", "--chunk-size", "1000"])
        == 0
    )
    out = capsys.readouterr().out
    assert "(3000 states)" in out and (tmp_path / "r" / "report.html").exists()
    html = (tmp_path / "r" / "report.html").read_text()
    assert "Mean |contribution| over all 3000 states" in html and "uniform sample of 1000" in html
    assert not (tmp_path / "r" / "explanations.jsonl").exists()
    explain_to_parquet(POLICY, STATES, tmp_path / "p", background=BG, chunk_size=1000, progress=True)
    err = capsys.readouterr().err
    assert "2345/2345" in err and "states/s" in err
    assert main(["explain", "--format", "parquet"]) == 2  # a folder is needed
