"""Hostile input to the real-flight path (issue 51, items 3 and 5): non-finite measurements in flight exports, a NaN
where a policy acts, and UKM zips that are encrypted, have over-long member names, are empty or truncated. Each is
refused with one line that names the file (and the row), from the API and from ``xairl report``. Tests that build
their files from a real export skip where ../shared/data/ukm-uav-lte is absent; the others need no data."""

import io
import re
import zipfile
from pathlib import Path

import numpy as np
import pytest
import torch
from uav_hostile_helpers import NB_RSRP, UKM, data_home, needs_data, one_line_error, report_argv  # noqa: F401

from xairl import InputError
from xairl.plugin import CheckpointError
from xairl_uav_handover import ukm
from xairl_uav_handover.config import SimConfig
from xairl_uav_handover.env import HandoverVecEnv
from xairl_uav_handover.evaluate import run_flights
from xairl_uav_handover.exports import PCI, RSRP, RealFlight, load_flight
from xairl_uav_handover.features import FEATURES
from xairl_uav_handover.policy import DQNController, build_qnet, greedy, load_checkpoint, save_checkpoint
from xairl_uav_handover.real_data import Walk, agreement, walk
from xairl_uav_handover.report import real_source

# ---------------------------------------------------------------- item 3: non-finite measurements in real flights


def hostile_export(tmp_path: Path, column: str, value: str, name: str = "100m.csv", nth: int = 7) -> tuple[Path, int]:
    """The first 600 lines of the real 100 m flight with ``value`` written into ``column`` of the ``nth`` row that has
    a value there; the file and the 1-based line number of that row."""
    lines = (UKM / "100m.csv").read_text().splitlines()[:600]
    header = lines[0].split(",")
    j, seen = header.index(column), 0
    for k in range(1, len(lines)):
        cells = lines[k].split(",")
        if len(cells) > j and cells[j].strip():
            seen += 1
            if seen == nth:
                cells[j] = value
                lines[k] = ",".join(cells)
                path = tmp_path / name
                path.write_text("\n".join(lines) + "\n")
                return path, k + 1
    raise AssertionError(f"fewer than {nth} rows with {column}")


@needs_data
@pytest.mark.parametrize("column", [RSRP, NB_RSRP, "Latitude", PCI])
@pytest.mark.parametrize("value", ["inf", "1e400", "-inf"])
def test_non_finite_measurement_is_refused_by_file_and_line(tmp_path, column, value):
    path, line = hostile_export(tmp_path, column, value)
    with pytest.raises(InputError) as info:
        load_flight(path)
    msg = str(info.value)
    assert str(path) in msg and f"line {line}" in msg and f"'{column}'" in msg and "non-finite" in msg, msg
    assert "\n" not in msg


@needs_data
@pytest.mark.parametrize(
    "column, value",
    [(RSRP, "1e300"), (RSRP, "-3.4e38"), ("RSRQ (LTE pcell)", "-1e30"), ("RS SNR", "9e99"), (PCI, "1e20")],
)
def test_finite_but_impossible_measurement_is_refused(tmp_path, column, value):
    """Finite values no UE reports overflow the DQN's float32 input to inf: refused like inf."""
    path, line = hostile_export(tmp_path, column, value)
    with pytest.raises(InputError, match=rf"line {line}: .*outside") as info:
        load_flight(path)
    assert f"'{column}'" in str(info.value)


@needs_data
def test_report_refuses_a_folder_of_hostile_flights_in_one_line(tmp_path, capsys):
    real = tmp_path / "real"
    real.mkdir()
    path, line = hostile_export(real, RSRP, "1e400")
    msg = one_line_error(capsys, report_argv(real, tmp_path / "rep"))
    assert str(path) in msg and f"line {line}" in msg and "non-finite" in msg
    assert not (tmp_path / "rep" / "report.html").exists()


@needs_data
def test_report_names_the_skipped_hostile_flight(tmp_path, capsys):
    """A folder with a good flight and a hostile one: the hostile one is skipped by name (on stderr too), never
    walked."""
    real = tmp_path / "real"
    real.mkdir()
    (real / "25m.csv").write_text("\n".join((UKM / "25m.csv").read_text().splitlines()[:800]) + "\n")
    path, line = hostile_export(real, RSRP, "inf")
    from xairl_uav_handover.report import _load_real  # the report reads the flights before anything else

    flights, bad = _load_real(real)
    assert [f.name for f in flights] == ["25m.csv"]
    assert len(bad) == 1 and str(path) in bad[0] and f"line {line}" in bad[0]
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("xairl: report: skipped 1 of 2 flight file(s)") and bad[0] in err[0]


def small_flight(**changes) -> dict:
    n = 4
    fields = dict(
        name="50m.csv",
        altitude_m=50.0,
        t=np.arange(n, dtype=float),
        xy=np.zeros((n, 2)),
        pci=np.array([1.0, 1, 2, 2]),
        rsrp=np.full(n, -80.0),
        rsrq=np.full(n, -10.0),
        snr=np.full(n, 5.0),
        nb_pci=np.array([[2.0], [2], [1], [1]]),
        nb_rsrp=np.full((n, 1), -82.0),
        nb_rsrq=np.full((n, 1), -11.0),
    )
    return fields | changes


def test_a_flight_built_in_code_is_checked_too():
    walk(RealFlight(**small_flight()))  # a sane one walks
    for field, bad in (
        ("rsrp", np.array([-80.0, np.inf, -80, -80])),
        ("xy", np.array([[0, 0], [0, np.nan]] * 2)),
        ("nb_rsrp", np.array([[-82.0], [np.inf], [-82], [-82]])),
    ):
        with pytest.raises(InputError, match=rf"50m.csv: .*{field}.* sample 1") as info:
            walk(RealFlight(**small_flight(**{field: bad})))
        assert "\n" not in str(info.value)


# ---------------------------------------------------------------- item 3: a NaN where a policy acts


@pytest.fixture(scope="module")
def ckpt():
    return load_checkpoint()


def nan_net(ckpt):
    net = build_qnet(np.zeros(len(FEATURES)), np.ones(len(FEATURES)))
    net.load_state_dict(ckpt.net.state_dict())
    with torch.no_grad():
        net[-1].bias[2] = float("nan")
    return net.eval()


def test_nan_q_values_raise_instead_of_picking_stay(ckpt):
    states = np.tile(np.array([0, 0, 50, 0, 0, -80, -85, -90, -95, -8, -12, -14, -16], np.float32), (3, 1))
    assert greedy(ckpt.net, states, ckpt.sim_config).shape == (3,)
    with pytest.raises(CheckpointError, match="NaN or inf"):
        greedy(nan_net(ckpt), states, ckpt.sim_config)
    hostile = states.copy()
    hostile[1, 5] = np.inf  # a state the DQN cannot act on: named by its index and feature
    with pytest.raises(InputError, match=r"state 1 .*rsrp_0") as info:
        greedy(ckpt.net, hostile, ckpt.sim_config)
    assert "\n" not in str(info.value)
    hostile[1, 5] = 3e38  # finite, but the network's float32 arithmetic overflows on it
    with pytest.raises(InputError, match=r"state 1 .*rsrp_0"):
        greedy(ckpt.net, hostile, ckpt.sim_config)


def test_evaluation_with_a_nan_network_raises(ckpt):
    cfg = SimConfig.model_validate(
        ckpt.sim_config.model_dump() | {"flight": ckpt.sim_config.flight.model_dump() | {"duration_s": 1.0}}
    )
    with pytest.raises(CheckpointError, match="NaN or inf"):
        run_flights(DQNController(nan_net(ckpt)), cfg, 2, seed=0)


def test_checkpoint_with_nan_weights_is_refused(ckpt, tmp_path, capsys):
    path = tmp_path / "nan.safetensors"
    save_checkpoint(nan_net(ckpt), path, ckpt.meta)
    with pytest.raises(CheckpointError, match=r"nan.safetensors: .*NaN or inf") as info:
        load_checkpoint(path)
    assert "\n" not in str(info.value)
    msg = one_line_error(capsys, ["uav", "evaluate", "--checkpoint", str(path), "--flights", "1", "--duration", "1"])
    assert str(path) in msg and "NaN or inf" in msg


@pytest.mark.parametrize("action", [np.nan, np.inf, -1, 4, 1.5])
def test_env_refuses_an_action_that_is_no_candidate(action):
    env = HandoverVecEnv(SimConfig(), n_flights=2)
    env.reset(seed=0)
    with pytest.raises(InputError, match="action") as info:
        env.step(np.array([0, action]))
    assert "flight 1" in str(info.value) and "\n" not in str(info.value)


def small_walk() -> Walk:
    states = np.tile(np.array([0, 0, 50, 0, 0, -80, -85, -90, -95, -8, -12, -14, -16], np.float32), (4, 1))
    return Walk(np.arange(4.0), states, [[1.0, 2.0]] * 4, np.array([1.0, 2, 2, 2]), np.zeros(4), 0.0)


@pytest.mark.parametrize("action", [np.nan, -1, 7, 0.5])
def test_open_loop_replay_refuses_a_nan_action(action):
    assert agreement([small_walk()], lambda w: lambda s, c, t: 1).handover_agreement == 1.0
    with pytest.raises(InputError, match="action") as info:
        agreement([small_walk()], lambda w: lambda s, c, t: action if t == 2 else 0)
    assert "sample 2" in str(info.value) and "\n" not in str(info.value)


# ---------------------------------------------------------------- item 5: hostile UKM zips

CSV = b"Time,Latitude,Longitude\n10:00:00.000,2.92,101.77\n"


def zip_bytes(members: dict[str, bytes]) -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zf:
        for name, data in members.items():
            zf.writestr(name, data)
    return buf.getvalue()


def encrypted(data: bytes) -> bytes:
    """``data`` with the 'encrypted' flag (bit 0) set on every member, in local and central headers (zipfile cannot
    encrypt; reading such a member without a password raises RuntimeError)."""
    out = bytearray(data)
    for sig, at in ((b"PK\x03\x04", 6), (b"PK\x01\x02", 8)):
        k = out.find(sig)
        while k >= 0:
            out[k + at] |= 0x01
            k = out.find(sig, k + 4)
    return bytes(out)


def hostile_zips(tmp_path: Path) -> dict[str, tuple[Path, str]]:
    """name: (the zip, a regex its one-line refusal must match)."""
    good = zip_bytes({"Measured Data/100m.csv": CSV, "Measured Data/25m.csv": CSV})
    made = {
        "encrypted": (encrypted(good), r"'Measured Data/100m.csv' is encrypted"),
        "long-name": (zip_bytes({f"Measured Data/{'a' * 300}100m.csv": CSV}), r"longer than the 255 bytes"),
        "empty": (b"", r"is empty \(0 bytes\)"),
        "truncated": (good[: len(good) * 2 // 3], r"truncated"),
        "not-a-zip": (CSV, r"neither a folder nor a zip"),
    }
    out = {}
    for name, (data, match) in made.items():
        path = tmp_path / f"{name}.zip"
        path.write_bytes(data)
        out[name] = (path, match)
    return out


@pytest.mark.parametrize("kind", ["encrypted", "long-name", "empty", "truncated", "not-a-zip"])
def test_hostile_zip_is_refused_in_one_line(tmp_path, data_home, kind, monkeypatch):  # noqa: F811
    path, match = hostile_zips(tmp_path)[kind]
    for call in (lambda: ukm.flights_folder(path), lambda: real_source(str(path))):
        with pytest.raises(InputError, match=match) as info:
            call()
        msg = str(info.value)
        assert str(path) in msg and "\n" not in msg and "no such" not in msg, msg
    monkeypatch.setenv(ukm.ENV, str(path))  # the same file named by the environment variable
    with pytest.raises(InputError, match=match):
        ukm.flights_folder()
    assert not data_home.exists() or not any(p.glob("*.csv") for p in data_home.iterdir()), "nothing half-extracted"


@pytest.mark.parametrize("kind", ["encrypted", "long-name", "empty", "truncated"])
def test_report_with_a_hostile_zip_exits_2_with_one_line(tmp_path, capsys, kind):
    path, match = hostile_zips(tmp_path)[kind]
    msg = one_line_error(capsys, report_argv(path, tmp_path / "rep"))
    assert str(path) in msg and "no such" not in msg and "internal error" not in msg
    assert re.search(match, msg), msg


def test_unreadable_zip_says_so(tmp_path):
    path = tmp_path / "locked.zip"
    path.write_bytes(zip_bytes({"Measured Data/100m.csv": CSV}))
    path.chmod(0)
    try:
        try:
            path.open("rb").close()
            pytest.skip("this user reads a file of mode 000 (root): nothing to test")
        except PermissionError:
            pass
        with pytest.raises(InputError, match="cannot read") as info:
            ukm.flights_folder(path)
        assert str(path) in str(info.value) and "\n" not in str(info.value)
    finally:
        path.chmod(0o644)
