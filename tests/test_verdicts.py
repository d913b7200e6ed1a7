"""Three verdicts on every surface (issue 65): verified, contradicted, or partly checked with its coverage, and beside
each the account of the margin, in the API (a Narrative), its evidence and notebook card, the HTML report, the review
page and its store (an old store still opens), and ``xairl explain --narrate`` / ``xairl review``."""

import json
import re
import sqlite3

import pytest

import xairl
from tests.conftest import run
from xairl.explanations.evidence import card_html, verdict_text
from xairl.narrators.base import Narrative, Narrator
from xairl.outputs.feedback import FeedbackStore
from xairl.outputs.report_html import page as report_page
from xairl.outputs.review import page as review_page
from xairl.templates.tracking import Rendered
from xairl.toy import toy_policy
from xairl.verification.result import Claim, SentenceCheck, Verification

ACCOUNT = "its 1 feature accounts for +0.9 of the margin 2.1 (a over b; base +1.2); 2 more features pushed against it"


def _check(*statuses: str, account: str = "") -> Verification:
    """A verification of one sentence per status ('verified', 'contradicted', 'unchecked')."""
    return Verification(
        tuple(SentenceCheck(f"S{k}.", (Claim("number", str(k), st),)) for k, st in enumerate(statuses)),
        account=account,
    )


def _narrative(check: Verification) -> Narrative:
    return Narrative(
        "S0. S1.",
        check.claims,
        check.ok,
        0.5,
        {},
        "template",
        "t",
        0,
        sentences=tuple((s.text, s.status) for s in check.sentences),
        status=check.status,
        coverage=check.coverage,
        account=check.account,
    )


@pytest.fixture(scope="module")
def narrated():
    policy = toy_policy()
    exp = xairl.explain(policy, policy.background(2, seed=4), background=policy.background(40))
    return xairl.narrate(exp, 0, policy=policy, robustness=False), policy


@pytest.mark.parametrize(
    "statuses, verdict, words",
    [
        (("verified", "verified"), "verified", "verified"),
        (("verified", "contradicted"), "contradicted", "contradicted"),
        (("verified", "unchecked"), "partly checked", "partly checked (coverage 50 %)"),
    ],
)
def test_a_narrative_its_card_and_the_report_say_the_verdict(statuses, verdict, words):
    n = _narrative(_check(*statuses, account=ACCOUNT))
    assert n.status == verdict and n.verified == (verdict == "verified")
    assert verdict_text(n.status, n.coverage) == words
    for html in (
        n._repr_html_(),
        card_html(
            n.text,
            {
                "sentences": [list(s) for s in n.sentences],
                "status": verdict,
                "coverage": n.coverage,
                "account": ACCOUNT,
            },
        ),
    ):
        assert f"verdict: <b>{words}</b>" in html and ACCOUNT in html
    page = report_page(
        "t",
        findings=[],
        tables=[],
        notes=[],
        exps=[],
        figures=[],
        settings={},
        narratives=[(n, {"sentences": [list(s) for s in n.sentences]})],
    )
    assert f"verdict: <b>{words}</b> &middot; {ACCOUNT}" in page and "NOT verified" not in page
    assert "<b>partly checked</b> (nothing false; the coverage is" in page  # the marks' legend says all three


def test_a_narrative_without_a_status_reads_it_and_refuses_one_that_disagrees():
    sentences = (("S0.", "verified"), ("S1.", "contradicted"))
    assert Narrative("t", (), False, 0.0, {}, "s", "t", 0, sentences=sentences).status == "contradicted"
    assert Narrative("t", (), False, 0.0, {}, "s", "t", 0).status == "partly checked"
    assert Narrative("t", (), True, 0.5, {}, "s", "t", 0).status == "verified"
    with pytest.raises(xairl.errors.InputError, match="'verified' exactly when verified is true"):
        Narrative("t", (), False, 0.0, {}, "s", "t", 0, status="verified")


def test_a_narrative_of_several_outputs_takes_the_worst_verdict():
    """A continuous action's dimensions each have their verdict: contradicted, then partly checked, wins."""

    def told(*checks):
        words = [(Rendered(f"D{j}."), c, "template", None, 1) for j, c in enumerate(checks)]
        return Narrator()._told(words, 0.5, {}, "t", 0, "given")

    ok, partly, wrong = _check("verified"), _check("verified", "unchecked"), _check("contradicted")
    assert told(ok, ok).status == "verified" and told(ok, ok).verified
    n = told(ok, partly)
    assert (n.status, n.verified, n.coverage) == ("partly checked", False, pytest.approx(2 / 3))
    assert told(partly, wrong, ok).status == "contradicted"
    accounts = told(_check("verified", account="A one"), _check("verified", account="A two")).account
    assert accounts == "A one | A two"


def test_the_evidence_and_the_json_records_say_the_verdict_coverage_and_account(narrated, capsys):
    n, _ = narrated
    assert n.evidence["status"] == n.status and n.evidence["coverage"] == n.coverage
    assert n.evidence["account"] == n.account and n.account.startswith("its ")
    assert f"verdict: <b>{verdict_text(n.status, n.coverage)}</b>" in n._repr_html_()
    rc, out, err = run(
        capsys, "explain", "--n", "1", "--narrate", "--no-record", "--no-robustness", "--format", "jsonl"
    )
    rec = json.loads(out)
    assert rc == 0 and rec["verdict"] in ("verified", "contradicted", "partly checked"), err
    assert rec["verified"] == (rec["verdict"] == "verified") and 0 <= rec["coverage"] <= 1
    assert rec["account"].startswith("its ")
    rc, out, _ = run(capsys, "explain", "--n", "1", "--narrate", "--no-record", "--no-robustness")
    head = out.splitlines()[0]
    assert re.match(r"state 0 \[(verified|contradicted|partly checked \(coverage \d+ %\)), confidence", head), head
    assert "NOT VERIFIED" not in out and "\n    account: its " in out


def test_the_review_page_and_listing_say_the_verdict(narrated, tmp_path, capsys, monkeypatch):
    n, policy = narrated
    store = FeedbackStore(tmp_path / "fb.sqlite")
    store.record(n, policy)
    store.record(_narrative(_check("verified", "contradicted", account=ACCOUNT)))
    first, second = store.records()
    assert (first.verdict, first.coverage, first.account) == (n.status, n.coverage, n.account)
    assert second.verdict == "contradicted" and second.account == ACCOUNT
    html = review_page(store, "t")
    assert f"verdict: <b>{verdict_text(n.status, n.coverage)}</b>" in html and "verdict: <b>contradicted</b>" in html
    assert ACCOUNT in html
    monkeypatch.setattr("builtins.input", lambda *_: "s")  # skip each narrative
    rc, out, _ = run(capsys, "review", "--db", str(tmp_path / "fb.sqlite"))
    assert rc == 0 and f"{verdict_text(n.status, n.coverage)}" in out and f"account: {ACCOUNT}" in out
    assert "contradicted: 1 claim(s) not verified]" in out


def test_a_store_from_before_the_three_verdicts_opens_and_reads_them(tmp_path, capsys):
    """An old store (no evidence, verdict, coverage nor account column) gains the columns; its rows read their verdict
    from ``verified`` and their evidence's sentences."""
    path = tmp_path / "old.sqlite"
    db = sqlite3.connect(path)
    db.execute(
        "CREATE TABLE narratives (id INTEGER PRIMARY KEY AUTOINCREMENT, created REAL NOT NULL, policy TEXT, "
        "model_hash TEXT, template TEXT, source TEXT, method TEXT, state_index INTEGER, text TEXT NOT NULL, "
        "claims TEXT NOT NULL, verified INTEGER NOT NULL, confidence REAL NOT NULL, status TEXT NOT NULL DEFAULT "
        "'pending', correction TEXT, reviewed REAL)"
    )
    for verified in (1, 0):
        db.execute(
            "INSERT INTO narratives (created, text, claims, verified, confidence) VALUES (0, 'A.', '[]', ?, 0.5)",
            (verified,),
        )
    db.commit()
    db.close()
    store = FeedbackStore(path)
    assert [r.verdict for r in store.records()] == ["verified", "partly checked"]
    with sqlite3.connect(path) as db:  # an old row with evidence: a contradicted sentence says contradicted
        ev = {"sentences": [["A.", "contradicted"]], "verified": False}
        db.execute("UPDATE narratives SET evidence = ? WHERE id = 2", (json.dumps(ev),))
    assert store.records()[1].verdict == "contradicted" and store.records()[1].coverage is None
    store.record(_narrative(_check("verified", "unchecked", account=ACCOUNT)))
    new = store.records()[2]
    assert (new.verdict, new.coverage, new.account) == ("partly checked", 0.5, ACCOUNT)
    assert "partly checked (coverage 50 %)" in review_page(store, "t")


@pytest.mark.parametrize(
    "ev, verdict",
    [
        ({"sentences": [["A.", "verified"], ["B.", "none"]]}, "verified"),
        ({"sentences": [["A.", "verified"], ["B.", "unchecked"]]}, "partly checked"),
        ({"sentences": [["A.", "contradicted"]], "verified": False}, "contradicted"),
        ({"sentences": [], "verified": True}, "verified"),
        ({"sentences": []}, "partly checked"),
    ],
)
def test_a_card_without_a_recorded_verdict_reads_it_from_its_sentences(ev, verdict):
    assert f"verdict: <b>{verdict}</b>" in card_html(" ".join(s for s, _ in ev["sentences"]) or "A.", ev)
