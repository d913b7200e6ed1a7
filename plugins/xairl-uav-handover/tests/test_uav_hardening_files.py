"""Hostile files on the real-flight folder path (issue 64): special files (a FIFO, a link to /dev/zero) refused
quickly, and rows that cannot be read (text or NUL bytes where a number belongs, long rows) counted and named, not
dropped in silence."""

import os
from pathlib import Path

import pytest
from uav_hostile_helpers import NB_RSRP, UKM, data_home, needs_data, one_line_error, report_argv  # noqa: F401

from xairl import InputError
from xairl_uav_handover import ukm
from xairl_uav_handover.exports import RSRP, load_flight

# ---------------------------------------------------------------- issue 64: special files, and rows that cannot be read


def export_lines(n: int = 300) -> list[str]:
    """A small export of ``n`` rows in the UKM layout (the required columns, a detected-cell slot), then its footer."""
    from xairl_uav_handover.exports import REQUIRED

    header = [*REQUIRED, "Physical cell identity (LTE detected) - 1", NB_RSRP]
    rows = [
        f"10:{k // 120:02d}:{k % 120 // 2:02d}.{k % 2 * 500:03d},2.9228,{101.7715 + k * 1e-5:.5f},{110 + k // 100},"
        f"-80.0,-8.0,10.0,{111 + k // 100},-85.0"
        for k in range(n)
    ]
    return [",".join(header), *rows, ",,,,,,,,", "Exported Measurements"]


def write_export(path: Path, lines: list[str]) -> Path:
    path.write_text("\n".join(lines) + "\n")
    return path


def test_a_clean_small_export_loads_without_its_footer(tmp_path):
    f = load_flight(write_export(tmp_path / "100m.csv", export_lines()))
    assert len(f.t) == 300 and f.observed_handovers == 2


def refused_rows(tmp_path, lines) -> str:
    with pytest.raises(InputError) as info:
        load_flight(write_export(tmp_path / "100m.csv", lines))
    msg = str(info.value)
    assert "100m.csv" in msg and "\n" not in msg and "fix or delete those rows" in msg, msg
    return msg


def test_rows_with_text_where_a_number_belongs_are_counted_not_dropped(tmp_path):
    """150 of 300 rows with a string in RSRP were dropped in silence (the flight got shorter)."""
    lines = export_lines()
    for k in range(1, 301, 2):
        lines[k] = lines[k].replace(",-80.0,", ",strong,")
    msg = refused_rows(tmp_path, lines)
    assert "150 of 300 rows cannot be read" in msg and "first line 2" in msg and "'strong'" in msg, msg
    assert f"'{RSRP}'" in msg


def test_rows_with_nul_bytes_are_counted_not_dropped(tmp_path):
    lines = export_lines()
    for k in range(10, 160):
        lines[k] = lines[k].replace("-8.0", "-8\0.0")
    msg = refused_rows(tmp_path, lines)
    assert "150 row(s) hold a NUL byte" in msg and "first on line 11" in msg, msg


def test_a_time_that_does_not_parse_before_the_footer_is_refused(tmp_path):
    lines = export_lines()
    lines[42] = "yesterday" + lines[42][lines[42].index(",") :]
    msg = refused_rows(tmp_path, lines)
    assert "1 of 300 rows cannot be read, first line 43: its Time does not parse" in msg, msg


@pytest.mark.parametrize("row", [1, 150])
def test_a_long_row_is_refused_not_cut_or_shifted(tmp_path, row):
    """A row with more fields than the header: pandas shifted every column (the first row) or failed in its own
    words (a later one)."""
    lines = export_lines()
    lines[row] += ",-70.0,-5.0"
    msg = refused_rows(tmp_path, lines)
    assert f"1 row(s) hold more fields than the header's 9, first line {row + 1} (11)" in msg, msg


def test_a_blank_line_inside_an_export_is_no_bad_row(tmp_path):
    lines = export_lines()
    lines.insert(100, "")
    assert len(load_flight(write_export(tmp_path / "100m.csv", lines)).t) == 300


def special_files(folder: Path) -> dict[str, Path]:
    """A FIFO (a read blocks for ever) and a link to /dev/zero (a read never ends), named as flight exports."""
    folder.mkdir(exist_ok=True)
    fifo, zero = folder / "100m.csv", folder / "25m.csv"
    os.mkfifo(fifo)
    zero.symlink_to("/dev/zero")
    return {"fifo": fifo, "zero": zero}


needs_special_files = pytest.mark.skipif(
    not hasattr(os, "mkfifo") or not Path("/dev/zero").exists(), reason="no FIFOs or /dev/zero here"
)


@pytest.mark.slow
@needs_special_files
def test_report_refuses_a_folder_of_a_fifo_and_a_link_to_dev_zero_quickly(tmp_path):
    """Run as a subprocess, bounded in time and memory: the loader used to block on the FIFO for ever, and read
    /dev/zero for 4.5 GB."""
    import resource
    import subprocess
    import sys
    import time

    special_files(tmp_path / "real")

    def bounded():  # 3 GB of address space: reading /dev/zero fails fast instead of filling the machine
        resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))

    argv = [sys.executable, "-m", "xairl.cli", *report_argv(tmp_path / "real", tmp_path / "rep")]
    t0 = time.monotonic()
    try:
        run = subprocess.run(argv, capture_output=True, text=True, timeout=120, preexec_fn=bounded)
    except subprocess.TimeoutExpired:
        pytest.fail("the report hung on a folder with a FIFO in it")
    err = run.stderr.strip().splitlines()
    assert run.returncode == 2 and len(err) == 1 and "Traceback" not in run.stderr, run.stderr[-2000:]
    assert "no loadable flight export (2 bad file(s))" in err[0], err
    assert "100m.csv: a named pipe (FIFO), not a regular file" in err[0], err
    assert time.monotonic() - t0 < 60


@needs_special_files
def test_special_files_are_named_and_skipped_beside_a_good_flight(tmp_path):
    import threading

    from xairl_uav_handover.exports import load_folder

    files = special_files(tmp_path / "real")
    write_export(tmp_path / "real" / "50m.csv", export_lines())
    done = []  # in a thread, so that a loader that blocks on the FIFO (read first: sorted by name) fails, not hangs
    worker = threading.Thread(target=lambda: done.append(load_folder(tmp_path / "real")), daemon=True)
    worker.start()
    worker.join(timeout=30)
    assert done, "load_folder blocked on a FIFO"
    flights, bad = done[0]
    assert [f.name for f in flights] == ["50m.csv"] and len(bad) == 2
    assert bad[0].startswith(f"{files['fifo']}: a named pipe (FIFO), not a regular file; refused unread"), bad
    assert bad[1].startswith(f"{files['zero']} (a link to /dev/zero): a character device, not a regular file"), bad
    for path in files.values():  # the zip path refuses them with the same check
        with pytest.raises(InputError, match="not a regular file"):
            ukm.flights_folder(path)


def test_an_export_over_the_size_limit_is_refused_unread(tmp_path, monkeypatch):
    from xairl_uav_handover import exports

    path = write_export(tmp_path / "100m.csv", export_lines())
    monkeypatch.setattr(exports, "MAX_FILE_BYTES", 1000)
    monkeypatch.setattr(exports.read_plain, "__defaults__", (1000,))
    with pytest.raises(InputError, match=r"100m.csv: \d+ bytes, more than the 1000 allowed here; refused unread"):
        load_flight(path)
