"""The example policy: a hand-written 2-feature Q-network with feature metadata and a background sampler."""

import numpy as np
import torch

import xairl


def thermostat_policy() -> xairl.Policy:
    """Heat when cold, idle when warm."""
    net = torch.nn.Linear(2, 2)
    with torch.no_grad():
        net.weight.copy_(torch.tensor([[-1.0, 0.2], [1.0, -0.2]]))  # columns: temperature, occupancy
        net.bias.copy_(torch.tensor([20.0, -20.0]))
    return xairl.Policy(
        net,
        ["temperature", "occupancy"],
        ["heat", "idle"],
        features={"temperature": xairl.FeatureInfo("degC", "the room temperature", "cold", "warm")},
        background_sampler=lambda n, seed: np.random.default_rng(seed).normal([20.0, 1.0], [3.0, 1.0], size=(n, 2)),
        name="thermostat",
    )
