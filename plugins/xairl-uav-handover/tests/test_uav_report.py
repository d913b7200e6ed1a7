"""The UAV report as a reader meets it (issue 64): the words about contributions agree with the figures, numbers
have units, an identifier gets no percentiles, every column a label, no local path, Table I no repeated row and a
reason where SA-MRO's figures equal CHM's, and the main findings first. All read one report (``real_report``)."""

import html as htmllib
import json
import re
import shutil
import subprocess

import pytest

# every test here reads one report built with the real flights (a session fixture of about a minute)
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def page(real_report) -> str:
    out, _ = real_report
    return (out / "report.html").read_text()


def text_of(page: str) -> str:
    """The page's visible text: no images, no style, tags as spaces."""
    page = re.sub(r"<style>.*?</style>|data:image/png;base64,[A-Za-z0-9+/=]+", " ", page, flags=re.S)
    return htmllib.unescape(re.sub(r"<[^>]+>", " ", page))


def section(page: str, heading: str) -> str:
    """The HTML of the section under the first <h2> that starts with ``heading``, up to the next <h2>."""
    start = re.search(rf"<h2 id=s\d+>{re.escape(heading)}", page)
    assert start, heading
    end = page.find("<h2", start.end())
    return page[start.start() : end if end > 0 else len(page)]


def rows(table_html: str) -> list[list[str]]:
    return [
        [htmllib.unescape(c) for c in re.findall(r"<t[dh]>(.*?)</t[dh]>", r)]
        for r in re.findall(r"<tr>(.*?)</tr>", table_html)
    ]


def test_the_notes_name_the_view_every_figure_shows(page):
    notes = text_of(section(page, "Notes"))
    assert "Contributions are to the chosen action's Q-value" not in notes
    assert "margin of the chosen action's Q-value over the runner-up's" in notes
    assert "contribution to the margin over the runner-up" in page  # the figures' captions


def test_numbers_are_readable_and_the_buffer_has_a_unit(page):
    shown = text_of(page)
    big = re.findall(r"\S*\d(?:\.\d+)?e\+\d\d\S*", shown)  # 2.391e+06: a number no reader reads at a glance
    assert not big, big[:5]
    cards = [r for r in rows(section(page, "Narrated decisions")) if r and r[0] == "buffer_queue_size"]
    assert cards and all(r[1].endswith("% full") for r in cards), cards
    quantiles = {r[0]: r for r in rows(section(page, "Real states in the training distribution"))}
    assert all(v.endswith("% full") for v in quantiles["buffer_queue_size"][1:7]), quantiles["buffer_queue_size"]
    assert quantiles["rsrp_0"][2].endswith(" dBm")


def test_an_identifier_gets_no_percentiles(page):
    quantiles = [r[0] for r in rows(section(page, "Real states in the training distribution"))]
    assert "rsrp_0" in quantiles and "serving_bs" not in quantiles


def test_every_column_has_a_label(page):
    headers = re.findall(r"<tr>((?:<th>.*?</th>)+)</tr>", page)
    assert headers and all("<th></th>" not in h for h in headers)


def test_no_local_path_is_printed(page, real_report):
    _, real = real_report
    shown = text_of(page)
    assert str(real) not in page and str(real.parent.parent) not in page
    assert "real flights from ukm" in shown  # the folder, by name


def test_table_one_repeats_no_row_and_says_why_sa_mro_equals_chm(page):
    table = rows(section(page, "Table I"))
    labels = [r[0] for r in table[1:]]
    assert len(set(labels)) == len(labels)
    pingpong = [tuple(r[1:]) for r in table[1:] if "ping-pong share" in r[0]]
    assert len(set(pingpong)) == len(pingpong), "two ping-pong rows repeat the same figures"
    sa, chm = ([r[table[0].index(n)] for r in table[1:]] for n in ("SA-MRO", "CHM"))
    notes = text_of(section(page, "Notes"))
    assert sa == chm and "SA-MRO's figures equal CHM's on Table I's 8 simulated flights" in notes
    assert "so its offsets never left CHM's" in notes


def test_the_open_loop_rows_that_equal_each_other_are_explained(page):
    table = {r[0].split(" ")[0]: r[1:] for r in rows(section(page, "Open-loop agreement"))}
    assert table["CHM"] == table["SA-MRO"]
    notes = text_of(section(page, "Notes"))
    assert "SA-MRO's figures equal CHM's on the 2 real flights' samples" in notes
    assert "it counted 0 too-early, 0 too-late and 0 wrong-cell handovers and 0 ping-pongs" in notes


def test_the_main_finding_comes_first_with_contents(page):
    assert (
        page.index("Figure 2 finding (buffer first") < page.index("<nav class=toc>") < page.index("<h2 id=s2>Settings")
    )
    toc = page[page.index("<nav class=toc>") : page.index("</nav>")]
    for heading in ("Table I", "Calibration", "Open-loop agreement", "Narrated decisions", "Notes"):
        assert f">{heading}" in toc, heading


def test_report_with_real_data(real_report):
    """Its sections with the real flights, and both datasets explained (in this file: the one report built once)."""
    out, _ = real_report
    html = (out / "report.html").read_text()
    assert "Calibration: handovers per minute by altitude band (2 real flights" in html and "Baltaci" in html
    assert "Open-loop agreement with the live network" in html and "Spearman rank correlation real vs simulated" in html
    assert "finding (buffer first, position second)" in html
    datasets = {json.loads(x)["dataset"] for x in (out / "explanations.jsonl").read_text().splitlines()}
    assert datasets == {"simulated", "real"}


def test_the_report_says_what_it_is_doing(real_report):
    """`make demo` printed nothing for 97 s, then for 124 s: each long step is said (every 10 s while it runs:
    tests/test_progress.py), the plugin's own steps inside the command's."""
    out, _ = real_report
    lines = (out.parent / "stderr.txt").read_text().splitlines()
    said = [line for line in lines if line.startswith("xairl: ") and not line.startswith("xairl: still ")]
    starts = [line[len("xairl: ") : -len(" ...")] for line in said if line.endswith(" ...")]
    steps = [
        "reading the real flights",
        "building the uav-handover report's content",
        "Table I: CHM, SA-MRO and the DQN on 4 simulated flights",
        "comparing with the real flights (calibration, agreement)",
        "simulating 16 flights: the states the real ones are compared with",
        "simulating handovers per altitude band (calibration)",
        "replaying the real flights open-loop (agreement)",
        "simulating handovers by altitude (the figure)",
        "simulating and explaining the flights at a glance",
        "explaining (deep_shap) 30 simulated states",
        "explaining (deep_shap) 30 real states",
        "drawing the figures",
        "narrating 6 decisions",
    ]
    quick = {"reading the real flights", "replaying the real flights open-loop (agreement)"}  # a fraction of a
    quick |= {s for s in steps if s.startswith(("explaining", "simulating and"))}  # second: said when in time
    assert starts == [s for s in steps if s in starts], said  # in this order, each once
    assert set(steps) - set(starts) <= quick, said  # every step of a second or more is said
    assert all(any(line.startswith(f"xairl: {s}: done in ") for line in said) for s in starts), said


@pytest.mark.skipif(not shutil.which("chromium"), reason="chromium is not installed")
def test_report_renders_in_headless_chromium(real_report, tmp_path):
    out, _ = real_report
    shot = tmp_path / "shot.png"
    browser = ["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run"]
    browser += ["--disable-background-networking", "--disable-component-update", "--disable-sync"]
    browser += [f"--user-data-dir={tmp_path / 'profile'}", f"--screenshot={shot}", "--window-size=1200,2000"]
    subprocess.run([*browser, (out / "report.html").as_uri()], check=True, capture_output=True, timeout=120)
    assert shot.stat().st_size > 20_000


@pytest.mark.parametrize(
    "statuses, verdict",
    [
        (("verified",), "verified"),
        (("contradicted",), "contradicted"),
        (("verified", "unchecked"), "partly checked (coverage 50 %)"),
    ],
)
def test_a_flight_at_a_glance_says_its_verdict_and_account(statuses, verdict):
    """The caption says the summary's verdict (was: 'verified' or 'NOT verified') and its account of the importance."""
    from xairl.verification.result import Claim, SentenceCheck, Verification
    from xairl_uav_handover.report import glance_caption

    account = "its 2 features carry 61 % of the mean |contribution| over 600 states; 3 more features are left out"
    check = Verification(
        (SentenceCheck("A.", tuple(Claim("number", str(k), st) for k, st in enumerate(statuses))),), account=account
    )
    caption = glance_caption("simulated flight 1", "It handed over twice.", check)
    assert caption == f"Flight at a glance: simulated flight 1. It handed over twice. [verdict: {verdict}; {account}]"
