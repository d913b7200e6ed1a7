"""Narration of image policies in regions: seconds per frame (template narrator, with and without the robustness
components of the confidence), whether each narrative is verified, and how many regions it speaks of.

Networks: SB3's NatureCNN layout on Atari frames (4, 84, 84) and on RGB frames (3, 64, 64), random weights, 50
background frames. Target (issue 29): at most 2 s per frame on 2 cores.
Run: .venv/bin/python benchmarks/bench_image_narration.py [--frames 5]
"""

import argparse
import time

import numpy as np
import torch

import xairl


def nature_cnn(shape, actions=6):
    torch.manual_seed(0)
    conv = torch.nn.Sequential(
        torch.nn.Conv2d(shape[0], 32, 8, 4),
        torch.nn.ReLU(),
        torch.nn.Conv2d(32, 64, 4, 2),
        torch.nn.ReLU(),
        torch.nn.Conv2d(64, 64, 3, 1),
        torch.nn.ReLU(),
        torch.nn.Flatten(),
    )
    flat = conv(torch.zeros(1, *shape)).shape[1]
    return torch.nn.Sequential(conv, torch.nn.Linear(flat, 512), torch.nn.ReLU(), torch.nn.Linear(512, actions)).eval()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--frames", type=int, default=5)
    args = ap.parse_args()
    print(f"{'frames':<12} {'regions':>8} {'s/frame (robustness)':>21} {'s/frame (without)':>18} {'verified':>9}")
    for shape in ((4, 84, 84), (3, 64, 64)):
        policy = xairl.Policy(nature_cnn(shape), observation=shape, name="cnn")
        frames = np.random.default_rng(0).random((args.frames + 50, *shape), dtype=np.float32)
        bg, x = frames[args.frames :], frames[: args.frames]
        exp = xairl.explain(policy, x, background=bg)
        xairl.narrate(exp, 0, policy=policy, robustness=False)  # warm: the template, the vocabulary, spaCy
        with_r, without, ok = [], [], 0
        for i in range(args.frames):
            t = time.perf_counter()
            n = xairl.narrate(exp, i, policy=policy, background=bg)
            with_r.append(time.perf_counter() - t)
            t = time.perf_counter()
            ok += xairl.narrate(exp, i, policy=policy, robustness=False).verified and n.verified
            without.append(time.perf_counter() - t)
        regions = len(xairl.in_regions(exp).feature_names)
        print(
            f"{'x'.join(map(str, shape)):<12} {regions:>8} {np.median(with_r):>21.2f} {np.median(without):>18.2f} "
            f"{ok:>6}/{args.frames}"
        )


if __name__ == "__main__":
    main()
