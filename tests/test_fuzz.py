"""Property-based fuzzing: whatever the input, the API raises only our errors and the CLI never shows a traceback.

Case counts (max_examples) add up to 3,600 generated cases per run, 2,300 of them for the CLI's input readers
(.npy, .npz, CSV, JSON, command-line values, the streaming engine's CSV and Parquet) and Explanation.from_json
(issues 27 and 28); hypothesis is seeded so runs repeat.
"""

import json
import string

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import xairl
from xairl.cli import main
from xairl.errors import XairlError
from xairl.toy import FEATURES, toy_policy

POLICY = toy_policy()
BG = POLICY.background(20)


def fast(n):
    return settings(
        max_examples=n, deadline=None, suppress_health_check=list(HealthCheck), derandomize=True, database=None
    )


floats = st.floats(allow_nan=True, allow_infinity=True, width=64)
arrays = hnp.arrays(
    dtype=st.sampled_from([np.float32, np.float64, np.int64, np.int8, np.bool_, np.complex64]),
    shape=hnp.array_shapes(min_dims=0, max_dims=3, min_side=0, max_side=7),
)
methods = st.sampled_from(["deep_shap", "exact", "integrated_gradients", "kernel_shap", "nope", "", "DEEP_SHAP"])


@pytest.mark.slow
@fast(400)
@given(
    states=st.one_of(
        arrays, st.lists(st.lists(st.one_of(floats, st.text(max_size=3), st.none()), max_size=6), max_size=4)
    ),
    method=methods,
)
def test_api_states_of_any_shape_dtype_and_value(states, method):
    try:
        exp = xairl.explain(
            POLICY, states, background=BG, method=method, options={"nsamples": 20} if method == "kernel_shap" else None
        )
    except XairlError:
        return
    assert exp.values.shape[1:] == (5, 3) and np.isfinite(exp.values).all()


@fast(300)
@given(
    options=st.dictionaries(
        st.text(string.ascii_lowercase + "_", max_size=12),
        st.one_of(st.integers(-(10**12), 10**12), floats, st.text(max_size=5), st.booleans(), st.none()),
        max_size=3,
    ),
    method=st.sampled_from(["deep_shap", "exact", "integrated_gradients", "kernel_shap"]),
)
def test_api_options(options, method):
    if method == "kernel_shap":
        options = {"nsamples": 16, **options}
    if method == "integrated_gradients" and isinstance(options.get("n_steps"), int):
        options["n_steps"] = min(abs(options["n_steps"]), 64) + 2
    try:
        exp = xairl.explain(POLICY, BG[:2], background=BG[:5], method=method, options=options)
    except XairlError as exc:
        assert "\n" not in str(exc)
        return
    _well_formed(exp, method, options)


def _well_formed(exp, method, options):
    """An explanation that was accepted: its shapes, finite numbers, the policy's own outputs (whatever the options),
    its contributions adding up to them (IG: up to the convergence delta it reports), the options it ran with."""
    assert exp.values.shape == (2, 5, 3) and exp.base_values.shape == exp.outputs.shape == (2, 3)
    assert all(np.isfinite(a).all() for a in (exp.values, exp.base_values, exp.outputs))
    assert exp.method == method and exp.feature_names == tuple(FEATURES) and len(exp.action_names) == 3
    np.testing.assert_allclose(exp.outputs, REFERENCE.outputs, rtol=1e-5, atol=1e-5)
    if method == "integrated_gradients":
        np.testing.assert_allclose(np.abs(exp.extras["convergence_delta"]), exp.additivity_gap, atol=1e-4)
    else:
        assert exp.additivity_gap.max() <= 1e-4
    assert set(options) <= set(exp.options)


cell = st.one_of(st.floats(width=32).map(repr), st.text(string.printable, max_size=6), st.just(""), st.just("nan"))


@pytest.mark.slow
@fast(300)
@given(
    header=st.lists(st.sampled_from(list(FEATURES) + ["junk", "", "x y"]), max_size=7),
    rows=st.lists(st.lists(cell, max_size=7), max_size=4),
    sep=st.sampled_from([",", ";", "\t"]),
)
def test_cli_csv_files(tmp_path_factory, header, rows, sep):
    path = tmp_path_factory.mktemp("csv") / "s.csv"
    path.write_text(sep.join(header) + "\n" + "\n".join(sep.join(r) for r in rows))
    _cli_ok(["explain", "--states", str(path), "--format", "jsonl"])


@pytest.mark.slow
@fast(300)
@given(
    doc=st.recursive(
        st.one_of(st.none(), st.booleans(), floats, st.text(max_size=4)),
        lambda inner: (
            st.lists(inner, max_size=5)
            | st.dictionaries(st.sampled_from(list(FEATURES) + ["states", "x"]), inner, max_size=6)
        ),
        max_leaves=30,
    ),
    raw=st.booleans(),
    garbage=st.text(max_size=20),
)
def test_cli_json_files(tmp_path_factory, doc, raw, garbage):
    path = tmp_path_factory.mktemp("json") / "s.json"
    path.write_text(garbage if raw else json.dumps(doc, allow_nan=True))
    _cli_ok(["explain", "--states", str(path), "--method", "exact"])


NPY_DTYPES = ["<f4", "<f8", "<i8", "|b1", "<c8", "<M8[D]", "<m8[s]", "|O", "<U3", "|V4"]


@pytest.mark.slow
@fast(500)
@given(
    dtype=st.sampled_from(NPY_DTYPES),
    shape=st.lists(st.one_of(st.integers(0, 6), st.integers(10**9, 10**12)), max_size=4),
    body=st.binary(max_size=200),
    cut=st.integers(0, 120),
    packed=st.booleans(),
    key=st.sampled_from(["arr_0", "obs", "x", ""]),
)
def test_cli_npy_and_npz_files_of_any_header_and_body(tmp_path_factory, dtype, shape, body, cut, packed, key):
    """Headers claiming any shape and dtype (objects, dates, complex, billions of rows), bodies short, long or random,
    headers cut anywhere, as a .npy or inside a .npz."""
    import io
    import zipfile

    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": dtype, "fortran_order": False, "shape": tuple(shape)})
    raw = buf.getvalue()
    raw = raw[:cut] if cut < 20 else raw + body
    folder = tmp_path_factory.mktemp("npy")
    if packed:
        path = folder / "s.npz"
        with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr(f"{key}.npy", raw)
    else:
        path = folder / "s.npy"
        path.write_bytes(raw)
    _cli_ok(["explain", "--states", str(path), "--method", "exact"])


@pytest.mark.slow
@fast(300)
@given(
    flag=st.sampled_from(
        ["--n", "--seed", "--background-size", "--top", "--index", "--port", "-o", "--out", "--feedback-db", "--export"]
    ),
    value=st.one_of(
        st.integers(-(10**20), 10**20).map(str),
        st.text(max_size=12),
        st.sampled_from(
            [
                "",
                "-",
                "nan",
                "1e999",
                "0",
                "/",
                "/etc/passwd",
                "nsamples=-5",
                "seed=1e400",
                "n_steps=" + "9" * 30,
                "max_pairs=[[[]]]",
                "=",
                "x=" + "[" * 3000,
            ]
        ),
    ),
)
def test_cli_values_of_any_flag(flag, value):
    """Command-line values: refused in one line or run; a valid run here is made small (one state, one sample)."""
    if flag in ("--index",):
        argv = ["verify", "text", "--explanation", "/nonexistent.json", flag, value]
    elif flag in ("--port", "--export"):
        argv = ["review", "--db", "/nonexistent/f.sqlite", flag, value]
    elif flag == "-o":
        argv = [
            "explain",
            "--n",
            "1",
            "--background-size",
            "5",
            "--method",
            "kernel_shap",
            "-o",
            "nsamples=8",
            flag,
            value,
        ]
    elif flag in ("--n", "--background-size"):
        argv = [
            "explain",
            "--method",
            "exact",
            "--background-size",
            "5",
            flag,
            value if not value.isdigit() or int(value) > 10**7 else "2",
        ]
    else:
        argv = ["explain", "--n", "1", "--background-size", "5", "--method", "exact", flag, value]
    if flag == "--out" and value and not value.startswith("/"):
        return  # a relative folder would be written into the checkout
    _cli_ok(argv)


REFERENCE = xairl.explain(POLICY, BG[:2], background=BG, method="exact")
EXPLANATION = REFERENCE.to_json()
json_values = st.recursive(
    st.one_of(st.none(), st.booleans(), st.integers(-(10**30), 10**30), floats, st.text(max_size=4)),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=6), inner, max_size=4),
    max_leaves=20,
)


@pytest.mark.slow
@fast(800)
@given(
    edits=st.lists(
        st.tuples(
            st.integers(0, len(EXPLANATION)),
            st.integers(0, 40),
            st.sampled_from(
                [
                    "",
                    "NaN",
                    "Infinity",
                    "1e400",
                    "-",
                    "[",
                    "]",
                    "{",
                    "}",
                    ",",
                    '"',
                    "null",
                    "true",
                    "1" + "0" * 400,
                    "[[[]]]",
                    '"values"',
                    '"x"',
                    "0.5",
                    "\\u0000",
                    "é",
                ]
            ),
        ),
        min_size=1,
        max_size=4,
    )
)
def test_explanation_from_json_with_any_edit(edits):
    """The JSON Explanation.to_json() writes, cut and spliced anywhere: an Explanation or one InputError line."""
    text = EXPLANATION
    for at, width, insert in edits:
        text = text[:at] + insert + text[at + width :]
    _from_json_ok(text)


@pytest.mark.slow
@fast(500)
@given(
    doc=st.dictionaries(
        st.sampled_from(
            [
                "values",
                "base_values",
                "outputs",
                "states",
                "feature_names",
                "action_names",
                "method",
                "options",
                "extras",
                "available",
                "output",
                "observation",
                "categories",
                "background_quantiles",
                "other",
            ]
        ),
        json_values,
        max_size=15,
    ),
    base=st.booleans(),
)
def test_explanation_from_json_of_any_document(doc, base):
    """Any JSON document keyed by the schema's fields, alone or over a valid explanation."""
    whole = {**json.loads(EXPLANATION), **doc} if base else doc
    _from_json_ok(json.dumps(whole, allow_nan=True))


def _from_json_ok(text):
    try:
        exp = xairl.Explanation.from_json(text)
    except XairlError as exc:
        assert "\n" not in str(exc)
        return
    assert np.isfinite(exp.values).all() and np.isfinite(exp.outputs).all()


def _cli_ok(argv):
    import contextlib
    import io

    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        rc = main(argv)
    text = err.getvalue()
    assert rc in (0, 2), text
    assert "Traceback" not in text and "internal error" not in text, text
    if rc == 2:
        assert text.count("\n") == 1 and text.startswith("xairl: error: ")


@pytest.mark.slow
@fast(200)
@given(
    header=st.lists(st.sampled_from(list(FEATURES) + ["junk", ""]), max_size=7),
    rows=st.lists(st.lists(cell, max_size=7), max_size=5),
    as_parquet=st.booleans(),
    chunk=st.integers(1, 4),
)
def test_streamed_readers_of_any_csv_or_parquet(tmp_path_factory, header, rows, as_parquet, chunk):
    """The streaming engine's readers (pyarrow's CSV and Parquet): chunks of checked states, or one InputError line."""
    from xairl.runs.chunks import state_chunks

    folder = tmp_path_factory.mktemp("stream")
    path = folder / "s.csv"
    path.write_text(",".join(header) + "\n" + "\n".join(",".join(r) for r in rows))
    if as_parquet:
        import pyarrow.csv
        import pyarrow.parquet

        try:
            table = pyarrow.csv.read_csv(path)
        except Exception:  # not even a table: nothing to convert
            return
        path = folder / "s.parquet"
        pyarrow.parquet.write_table(table, path)
    try:
        for first, x in state_chunks(path, POLICY, chunk_size=chunk):
            assert x.dtype == np.float32 and x.shape[1] == 5 and np.isfinite(x).all() and first % chunk == 0
    except XairlError as exc:
        assert "\n" not in str(exc)
