"""Issue 51, hardening round 3 (items 4, 6, 9, 10, 16, 17): what a user brings (a saved explanation, a Parquet file,
a float64 network, huge numbers, an episode to slice out, a parametrised action space) is explained correctly or
refused in one line that says what to do, never a raw exception or a silent wrong answer."""

import json

import numpy as np
import pytest
import torch

import xairl
from tests.conftest import ReusedActivations, mlp, one_line_error, run
from xairl.errors import InputError
from xairl.toy import FEATURES, toy_policy

POLICY = toy_policy()
METHODS = ["deep_shap", "integrated_gradients", "kernel_shap", "exact"]


# 9. float64 networks ----------------------------------------------------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("net", [lambda: mlp([6, 12, 3]), ReusedActivations], ids=["sequential", "forward"])
@pytest.mark.parametrize("method", METHODS)
def test_a_float64_network_is_explained_in_float64(method, net):
    """A float64 network failed with 'mat1 and mat2 must have the same dtype ... check that it takes (n, 6)': the
    states were cast to float32. Now it runs in float64, with float64 precision in every method."""
    module = net().double()
    policy = xairl.Policy(module, feature_names=[f"f{i}" for i in range(6)], action_names=["a", "b", "c"])
    r = np.random.default_rng(0)
    x, bg = r.normal(size=(3, 6)), r.normal(size=(12, 6))
    exp = xairl.explain(policy, x, background=bg, method=method)
    with torch.no_grad():
        expected = module(torch.as_tensor(x)).numpy()
    np.testing.assert_allclose(exp.outputs, expected, rtol=0, atol=1e-12)  # float32 states would be off by ~1e-7
    np.testing.assert_array_equal(exp.states, x)
    if method != "integrated_gradients":  # a quadrature, not exact
        assert exp.additivity_gap.max() < 1e-9


def test_a_network_of_another_dtype_is_refused_naming_the_dtype():
    policy = xairl.Policy(mlp([5, 4, 2]).half(), feature_names=FEATURES, action_names=["a", "b"])
    with pytest.raises(InputError, match=r"computes in float16 .* convert it with module.float\(\)") as err:
        xairl.explain(policy, POLICY.background(2), background=POLICY.background(4))
    assert "check that it takes" not in str(err.value)


# 10. numbers beyond float32 -----------------------------------------------------------------------------------------
def test_a_finite_number_beyond_float32_is_named_an_overflow():
    """1e300 is finite; it was reported as a 'NaN/inf value', which the user's file does not hold."""
    states = POLICY.background(2).astype(np.float64)
    states[1, 2] = 1e300
    with pytest.raises(
        InputError,
        match=r"1 value\(s\) beyond the float32 range .* row 1, column 2 \(1e\+300\); "
        r"scale those inputs down, or give a float64 network",
    ) as err:
        xairl.explain(POLICY, states, background=POLICY.background(4))
    assert "NaN" not in str(err.value)
    states[1, 2] = np.nan
    with pytest.raises(InputError, match="NaN/inf"):
        POLICY.check_states(states)


def test_a_float64_network_takes_numbers_beyond_float32(tmp_path, capsys):
    policy = xairl.Policy(torch.nn.Linear(5, 2).double(), feature_names=FEATURES)
    states = np.zeros((1, 5))
    states[0, 0] = 1e300
    exp = xairl.explain(policy, states, background=np.zeros((3, 5)), method="exact")
    assert exp.states[0, 0] == 1e300 and np.isfinite(exp.values).all()


# 6. Parquet states files ------------------------------------------------------------------------------------------
def _parquet(path, columns: dict, names=None):
    import pyarrow as pa
    import pyarrow.parquet as pq

    names = names or list(columns)
    arrays = [pa.array(columns[n]) if not isinstance(columns[n], pa.Array) else columns[n] for n in names]
    pq.write_table(pa.Table.from_arrays(arrays, names=names), path)
    return str(path)


def _columns(n=4):
    x = POLICY.background(n, seed=3).astype(np.float64)
    return {f: x[:, j] for j, f in enumerate(FEATURES)}, x


def test_a_parquet_states_file_is_explained(tmp_path, capsys):
    """`xairl explain --states f.parquet` said "unknown file type '.parquet'" though --format parquet reads it;
    other columns (an episode id) are ignored, the features read in the policy's order."""
    cols, x = _columns()
    path = _parquet(tmp_path / "s.parquet", {"episode": np.arange(4), **dict(reversed(list(cols.items())))})
    from xairl.runs.inputs import read_states

    np.testing.assert_array_equal(read_states(path, FEATURES), x)
    rc, out, err = run(capsys, "explain", "--states", path, "--background", path, "--method", "exact")
    assert rc == 0 and out.count("state ") == 4, err


@pytest.mark.parametrize(
    "column, words",
    [
        ("timestamp", ["column 'speed' holds timestamp[us] values, not numbers"]),
        ("string", ["column 'speed' holds string values, not numbers"]),
        ("duplicate", ["column(s) speed appear more than once"]),
    ],
)
def test_a_parquet_file_with_a_column_that_is_not_numbers_is_one_line(tmp_path, capsys, column, words):
    import datetime

    cols, _ = _columns()
    names = list(FEATURES)
    if column == "timestamp":
        cols["speed"] = [datetime.datetime(2026, 1, 1, 0, 0, i) for i in range(4)]
    elif column == "string":
        cols["speed"] = ["fast", "slow", "fast", "slow"]
    else:
        names = names + ["speed"]
    path = _parquet(tmp_path / "s.parquet", cols, names)
    rc, _, err = run(capsys, "explain", "--states", path, "--method", "exact")
    one_line_error(rc, err, path, *words)


def test_a_streamed_parquet_file_with_a_timestamp_column_is_one_line(tmp_path, capsys):
    import datetime

    cols, _ = _columns()
    cols["speed"] = [datetime.datetime(2026, 1, 1, 0, 0, i) for i in range(4)]
    path = _parquet(tmp_path / "s.parquet", cols)
    rc, _, err = run(
        capsys,
        "explain",
        "--states",
        path,
        "--format",
        "parquet",
        "--out",
        str(tmp_path / "run"),
        "--method",
        "exact",
        "--no-robustness",
    )
    one_line_error(rc, err, "column 'speed' holds timestamp")


# 4. a saved explanation's structured fields -----------------------------------------------------------------------
def _saved(tmp_path, **fields):
    exp = xairl.explain(POLICY, POLICY.background(2, seed=1), background=POLICY.background(20), method="exact")
    data = {**json.loads(exp.to_json()), **fields}
    path = tmp_path / "e.json"
    path.write_text(json.dumps(data))
    return str(path)


@pytest.mark.parametrize(
    "fields, words",
    [
        (
            {"observation": {"kind": "flat", "parts": [{"key": "obs", "shape": 5, "categories": None}]}},
            ["Explanation.observation", "parts.0.shape"],
        ),
        ({"observation": {"kind": "flat"}}, ["Explanation.observation", "parts: Field required"]),
        ({"observation": {"a": 1}}, ["kind: Field required", "a: unknown field"]),
        (
            {"observation": {"kind": "flat", "parts": [{"key": "obs", "shape": [7], "categories": None}]}},
            ["describes 7 input columns but the values have 5 features"],
        ),
        (
            {"observation": {"kind": "array", "parts": [{"key": "obs", "shape": [0], "categories": None}]}},
            ["greater than or equal to 1"],
        ),
        ({"background_quantiles": []}, ["background_quantiles has shape (0,), expected (3, 5)"]),
        ({"background_quantiles": [[1]]}, ["background_quantiles has shape (1, 1), expected (3, 5)"]),
        ({"output": "discrete"}, ["Explanation.output 'discrete' is not one of actions, continuous, value"]),
    ],
)
def test_a_saved_explanation_with_a_malformed_field_is_refused_when_read(tmp_path, capsys, fields, words):
    """A malformed observation or quartiles was read without complaint, then narrate and verify raised a raw
    TypeError, KeyError or IndexError (rc 1)."""
    path = _saved(tmp_path, **fields)
    rc, _, err = run(capsys, "verify", "The policy chose turn because of battery.", "--explanation", path)
    one_line_error(rc, err, *words)
    with pytest.raises(InputError, match=words[0].replace("(", r"\(").replace(")", r"\)")):
        xairl.Explanation.from_json(open(path).read())


def test_a_saved_explanation_keeps_its_observation_and_quartiles(tmp_path):
    policy = xairl.Policy(torch.nn.Sequential(torch.nn.Flatten(), mlp([2 * 3 * 3, 4, 2])), observation=(2, 3, 3))
    r = np.random.default_rng(0)
    exp = xairl.explain(policy, r.normal(size=(2, 2, 3, 3)), background=r.normal(size=(6, 2, 3, 3)))
    back = xairl.Explanation.from_json(exp.to_json())
    assert back.observation == exp.observation and back.image_shape == (2, 3, 3)
    np.testing.assert_array_equal(back.background_quantiles, exp.background_quantiles)


# 16. an episode out of a run ----------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def run_exp():
    masked = xairl.Policy(
        POLICY.module,
        FEATURES,
        POLICY.action_names,
        action_mask=lambda x: np.c_[x[:, :1] > 0, np.ones((len(x), 2), bool)],
    )
    return xairl.explain(
        masked,
        POLICY.background(10, seed=5),
        background=POLICY.background(20),
        method="integrated_gradients",
        options={"n_steps": 8},
    )


def _same_states(part, whole, rows):
    for field in ("values", "base_values", "outputs", "states", "available"):
        np.testing.assert_array_equal(getattr(part, field), getattr(whole, field)[rows])
    np.testing.assert_array_equal(part.extras["convergence_delta"], whole.extras["convergence_delta"][rows])
    np.testing.assert_array_equal(part.chosen, whole.chosen[rows])
    np.testing.assert_array_equal(part.background_quantiles, whole.background_quantiles)
    assert (part.feature_names, part.action_names, part.method, part.options, part.output, part.observation) == (
        whole.feature_names,
        whole.action_names,
        whole.method,
        whole.options,
        whole.output,
        whole.observation,
    )
    assert len(part) == len(np.arange(len(whole))[rows])


@pytest.mark.parametrize(
    "key", [slice(None, 4), slice(3, 8), slice(None, None, 3), slice(-2, None), [7, 2, 2, -1], np.array([0, 9]), "mask"]
)
def test_an_explanation_is_sliced_state_by_state(run_exp, key):
    """exp[:n] and exp[mask] raised TypeError ('Explanation' object is not subscriptable)."""
    if isinstance(key, str):
        key = run_exp.states[:, 0] > 0
    part = run_exp[key]
    assert isinstance(part, xairl.Explanation)
    _same_states(part, run_exp, key)
    assert part.additivity_gap.max() <= run_exp.additivity_gap.max()


def test_an_int_gives_a_one_state_explanation_that_narrates(run_exp):
    """An int is exp[i:i + 1] (not an array): narrate(exp[i], 0) says what narrate(exp, i) says."""
    for i in (4, -1):
        one = run_exp[i]
        _same_states(one, run_exp, [i])
    assert (
        xairl.narrate(run_exp[4], 0, policy=POLICY, robustness=False).text
        == xairl.narrate(run_exp, 4, policy=POLICY, robustness=False).text
    )
    back = xairl.Explanation.from_json(run_exp.to_json())[2:5]  # extras read from JSON (lists) are cut too
    assert np.shape(back.extras["convergence_delta"]) == (3, 3)


@pytest.mark.parametrize(
    "key, words",
    [
        (10, "index 10 is out of range"),
        (-11, "index -11 is out of range"),
        (slice(5, 5), "holds no state"),
        (np.zeros(10, bool), "holds no state"),
        (np.ones(4, bool), "one bool per state: got shape (4,) for 10"),
        ([0, 12], "position 12 is out of range"),
        (1.5, "not float '1.5'"),
        ("battery", "not str 'battery'"),
        ((slice(None), 0), "output_slice"),
    ],
)
def test_a_selection_that_is_not_of_states_is_one_line(run_exp, key, words):
    with pytest.raises(InputError) as err:
        run_exp[key]
    assert words in str(err.value) and "\n" not in str(err.value)


# 17. a parametrised action space ------------------------------------------------------------------------------------
HYBRID = ["dash", "turn", "kick", "dash_power", "turn_angle", "kick_power"]
KINDS = ["actions"] * 3 + ["continuous"] * 3


@pytest.fixture(scope="module")
def hybrid():
    return mlp([4, 16, 6])


def test_outputs_named_as_parameters_of_actions_are_refused(hybrid):
    """Six outputs, three logits and their three parameters, were ranked together: 'chose kick_power'."""
    with pytest.raises(
        InputError,
        match=r"output 'dash_power' reads as a parameter of action 'dash'.*"
        r"xairl.Policy.heads\(module, output=\[...\]\).*output='actions'",
    ):
        xairl.Policy(hybrid, feature_names=list("abcd"), action_names=HYBRID)


def test_declared_actions_are_taken_at_their_word_also_through_replace(hybrid):
    """output='actions' (or one 'actions' per column) lets such names be actions, and dataclasses.replace keeps it;
    axis and direction words name no parameter ('move_x', 'rotate_y', 'keep_speed' are actions of their own)."""
    from dataclasses import replace

    for output in ("actions", ["actions"] * 6):
        policy = xairl.Policy(hybrid, feature_names=list("abcd"), action_names=HYBRID, output=output)
        assert replace(policy, name="renamed").output == "actions"
    for names in (["move", "move_x", "move_y", "rotate", "rotate_z", "keep"], ["keep", "keep_speed", *"abcd"]):
        assert xairl.Policy(hybrid, feature_names=list("abcd"), action_names=names).output == "actions"


def test_outputs_declared_of_mixed_kinds_are_refused(hybrid):
    with pytest.raises(
        InputError,
        match=r"mixed kinds \(actions: dash, turn, kick; continuous: dash_power, "
        r"turn_angle, kick_power\).*Policy.heads",
    ):
        xairl.Policy(hybrid, feature_names=list("abcd"), action_names=HYBRID, output=KINDS)
    with pytest.raises(InputError, match="output gives 5 kinds for 6 outputs"):
        xairl.Policy(hybrid, feature_names=list("abcd"), action_names=HYBRID, output=KINDS[:5])
    with pytest.raises(InputError, match=r"output \['actions', 'discrete'\] is unknown"):
        xairl.Policy(hybrid, feature_names=list("abcd"), output=["actions", "discrete"])
    same = xairl.Policy(hybrid, feature_names=list("abcd"), action_names=HYBRID, output=["actions"] * 6)
    assert same.output == "actions"  # declared all discrete: the user's word is taken


@pytest.mark.parametrize("method", METHODS)
def test_heads_explain_the_actions_and_their_parameters_apart(hybrid, method):
    heads = xairl.Policy.heads(hybrid, output=KINDS, action_names=HYBRID, feature_names=list("abcd"))
    assert list(heads) == ["actions", "continuous"]
    r = np.random.default_rng(0)
    x, bg = r.normal(size=(3, 4)).astype(np.float32), r.normal(size=(10, 4)).astype(np.float32)
    with torch.no_grad():
        full = hybrid(torch.as_tensor(x)).numpy()
    acts, params = (xairl.explain(heads[k], x, background=bg, method=method) for k in ("actions", "continuous"))
    assert acts.action_names == ("dash", "turn", "kick") and acts.decides
    assert params.action_names == ("dash_power", "turn_angle", "kick_power") and params.output == "continuous"
    np.testing.assert_allclose(acts.outputs, full[:, :3], atol=1e-6)
    np.testing.assert_allclose(params.outputs, full[:, 3:], atol=1e-6)
    assert set(acts.chosen) <= {0, 1, 2}


def test_a_per_run_extra_as_long_as_the_states_is_kept_whole():
    """Only the per-state extras are cut: one entry per feature, numbering as many as the states, stays whole."""
    from dataclasses import replace

    policy = toy_policy()
    exp = xairl.explain(policy, policy.background(len(FEATURES), seed=3), background=policy.background(20))
    per_feature, delta = np.arange(len(FEATURES), dtype=float), np.arange(len(FEATURES) * 2.0).reshape(-1, 2)
    exp = replace(exp, extras={"per_feature": per_feature, "convergence_delta": delta})
    part = exp[1:3]
    assert np.array_equal(part.extras["per_feature"], per_feature)
    assert np.array_equal(part.extras["convergence_delta"], delta[1:3])
