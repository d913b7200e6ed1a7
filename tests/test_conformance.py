"""One table over every registered attributor (captum's idea): shape, determinism, additivity, clean-up."""

import numpy as np
import pytest
import torch

import xairl
from tests.conftest import ReusedActivations, mlp
from xairl.attributors.base import Attributor
from xairl.registry import plugins

MODELS = {
    "relu_mlp": lambda: mlp([5, 16, 16, 3]),
    "mixed_acts": lambda: torch.nn.Sequential(
        torch.nn.Linear(5, 8),
        torch.nn.LeakyReLU(0.1),
        torch.nn.Linear(8, 8),
        torch.nn.ELU(),
        torch.nn.Linear(8, 8),
        torch.nn.SiLU(),
        torch.nn.Linear(8, 8),
        torch.nn.Sigmoid(),
        torch.nn.Linear(8, 8),
        torch.nn.Softplus(),
        torch.nn.Linear(8, 8),
        torch.nn.GELU(),
        torch.nn.Linear(8, 4),
    ),
    "reused_relu": lambda: ReusedActivations(f=5),
}
# IG is not a Shapley method: its gap is its convergence delta, bounded here for 64 Gauss-Legendre steps
GAP_LIMIT = {"integrated_gradients": 5e-2}
SMALL = {"kernel_shap": {"nsamples": 64}}


def all_methods():
    plugins.reset()
    names = plugins.registry("attributor").names()
    plugins.reset()
    return names


def make_policy(model_name):
    torch.manual_seed(3)
    net = MODELS[model_name]().eval()
    n_out = net(torch.zeros(1, 5)).shape[1]
    return xairl.Policy(net, [f"f{i}" for i in range(5)], [f"a{i}" for i in range(n_out)])


@pytest.fixture(scope="module")
def data():
    r = np.random.default_rng(7)
    return r.normal(size=(6, 5)).astype(np.float32), r.normal(size=(20, 5)).astype(np.float32)


def test_builtins_are_registered():
    assert {"deep_shap", "kernel_shap", "integrated_gradients", "exact"} <= set(plugins.registry("attributor").names())


@pytest.mark.parametrize("model_name", sorted(MODELS))
@pytest.mark.parametrize("method", all_methods())
def test_shape_determinism_additivity(method, model_name, data):
    x, bg = data
    policy = make_policy(model_name)
    opts = SMALL.get(method, {})
    e1 = xairl.explain(policy, x, background=bg, method=method, options=opts)
    e2 = xairl.explain(policy, x, background=bg, method=method, options=opts)
    assert e1.values.shape == (6, 5, policy.n_actions)
    assert e1.base_values.shape == (6, policy.n_actions)
    assert e1.method == method
    np.testing.assert_array_equal(e1.values, e2.values)
    np.testing.assert_allclose(e1.outputs, policy.scores(x), rtol=0, atol=1e-6)
    assert e1.additivity_gap.max() <= GAP_LIMIT.get(method, 1e-4)
    if method == "integrated_gradients":
        np.testing.assert_allclose(np.abs(e1.extras["convergence_delta"]), e1.additivity_gap, atol=1e-4)


class Exploding(torch.nn.Module):
    """Raises on its `fuse`-th forward call, after the attributor has set up whatever it uses."""

    def __init__(self, fuse):
        super().__init__()
        self.net = mlp([5, 8, 3])
        self.calls, self.fuse = 0, fuse

    def forward(self, x):
        self.calls += 1
        if self.calls == self.fuse:
            raise RuntimeError("injected failure")
        return self.net(x)


def hook_count(module):
    return sum(len(m._forward_hooks) + len(m._forward_pre_hooks) + len(m._backward_hooks) for m in module.modules())


@pytest.mark.parametrize("method", all_methods())
def test_hooks_and_mode_restored_after_error(method, data):
    x, bg = data
    net = Exploding(fuse=2)  # call 1 is the policy's own scoring; call 2 is inside the attributor
    net.train()
    policy = xairl.Policy(net, [f"f{i}" for i in range(5)], ["a", "b", "c"])
    # the user's exception comes out as one xairl line naming the module and the input's shape
    with pytest.raises(
        xairl.InputError, match=r"module Exploding raised RuntimeError \(injected failure\) on input \("
    ):
        xairl.explain(policy, x, background=bg, method=method, options=SMALL.get(method, {}))
    assert net.calls >= 2
    assert hook_count(net) == 0
    assert net.training, "the module's training flag must be put back"


def test_seeded_kernel_shap_differs_across_seeds(data):
    x, bg = data
    policy = make_policy("relu_mlp")
    a = xairl.explain(policy, x, background=bg, method="kernel_shap", options={"nsamples": 20, "seed": 1})
    b = xairl.explain(policy, x, background=bg, method="kernel_shap", options={"nsamples": 20, "seed": 2})
    assert not np.array_equal(a.values, b.values)


def test_every_registered_attributor_subclasses_base():
    for name in plugins.registry("attributor").names():
        assert issubclass(plugins.get_attributor(name), Attributor)
