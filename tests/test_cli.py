import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import xairl
from tests.conftest import one_line_error, run
from xairl.cli import main
from xairl.toy import FEATURES, toy_policy


def test_help_does_not_import_heavy_libraries():
    code = (
        "import sys\nfrom xairl.cli import main\ntry:\n    main(['--help'])\nexcept SystemExit:\n    pass\n"
        "print([m for m in ('torch', 'shap', 'transformers', 'captum') if m in sys.modules])"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert "explain" in out and out.strip().endswith("[]")


def test_plugins_and_attributors(capsys):
    rc, out, _ = run(capsys, "plugins")
    assert rc == 0 and "xairl" in out and "deep_shap" in out and "toy" in out
    rc, out, _ = run(capsys, "attributors", "--json")
    rows = {r["name"]: r for r in json.loads(out)}
    assert set(rows) >= {"deep_shap", "exact", "kernel_shap", "integrated_gradients"}
    assert "n_steps" in rows["integrated_gradients"]["options"]["properties"]
    assert rows["exact"]["options"]["additionalProperties"] is False


def test_explain_csv_jsonl_matches_api(tmp_path, capsys):
    policy = toy_policy()
    states = policy.background(3, seed=9)
    csv = tmp_path / "s.csv"
    csv.write_text(",".join(FEATURES) + "\n" + "\n".join(",".join(map(repr, r.tolist())) for r in states) + "\n")
    bg = tmp_path / "bg.npy"
    np.save(bg, policy.background(20))
    rc, out, err = run(
        capsys, "explain", "--states", str(csv), "--background", str(bg), "--method", "exact", "--format", "jsonl"
    )
    assert rc == 0, err
    recs = [json.loads(line) for line in out.splitlines()]
    ref = xairl.explain(policy, states, background=np.load(bg), method="exact")
    assert len(recs) == 3
    for i, rec in enumerate(recs):
        assert rec["chosen"] == ref.action_names[ref.chosen[i]]
        for j, f in enumerate(FEATURES):
            assert rec["values"][f][rec["chosen"]] == pytest.approx(ref.values[i, j, ref.chosen[i]], abs=1e-9)


def test_narration_marks_each_sentence(tmp_path, capsys):
    """A customised template with a sentence that claims nothing checkable: the CLI says so, line by line and in
    JSONL, and the narrative is shown as verified only while coverage stays above the threshold."""
    src = (Path(xairl.__file__).parents[1] / "prompts" / "explain_action.yaml").read_text()
    extra = '  - - "Operators should keep an eye on this state."\n'
    (tmp_path / "explain_action.yaml").write_text(src.rstrip("\n") + "\n" + extra)
    args = ("explain", "--n", "1", "--narrate", "--no-record", "--no-robustness", "--prompts", str(tmp_path))
    rc, out, err = run(capsys, *args)
    assert rc == 0, err
    lines = out.splitlines()
    assert lines[0].startswith("state 0 [verified")
    lines = [line for line in lines if not line.startswith("    account: ")]
    assert lines[-1].split() == ["(no", "claim)", "Operators", "should", "keep", "an", "eye", "on", "this", "state."]
    assert all(line.split()[0] == "verified" for line in lines[1:-1]) and len(lines) >= 3
    rc, out, err = run(capsys, *args, "--format", "jsonl")
    rec = json.loads(out)
    assert [s["status"] for s in rec["sentences"]][-1] == "none"  # (it states nothing to check)
    assert rec["text"].endswith("Operators should keep an eye on this state.")
    assert {s["status"] for s in rec["sentences"][:-1]} == {"verified"}


def test_explain_table_and_options(capsys):
    rc, out, err = run(
        capsys,
        "explain",
        "--n",
        "2",
        "--method",
        "integrated_gradients",
        "-o",
        "n_steps=16",
        "-o",
        "method=riemann_left",
        "--top",
        "2",
    )
    assert rc == 0, err
    assert out.count(": chose ") == 2 and "integrated_gradients" in out
    assert out.startswith("contributions to the margin") and out.count("expected margin") == 2
    rc, out, err = run(capsys, "explain", "--n", "2", "--top", "2", "--view", "score")
    assert out.startswith("contributions to the chosen action's score") and out.count("additivity gap") == 2


def test_version_and_examples(capsys):
    from importlib.metadata import version

    with pytest.raises(SystemExit):
        main(["--version"])
    assert capsys.readouterr().out.strip().startswith(f"xairl {version('xairl')}")
    for argv in (["--help"], ["explain", "--help"], ["verify", "--help"]):
        with pytest.raises(SystemExit):
            main(argv)
        assert "examples:" in capsys.readouterr().out


@pytest.mark.parametrize(
    "argv, match",
    [
        (["explain", "--method", "shapley"], "unknown attributor 'shapley'"),
        (["explain", "--policy", "nope"], "unknown policy 'nope'"),
        (["explain", "-o", "foo=1"], "foo: unknown option"),
        (["explain", "-o", "novalue"], "is not key=value"),
        (["explain", "--method", "exact", "-o", "max_rows=-3"], "max_rows"),
        (["explain", "--states", "/nonexistent.csv"], "no such file"),
        # -n is --narrator-option: `-n 3` once explained the default 5 states, and with --narrate named -o
        (
            ["explain", "-n", "3"],
            "-n/--narrator-option: '3' is not key=value; write e.g. -n audience=operator; to explain 3",
        ),
        (["explain", "-n", "3", "--narrate"], "to explain 3 states, write --n 3"),
        (["explain", "--narrate", "-n", "operator"], "'operator' is not key=value; write e.g. -n audience=operator;"),
    ],
)
def test_user_errors_are_one_line_exit_2(capsys, argv, match):
    rc, out, err = run(capsys, *argv)
    assert rc == 2
    assert match in err and err.count("\n") == 1 and "Traceback" not in err


@pytest.mark.parametrize(
    "content, match",
    [
        ("battery,distance\n1,2\n", "lack column"),
        (",".join(FEATURES) + "\n1,2,nan,4,5\n", "NaN/inf"),
        (",".join(FEATURES) + "\n1,2,three,4,5\n", "'three' is not a number"),
    ],
)
def test_bad_state_files(tmp_path, capsys, content, match):
    p = tmp_path / "s.csv"
    p.write_text(content)
    rc, _, err = run(capsys, "explain", "--states", str(p))
    assert rc == 2 and match in err and "Traceback" not in err


def test_background_of_wrong_width(tmp_path, capsys):
    bg = tmp_path / "bg.npy"
    np.save(bg, np.zeros((4, 3)))
    rc, _, err = run(capsys, "explain", "--background", str(bg))
    assert rc == 2 and "has 3 features but the policy expects 5" in err


@pytest.mark.slow
def test_installed_script_smoke():
    exe = shutil.which("xairl", path=str(Path(sys.executable).parent)) or shutil.which("xairl")
    assert exe, "the console script `xairl` is not installed"
    res = subprocess.run(
        [exe, "explain", "--n", "1", "--format", "jsonl"],
        capture_output=True,
        text=True,
        env={**os.environ, "XAIRL_DEBUG": ""},
        timeout=120,
    )
    assert res.returncode == 0, res.stderr
    assert json.loads(res.stdout)["method"] == "deep_shap"


def test_verify_trace_names_the_reading_of_each_claim(tmp_path, capsys):
    exp = xairl.Explanation(
        values=np.array([[[0.3], [-0.2]]]),
        base_values=np.zeros((1, 1)),
        outputs=np.array([[0.1]]),
        states=np.array([[1.0, 2.0]]),
        feature_names=("speed", "load"),
        action_names=("risk",),
        method="given",
        output="value",
    )
    path = tmp_path / "exp.json"
    path.write_text(exp.to_json())
    rc, out, _ = run(
        capsys, "verify", "Speed raised the risk by 0.3 over the last 30 days.", "--explanation", str(path), "--trace"
    )
    assert rc == 0 and "verdict: verified" in out  # ('30 days' is a span of time: no claim about the decision)
    assert "number.subject-by" in out and "skip.span" in out and "a span of time" in out
    assert "  number.subject-by: a number bound by " in out  # (what each reading that fired is, from the table)
    rc, out, _ = run(capsys, "verify", "The load lowered it by 0.5.", "--explanation", str(path))
    assert rc == 1 and out.startswith("[contradicted]") and "verdict: contradicted" in out
    rc, _, err = run(capsys, "verify", "x", "--explanation", str(tmp_path / "missing.json"))
    assert rc == 2 and err.count("\n") == 1 and "--explanation" in err
    rc, _, err = run(capsys, "verify", "x", "--explanation", str(path), "--index", "3")
    assert rc == 2 and "--index 3" in err


@pytest.fixture(scope="module")
def report_dir(tmp_path_factory):
    """``xairl explain --n 3 --out DIR`` under the umask 022: DIR holds explanations.jsonl and the report."""
    out = tmp_path_factory.mktemp("report") / "r"
    mask = os.umask(0o022)
    try:
        assert main(["explain", "--n", "3", "--out", str(out), "--background-size", "10"]) == 0
    finally:
        os.umask(mask)
    return out


def test_output_files_get_the_umasks_permissions_so_a_report_can_be_shared(report_dir, tmp_path):
    """mkstemp made every file -rw-------: a report no web server or colleague could read."""
    from xairl.runs.files import write_text

    modes = {p.name: p.stat().st_mode & 0o777 for p in report_dir.iterdir()}
    assert {"report.html", "explanations.jsonl"} <= modes.keys() and set(modes.values()) == {0o644}, modes
    mask = os.umask(0o027)
    try:
        write_text(tmp_path / "shared.txt", "x")
    finally:
        os.umask(mask)
    assert (tmp_path / "shared.txt").stat().st_mode & 0o777 == 0o640


def test_verify_reads_the_records_that_explain_out_writes(report_dir, capsys):
    """`xairl verify --explanation DIR/explanations.jsonl` once failed with "Extra data: line 2": a record is chosen
    with --index, and a file of several records without one is refused, saying how many it holds."""
    path = str(report_dir / "explanations.jsonl")
    records = [json.loads(line) for line in (report_dir / "explanations.jsonl").read_text().splitlines()]
    rec = records[1]
    margin = {f: v[rec["chosen"]] - v[rec["runner_up"]] for f, v in rec["values"].items()}
    top = max(margin, key=lambda f: abs(margin[f]))
    verb = "raised" if margin[top] > 0 else "lowered"
    said = f"{top.capitalize()} {verb} the margin by {abs(margin[top]):.2f}. The policy chose {rec['chosen']}."
    rc, out, _ = run(capsys, "verify", said, "--explanation", path, "--index", "1")
    assert rc == 0 and out.count("[verified]") == 2 and "verdict: verified" in out, out
    wrong = f"{top.capitalize()} {verb} the margin by {abs(margin[top]) + 1:.2f}."
    rc, out, _ = run(capsys, "verify", wrong, "--explanation", path, "--index", "1")
    assert rc == 1 and out.startswith("[contradicted]")
    rc, _, err = run(capsys, "verify", said, "--explanation", path)
    one_line_error(rc, err, "holds 3 records", "--index 0..2")
    rc, _, err = run(capsys, "verify", said, "--explanation", path, "--index", "3")
    one_line_error(rc, err, "--index 3", "holds 3 record(s)")


def test_verify_says_the_verdict_and_its_exit_status_says_which(tmp_path, capsys):
    """Three verdicts, three exit statuses (issue 65): 0 verified, 1 contradicted, 3 partly checked (with the
    coverage); 2 stays a usage error. Real texts about the toy policy's decision: its feature pushing hardest against
    the choice, said rightly, said the wrong way, and said rightly beside a number that is no fact of it. Each run
    prints the account: the features the text leaves out, with their sum (was: 'accurate: yes; ok: no', exit 0)."""
    policy = toy_policy()
    exp = xairl.explain(policy, policy.background(2, seed=3), background=policy.background(40))
    path = tmp_path / "exp.json"
    path.write_text(exp.to_json())
    margin = dict(zip(exp.feature_names, exp.margin()[0]))
    against = min(margin, key=margin.get)
    assert margin[against] < 0
    said = f"{against.capitalize()} lowered the margin by {-margin[against]:.2f}"
    left_out = sorted((f for f in margin if f != against), key=lambda f: -abs(margin[f]))
    cases = [
        (f"{said}.", 0, "verdict: verified"),
        (f"{against.capitalize()} raised the margin by {-margin[against]:.2f}.", 1, "verdict: contradicted"),
        (f"{said} while 731 birds flew past.", 3, "verdict: partly checked (coverage 67 %)"),  # 731 is no fact
    ]
    for text, code, verdict in cases:
        rc, out, err = run(capsys, "verify", text, "--explanation", str(path), "--index", "0")
        assert (rc, err) == (code, ""), out
        assert verdict in out.splitlines(), out
        account = next(line for line in out.splitlines() if line.startswith("account: "))
        assert account.startswith("account: its 1 feature accounts for ") and left_out[0] in account, account
    with pytest.raises(SystemExit):
        main(["verify", "--help"])
    out = capsys.readouterr().out
    assert "0 verified" in out and "1 contradicted" in out and "3 partly checked" in out


@pytest.mark.parametrize("status, code", [("verified", 0), ("contradicted", 1), ("partly checked", 3)])
def test_verify_exit_status_follows_the_verdict_alone(status, code, tmp_path, capsys, monkeypatch):
    """The exit status is the verdict's, whatever the reader (a stand-in verification of each verdict)."""
    import xairl.verification as verification
    from xairl.verification.result import Claim, SentenceCheck, Verification

    claim = {"verified": "verified", "contradicted": "contradicted", "partly checked": "unchecked"}[status]
    result = Verification((SentenceCheck("A.", (Claim("number", "1", claim), Claim("number", "2", "verified"))),))
    monkeypatch.setattr(verification, "verify", lambda *a, **k: result)
    exp = xairl.explain(toy_policy(), toy_policy().background(1), background=toy_policy().background(10))
    (tmp_path / "e.json").write_text(exp.to_json())
    rc, out, _ = run(capsys, "verify", "A.", "--explanation", str(tmp_path / "e.json"))
    words = {"partly checked": "partly checked (coverage 50 %)"}.get(status, status)
    assert rc == code and f"verdict: {words}" in out


def test_verify_names_a_file_of_narratives_for_what_it_is(tmp_path, capsys):
    """explain --narrate --format jsonl writes narratives, not explanations: verify says so (was: 'the explanation is
    not valid JSON (Extra data: line 2 ...)')."""
    rc, out, _ = run(capsys, "explain", "--policy", "toy", "--n", "2", "--format", "jsonl", "--narrate", "--no-record")
    assert rc == 0
    (tmp_path / "o.jsonl").write_text(out)
    rc, _, err = run(capsys, "verify", "x", "--explanation", str(tmp_path / "o.jsonl"), "--index", "0")
    one_line_error(rc, err, "holds narratives", "explanations.jsonl")


@pytest.mark.slow
def test_a_reader_that_stops_early_gets_no_error(tmp_path):
    """`xairl explain ... | head -2`: the pipe closes early; xairl stops quietly (141, as other tools), no
    'internal error: BrokenPipeError'."""
    import subprocess
    import sys

    proc = subprocess.Popen(
        [sys.executable, "-m", "xairl.cli", "explain", "--n", "300", "--no-robustness"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    proc.stdout.readline()
    proc.stdout.close()
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == 141 and "error" not in err, err
