"""An Atari-style CNN Q-network (SB3's NatureCNN on 4 stacked 84x84 frames) explained with xairl: pixels, patches,
an image plot, and the same policy from the command line with nothing installed.

Run: python examples/atari_cnn.py [--out out/atari-report]
CLI: xairl explain --policy examples/atari_cnn.py:make_policy --policy-arg seed=0 --states s.npy --background bg.npy \
       --out DIR        (s.npy, bg.npy: uint8 or float frames of shape (n, 4, 84, 84); this script writes both)
"""

import argparse
from pathlib import Path

import numpy as np
import torch

import xairl

ACTIONS = ["noop", "fire", "up", "right", "left", "down"]


def make_policy(seed: int = 0, checkpoint: str | None = None) -> xairl.Policy:
    """NatureCNN + a Q head (random weights, or a state dict saved with torch.save(module.state_dict(), path))."""
    from gymnasium import spaces
    from stable_baselines3.common.torch_layers import NatureCNN

    torch.manual_seed(int(seed))
    net = torch.nn.Sequential(NatureCNN(spaces.Box(0, 255, (4, 84, 84), np.uint8)), torch.nn.Linear(512, 6))
    if checkpoint:
        net.load_state_dict(torch.load(checkpoint, weights_only=True))
    # frames arrive as 0..255; the network sees them / 255 as SB3 does (a linear step, explained through)
    return xairl.Policy(
        torch.nn.Sequential(Scale(1 / 255), net).eval(),
        observation=xairl.Observation.array((4, 84, 84), channels="frames"),  # a stack of 4 frames
        action_names=ACTIONS,
        name="atari-nature-cnn",
    )


class Scale(torch.nn.Module):
    xairl_linear = True  # an affine map: deep_shap may read its gradient as its multiplier

    def __init__(self, factor: float):
        super().__init__()
        self.factor = factor

    def forward(self, x):
        return x * self.factor


def frames(n: int, seed: int) -> np.ndarray:
    """Moving-blob frames, 4 stacked: something for the network to look at."""
    rng = np.random.default_rng(seed)
    out = rng.integers(0, 40, (n, 4, 84, 84)).astype(np.uint8)
    for i in range(n):
        r, c = rng.integers(10, 70, 2)
        for t in range(4):
            out[i, t, r + t : r + t + 8, c : c + 8] = 255
    return out


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="out/atari-report")
    args = ap.parse_args()
    policy = make_policy()
    states, background = frames(3, seed=1), frames(10, seed=2)
    exp = xairl.explain(policy, states, background=background, method="deep_shap")
    print("chosen:", [ACTIONS[a] for a in exp.chosen], "additivity gap:", float(exp.additivity_gap.max()))
    by_patch = exp.grouped(xairl.patches((4, 84, 84), 6))  # 14 x 14 patches of 6 x 6 pixels over the 4 frames
    top = np.argsort(-np.abs(by_patch.for_chosen()[0]))[:3]
    print("state 0, strongest patches:", [by_patch.feature_names[j] for j in top])
    print(xairl.narrate(by_patch, None).text)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    np.save(out / "states.npy", states)
    np.save(out / "background.npy", background)
    from xairl import plots

    print("image plot:", plots.save(plots.image(exp, 0), out / "image.png"))
