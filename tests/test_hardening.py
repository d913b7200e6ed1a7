"""Issue 27, hardening round 2: each hostile input found from outside, refused with one line (exit status 2 from the
CLI), never a traceback, a wrong result marked verified, or a partial file. The review page's items are in
tests/test_review_page.py, the templates' in tests/test_prompts.py, the layers' in tests/test_layers.py and the fuzz
runs in tests/test_fuzz.py."""

import io
import json
import os
import signal
import subprocess
import sys
import textwrap
import zipfile

import numpy as np
import pytest

import xairl
from tests.conftest import one_line_error, run
from xairl.cli import main
from xairl.errors import InputError
from xairl.runs.inputs import read_states
from xairl.toy import FEATURES, toy_policy

POLICY = toy_policy()


# 1. non-finite results ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("method", ["deep_shap", "integrated_gradients", "kernel_shap", "exact"])
def test_states_that_overflow_the_network_are_refused_not_explained_as_nan(method):
    """Finite float32 states of 3e38 make the network output inf/NaN; every method returned an Explanation of NaN and
    narrate() wrote 'score nan ... margin of nan' marked verified."""
    states = np.full((2, len(FEATURES)), 3e38, dtype=np.float32)
    with pytest.raises(InputError, match="NaN or infinite for 2 state"):
        xairl.explain(POLICY, states, background=POLICY.background(20), method=method)


def test_an_explanation_of_non_finite_numbers_cannot_be_built_or_read():
    exp = xairl.explain(POLICY, POLICY.background(2, seed=1), method="exact")
    for field in ("values", "base_values", "outputs", "states"):
        bad = getattr(exp, field).copy()
        bad.flat[0] = np.nan
        with pytest.raises(InputError, match=f"Explanation.{field} holds NaN or infinity"):
            xairl.Explanation(**{**exp.__dict__, field: bad})
    text = exp.to_json()
    for token in ("NaN", "Infinity", "-Infinity", "1e400"):
        with pytest.raises(InputError, match="not a finite number"):
            xairl.Explanation.from_json(text.replace("[[[", f"[[[{token}, ", 1))


@pytest.mark.parametrize(
    "text, words",
    [
        ("", "not valid JSON"),
        ("{", "not valid JSON"),
        ("[]", "does not match"),
        ("null", "does not match"),
        ('{"values": 1}', "does not match"),
        ("[" * 5000 + "]" * 5000, "nested too deeply"),
        (b"\xff\xfe\x00", "not valid JSON"),
        (
            '{"values": [[[1]]], "base_values": [[0]], "outputs": [[1]], '
            '"states": null, "feature_names": ["a"], "action_names": ["x", "y"], '
            '"method": "m"}',
            "names do not match",
        ),
        (
            '{"values": [[[1], [2, 3]]], "base_values": [[0]], "outputs": [[1]], "states": null, "feature_names": ["a", "b"],'
            ' "action_names": ["x"], "method": "m"}',
            "rows of different lengths",
        ),
        (
            '{"values": [[[1e308]], [[1e308]]], "base_values": [[0], [0]], "outputs": [[1' + "0" * 400 + "], [1]], "
            '"states": null, "feature_names": ["a"], "action_names": ["x"], "method": "m"}',
            "does not match",
        ),
    ],
)
def test_from_json_refuses_bad_input_in_one_line(text, words):
    """It used to raise raw pydantic, JSONDecodeError or IndexError text."""
    with pytest.raises(InputError, match=words) as info:
        xairl.Explanation.from_json(text)
    assert "\n" not in str(info.value)


def test_json_round_trip_keeps_every_field():
    policy = xairl.Policy(
        POLICY.module,
        FEATURES,
        POLICY.action_names,
        action_mask=lambda x: np.ones((len(x), 3), bool),
        features={"wind": xairl.FeatureInfo(categories=("calm", "storm"))},
    )
    exp = xairl.explain(policy, POLICY.background(3, seed=1), background=POLICY.background(20), method="exact")
    back = xairl.Explanation.from_json(exp.to_json())
    for f in ("values", "base_values", "outputs", "states", "background_quantiles", "available"):
        assert np.array_equal(getattr(back, f), getattr(exp, f)), f
    for f in ("feature_names", "action_names", "method", "output", "observation", "categories"):
        assert getattr(back, f) == getattr(exp, f), f
    assert dict(back.options) == dict(exp.options)


# 4. inputs that should be refused ---------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "states, words",
    [
        (np.ones((2, 5)) * (1 + 2j), "complex numbers"),
        (np.array([np.datetime64("2026-01-01")] * 5)[None], "dates"),
        (np.array([np.timedelta64(3, "s")] * 5)[None], "time spans"),
        ([[10**400, 1, 1, 1, 1]], "must be numeric"),
    ],
)
def test_states_that_numpy_would_misread_are_refused(states, words):
    """Complex arrays lost their imaginary part with a warning; dates and time spans were taken as counts."""
    with pytest.raises(InputError, match=words):
        POLICY.check_states(states)


def _npy_header(shape) -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": "<f8", "fortran_order": False, "shape": shape})
    return buf.getvalue()


def test_a_small_file_that_would_expand_enormously_is_refused_before_loading(tmp_path, capsys):
    """A 3.9 MB .npz expanding to 4 GB and a .npy header claiming 10^11 rows ended in MemoryError."""
    bomb = tmp_path / "bomb.npz"
    with zipfile.ZipFile(bomb, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("arr_0.npy", _npy_header((10**11, 5)) + b"\0" * 1000)
    rc, _, err = run(capsys, "explain", "--states", str(bomb))
    one_line_error(rc, err, "would take 3.73e+03 GiB", "XAIRL_MAX_STATES_BYTES")
    claim = tmp_path / "claim.npy"
    claim.write_bytes(_npy_header((10**11, 5)) + b"\0" * 100)
    rc, _, err = run(capsys, "explain", "--states", str(claim))
    one_line_error(rc, err, "claim.npy")
    truncated = tmp_path / "truncated.npy"
    truncated.write_bytes(_npy_header((1000, 5)) + b"\0" * 100)
    rc, _, err = run(capsys, "explain", "--states", str(truncated))
    one_line_error(rc, err, "truncated")


def test_the_size_limit_can_be_raised(tmp_path, monkeypatch):
    path = tmp_path / "s.npy"
    np.save(path, POLICY.background(40))
    monkeypatch.setenv("XAIRL_MAX_STATES_BYTES", "800")
    with pytest.raises(InputError, match="more than the 7.45e-07 GiB limit"):
        read_states(path, FEATURES)
    monkeypatch.setenv("XAIRL_MAX_STATES_BYTES", "1600")
    assert read_states(path, FEATURES).shape == (40, 5)


# 5. one-line errors, exit 2 ---------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "argv, words",
    [
        (["explain", "--n", "-1"], "--n: -1 must be between 1"),
        (["explain", "--seed", "-1"], "--seed: -1 must be between 0"),
        (["explain", "--background-size", "-5"], "--background-size: -5"),
        (["explain", "--method", "kernel_shap", "-o", "nsamples=-5"], "nsamples"),
        (["explain", "--method", "kernel_shap", "-o", "seed=-3"], "seed"),
        (["explain", "--top", "-1"], "--top: -1 must be at least 1"),
        (["explain", "--n", "two"], "'two' is not a whole number"),
        (["review", "--serve", "--port", "99999"], "--port: 99999 must be between 0 and 65535"),
        (["report", "--plugin", "uav-handover", "--n", "0"], "--n: 0"),
        (["explain", "--nonsense"], "unrecognized arguments: --nonsense"),
    ],
)
def test_bad_numbers_and_flags_are_one_line_errors(capsys, argv, words):
    rc, _, err = run(capsys, *argv)
    one_line_error(rc, err, words)


def test_bad_paths_are_one_line_errors(capsys, tmp_path):
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    missing = tmp_path / "missing" / "deeper"
    for argv, words in [
        (["explain", "--out", str(a_file)], "is a file, not a folder"),
        (["explain", "--out", str(a_file / "report")], "is a file, so no folder can be made under it"),
        (["explain", "--narrate", "--feedback-db", str(missing / "f.sqlite")], "does not exist"),
        (["review", "--db", str(missing / "f.sqlite")], "does not exist"),
        (["review", "--export", str(missing / "c.jsonl"), "--db", str(tmp_path / "f.sqlite")], "does not exist"),
        (["review", "--export", str(tmp_path), "--db", str(tmp_path / "f.sqlite")], "is a folder"),
        (["verify", "text", "--explanation", "/bin/sh"], "not valid JSON"),
        (["verify", "text", "--explanation", str(tmp_path)], "--explanation"),
    ]:
        rc, _, err = run(capsys, *argv)
        one_line_error(rc, err, words)
    assert not (tmp_path / "missing").exists()  # nothing was created on the way
    # a report folder is made with the folders above it, as mkdir -p does (make demo writes out/report)
    assert main(["explain", "--n", "2", "--method", "exact", "--no-robustness", "--out", str(missing / "r")]) == 0
    assert (missing / "r" / "report.html").exists()


@pytest.mark.slow
def test_a_model_folder_holding_a_pickle_is_refused_without_loading_it(tmp_path, capsys):
    """transformers would unpickle pytorch_model.bin; only safetensors (or GGUF) weights are read."""
    folder = tmp_path / "lm"
    folder.mkdir()
    (folder / "config.json").write_text(
        json.dumps({"model_type": "gpt2", "n_layer": 1, "n_head": 1, "n_embd": 8, "vocab_size": 10})
    )
    marker = tmp_path / "ran"
    (folder / "pytorch_model.bin").write_bytes(
        b"cos\nsystem\n(S'touch " + str(marker).encode() + b"'\ntR."
    )  # a pickle that runs a command
    from xairl.narrators.local_lm import load_model

    with pytest.raises(InputError, match="cannot load the model .*safetensors"):
        load_model(str(folder))
    assert not marker.exists()


@pytest.mark.parametrize("index", [1.5, "0", True, None, [0]])
def test_a_state_index_must_be_a_whole_number(index):
    exp = xairl.explain(POLICY, POLICY.background(2, seed=1), method="exact")
    if index is None:  # None is the global summary's index: refused for a decision template only
        with pytest.raises(InputError, match="decision template"):
            xairl.narrate(exp, index, template="explain_action")
        return
    for call in (lambda: xairl.narrate(exp, index), lambda: xairl.verify("Wind raised it.", exp, index)):
        with pytest.raises(InputError, match="a state index is a whole number"):
            call()
    assert xairl.narrate(exp, np.int64(1), robustness=False).index == 1


def test_verify_reads_text_not_bytes():
    exp = xairl.explain(POLICY, POLICY.background(1, seed=1), method="exact")
    with pytest.raises(InputError, match="decode it first"):
        xairl.verify(b"Wind raised it.", exp, 0)


# 6. messages and small wrongs ---------------------------------------------------------------------------------------
def test_csv_with_a_byte_order_mark_or_a_duplicated_column(tmp_path, capsys):
    bom = tmp_path / "bom.csv"
    bom.write_text(",".join(FEATURES) + "\n1,2,3,4,5\n", encoding="utf-8-sig")  # Excel's "CSV UTF-8"
    assert read_states(bom, FEATURES).tolist() == [[1, 2, 3, 4, 5]]
    dup = tmp_path / "dup.csv"
    dup.write_text(",".join(FEATURES) + ",speed\n1,2,3,4,5,6\n")
    rc, _, err = run(capsys, "explain", "--states", str(dup))
    one_line_error(rc, err, "speed appear more than once")


def test_errors_about_the_background_file_say_background(tmp_path, capsys):
    path = tmp_path / "bg.csv"
    path.write_text("battery,distance\n1,2\n")
    rc, _, err = run(capsys, "explain", "--background", str(path))
    one_line_error(rc, err, "bg.csv", "background")
    rc, _, err = run(capsys, "explain", "--background", str(tmp_path / "nope.csv"))
    one_line_error(rc, err, "file of background")


def test_top_prints_as_many_features_as_asked(capsys):
    rc, out, _ = run(capsys, "explain", "--n", "1", "--top", "5", "--method", "exact")
    assert rc == 0 and out.count("   contribution ") == 5


# 7. atomic writes ---------------------------------------------------------------------------------------------------
def test_a_killed_writer_leaves_no_partial_file_under_the_final_name(tmp_path):
    target = tmp_path / "explanations.jsonl"
    target.write_text("the previous complete run\n")
    code = textwrap.dedent(f"""
        import sys, time
        from xairl.runs.files import atomic_write
        with atomic_write({str(target)!r}) as fh:
            for i in range(100000):
                fh.write('{{"index": %d}}\\n' % i)
                if i == 1000:
                    fh.flush(); print('writing', flush=True)
                    time.sleep(60)
    """)
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "writing"
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    assert target.read_text() == "the previous complete run\n"  # the old file, whole
    assert [p.name for p in tmp_path.iterdir() if p.name.endswith(".part")]  # the partial one, marked as such


def test_a_failed_report_leaves_neither_partial_files_nor_the_last_runs_report(tmp_path, monkeypatch, capsys):
    out = tmp_path / "rep"
    assert run(capsys, "explain", "--n", "3", "--method", "exact", "--out", str(out), "--no-robustness")[0] == 0
    assert (out / "report.html").exists()
    from xairl import plots

    def broken(*args, **kwargs):
        raise RuntimeError("disk full")

    monkeypatch.setattr(plots, "beeswarm", broken)
    monkeypatch.setenv("XAIRL_DEBUG", "")
    rc, _, err = run(capsys, "explain", "--n", "4", "--method", "exact", "--out", str(out))
    assert rc == 1 and "disk full" in err
    assert not (out / "report.html").exists()  # no report of the last run beside this run's explanations
    assert len((out / "explanations.jsonl").read_text().splitlines()) == 4  # this run's, whole
    assert not [p for p in out.iterdir() if p.name.endswith(".part")]


# 8. say what runs code ----------------------------------------------------------------------------------------------
def test_help_says_that_a_module_attr_policy_runs_code(capsys):
    with pytest.raises(SystemExit):
        main(["explain", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "imports and runs that code" in out and "trust" in out


# 9. code health -----------------------------------------------------------------------------------------------------
def test_the_confidence_doc_states_the_weights_the_code_uses():
    import importlib
    import re

    confidence = importlib.import_module("xairl.narrators.confidence")  # (the package exports a function of that name)
    stated = {k: float(w) for k, w in re.findall(r"``(\w+)`` \(weight ([\d.]+)\)", confidence.__doc__)}
    assert stated == confidence.WEIGHTS


def test_a_policy_is_built_normalised_and_frozen():
    import dataclasses

    policy = xairl.Policy(
        POLICY.module, list(FEATURES), ["forward", "turn", "recharge"], groups={"motion": ["speed", "wind"]}
    )
    assert policy.feature_names == FEATURES and isinstance(policy.action_names, tuple)
    assert policy.groups == {"motion": ("speed", "wind")}
    with pytest.raises(dataclasses.FrozenInstanceError):
        policy.feature_names = ("a",)
    renamed = dataclasses.replace(policy, name="renamed")  # a changed policy is a new one, checked again
    assert renamed.name == "renamed" and renamed.network is not policy.network
    with pytest.raises(InputError, match="duplicates"):
        dataclasses.replace(policy, action_names=["a", "a", "b"])
