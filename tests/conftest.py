"""Helpers shared by the core tests. The core is tested alone: no installed plugin is loaded."""

import numpy as np
import pytest
import torch

import xairl
from xairl.cli import main
from xairl.registry import plugins


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


def run(capsys, *argv):
    """``xairl ARGV`` in this process: (exit status, stdout, stderr)."""
    rc = main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, err


def one_line_error(rc, err, *words):
    """A user's error as the CLI must report it: exit status 2, one line, no traceback, naming ``words``."""
    assert rc == 2 and err.startswith("xairl: error: ") and err.count("\n") == 1, err
    assert "Traceback" not in err and "internal error" not in err
    for w in words:
        assert w in err, (w, err)


def small_cnn(observation=(3, 64, 64)):
    """A two-layer CNN over 3x64x64 frames (NatureCNN-like), its policy, and 10 seeded frames."""
    torch.manual_seed(0)
    net = torch.nn.Sequential(
        torch.nn.Conv2d(3, 4, 8, 4),
        torch.nn.ReLU(),
        torch.nn.Conv2d(4, 8, 4, 2),
        torch.nn.ReLU(),
        torch.nn.Flatten(),
        torch.nn.Linear(8 * 6 * 6, 4),
    )
    policy = xairl.Policy(net, observation=observation, name="cnn")
    frames = np.random.default_rng(0).integers(0, 256, (10, 3, 64, 64)).astype(np.float32)
    return policy, frames
