"""Every simulator, CHM and SA-MRO setting carries its source, and docs/uav-reference.md holds the table of them."""

from pathlib import Path

from xairl_uav_handover import parameters

DOCS = Path(__file__).resolve().parents[3] / "docs" / "uav-reference.md"


def test_every_setting_names_its_source():
    assert parameters.undocumented() == []


def test_the_docs_hold_the_generated_table():
    text = DOCS.read_text()
    assert parameters.table() in text, (
        "docs/uav-reference.md's parameter table is stale: paste the output of "
        "`python -m xairl_uav_handover.parameters` between its markers"
    )


def test_rows_flatten_nested_sections():
    names = [n for n, _, _ in parameters.rows(parameters.SimConfig())]
    assert "antenna.downtilt_deg" in names and "handover.t310_s" in names and len(names) == len(set(names))
