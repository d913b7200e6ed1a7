"""The reference plugin's tests run with this plugin selected and no other. ``real_report``: the one report with real
flights that the report's tests read (a report costs a minute: built once per session)."""

import contextlib
import io
import shutil
from pathlib import Path

import pytest

from xairl.explanations import display
from xairl.registry import plugins

DATA = Path(__file__).resolve().parents[3].parent / "shared" / "data"
UKM = DATA / "ukm-uav-lte" / "raw"
BALTACI = DATA / "baltaci-imc22-handovers"


@pytest.fixture(autouse=True)
def only_this_plugin(monkeypatch):
    monkeypatch.setenv(plugins.LOAD_ENV, "uav-handover")


@pytest.fixture(scope="session")
def real_report(tmp_path_factory) -> tuple[Path, Path]:
    """(report folder, real-flights folder): two UKM flights with the Baltaci events beside them, few simulated
    flights (Table I's SA-MRO then never updates: its columns equal CHM's) and 16 calibration flights, narrated
    without robustness. What it said on stderr is kept beside the report folder, in stderr.txt."""
    from xairl.cli import main

    if not UKM.is_dir():
        pytest.skip("../shared/data/ukm-uav-lte is not here")
    root = tmp_path_factory.mktemp("real")
    real = root / "data" / "ukm"
    real.mkdir(parents=True)
    for name in ("25m.csv", "100m.csv"):
        shutil.copy(UKM / name, real / name)
    if BALTACI.is_dir():
        shutil.copytree(BALTACI, root / "data" / "baltaci-imc22-handovers")
    out = root / "rep"
    argv = ["report", "--plugin", "uav-handover", "--n", "30", "-o", f"real={real}", "-o", "flights=4"]
    argv += ["-o", "timelines=0", "-o", "calibration_flights=16", "--narrate", "--no-robustness", "--out", str(out)]
    with pytest.MonkeyPatch.context() as mp, contextlib.redirect_stderr(io.StringIO()) as err:
        mp.setenv(plugins.LOAD_ENV, "uav-handover")
        mp.setattr(display, "EVERY", 0.01)  # each step is long at this scale: each is said
        code = main(argv)
    assert code == 0, err.getvalue()[-2000:]
    (root / "stderr.txt").write_text(err.getvalue())
    return out, real
