"""A plain torch Q-network (CleanRL style), trained briefly on CartPole, explained through xairl.Policy.

Run: python examples/cleanrl_style.py [--steps 2000]
"""

import argparse
import random

import gymnasium as gym
import numpy as np
import torch

import xairl

ap = argparse.ArgumentParser()
ap.add_argument("--steps", type=int, default=2000)
args = ap.parse_args()
torch.manual_seed(0)
random.seed(0)
env = gym.make("CartPole-v1")
q = torch.nn.Sequential(
    torch.nn.Linear(4, 64), torch.nn.ReLU(), torch.nn.Linear(64, 64), torch.nn.ReLU(), torch.nn.Linear(64, 2)
)
opt = torch.optim.Adam(q.parameters(), lr=1e-3)
obs, _ = env.reset(seed=0)
seen = []
for step in range(args.steps):  # one-step Q-learning, no replay: short and good enough to have a policy to explain
    eps = max(0.05, 1 - step / (0.5 * args.steps))
    with torch.no_grad():
        a = env.action_space.sample() if random.random() < eps else int(q(torch.as_tensor(obs)).argmax())
    nxt, r, term, trunc, _ = env.step(a)
    with torch.no_grad():
        target = r + 0.99 * q(torch.as_tensor(nxt)).max() * (not term)
    loss = (q(torch.as_tensor(obs))[a] - target) ** 2
    opt.zero_grad()
    loss.backward()
    opt.step()
    seen.append(obs)
    obs = env.reset()[0] if term or trunc else nxt

policy = xairl.Policy(q, ["cart_position", "cart_velocity", "pole_angle", "pole_velocity"], ["left", "right"])
exp = xairl.explain(policy, np.array(seen[-3:]), background=np.array(seen[:200]), method="exact")
print(xairl.narrate(exp, 0, policy=policy, template="why_not").text)
print("global:", xairl.narrate(exp, None, policy=policy).text)
