"""The SQLite feedback store: record, review, export, concurrent writers, interrupted writes, CLI review."""

import io
import json
import multiprocessing as mp
import sqlite3

import pytest

import xairl
from xairl.cli import main
from xairl.errors import InputError
from xairl.outputs.feedback import FeedbackStore
from xairl.toy import toy_policy


@pytest.fixture(scope="module")
def narrative():
    p = toy_policy()
    e = xairl.explain(p, p.background(2))
    return xairl.narrate(e, 0, policy=p), p


def test_record_review_export(tmp_path, narrative):
    n, policy = narrative
    store = FeedbackStore(tmp_path / "fb.sqlite")
    a, b = store.record(n, policy), store.record(n, policy)
    store.review(a, "accepted")
    store.review(b, "corrected", "The policy turned because of the distance.")
    assert [r.status for r in store.records()] == ["accepted", "corrected"]
    assert store.records()[0].claims and store.records()[0].verified
    buf = io.StringIO()
    assert store.export_corrections(buf) == 1
    assert json.loads(buf.getvalue())["correction"].startswith("The policy turned")
    assert store.examples()[-1].startswith("The policy turned")
    with pytest.raises(InputError, match="no narrative with id 99"):
        store.review(99, "accepted")
    with pytest.raises(InputError, match="needs its text"):
        store.review(a, "corrected")


def _writer(path, n, text, start=None):
    from xairl.narrators.base import Narrative
    from xairl.outputs.feedback import FeedbackStore

    store = FeedbackStore(path)
    if start is not None:  # every writer waits until all have imported, so their writes overlap whatever the load
        start.wait()
    for i in range(n):
        store.record(Narrative(f"{text} {i}", (), True, 0.5, {}, "template", "t", i))


@pytest.mark.slow
def test_concurrent_writers_lose_nothing(tmp_path):
    """Four processes write at once (a barrier holds them until all are up, so the test does not depend on how fast
    the machine imports): every row is kept, and the writers' rows interleave (the writes really were concurrent)."""
    path = tmp_path / "fb.sqlite"
    FeedbackStore(path)
    ctx = mp.get_context("spawn")
    start = ctx.Barrier(4)
    procs = [ctx.Process(target=_writer, args=(path, 300, f"p{k}", start)) for k in range(4)]
    for p in procs:
        p.start()
    for p in procs:
        p.join(600)  # a bound against a hang, not a timing: the work is a few seconds once all have started
        assert p.exitcode == 0
    texts = [r.text for r in FeedbackStore(path).records()]
    assert len(texts) == 1200 and len(set(texts)) == 1200
    writers = [t.split()[0] for t in texts]
    switches = sum(a != b for a, b in zip(writers, writers[1:]))
    assert switches > 3, "the writers ran one after another: nothing concurrent was tested"


@pytest.mark.slow
def test_writer_killed_mid_run_leaves_store_readable(tmp_path):
    import os
    import signal
    import time

    path = tmp_path / "fb.sqlite"
    FeedbackStore(path)
    p = mp.get_context("spawn").Process(target=_writer, args=(path, 1_000_000, "victim"))
    p.start()
    deadline = time.time() + 60
    while time.time() < deadline and len(FeedbackStore(path).records()) < 50:
        time.sleep(0.2)
    os.kill(p.pid, signal.SIGKILL)
    p.join()
    rows = FeedbackStore(path).records()
    assert len(rows) >= 50 and [r.text for r in rows] == [f"victim {i}" for i in range(len(rows))]
    assert sqlite3.connect(path).execute("PRAGMA integrity_check").fetchone()[0] == "ok"


def test_interrupted_write_leaves_store_readable(tmp_path, narrative):
    n, policy = narrative
    store = FeedbackStore(tmp_path / "fb.sqlite")
    store.record(n, policy)
    with pytest.raises(RuntimeError):
        with store._tx() as db:
            db.execute("INSERT INTO narratives (created, text, claims, verified, confidence) VALUES (0,'x','[]',1,1)")
            raise RuntimeError("killed mid-write")
    assert len(store.records()) == 1
    assert sqlite3.connect(store.path).execute("PRAGMA integrity_check").fetchone()[0] == "ok"


def test_corrupt_store_is_a_clear_error(tmp_path):
    bad = tmp_path / "bad.sqlite"
    bad.write_bytes(b"this is not sqlite" * 100)
    with pytest.raises(InputError, match="not a usable feedback store"):
        FeedbackStore(bad)


def test_cli_narrate_then_review(tmp_path, capsys, monkeypatch):
    db = tmp_path / "fb.sqlite"
    assert main(["explain", "--n", "2", "--narrate", "--feedback-db", str(db), "--format", "jsonl"]) == 0
    lines = [json.loads(x) for x in capsys.readouterr().out.splitlines()]
    assert len(lines) == 2 and all(x["verified"] and 0 < x["confidence"] <= 1 for x in lines)
    monkeypatch.setattr("sys.stdin", io.StringIO("r\nc\nOperator wording.\n"))
    assert main(["review", "--db", str(db)]) == 0
    shown = capsys.readouterr().out
    first = lines[0]["sentences"][0]["text"]
    assert f"    verified      {first}" in shown.splitlines()  # each sentence with its status
    assert [r.status for r in FeedbackStore(db).records()] == ["rejected", "corrected"]
    out = tmp_path / "corr.jsonl"
    assert main(["review", "--db", str(db), "--export", str(out)]) == 0
    assert json.loads(out.read_text())["correction"] == "Operator wording."
