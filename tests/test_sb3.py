"""xairl.from_sb3 on real Stable-Baselines3 models (a few gradient steps, no mocks)."""
import gymnasium as gym
import numpy as np
import pytest
import torch

import xairl
from xairl.errors import InputError


def test_ppo_logits_match_the_sb3_policy():
    from stable_baselines3 import PPO

    env = gym.make("CartPole-v1")
    model = PPO("MlpPolicy", env, n_steps=32, batch_size=32, n_epochs=1, seed=0).learn(32)
    policy = xairl.from_sb3(model)
    assert policy.feature_names == ["obs_0", "obs_1", "obs_2", "obs_3"] and policy.n_actions == 2
    obs = np.stack([env.reset(seed=s)[0] for s in range(12)])
    with torch.no_grad():
        dist = model.policy.get_distribution(torch.as_tensor(obs))
    # torch's Categorical keeps normalised logits (log-probabilities); ours are the raw action-net outputs
    ours = torch.log_softmax(torch.as_tensor(policy.scores(obs)), dim=1).numpy()
    np.testing.assert_allclose(ours, dist.distribution.logits.numpy(), atol=1e-5)
    exp = xairl.explain(policy, obs[:3], background=obs[3:], method="deep_shap")
    assert exp.additivity_gap.max() < 1e-4


def test_continuous_actions_are_refused():
    from stable_baselines3 import PPO

    model = PPO("MlpPolicy", gym.make("Pendulum-v1"), n_steps=16, batch_size=16, seed=0)
    with pytest.raises(InputError, match="discrete actions"):
        xairl.from_sb3(model)
