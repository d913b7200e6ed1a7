"""Train a tiny Stable-Baselines3 DQN on CartPole for a few seconds, then explain its decisions with xairl.

Run: python examples/sb3_cartpole.py [--timesteps 3000]
"""

import argparse

import gymnasium as gym
from stable_baselines3 import DQN

import xairl

ap = argparse.ArgumentParser()
ap.add_argument("--timesteps", type=int, default=3000)
args = ap.parse_args()
env = gym.make("CartPole-v1")
model = DQN("MlpPolicy", env, learning_starts=200, seed=0, verbose=0).learn(args.timesteps)
states = [env.reset(seed=s)[0] for s in range(60)]

# --- xairl: the whole explanation in a few lines ---
policy = xairl.from_sb3(
    model,
    feature_names=["cart_position", "cart_velocity", "pole_angle", "pole_velocity"],
    action_names=["push_left", "push_right"],
)
exp = xairl.explain(policy, states[:5], background=states[5:], method="deep_shap")
for i in range(len(exp.values)):
    print(xairl.narrate(exp, i, policy=policy).text)
print("additivity gap:", float(exp.additivity_gap.max()))
