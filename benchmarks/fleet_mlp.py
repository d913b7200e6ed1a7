"""The fleet benchmarks' policy (bench_stream.py through the CLI, bench_ray.py in process): an 8-64-64-4 ReLU MLP,
seeded, as ``xairl explain --policy benchmarks/fleet_mlp.py:make_policy`` loads it."""

import torch

import xairl


def make_policy() -> xairl.Policy:
    torch.manual_seed(0)
    net = torch.nn.Sequential(
        torch.nn.Linear(8, 64), torch.nn.ReLU(), torch.nn.Linear(64, 64), torch.nn.ReLU(), torch.nn.Linear(64, 4)
    )
    return xairl.Policy(net, [f"s{i}" for i in range(8)], ["a0", "a1", "a2", "a3"])
