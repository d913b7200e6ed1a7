"""Issue 52: a template's line breaks (a sentence written as a YAML block scalar, a bullet list) survive rendering,
the terminal's marked rows (``xairl explain --narrate``, ``xairl review``) and the HTML card (the report, Jupyter,
the review page), with the HTML still escaped."""

import io
import json
import re
from html.parser import HTMLParser

import pytest

import xairl
from tests.conftest import run
from xairl.cli import main
from xairl.cli.explain import marked_rows
from xairl.explanations.evidence import card_html, sentence_lines
from xairl.outputs.feedback import FeedbackStore
from xairl.outputs.report import ReportContent, ReportRequest, write_report
from xairl.outputs.review import page
from xairl.toy import toy_policy

#: one plain sentence, then one sentence of several lines: a heading with characters HTML must escape and a list
#: whose items have two sentences each
LISTED = """\
name: listed
kind: decision
sentences:
  - ["The policy {{ action|role('chose') }} {{ action }} {{ runner_up|role('', 'over') }} {{ runner_up }}."]
  - - |
      Reasons <why> & how:
      {% for f in margin_top %}
      - {{ f.label }} moved the margin by {{ f.contribution|signed }}. It is item {{ loop.index }}.
      {% endfor %}
"""
HEADING = "Reasons <why> & how:"
ITEM = re.compile(r"- .+ moved the margin by [-+]\d\.\d+\. It is item (\d)\.")


@pytest.fixture
def listed(tmp_path):
    """(narrative of state 0 with the 'listed' template, its policy, the prompts folder)."""
    (tmp_path / "listed.yaml").write_text(LISTED)
    p = toy_policy()
    exp = xairl.explain(p, p.background(2, seed=3), background=p.background(30))
    n = xairl.narrate(exp, 0, template="listed", policy=p, robustness=False, prompt_dirs=[tmp_path])
    return n, p, tmp_path


def check_lines(lines: list[str]) -> None:
    """The narrative's lines, as the text has them: the first sentence, the heading, one line per list item."""
    assert lines[0].startswith("The policy chose ") and lines[1] == HEADING, lines
    assert len(lines) >= 4, lines  # at least two items
    for k, line in enumerate(lines[2:], 1):
        m = ITEM.fullmatch(line)
        assert m and m.group(1) == str(k), line


def test_the_text_keeps_the_template_lines(listed):
    n, _, _ = listed
    check_lines(n.text.split("\n"))
    assert n.source == "template" and dict(n.sentences)[HEADING] == "none"  # (a heading states nothing)
    items = [s for s, _ in n.sentences if s.startswith("It is item")]  # an item's sentences are two sentences
    assert items == [f"It is item {k}." for k in range(1, len(n.text.split("\n")) - 1)]


def terminal_lines(rows: list[str]) -> list[tuple[str, str]]:
    """(mark, row's words) per row of marked rows, checked to be aligned: the mark in columns 4-16, the words from
    column 18 on."""
    out = []
    for row in rows:
        mark = row[4:17].strip()
        assert row[:4] == "    " and row[4:18] == f"{mark:<13} " and row[18:].strip(), row
        out.append((mark, row[18:]))
    return out


def check_rows(rows: list[str], text: str) -> None:
    """A row per sentence: each list item on its own row with its bullet and mark, its second sentence indented
    under the item's words; joined back line by line, the rows are the text's lines."""
    shown = terminal_lines([r for r in rows if not r.startswith("    account: ")])
    assert shown[0][0] == "verified" and shown[1] == ("(no claim)", HEADING)
    lines, items = [], 0
    for mark, words in shown:
        assert mark in ("verified", "(no claim)"), (mark, words)
        if words.startswith("  "):  # a sentence after the one before on its line
            assert words.startswith("  It is item") and lines[-1].startswith("- ")
            lines[-1] += " " + words.strip()
        else:
            items += words.startswith("- ")
            lines.append(words)
    assert lines == text.split("\n") and items == len(lines) - 2


def test_the_explain_command_prints_each_line_of_the_list_with_its_mark(listed, capsys):
    _, _, prompts = listed
    args = ("explain", "--n", "1", "--narrate", "--no-record", "--no-robustness", "--prompts", str(prompts))
    rc, out, err = run(capsys, *args, "--template", "listed")
    assert rc == 0, err
    rc, js, err = run(capsys, *args, "--template", "listed", "--format", "jsonl")
    assert rc == 0, err
    text = json.loads(js)["text"]
    check_lines(text.split("\n"))
    head, *rows = out.splitlines()
    assert head.startswith("state 0 [")
    check_rows(rows, text)


def test_marked_rows_of_the_narrative(listed):
    n, _, _ = listed
    rows = marked_rows(n.text, n.sentences).split("\n")
    check_rows(rows, n.text)
    assert rows[2].startswith("    verified      - ") and rows[3].startswith("    (no claim)      It is item 1.")


def test_marked_rows_of_prose_are_as_before():
    """No line break: a sentence per row after its mark, nothing indented (what the CLI always printed)."""
    sentences = (("The policy chose left.", "verified"), ("Speed was high.", "contradicted"), ("Look.", "unchecked"))
    assert marked_rows("The policy chose left. Speed was high. Look.", sentences).split("\n") == [
        "    verified      The policy chose left.",
        "    CONTRADICTED  Speed was high.",
        "    unchecked     Look.",
    ]


def test_marked_rows_edge_cases():
    # a numbered list: the second sentence of an item under its words; a blank line is a blank row
    text = "Why:\n1. Speed rose. It rose fast.\n\n2. Angle fell."
    sentences = [("Why:", "unchecked"), ("1. Speed rose.", "verified"), ("It rose fast.", "unchecked")]
    sentences.append(("2. Angle fell.", "verified"))
    assert marked_rows(text, sentences).split("\n") == [
        "    unchecked     Why:",
        "    verified      1. Speed rose.",
        "    unchecked        It rose fast.",
        "",
        "    verified      2. Angle fell.",
    ]
    # a bullet the verifier left on the sentence (after a full stop) and one it took off: the same row
    text = "A.\n- b one.\n- c two."
    assert sentence_lines(text, [("A.", "verified"), ("- b one.", "verified"), ("c two.", "verified")]) == [
        (0, "", "A.", "verified"),
        (1, "-", "b one.", "verified"),
        (1, "-", "c two.", "verified"),
    ]
    # no sentences: the text's own lines, indented; sentences that are not the text's: a row each, as before
    assert marked_rows("one\ntwo", []) == "    one\n    two"
    assert marked_rows("other words", [("a\nb", "unchecked"), ("c", "verified")]).split("\n") == [
        "    unchecked     a",
        "                  b",
        "    verified      c",
    ]


class Narratives(HTMLParser):
    """The lines of each <p class=narrative>: (words, [status of each sentence span starting on the line])."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.paragraphs, self.inside = [], False

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "p" and a.get("class") == "narrative":
            self.inside = True
            self.paragraphs.append([["", []]])
        elif self.inside and tag == "br":
            self.paragraphs[-1].append(["", []])
        elif self.inside and tag == "span":
            self.paragraphs[-1][-1][1].append(a["class"].split()[1])
        elif self.inside:
            assert tag == "sup", tag  # nothing from the text became a tag

    def handle_endtag(self, tag):
        if tag == "p":
            self.inside = False

    def handle_data(self, data):
        if self.inside:
            self.paragraphs[-1][-1][0] += data

    @classmethod
    def of(cls, page: str) -> list[list[tuple[str, list[str]]]]:
        parser = cls()
        parser.feed(page)
        return [[(" ".join(words.split()), marks) for words, marks in p] for p in parser.paragraphs]


def check_card(lines: list[tuple[str, list[str]]], text: str) -> None:
    """The card's lines are the text's, each sentence followed by its mark (✓ or ?)."""
    marks = {"verified": "\u2713", "unchecked": "?", "none": ""}
    expected = []
    for line in text.split("\n"):
        sentences = re.split(r"(?<=[.:])\s+(?=[A-Z])", line)
        sentences[0] = sentences[0].removeprefix("- ")
        expected.append(sentences)
    assert len(lines) == len(expected), lines
    for (words, statuses), sentences, line in zip(lines, expected, text.split("\n")):
        assert len(statuses) == len(sentences), (words, statuses)
        bullet = "- " if line.startswith("- ") else ""
        assert words == bullet + " ".join(f"{s} {marks[st]}".rstrip() for s, st in zip(sentences, statuses)), words
    assert lines[1] == (HEADING, ["none"])


def test_the_card_has_a_line_break_between_the_lines_and_stays_escaped(listed):
    n, _, _ = listed
    html = card_html(n.text, n.evidence)
    assert "Reasons &lt;why&gt; &amp; how:" in html and "<for>" not in html
    assert html.count("<br>") == len(n.text.split("\n")) - 1
    (lines,) = Narratives.of(html)
    check_card(lines, n.text)
    (lines,) = Narratives.of(n._repr_html_())  # Jupyter's view is the same card
    check_card(lines, n.text)


def test_the_card_escapes_a_sentence_that_looks_like_a_line_break():
    html = card_html("A <br> B.\nC.", {"sentences": [["A <br> B.", "unchecked"], ["C.", "verified"]]})
    assert "A &lt;br&gt; B." in html and html.count("<br>") == 1
    assert Narratives.of(html) == [[("A <br> B. ?", ["unchecked"]), ("C. \u2713", ["verified"])]]
    # a narrative without sentences: its own lines, escaped
    html = card_html("one <b>\ntwo", {"verified": True})
    assert Narratives.of(html) == [[("one <b>", ["verified"]), ("two \u2713", [])]]


def test_the_report_card_keeps_the_lines(listed, tmp_path):
    _, p, prompts = listed
    req = ReportRequest(
        tmp_path / "report",
        template="listed",
        prompt_dirs=[prompts],
        n_narrated=1,
        robustness=False,
        progress=False,
        records=False,
    )
    path = write_report(req, ReportContent("toy", p, p.background(30), [("states", p.background(2, seed=3))]))
    html = path.read_text()
    assert "Reasons &lt;why&gt; &amp; how:" in html and "<for>" not in html
    cards = [lines for lines in Narratives.of(html) if len(lines) > 1 and lines[1][0] == HEADING]
    assert len(cards) == 1
    text = "\n".join(words.replace(" \u2713", "").replace(" ?", "") for words, _ in cards[0])
    check_lines(text.split("\n"))
    check_card(cards[0], text)


def test_the_review_page_and_the_terminal_review_keep_the_lines(listed, tmp_path, capsys, monkeypatch):
    n, p, _ = listed
    store = FeedbackStore(tmp_path / "fb.sqlite")
    rid = store.record(n, p)
    (lines,) = Narratives.of(page(store, "token"))
    check_card(lines, n.text)
    monkeypatch.setattr("sys.stdin", io.StringIO("q\n"))
    assert main(["review", "--db", str(store.path)]) == 0
    shown = capsys.readouterr().out.splitlines()
    start = next(i for i, row in enumerate(shown) if row.startswith(f"#{rid} ")) + 1
    rows = [row for row in shown[start:] if not row.startswith("    account: ")]
    check_rows(rows[: len(n.sentences)], n.text)
    store.review(rid, "corrected", "First line <i>.\r\nSecond line.")  # the page's textarea sends CRLF
    html = page(store, "token", show_all=True)
    assert "correction: <i>First line &lt;i&gt;.<br>Second line.</i>" in html
