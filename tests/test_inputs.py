"""Bad input gives one clear InputError through the API."""

import numpy as np
import pytest
import torch

import xairl
from xairl.errors import InputError, UnknownNameError
from xairl.runs.inputs import read_states
from xairl.toy import FEATURES, toy_policy


@pytest.fixture
def policy():
    return toy_policy()


@pytest.mark.parametrize(
    "states, match",
    [
        (np.zeros((2, 4)), "have 4 features but the policy expects 5"),
        (np.zeros((0, 5)), "empty"),
        (np.array([[np.nan, 0, 0, 0, 0]]), "NaN/inf value.*row 0, column 0"),
        (np.array([[0, 0, np.inf, 0, 0]]), "NaN/inf"),
        (np.full((1, 5), 1e300), "beyond the float32 range"),
        (np.zeros((2, 5, 1)), "2-D array"),
        ([["a", 1, 2, 3, 4]], "numeric"),
        ([[1, 2], [1, 2, 3]], "numeric"),
    ],
)
def test_bad_states(policy, states, match):
    with pytest.raises(InputError, match=match):
        xairl.explain(policy, states, background=np.zeros((3, 5)))


def test_one_state_as_vector_and_tensor(policy):
    e = xairl.explain(policy, torch.zeros(5), background=np.ones((4, 5)))
    assert e.values.shape == (1, 5, 3)


def test_background_of_wrong_width(policy):
    with pytest.raises(InputError, match="background has 3 features"):
        xairl.explain(policy, np.zeros((1, 5)), background=np.zeros((4, 3)))


def test_unknown_method_and_option(policy):
    with pytest.raises(UnknownNameError, match="unknown attributor 'deepshap'; known: deep_shap"):
        xairl.explain(policy, np.zeros((1, 5)), method="deepshap")
    with pytest.raises(InputError, match="n_step: unknown option.*options: n_steps"):
        xairl.explain(policy, np.zeros((1, 5)), method="integrated_gradients", options={"n_step": 3})
    with pytest.raises(InputError, match="n_steps"):
        xairl.explain(policy, np.zeros((1, 5)), method="integrated_gradients", options={"n_steps": "many"})


def test_policy_checks_names_and_module():
    net = torch.nn.Linear(2, 2)
    with pytest.raises(InputError, match="duplicates"):
        xairl.Policy(net, ["a", "a"], ["x", "y"])
    with pytest.raises(InputError, match="torch.nn.Module"):
        xairl.Policy(lambda x: x, ["a", "b"], ["x", "y"])
    with pytest.raises(InputError, match="returned shape"):
        xairl.Policy(net, ["a", "b"], ["x", "y", "z"]).scores(np.zeros((1, 2)))
    with pytest.raises(InputError, match="no background sampler; give background states: --background FILE"):
        xairl.explain(xairl.Policy(net, ["a", "b"], ["x", "y"]), np.zeros((1, 2)))


def write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_csv_reorders_columns_by_header(tmp_path):
    header = ",".join(reversed(FEATURES))
    p = write(tmp_path, "s.csv", f"{header}\n5,4,3,2,1\n")
    np.testing.assert_array_equal(read_states(p, FEATURES), [[1, 2, 3, 4, 5]])


@pytest.mark.parametrize(
    "name, text, match",
    [
        ("a.csv", "battery,distance,speed,obstacle\n1,2,3,4\n", "states lack column.*wind"),
        ("b.csv", ",".join(FEATURES) + "\n1,2,x,4,5\n", "line 2, column 'speed': 'x' is not a number"),
        ("c.csv", "", "empty"),
        ("d.csv", ",".join(FEATURES) + "\n", "empty"),
        ("e.json", "{not json", "cannot read"),
        ("f.json", '[{"battery": 1}]', "lack key"),
        ("g.txt", "1,2", "unknown file type"),
        ("h.npy", "not an array", "cannot read"),
    ],
)
def test_bad_files_name_the_file(tmp_path, name, text, match):
    p = write(tmp_path, name, text)
    with pytest.raises(InputError, match=match) as info:
        read_states(p, FEATURES)
    assert str(info.value).startswith(str(p))
    assert "\n" not in str(info.value)


def test_json_rows_and_objects(tmp_path):
    rows = write(tmp_path, "r.json", "[[1,2,3,4,5]]")
    objs = write(tmp_path, "o.json", '{"states": [{"battery":1,"distance":2,"speed":3,"obstacle":4,"wind":5}]}')
    np.testing.assert_array_equal(read_states(rows, FEATURES), read_states(objs, FEATURES))
