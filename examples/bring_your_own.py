"""Bring your own policy to the CLI with nothing installed: a CleanRL-style Q-network saved with torch.save, and a
function that builds the xairl Policy from the checkpoint.

Run: python examples/bring_your_own.py --out byo   (writes byo/my_q.pt, byo/states.npy, byo/background.npy)
then: xairl explain --policy examples/bring_your_own.py:make_policy --policy-arg checkpoint=byo/my_q.pt \
        --states byo/states.npy --background byo/background.npy --out byo/report
"""

import argparse
from pathlib import Path

import numpy as np
import torch
from torch import nn

import xairl

FEATURES = ["cart_position", "cart_velocity", "pole_angle", "pole_velocity"]


class QNetwork(nn.Module):
    """CleanRL's DQN network for CartPole."""

    def __init__(self, n_obs: int = 4, n_actions: int = 2):
        super().__init__()
        self.network = nn.Sequential(
            nn.Linear(n_obs, 120), nn.ReLU(), nn.Linear(120, 84), nn.ReLU(), nn.Linear(84, n_actions)
        )

    def forward(self, x):
        return self.network(x)


def make_policy(checkpoint: str) -> xairl.Policy:
    net = QNetwork()
    net.load_state_dict(torch.load(checkpoint, weights_only=True))
    return xairl.Policy(net.eval(), FEATURES, ["push_left", "push_right"], name="my-q")


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="byo")
    ap.add_argument("--states", type=int, default=10_000)
    ap.add_argument("--background", type=int, default=100)
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    torch.manual_seed(0)
    torch.save(QNetwork().state_dict(), out / "my_q.pt")
    rng = np.random.default_rng(0)
    scale = np.array([2.4, 1.0, 0.2, 1.0], dtype=np.float32)
    np.save(out / "states.npy", (rng.uniform(-1, 1, (args.states, 4)) * scale).astype(np.float32))
    np.save(out / "background.npy", (rng.uniform(-1, 1, (args.background, 4)) * scale).astype(np.float32))
    print(
        f"xairl explain --policy {__file__}:make_policy --policy-arg checkpoint={out / 'my_q.pt'} "
        f"--states {out / 'states.npy'} --background {out / 'background.npy'} --out {out / 'report'}"
    )
