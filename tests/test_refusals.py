"""No silent wrong answer: each network that used to be explained wrongly, or to crash with a raw error, is now
refused with one line that says why and names only methods that accept it."""

import numpy as np
import pytest
import torch
from torch import nn

import xairl
from xairl.errors import InputError, UnsupportedModelError


def data(f, n=3, m=12, seed=0):
    rng = np.random.default_rng(seed)
    return rng.normal(size=(n, f)).astype(np.float32), rng.normal(size=(m, f)).astype(np.float32)


class FunctionalTanhActor(nn.Module):
    """SB3's SAC actor as users often write it: the squashing tanh as a function call."""

    def __init__(self):
        super().__init__()
        torch.manual_seed(0)
        self.net = nn.Sequential(nn.Linear(3, 64), nn.ReLU(), nn.Linear(64, 1))

    def forward(self, x):
        return 2.0 * torch.tanh(self.net(x))


def test_functional_nonlinearity_is_refused_by_deep_shap():
    policy = xairl.Policy(FunctionalTanhActor(), ["cos", "sin", "vel"], ["torque"], output="continuous")
    x, bg = data(3)
    with pytest.raises(
        UnsupportedModelError,
        match=r"functional nonlinearity \(torch.tanh.*use method="
        r"'exact' or 'integrated_gradients' or 'kernel_shap' \(exact: true Shapley values",
    ):
        xairl.explain(policy, x, background=bg, method="deep_shap")
    # the same actor with the tanh as a module is explained exactly
    fixed = nn.Sequential(FunctionalTanhActor().net, nn.Tanh())
    e = xairl.explain(xairl.Policy(fixed, ["cos", "sin", "vel"], ["torque"], output="continuous"), x, background=bg)
    assert e.additivity_gap.max() < 1e-6


class OneHotInside(nn.Module):
    """A module that one-hot encodes an integer input itself (as SB3 does for Discrete observations)."""

    def __init__(self):
        super().__init__()
        torch.manual_seed(0)
        self.net = nn.Sequential(nn.Linear(5 + 2, 16), nn.ReLU(), nn.Linear(16, 2))

    def forward(self, x):
        code = nn.functional.one_hot(x[:, 0].long().clamp(0, 4), 5).float()
        return self.net(torch.cat([code, x[:, 1:]], dim=1))


def test_integrated_gradients_refuses_a_one_hot_input_it_cannot_differentiate():
    policy = xairl.Policy(OneHotInside(), ["mode", "a", "b"], ["left", "right"])
    rng = np.random.default_rng(0)
    x = np.c_[rng.integers(0, 5, 4), rng.normal(size=(4, 2))].astype(np.float32)
    bg = np.c_[rng.integers(0, 5, 20), rng.normal(size=(20, 2))].astype(np.float32)
    with pytest.raises(UnsupportedModelError, match=r"integrated_gradients .* not differentiable .*one-hot"):
        xairl.explain(policy, x, background=bg, method="integrated_gradients")
    e = xairl.explain(policy, x, background=bg, method="kernel_shap")  # the suggested method explains it
    assert e.additivity_gap.max() < 1e-4


def test_a_module_returning_a_tuple_is_refused():
    class LogitsAndValue(nn.Module):
        def __init__(self):
            super().__init__()
            self.pi, self.v = nn.Linear(4, 2), nn.Linear(4, 1)

        def forward(self, x):
            return self.pi(x), self.v(x)

    policy = xairl.Policy(LogitsAndValue(), [f"o{i}" for i in range(4)], ["a", "b"])
    with pytest.raises(InputError, match="returned a tuple, not a tensor; wrap it so that it returns one"):
        policy.scores(np.zeros((2, 4)))


def test_a_module_taking_two_inputs_given_one_says_so():
    class TwoInputs(nn.Module):
        def __init__(self):
            super().__init__()
            self.lin = nn.Linear(6, 2)

        def forward(self, a, b):
            return self.lin(torch.cat([a, b], dim=1))

    flat = xairl.Policy(TwoInputs(), [f"o{i}" for i in range(6)], ["a", "b"])
    with pytest.raises(
        InputError,
        match=r"module TwoInputs raised TypeError \(.*missing 1 required positional "
        r"argument.*\) on input \(2, 6\)",
    ):
        flat.scores(np.zeros((2, 6)))
    two = xairl.Policy(TwoInputs(), observation=[(4,), (2,)], action_names=["a", "b"])
    assert two.feature_names[:2] == ("input0[0]", "input0[1]") and two.feature_names[4:] == ("input1[0]", "input1[1]")
    rng = np.random.default_rng(0)
    e = xairl.explain(
        two,
        [rng.normal(size=(2, 4)), rng.normal(size=(2, 2))],
        background=[rng.normal(size=(9, 4)), rng.normal(size=(9, 2))],
    )
    assert e.values.shape == (2, 6, 2) and e.additivity_gap.max() < 1e-6


def test_refusals_suggest_only_methods_that_accept_the_network():
    net = nn.Sequential(nn.Flatten(), nn.Linear(784, 32), nn.LayerNorm(32), nn.Linear(32, 10))
    policy = xairl.Policy(net, observation=(1, 28, 28))
    x, bg = data(784)
    with pytest.raises(UnsupportedModelError) as info:
        xairl.explain(policy, x, background=bg, method="deep_shap")
    msg = str(info.value)
    assert "LayerNorm" in msg and "'exact'" not in msg and "'kernel_shap'" in msg and "\n" not in msg
    with pytest.raises(InputError, match="784 features is more than 16: use method='deep_shap' or 'kernel_shap'"):
        xairl.explain(policy, x, background=bg, method="exact")


def test_states_of_the_wrong_structure_name_the_expected_one():
    policy = xairl.Policy(nn.Sequential(nn.Flatten(), nn.Linear(3 * 8 * 8, 2)), observation=(3, 8, 8))
    with pytest.raises(InputError, match=r"states must be \(n, 3, 8, 8\) or a flat \(n, 192\) array; got shape"):
        policy.scores(np.zeros((2, 3, 8)))
    d = xairl.Policy(nn.Linear(5, 1), observation={"v": (5,)}, output="value")
    with pytest.raises(InputError, match=r"states lack key\(s\) v; the policy takes \{v: \(n, 5\)\}"):
        d.scores({"w": np.zeros((2, 5))})
