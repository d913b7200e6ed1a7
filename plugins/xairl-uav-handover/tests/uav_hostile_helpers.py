"""What the hostile-input tests of the real-flight path share (test_uav_hardening.py, test_uav_hardening_files.py):
the real flights' folder, the user data folder in tmp_path, the CLI's one-line error, the cheapest report."""

from pathlib import Path

import pytest

from xairl.cli import main
from xairl_uav_handover import ukm

UKM = Path(__file__).resolve().parents[3].parent / "shared" / "data" / "ukm-uav-lte" / "raw"
needs_data = pytest.mark.skipif(not UKM.is_dir(), reason="../shared/data/ukm-uav-lte is not here")
NB_RSRP = "RSRP (LTE detected) - 1"


@pytest.fixture(autouse=True)
def data_home(tmp_path, monkeypatch) -> Path:
    """The user data folder (where zips are extracted) in tmp_path, and no $XAIRL_UKM_DATA."""
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "share"))
    monkeypatch.delenv(ukm.ENV, raising=False)
    return tmp_path / "share" / "xairl"


def one_line_error(capsys, argv) -> str:
    """Run the CLI; it must exit with status 2 and print exactly one line (no traceback)."""
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("xairl: error: ") and "Traceback" not in err[0], err
    return err[0]


def report_argv(real, out: Path) -> list[str]:
    """The cheapest report that loads real flights (on a build that does not refuse them: a few seconds)."""
    return [
        "report",
        "--plugin",
        "uav-handover",
        "--n",
        "10",
        "-o",
        f"real={real}",
        "-o",
        "flights=1",
        "-o",
        "timelines=0",
        "--out",
        str(out),
    ]
