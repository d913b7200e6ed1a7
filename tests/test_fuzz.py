"""Property-based fuzzing: whatever the input, the API raises only our errors and the CLI never shows a traceback.

Case counts (max_examples) add up to 1,300 generated cases per run; hypothesis is seeded so runs repeat.
"""
import json
import string

import numpy as np
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
    return settings(max_examples=n, deadline=None, suppress_health_check=list(HealthCheck), derandomize=True,
                    database=None)
floats = st.floats(allow_nan=True, allow_infinity=True, width=64)
arrays = hnp.arrays(dtype=st.sampled_from([np.float32, np.float64, np.int64, np.int8, np.bool_, np.complex64]),
                    shape=hnp.array_shapes(min_dims=0, max_dims=3, min_side=0, max_side=7))
methods = st.sampled_from(["deep_shap", "exact", "integrated_gradients", "kernel_shap", "nope", "", "DEEP_SHAP"])


@fast(400)
@given(states=st.one_of(arrays, st.lists(st.lists(st.one_of(floats, st.text(max_size=3), st.none()), max_size=6),
                                         max_size=4)),
       method=methods)
def test_api_states_of_any_shape_dtype_and_value(states, method):
    try:
        exp = xairl.explain(POLICY, states, background=BG, method=method, options={"nsamples": 20}
                            if method == "kernel_shap" else None)
    except XairlError:
        return
    assert exp.values.shape[1:] == (5, 3) and np.isfinite(exp.values).all()


@fast(300)
@given(options=st.dictionaries(st.text(string.ascii_lowercase + "_", max_size=12),
                               st.one_of(st.integers(-10 ** 12, 10 ** 12), floats, st.text(max_size=5), st.booleans(),
                                         st.none()), max_size=3),
       method=st.sampled_from(["deep_shap", "exact", "integrated_gradients", "kernel_shap"]))
def test_api_options(options, method):
    if method == "kernel_shap":
        options = {"nsamples": 16, **options}
    if method == "integrated_gradients" and isinstance(options.get("n_steps"), int):
        options["n_steps"] = min(abs(options["n_steps"]), 64) + 2
    try:
        xairl.explain(POLICY, BG[:2], background=BG[:5], method=method, options=options)
    except XairlError:
        pass


cell = st.one_of(st.floats(width=32).map(repr), st.text(string.printable, max_size=6), st.just(""), st.just("nan"))


@fast(300)
@given(header=st.lists(st.sampled_from(list(FEATURES) + ["junk", "", "x y"]), max_size=7),
       rows=st.lists(st.lists(cell, max_size=7), max_size=4), sep=st.sampled_from([",", ";", "\t"]))
def test_cli_csv_files(tmp_path_factory, header, rows, sep):
    path = tmp_path_factory.mktemp("csv") / "s.csv"
    path.write_text(sep.join(header) + "\n" + "\n".join(sep.join(r) for r in rows))
    _cli_ok(["explain", "--states", str(path), "--format", "jsonl"])


@fast(300)
@given(doc=st.recursive(st.one_of(st.none(), st.booleans(), floats, st.text(max_size=4)),
                        lambda inner: st.lists(inner, max_size=5) | st.dictionaries(
                            st.sampled_from(list(FEATURES) + ["states", "x"]), inner, max_size=6), max_leaves=30),
       raw=st.booleans(), garbage=st.text(max_size=20))
def test_cli_json_files(tmp_path_factory, doc, raw, garbage):
    path = tmp_path_factory.mktemp("json") / "s.json"
    path.write_text(garbage if raw else json.dumps(doc, allow_nan=True))
    _cli_ok(["explain", "--states", str(path), "--method", "exact"])


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
