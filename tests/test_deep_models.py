"""Conformance of deep_shap on the networks of shap's own DeepExplainer tests, SB3's NatureCNN and dict / multi-input
networks: values against shap.DeepExplainer and captum's DeepLiftShap, additivity, hooks removed after a failure."""

import numpy as np
import pytest
import torch

import xairl
from tests.deep_models import NAMES, build, captum_values, shap_values

#: captum's DeepLiftShap gives all of a max-pool window's change to the state's arg-max; shap (and xairl) split it
#: between the state's and the reference's arg-max (DeepLIFT's rule as shap implements it). Where a network's
#: max-pools see different arg-maxes the two differ, so captum is the reference only for the other networks.
CAPTUM_MAXPOOL_RULE_DIFFERS = {"mnist_cnn", "dict"} | {n for n in NAMES if n.startswith("multi_input")}


@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES)
def test_deep_shap_equals_shap_and_captum(name):
    policy, x, bg, inputs = build(name)
    e = xairl.explain(policy, x, background=bg, method="deep_shap")
    assert e.values.shape == (2, policy.n_features, policy.n_actions)
    assert e.additivity_gap.max() <= 1e-5
    ref = shap_values(policy, inputs)
    assert np.abs(e.values - ref).max() <= 1e-5, f"max difference to shap {np.abs(e.values - ref).max():.3g}"
    assert np.abs(e.values).max() > 1e-6  # not a trivially zero comparison
    if name not in CAPTUM_MAXPOOL_RULE_DIFFERS and not name.startswith("multi_input:disconnected"):
        np.testing.assert_allclose(e.values, captum_values(policy, x, bg), rtol=0, atol=1e-5)


def hook_count(module):
    return sum(len(m._forward_hooks) + len(m._forward_pre_hooks) + len(m._backward_hooks) for m in module.modules())


@pytest.mark.parametrize("name", ["mnist_cnn", "dict"])
def test_hooks_removed_after_an_injected_failure(name):
    policy, x, bg, _ = build(name)
    last = list(policy.module.modules())[-1]  # the final layer: hooks are on every nonlinear layer by then

    calls = []

    def fail(module, inputs, output):  # call 1 is the policy's own scoring; call 2 runs inside the attributor
        calls.append(1)
        if len(calls) == 2:
            raise RuntimeError("injected failure")

    handle = last.register_forward_hook(fail)
    policy.module.train()
    try:
        with pytest.raises(xairl.InputError, match=r"raised RuntimeError \(injected failure\) on input"):
            xairl.explain(policy, x, background=bg, method="deep_shap")
    finally:
        handle.remove()
    assert hook_count(policy.module) == 0
    assert policy.module.training, "the module's training flag must be put back"


@pytest.mark.parametrize("name", ["nature_cnn", "dict", "multi_input:connected:relu", "nested"])
def test_split_layout_equals_the_joint_one(name):
    """The split layout (reference sides from one background pass, only state sides back-propagated) gives the
    joint layout's values (shap's: both sides back-propagated), max-pool networks included."""
    from xairl.attributors.deep_shap import DeepShap, _rescale, check_supported

    policy, x, bg, _ = build(name)
    rules = check_supported(policy.network)
    assert not any(rule is _rescale for _, rule in rules)  # no Softmax: the split layout is the one used
    xt, bt = torch.as_tensor(policy.check_states(x)), torch.as_tensor(policy.check_states(bg))
    attributor = DeepShap()
    split, base_s, _ = attributor._attribute_pairs(policy.network, rules, xt, bt, policy.n_actions, split=True)
    joint, base_j, _ = attributor._attribute_pairs(policy.network, rules, xt, bt, policy.n_actions, split=False)
    assert np.abs(split - joint).max() <= 1e-6 * max(1.0, np.abs(joint).max()) and np.abs(joint).max() > 1e-6
    np.testing.assert_allclose(base_s, base_j, rtol=1e-6, atol=1e-6)
    assert hook_count(policy.network) == 0
