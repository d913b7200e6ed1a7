"""Our values against independent references: shap.DeepExplainer, captum DeepLiftShap, brute-force Shapley."""

import itertools
from math import factorial

import numpy as np
import pytest
import torch

import xairl
from tests.conftest import ReusedActivations, mlp
from xairl.errors import InputError, UnsupportedModelError


def policy_of(net, f, a):
    return xairl.Policy(net.eval(), [f"f{i}" for i in range(f)], [f"a{i}" for i in range(a)])


REF_MODELS = {
    "relu_12_64_64_4": (lambda: mlp([12, 64, 64, 4]), 12, 4),
    "relu_8_32_2": (lambda: mlp([8, 32, 2], seed=5), 8, 2),
    "tanh_6_16_16_3": (lambda: mlp([6, 16, 16, 3], act=torch.nn.Tanh, seed=2), 6, 3),
}


@pytest.mark.parametrize("name", sorted(REF_MODELS))
def test_deep_shap_matches_shap_and_captum(name):
    import shap
    from captum.attr import DeepLiftShap

    build, f, a = REF_MODELS[name]
    net = build()
    r = np.random.default_rng(1)
    x = torch.tensor(r.normal(size=(10, f)), dtype=torch.float32)
    bg = torch.tensor(r.normal(size=(25, f)), dtype=torch.float32)
    ours = xairl.explain(policy_of(net, f, a), x, background=bg, method="deep_shap").values

    sv = shap.DeepExplainer(net, bg).shap_values(x, check_additivity=False)
    ref_shap = np.stack(sv, axis=-1) if isinstance(sv, list) else np.asarray(sv)
    assert ref_shap.shape == ours.shape
    np.testing.assert_allclose(ours, ref_shap, rtol=0, atol=1e-5)

    dls = DeepLiftShap(net)
    ref_captum = np.stack([dls.attribute(x, baselines=bg, target=k).detach().numpy() for k in range(a)], axis=-1)
    np.testing.assert_allclose(ours, ref_captum, rtol=0, atol=1e-5)


def test_deep_shap_reused_module_is_exact():
    """A ReLU module called twice: our per-call hooks keep additivity (shap/captum state per module breaks here)."""
    net = ReusedActivations(f=6)
    r = np.random.default_rng(2)
    e = xairl.explain(
        policy_of(net, 6, 3), r.normal(size=(8, 6)), background=r.normal(size=(16, 6)), method="deep_shap"
    )
    assert e.additivity_gap.max() < 1e-5


def test_deep_shap_refuses_unsupported_layer():
    net = torch.nn.Sequential(torch.nn.Linear(4, 4), torch.nn.LayerNorm(4), torch.nn.Linear(4, 2))
    with pytest.raises(UnsupportedModelError, match=r"LayerNorm.*kernel_shap"):
        xairl.explain(policy_of(net, 4, 2), np.ones((2, 4)), background=np.zeros((3, 4)), method="deep_shap")


def test_deep_shap_refuses_functional_nonlinearity():
    class Functional(torch.nn.Module):
        def __init__(self):
            super().__init__()
            self.a, self.b = torch.nn.Linear(4, 8), torch.nn.Linear(8, 2)

        def forward(self, x):
            return self.b(torch.relu(self.a(x)))

    torch.manual_seed(0)
    r = np.random.default_rng(0)
    with pytest.raises(UnsupportedModelError, match="do not add up"):
        xairl.explain(
            policy_of(Functional(), 4, 2),
            r.normal(size=(5, 4)) * 3,
            background=r.normal(size=(9, 4)),
            method="deep_shap",
        )


def brute_force_shapley(fn, x, bg):
    """Average marginal contribution over all feature orderings (a formula independent of ours)."""
    f = len(x)

    def v(coalition):
        rows = bg.copy()
        rows[:, list(coalition)] = x[list(coalition)]
        return fn(rows).mean(axis=0)

    phi = np.zeros((f, fn(bg[:1]).shape[1]))
    for order in itertools.permutations(range(f)):
        seen = []
        for j in order:
            before = v(seen)
            seen.append(j)
            phi[j] += v(seen) - before
    return phi / factorial(f)


def test_exact_equals_brute_force_on_four_features():
    net = mlp([4, 10, 10, 3], seed=4)
    policy = policy_of(net, 4, 3)
    r = np.random.default_rng(3)
    x, bg = r.normal(size=(3, 4)).astype(np.float32), r.normal(size=(12, 4)).astype(np.float32)
    e = xairl.explain(policy, x, background=bg, method="exact")
    for i in range(3):
        np.testing.assert_allclose(e.values[i], brute_force_shapley(policy.scores, x[i], bg), rtol=0, atol=1e-6)
    assert e.additivity_gap.max() < 1e-5


def test_exact_refuses_more_than_16_features():
    net = mlp([17, 4, 2])
    with pytest.raises(InputError, match="17 features.*16"):
        xairl.explain(policy_of(net, 17, 2), np.zeros((1, 17)), background=np.ones((2, 17)), method="exact")


def test_kernel_shap_approaches_exact_as_budget_grows():
    """Measured on this 10-feature MLP (2^10 coalitions), max |error| vs exact: 1.2e-2 at 60 samples, 3.2e-3 at 200,
    1.6e-3 at 600, 6e-9 at 1,100 (every coalition enumerated). The bounds sit 3x above those."""
    net = mlp([10, 32, 32, 3], seed=6)
    policy = policy_of(net, 10, 3)
    r = np.random.default_rng(4)
    x, bg = r.normal(size=(4, 10)), r.normal(size=(10, 10))
    truth = xairl.explain(policy, x, background=bg, method="exact").values
    errors = [
        np.abs(
            xairl.explain(policy, x, background=bg, method="kernel_shap", options={"nsamples": n}).values - truth
        ).max()
        for n in (60, 600, 1100)
    ]
    assert errors[0] > errors[1] > errors[2]
    assert errors[0] < 0.04
    assert errors[1] < 5e-3
    assert errors[2] < 1e-6


class PlainForward(torch.nn.Module):
    """A plain forward() network with distinct modules, dropout and batch norm (eval), as in shap's own tests."""

    def __init__(self, act):
        super().__init__()
        torch.manual_seed(8)
        self.fc1, self.bn, self.fc2, self.fc3 = (
            torch.nn.Linear(7, 24),
            torch.nn.BatchNorm1d(24),
            torch.nn.Linear(24, 12),
            torch.nn.Linear(12, 3),
        )
        self.a1, self.a2, self.drop = act(), act(), torch.nn.Dropout(0.2)
        with torch.no_grad():
            self.bn.running_mean.uniform_(-0.5, 0.5)
            self.bn.running_var.uniform_(0.5, 2.0)

    def forward(self, x):
        return self.fc3(self.drop(self.a2(self.fc2(self.a1(self.bn(self.fc1(x)))))))


SHAP_ACTS = [
    torch.nn.ReLU,
    torch.nn.LeakyReLU,
    torch.nn.ELU,
    torch.nn.Sigmoid,
    torch.nn.Tanh,
    torch.nn.Softplus,
    torch.nn.SELU,
    torch.nn.GELU,
]
CAPTUM_ACTS = {torch.nn.ReLU, torch.nn.ELU, torch.nn.Sigmoid, torch.nn.Tanh, torch.nn.Softplus}


@pytest.mark.parametrize("act", SHAP_ACTS, ids=lambda a: a.__name__)
def test_deep_shap_matches_references_per_activation(act):
    import shap
    from captum.attr import DeepLiftShap

    net = PlainForward(act).eval()
    r = np.random.default_rng(9)
    x = torch.tensor(r.normal(size=(8, 7)), dtype=torch.float32)
    bg = torch.tensor(r.normal(size=(20, 7)), dtype=torch.float32)
    ours = xairl.explain(policy_of(net, 7, 3), x, background=bg, method="deep_shap")
    assert ours.additivity_gap.max() < 1e-4
    ref = np.asarray(shap.DeepExplainer(net, bg).shap_values(x, check_additivity=False))
    np.testing.assert_allclose(ours.values, ref, rtol=0, atol=1e-5)
    if act in CAPTUM_ACTS:
        dls = DeepLiftShap(net)
        ref_c = np.stack([dls.attribute(x, baselines=bg, target=k).detach().numpy() for k in range(3)], axis=-1)
        np.testing.assert_allclose(ours.values, ref_c, rtol=0, atol=1e-5)


def test_deep_shap_chunking_does_not_change_values():
    net = mlp([6, 16, 2], seed=3)
    r = np.random.default_rng(5)
    x, bg = r.normal(size=(9, 6)), r.normal(size=(13, 6))
    p = policy_of(net, 6, 2)
    a = xairl.explain(p, x, background=bg, method="deep_shap").values
    b = xairl.explain(p, x, background=bg, method="deep_shap", options={"max_pairs": 5}).values
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-6)  # float32 sums in another order differ by ~4e-9
