import numpy as np
import pytest

import xairl
from xairl.errors import InputError
from xairl.toy import toy_policy


@pytest.fixture(scope="module")
def exp():
    policy = toy_policy()
    return xairl.explain(policy, policy.background(8, seed=1), background=policy.background(30), method="exact")


def test_for_chosen_and_margin(exp):
    idx = np.arange(8)
    chosen, runner = exp.chosen, exp.runner_up
    assert (chosen == exp.outputs.argmax(1)).all()
    assert (exp.outputs[idx, runner] <= exp.outputs[idx, chosen]).all() and (runner != chosen).all()
    np.testing.assert_array_equal(exp.for_chosen(), exp.values[idx, :, chosen])
    # the margin's contributions add up to the Q-gap minus the gap of the base values
    q_gap = exp.outputs[idx, chosen] - exp.outputs[idx, runner]
    base_gap = exp.base_values[idx, chosen] - exp.base_values[idx, runner]
    np.testing.assert_allclose(exp.margin().sum(axis=1), q_gap - base_gap, atol=1e-5)


def test_grouped_sums_members_and_keeps_additivity(exp):
    g = exp.grouped({"motion": ["speed", "wind"]})
    assert g.feature_names == ("battery", "distance", "motion", "obstacle")
    j = exp.feature_names.index
    np.testing.assert_allclose(g.values[:, 2], exp.values[:, j("speed")] + exp.values[:, j("wind")])
    np.testing.assert_allclose(g.additivity_gap, exp.additivity_gap, atol=1e-9)
    with pytest.raises(InputError, match="unknown feature 'nope'"):
        exp.grouped({"g": ["nope"]})
    with pytest.raises(InputError, match="must not overlap"):
        exp.grouped({"a": ["speed"], "b": ["speed", "wind"]})


def test_json_round_trip(exp):
    back = xairl.Explanation.from_json(exp.to_json())
    np.testing.assert_array_equal(back.values, exp.values)
    np.testing.assert_array_equal(back.states, exp.states)
    assert back.feature_names == exp.feature_names and back.method == "exact"
    assert back.options == dict(exp.options)


def test_records_are_one_per_state(exp):
    recs = exp.records()
    assert len(recs) == 8
    r = recs[3]
    assert r.chosen == exp.action_names[exp.chosen[3]]
    assert r.values["battery"][r.chosen] == pytest.approx(exp.values[3, 0, exp.chosen[3]])


def test_explanation_is_read_only(exp):
    with pytest.raises(ValueError):
        exp.values[0, 0, 0] = 1.0


def test_action_mask_restricts_chosen_and_runner_up():
    """A policy's action_mask: acting and the explained decision use available actions only; scores of every
    action are still explained, and the mask survives grouping and JSON."""
    from dataclasses import replace

    policy = toy_policy()
    states = policy.background(12, seed=3)
    scores = policy.scores(states)
    best = scores.argmax(1)
    masked = replace(policy, action_mask=lambda x: np.arange(policy.n_actions)[None, :] != best[: len(x), None])
    exp = xairl.explain(masked, states, background=policy.background(30), method="exact")
    allowed = np.where(exp.available, scores, -np.inf)
    np.testing.assert_array_equal(masked.act(states), allowed.argmax(1))
    np.testing.assert_array_equal(exp.chosen, allowed.argmax(1))
    assert (exp.chosen != best).all() and (exp.runner_up != best).all() and (exp.runner_up != exp.chosen).all()
    assert np.abs(exp.additivity_gap).max() < 1e-5  # every action, the masked one too, is explained
    back = xairl.Explanation.from_json(exp.to_json())
    np.testing.assert_array_equal(back.runner_up, exp.runner_up)
    np.testing.assert_array_equal(exp.grouped({"motion": ["speed", "wind"]}).chosen, exp.chosen)
    only = replace(policy, action_mask=lambda x: np.eye(policy.n_actions, dtype=bool)[np.zeros(len(x), int)])
    one = xairl.explain(only, states[:2], background=policy.background(30), method="exact")
    assert (one.chosen == 0).all() and (one.runner_up == 0).all() and not one.margin().any()
    bad = replace(policy, action_mask=lambda x: np.zeros((len(x), policy.n_actions), bool))
    with pytest.raises(InputError, match="at least one available action"):
        bad.act(states)


def test_patches_group_an_image_and_keep_additivity():
    groups = xairl.patches((4, 84, 84), 6)
    assert len(groups) == 196 and all(len(g) == 4 * 36 for g in groups.values())
    assert sorted(np.concatenate(list(groups.values()))) == list(range(4 * 84 * 84))
    rng = np.random.default_rng(0)
    f = 4 * 84 * 84
    e = xairl.Explanation(
        values=rng.normal(size=(2, f, 3)),
        base_values=np.zeros((2, 3)),
        outputs=np.zeros((2, 3)),
        states=rng.normal(size=(2, f)),
        feature_names=tuple(f"p{i}" for i in range(f)),
        action_names=("a", "b", "c"),
        method="test",
    )
    g = e.grouped(groups)
    assert g.feature_names[0] == "patch[0,0]" and g.values.shape == (2, 196, 3)
    np.testing.assert_allclose(g.values.sum(axis=1), e.values.sum(axis=1))
    np.testing.assert_allclose(g.values[:, 0], e.values[:, groups["patch[0,0]"]].sum(axis=1))
    with pytest.raises(xairl.InputError, match="groups must not overlap"):
        e.grouped({"x": [0, 1], "y": [1, 2]})
