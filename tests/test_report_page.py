"""The report's page (issue 64): its main findings come first, a table of contents links every section and figure
of a page that runs to 15,000 pixels, and a table's long title is a short heading over its caption."""

import re

import pytest

from xairl.outputs.report import ReportContent, ReportRequest, write_report
from xairl.toy import toy_policy

FINDING = "Finding of the toy: distance leads, as designed."
LONG = (
    "Table I: 6 held-out simulated flights of 120 s (SA-MRO's offsets adapted on 6 flights first), value [bootstrap "
    "95 % interval]. The DQN is worse than CHM beyond the intervals on no figure."
)


@pytest.fixture(scope="module")
def page(tmp_path_factory) -> str:
    p = toy_policy()
    content = ReportContent(
        "toy report",
        p,
        p.background(30),
        [("sampled", p.background(8, seed=1))],
        tables=[(LONG, "<table><tr><th>a</th></tr></table>")],
        notes=["A note of the plugin."],
        commentary=lambda exps: [FINDING],
    )
    req = ReportRequest(out=tmp_path_factory.mktemp("toy"), narrate=False, progress=False, counterfactuals=False)
    return write_report(req, content).read_text()


def test_the_main_findings_come_first_not_among_the_notes(page):
    assert page.index(FINDING) < page.index(">Settings<") < page.index(">Notes<")
    notes = page[page.index(">Notes<") :]
    assert FINDING not in notes and "A note of the plugin." in notes


def test_the_contents_link_every_section_and_figure(page):
    toc = page[page.index("<nav class=toc>") : page.index("</nav>")]
    sections = re.findall(r"<h2 id=(s\d+)>", page)
    figures = re.findall(r"<figure id=(f\d+)>", page)
    assert len(sections) >= 5 and len(figures) >= 3
    assert all(f"href='#{i}'" in toc for i in sections + figures)
    assert toc.count("<a ") == len(sections) + len(figures)


def test_a_long_table_title_is_a_short_heading_over_its_caption(page):
    from xairl.outputs.report_html import short_heading

    assert "<h2 id=s3>Table I</h2><p class=caption>" in page and short_heading(LONG) == "Table I"
    assert short_heading("Open-loop agreement with the live network's decisions (29 real flights from x)") == (
        "Open-loop agreement with the live network's decisions"
    )
    assert len(short_heading("word " * 40)) <= 71
