"""A GRU Q-network over the last 4 CartPole observations (CleanRL style), explained over its window: per signal, per
time step, as a signal x time heat map, and in words that speak of trends.

Run: python examples/cleanrl_gru.py [--steps 2000] [--out gru]
"""

import argparse
import random
from collections import deque
from pathlib import Path

import gymnasium as gym
import numpy as np
import torch

import xairl
from xairl import plots

SIGNALS = ["cart_position", "cart_velocity", "pole_angle", "pole_velocity"]
K = 4  # observations in the window: the GRU reads them oldest first

ap = argparse.ArgumentParser()
ap.add_argument("--steps", type=int, default=2000)
ap.add_argument("--out", default="gru")
args = ap.parse_args()
torch.manual_seed(0)
random.seed(0)


class GRUQ(torch.nn.Module):
    def __init__(self):
        super().__init__()
        self.gru = torch.nn.GRU(len(SIGNALS), 32, batch_first=True)
        self.head = torch.nn.Linear(32, 2)

    def forward(self, window):  # (batch, K, signals) -> (batch, 2)
        return self.head(self.gru(window)[0][:, -1])


q = GRUQ()
opt = torch.optim.Adam(q.parameters(), lr=1e-3)
env = gym.make("CartPole-v1")
env.reset(seed=0)  # every later episode follows from this seed
env.action_space.seed(0)


def start():
    obs = env.reset()[0]
    return deque([obs] * K, maxlen=K)  # the first window repeats the first observation


window, seen = start(), []
for step in range(args.steps):  # one-step Q-learning on the window, no replay: enough to have a policy to explain
    x = torch.as_tensor(np.array(window))[None]
    eps = max(0.05, 1 - step / (0.5 * args.steps))
    with torch.no_grad():
        a = env.action_space.sample() if random.random() < eps else int(q(x).argmax())
    nxt, r, term, trunc, _ = env.step(a)
    after = deque(window, maxlen=K)
    after.append(nxt)
    with torch.no_grad():
        target = r + 0.99 * q(torch.as_tensor(np.array(after))[None]).max() * (not term)
    loss = (q(x)[0, a] - target) ** 2
    opt.zero_grad()
    loss.backward()
    opt.step()
    seen.append(np.array(window))
    window = start() if term or trunc else after

policy = xairl.Policy(
    q,
    SIGNALS,  # the signals of one observation; the features are their slots, pole_angle[t-3] ... pole_angle[t]
    ["left", "right"],
    window=K,
    features={"pole_angle": xairl.FeatureInfo("rad", "the pole angle")},
)
states, background = np.array(seen[-3:]), np.array(seen[:: max(1, len(seen) // 40)][:40])
# a recurrent network: kernel_shap (model-agnostic) is the documented path; deep_shap has no rule for a GRU
exp = xairl.explain(policy, states, background=background, method="kernel_shap", options={"nsamples": 600})
print("per signal:", dict(zip(exp.by_signal().feature_names, np.round(exp.by_signal().margin()[0], 3))))
print("per step:", dict(zip(exp.by_step().feature_names, np.round(exp.by_step().margin()[0], 3))))
out = Path(args.out)
out.mkdir(parents=True, exist_ok=True)
plots.save(plots.window_heatmap(exp), out / "heatmap.png")
for i in range(len(states)):
    n = xairl.narrate(exp, i, policy=policy)
    print(f"[{'verified' if n.verified else 'NOT verified'}] {n.text}")
    print("  said as trends:", [f.name for f in xairl.facts.decision_facts(exp, i, policy).trends])
print("global:", xairl.narrate(exp, None, policy=policy).text)
