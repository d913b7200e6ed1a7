"""A continuous-control actor and its critic (SB3 TD3 on Pendulum, trained for a few seconds) explained with xairl:
each action dimension on its own, the critic's Q(s, actor(s)) as a value, both narrated and verified.

Run: python examples/continuous_actor.py [--timesteps 600]
"""

import argparse

import gymnasium as gym
from stable_baselines3 import TD3

import xairl

ap = argparse.ArgumentParser()
ap.add_argument("--timesteps", type=int, default=600)
args = ap.parse_args()
env = gym.make("Pendulum-v1")
model = TD3("MlpPolicy", env, learning_starts=100, buffer_size=5_000, seed=0, verbose=0).learn(args.timesteps)
states = [env.reset(seed=s)[0] for s in range(60)]
names = ["cos_theta", "sin_theta", "angular_velocity"]

# --- xairl: the actor's torque (in N m, as the environment takes it) and the critic's value of it ---
actor = xairl.from_sb3(model, feature_names=names, action_names=["torque"])  # output: continuous
critic = xairl.from_sb3(model, head="q", feature_names=names, action_names=["Q"])  # output: value
for policy in (actor, critic):
    exp = xairl.explain(policy, states[:2], background=states[2:], method="deep_shap")
    n = xairl.narrate(exp, 0, policy=policy, background=states[2:])
    print(f"[{policy.output}, verified={n.verified}, confidence {n.confidence:.2f}] {n.text}")
