"""Helpers shared by the core tests. The core is tested alone: no installed plugin is loaded."""

import numpy as np
import pytest
import torch

from xairl import plugins


@pytest.fixture(autouse=True)
def core_only(monkeypatch):
    """Load no entry-point plugin (the reference plugin may be installed): a test that needs one selects it."""
    monkeypatch.setenv(plugins.LOAD_ENV, "")


def mlp(sizes, act=torch.nn.ReLU, seed=0):
    torch.manual_seed(seed)
    layers = []
    for i, (a, b) in enumerate(zip(sizes[:-1], sizes[1:])):
        layers.append(torch.nn.Linear(a, b))
        if i < len(sizes) - 2:
            layers.append(act())
    return torch.nn.Sequential(*layers).eval()


class ReusedActivations(torch.nn.Module):
    """A plain forward() network that calls one ReLU module twice (a known pitfall) and mixes nonlinearities."""

    def __init__(self, f=6, h=12, a=3):
        super().__init__()
        torch.manual_seed(1)
        self.l1, self.l2, self.l3 = torch.nn.Linear(f, h), torch.nn.Linear(h, h), torch.nn.Linear(h, a)
        self.act = torch.nn.ReLU()
        self.squash = torch.nn.Tanh()

    def forward(self, x):
        return self.l3(self.squash(self.act(self.l2(self.act(self.l1(x))))))


@pytest.fixture
def rng():
    return np.random.default_rng(0)
