"""Hardening, round 3 (issue 51, items 2, 8 and 12): ``--resume`` trusts a part by its contents, not its name (a
fuzz of damaged, stray, foreign and reordered parts ends in every state exactly once, or in one line naming the file
to delete); a folder that cannot be written or a run.json that is no record is one line; ``--out`` on many states
streams."""

import json
import os
import random
import shutil

import numpy as np
import pyarrow.parquet as pq
import pytest

from tests.resume_fuzz import BG, CHUNK, POLICY, STATES, N, make_runs, mutate, one_case, part
from xairl.cli import explain as explain_cli
from xairl.cli import main
from xairl.errors import InputError
from xairl.registry import plugins
from xairl.runs.stream import DATASET, explain_to_parquet, read_parquet

CASES = 210  # with a fixed seed: the resume fuzz of the issue's "done when" (benchmarks/fuzz_resume.py runs more)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """A whole run of the fuzz's states, another run (another background) to take foreign parts from, the values of
    the whole run and its id."""
    root = tmp_path_factory.mktemp("runs")
    return (root, *make_runs(root))


def _resume(out):
    return explain_to_parquet(POLICY, STATES, out, background=BG, chunk_size=CHUNK, progress=False, resume=True)


@pytest.mark.slow
def test_resume_fuzz_ends_in_every_state_exactly_once_or_a_refusal_naming_the_part(runs, monkeypatch):
    """Bit flips, truncation, short parts, deletions, swapped names, stray and foreign parts, one to three at a time
    (and run.json made no record in one case in ten): each resume ends with every state exactly once and the values
    of an undamaged run, or in one line naming a file that is no part of this run, and deleting that file and resuming
    again ends whole; damage alone is never refused (the checks are in tests/resume_fuzz.one_case)."""
    monkeypatch.setattr(os, "fsync", lambda fd: None)  # durability is not what is tested here; fsync was half the time
    root, reference, run = runs
    rng = random.Random(51)
    ends = [one_case(case, root, reference, run, rng) for case in range(CASES)]
    refused = [e for e in ends if e["refusals"]]
    assert len(ends) == CASES and len(refused) > CASES // 4, len(refused)
    assert all(
        set(e["refusals"]) <= set(e["named"]) | {"run.json", *(part(f) for f in range(0, N, CHUNK))} for e in refused
    )


@pytest.mark.parametrize("kind", ["stray", "foreign"])
def test_a_stray_or_foreign_part_is_refused_by_name_before_anything_is_explained(runs, tmp_path, kind):
    root, _, _ = runs
    out = tmp_path / "out"
    shutil.copytree(root / "run", out)
    name = mutate(kind, out / DATASET, root / "other" / DATASET, random.Random(3))
    before = {p.name: p.stat().st_mtime_ns for p in (out / DATASET).iterdir()}
    with pytest.raises(InputError, match=f"{name}: not a part of this run .*delete it") as caught:
        _resume(out)
    assert "\n" not in str(caught.value)
    assert before == {p.name: p.stat().st_mtime_ns for p in (out / DATASET).iterdir()}  # nothing written


def test_read_parquet_refuses_a_folder_that_holds_a_row_twice(runs, tmp_path):
    root, reference, _ = runs
    shutil.copytree(root / "run" / DATASET, tmp_path / DATASET)
    shutil.copy(tmp_path / DATASET / part(20), tmp_path / DATASET / "part-000000000007.parquet")
    with pytest.raises(InputError, match="row 20 is in two parts"):
        read_parquet(tmp_path / DATASET)
    (tmp_path / DATASET / "part-000000000007.parquet").unlink()
    assert np.array_equal(read_parquet(tmp_path / DATASET).values, reference.values)


@pytest.mark.slow
def test_the_issues_cli_resumes_a_bit_flip_whole_and_refuses_part_07(tmp_path, capsys, caplog):
    argv = [
        "explain",
        "--n",
        "3000",
        "--out",
        str(tmp_path / "r"),
        "--format",
        "parquet",
        "--chunk-size",
        "500",
        "--background-size",
        "20",
    ]
    assert main(argv) == 0
    parts = tmp_path / "r" / DATASET
    flipped = parts / part(1000)
    data = bytearray(flipped.read_bytes())
    data[len(data) // 2] ^= 4
    flipped.write_bytes(bytes(data))
    shutil.copy(parts / part(0), parts / "part-000000000007.parquet")
    capsys.readouterr()
    assert main(argv + ["--resume"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "part-000000000007.parquet: not a part of this run" in err
    (parts / "part-000000000007.parquet").unlink()
    assert main(argv + ["--resume"]) == 0
    assert "(3000 states)" in capsys.readouterr().out and f"{flipped}: damaged" in caplog.text
    index = pq.read_table(parts, columns=["index"]).column("index").to_numpy()
    assert len(index) == 3000 and len(np.unique(index)) == 3000


def _small_run(out):
    """The command line of a run of 30 states in chunks of 10 into ``out``."""
    flags = "--n 30 --format parquet --chunk-size 10 --background-size 10".split()
    return ["explain", "--out", str(out), *flags]


@pytest.mark.slow
@pytest.mark.parametrize("record", ["[1, 2]", "42", '"a run"', "null", "[" * 100_000 + "]" * 100_000, "{", ""])
def test_a_run_json_that_is_no_record_is_refused_in_one_line(tmp_path, capsys, record):
    argv = _small_run(tmp_path / "r")
    assert main(argv) == 0
    (tmp_path / "r" / "run.json").write_text(record)
    capsys.readouterr()
    assert main(argv + ["--resume"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "run.json: not the record of a run" in err and "delete it" in err
    # as the line says: with no record of their bytes, the parts are explained again
    (tmp_path / "r" / "run.json").unlink()
    assert main(argv + ["--resume"]) == 0
    assert json.loads((tmp_path / "r" / "run.json").read_text())["chunk_size"] == 10


def test_a_truncated_part_is_explained_again_on_resume(tmp_path, capsys):
    argv = _small_run(tmp_path / "r")
    assert main(argv) == 0
    cut = tmp_path / "r" / DATASET / part(10)
    cut.write_bytes(cut.read_bytes()[:100])
    assert main(argv + ["--resume"]) == 0
    assert np.array_equal(np.sort(pq.read_table(cut.parent).column("index").to_numpy()), np.arange(30))


@pytest.mark.parametrize("fmt", [[], ["--format", "parquet"]])
def test_an_out_folder_that_cannot_be_made_is_one_line(tmp_path, capsys, fmt):
    assert main(["explain", "--n", "3", "--out", "/proc/forbidden", *fmt]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "/proc/forbidden: cannot write there" in err


def test_a_report_out_folder_that_cannot_be_made_is_one_line(capsys, monkeypatch):
    pytest.importorskip("xairl_uav_handover", reason="the UAV plugin (make setup installs it) has a report")
    monkeypatch.setenv(plugins.LOAD_ENV, "uav-handover")
    assert main(["report", "--plugin", "uav-handover", "--n", "5", "--out", "/proc/forbidden"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "/proc/forbidden: cannot write there" in err


@pytest.mark.slow
def test_out_on_many_states_streams_into_parquet_and_says_so(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(explain_cli, "STREAM_ABOVE", 1_000)  # (the default, 50,000, takes a while on 2 cores)
    assert main(["explain", "--n", "1001", "--out", str(tmp_path / "big"), "--background-size", "10"]) == 0
    out, err = capsys.readouterr()
    assert "1001 states: streaming them into" in err and "--format jsonl" in err and "(1001 states)" in out
    assert (tmp_path / "big" / DATASET).is_dir() and not (tmp_path / "big" / "explanations.jsonl").exists()
    assert (
        main(
            ["explain", "--n", "1001", "--out", str(tmp_path / "kept"), "--format", "jsonl", "--background-size", "10"]
        )
        == 0
    )  # asked for: one JSON lines file
    assert len((tmp_path / "kept" / "explanations.jsonl").read_text().splitlines()) == 1001
    assert main(["explain", "--n", "1000", "--out", str(tmp_path / "small"), "--background-size", "10"]) == 0
    assert (tmp_path / "small" / "explanations.jsonl").exists() and not (tmp_path / "small" / DATASET).exists()
    assert "streaming" not in capsys.readouterr().err


def test_the_default_above_which_out_streams_is_50000_states_and_the_help_says_so(capsys):
    assert explain_cli.STREAM_ABOVE == 50_000
    with pytest.raises(SystemExit):
        main(["explain", "--help"])
    assert "above 50,000 states" in " ".join(capsys.readouterr().out.split())


def test_progress_false_shows_no_bar(tmp_path, capsys):
    """The bar's function once shadowed the ``progress`` parameter, so ``progress=False`` still drew a bar."""
    explain_to_parquet(POLICY, STATES[:40], tmp_path / "quiet", background=BG, chunk_size=20, progress=False)
    assert capsys.readouterr().err == ""


def _flip_statistics(path, old: int, new: int) -> None:
    """Rewrites the int64 ``old`` as ``new`` in the Parquet footer of ``path`` only (the index column's min or max
    statistics): the columns and the xairl metadata stay as written, so their checksum still holds."""
    data = bytearray(path.read_bytes())
    footer = int.from_bytes(data[-8:-4], "little")
    start = len(data) - 8 - footer
    was, now = old.to_bytes(8, "little", signed=True), new.to_bytes(8, "little", signed=True)
    assert was in data[start:], "the statistic is not in the footer"
    data[start:] = data[start:].replace(was, now)
    path.write_bytes(bytes(data))


@pytest.fixture(scope="module")
def run_3000(tmp_path_factory):
    """The issue's run: 3,000 states in chunks of 500, streamed from a .npy file; (its command line, its folder)."""
    root = tmp_path_factory.mktemp("run3000")
    np.save(root / "states.npy", POLICY.background(3000, seed=11))
    argv = ["explain", "--states", str(root / "states.npy"), "--out", str(root / "r"), "--format", "parquet"]
    argv += ["--chunk-size", "500", "--background-size", "20"]
    assert main(argv) == 0
    return argv, root


@pytest.mark.slow
def test_a_part_whose_footer_statistics_were_flipped_is_explained_again_on_resume(run_3000, tmp_path, capsys, caplog):
    """Only the footer's statistics changed: the columns' checksum held, --resume kept the part, and a filtered read
    then skipped its row group (300 rows lost). The part's bytes are checked against the SHA-256 in run.json."""
    argv, root = run_3000
    out = tmp_path / "r"
    shutil.copytree(root / "r", out)
    argv = [str(out) if a == str(root / "r") else a for a in argv]
    _flip_statistics(out / DATASET / part(1000), 1499, 1199)  # its max: rows 1200..1499 look absent to a filter
    assert main(argv + ["--resume"]) == 0
    assert f"{out / DATASET / part(1000)}: damaged" in caplog.text and "explained again" in caplog.text
    index = pq.read_table(out / DATASET, columns=["index"], filters=[("index", ">=", 1200)]).column("index")
    assert len(index) == 1800


def test_a_states_file_rewritten_with_the_same_size_and_time_is_not_resumed(tmp_path, capsys):
    """Size and modification time once stood for the states: a rewritten file resumed into old rows and new ones
    (1,500 of each in the issue). Its content is hashed: one line saying the states changed and what to do, exit 2,
    nothing written."""
    out, states = tmp_path / "r", tmp_path / "states.npy"
    np.save(states, POLICY.background(600, seed=11))
    argv = ["explain", "--states", str(states), "--out", str(out), "--format", "parquet", "--chunk-size", "100"]
    argv += ["--background-size", "10"]
    assert main(argv) == 0
    for first in (300, 400, 500):  # a run cut off half-way
        (out / DATASET / part(first)).unlink()
    stat = states.stat()
    np.save(states, POLICY.background(600, seed=12))  # other states, the same shape: the same size
    os.utime(states, ns=(stat.st_atime_ns, stat.st_mtime_ns))
    assert states.stat().st_size == stat.st_size and states.stat().st_mtime_ns == stat.st_mtime_ns
    capsys.readouterr()
    assert main(argv + ["--resume"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{states} changed since" in err, err
    assert "without --resume" in err and f"delete {out}" in err
    assert sorted(p.name for p in (out / DATASET).iterdir()) == [part(f) for f in (0, 100, 200)]
