"""How an attribution runs the user's network (issue 64): in eval mode, saying so when BatchNorm or Dropout was
left in training mode (once per policy), each layer's flag put back; and on one torch thread for a small network,
torch's own count put back."""

import warnings

import numpy as np
import pytest
import torch

import xairl

NAMES = ["a", "b", "c", "d"]


class Recording(torch.nn.Module):
    """A small MLP (optionally wide) with BatchNorm and Dropout that records torch's thread count at each forward."""

    def __init__(self, width: int = 8):
        super().__init__()
        self.body = torch.nn.Sequential(
            torch.nn.Linear(4, width), torch.nn.BatchNorm1d(width), torch.nn.ReLU(), torch.nn.Dropout(0.5)
        )
        self.head = torch.nn.Linear(width, 2)
        self.threads: list[int] = []

    def forward(self, x):
        self.threads.append(torch.get_num_threads())
        return self.head(self.body(x))


@pytest.fixture
def data():
    rng = np.random.default_rng(0)
    return rng.normal(size=(2, 4)), rng.normal(size=(12, 4))


def test_layers_left_in_training_mode_are_named_once_per_policy(data):
    x, bg = data
    net = Recording()
    net.train()
    net.head.eval()  # a layer's own flag, put back as it was
    policy = xairl.Policy(net, NAMES, ["left", "right"])
    with pytest.warns(
        UserWarning, match=r"'policy': layers body\.1 \(BatchNorm1d\), body\.3 \(Dropout\) are in training mode; "
    ):
        exp = xairl.explain(policy, x, background=bg, method="exact")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # said once for this policy, not at every explanation
        again = xairl.explain(policy, x, background=bg, method="exact")
    np.testing.assert_array_equal(exp.values, again.values)  # eval mode: no dropout, running statistics
    assert net.training and net.body[1].training and net.body[3].training and not net.head.training
    with pytest.warns(UserWarning, match="explains the network in eval mode"):  # another policy is told too
        xairl.Policy(net, NAMES, name="other").scores(x)


def test_a_network_in_eval_mode_or_without_such_layers_is_not_warned_about(data):
    x, bg = data
    net = Recording().eval()
    plain = torch.nn.Sequential(torch.nn.Linear(4, 2)).train()  # training mode changes nothing here
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        xairl.explain(xairl.Policy(net, NAMES), x, background=bg, method="exact")
        xairl.explain(xairl.Policy(plain, NAMES), x, background=bg, method="exact")


@pytest.mark.parametrize("method", ["exact", "kernel_shap", "deep_shap"])
def test_a_small_network_is_attributed_on_one_thread_and_the_count_put_back(method, data):
    x, bg = data
    before = torch.get_num_threads()
    torch.set_num_threads(2)
    try:
        small, large = Recording().eval(), Recording(width=20_000).eval()  # 3.6 k and 180 k parameters
        for net in (small, large):
            policy = xairl.Policy(net, NAMES)
            net.threads.clear()
            xairl.explain(
                policy, x, background=bg, method=method, options={"nsamples": 40} if "kernel" in method else {}
            )
            assert torch.get_num_threads() == 2, "torch's thread count must be put back"
            inside = set(net.threads[1:])  # the first forward is the policy's own scoring, before the attribution
            assert inside == ({1} if net is small else {2}), (method, net is small, net.threads)
    finally:
        torch.set_num_threads(before)
