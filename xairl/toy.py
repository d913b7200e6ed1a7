"""A tiny, deterministic example policy, so the CLI and the tests have something to explain without any plugin."""

from __future__ import annotations

import numpy as np
import torch

from xairl.policies.policy import FeatureInfo, Policy

FEATURES = ("battery", "distance", "speed", "obstacle", "wind")
ACTIONS = ("forward", "turn", "recharge")


def toy_network(seed: int = 0) -> torch.nn.Module:
    """A 5-16-16-3 ReLU MLP with weights drawn from a seeded generator (no global RNG touched)."""
    gen = torch.Generator().manual_seed(seed)
    net = torch.nn.Sequential(
        torch.nn.Linear(5, 16), torch.nn.ReLU(), torch.nn.Linear(16, 16), torch.nn.ReLU(), torch.nn.Linear(16, 3)
    )
    with torch.no_grad():
        for p in net.parameters():
            p.copy_(torch.randn(p.shape, generator=gen) * 0.5)
    return net.eval()


def toy_background(n: int, seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).normal(size=(n, len(FEATURES))).astype(np.float32)


def toy_policy() -> Policy:
    return Policy(
        toy_network(),
        FEATURES,
        ACTIONS,
        features={
            "battery": FeatureInfo("", "battery charge (standardised)", "low", "high"),
            "distance": FeatureInfo("", "distance to the goal (standardised)", "close", "far"),
        },
        background_sampler=toy_background,
        name="toy",
    )
