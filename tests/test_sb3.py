"""xairl.from_sb3 on real Stable-Baselines3 models of every algorithm and policy kind (built untrained with small
buffers, a few gradient steps where cheap; no mocks). Each Policy's outputs are compared here with SB3's own."""

import gymnasium as gym
import numpy as np
import pytest
import torch
from gymnasium import spaces

import xairl
from xairl.errors import InputError

IMAGE = spaces.Box(0, 255, (4, 84, 84), np.uint8)  # Atari frames after SB3's VecFrameStack + transpose
DICT = spaces.Dict(
    {
        "image": spaces.Box(0, 255, (3, 36, 36), np.uint8),
        "vec": spaces.Box(-1, 1, (5,), np.float32),
        "mode": spaces.Discrete(3),
    }
)


class SpaceEnv(gym.Env):
    """Random observations of a given space: enough to build and briefly train any SB3 algorithm."""

    def __init__(self, obs, act):
        self.observation_space, self.action_space = obs, act

    def reset(self, seed=None, options=None):
        super().reset(seed=seed)
        return self.observation_space.sample(), {}

    def step(self, action):
        return (
            self.observation_space.sample(),
            float(self.np_random.normal()),
            False,
            bool(self.np_random.random() < 0.1),
            {},
        )


def states(space, n, seed=1):
    space.seed(seed)
    raw = [space.sample() for _ in range(n)]
    return {k: np.stack([r[k] for r in raw]) for k in space.spaces} if isinstance(space, spaces.Dict) else np.stack(raw)


def sb3_outputs(model, head, obs):
    """What SB3 itself computes for ``obs`` (the reference for each head)."""
    p = model.policy
    with torch.no_grad():
        t, _ = p.obs_to_tensor(obs)
        if head == "q-values":
            return p.q_net(t).numpy()
        if head == "log-probs":
            return p.get_distribution(t).distribution.logits.numpy()
        if head == "value":
            return p.predict_values(t).numpy()
        if head == "q":
            act = p.actor(t, deterministic=True) if hasattr(p.actor, "latent_pi") else p.actor(t)
            return p.critic.q1_forward(t, act).numpy()
    return np.asarray(model.predict(obs, deterministic=True)[0], dtype=np.float64)


def build(algo, policy_kind, obs, act, **kw):
    import stable_baselines3 as sb3

    cls = getattr(sb3, algo)
    if algo in ("DQN", "SAC", "TD3", "DDPG"):
        kw.setdefault("buffer_size", 200)
        kw.setdefault("learning_starts", 16)
    else:
        kw.setdefault("n_steps", 16)
        if algo == "PPO":
            kw.setdefault("batch_size", 16)
    return cls(policy_kind, SpaceEnv(obs, act) if not isinstance(obs, str) else gym.make(obs), seed=0, **kw)


CASES = [  # algorithm, policy, observation, action space, head, reference, output kind, train steps
    ("DQN", "MlpPolicy", "CartPole-v1", None, "policy", "q-values", "actions", 64),
    ("DQN", "CnnPolicy", IMAGE, spaces.Discrete(6), "policy", "q-values", "actions", 0),
    ("DQN", "MultiInputPolicy", DICT, spaces.Discrete(4), "policy", "q-values", "actions", 32),
    ("PPO", "MlpPolicy", "CartPole-v1", None, "policy", "log-probs", "actions", 32),
    ("PPO", "MlpPolicy", "CartPole-v1", None, "value", "value", "value", 0),
    ("PPO", "MlpPolicy", "Pendulum-v1", None, "policy", "predict", "continuous", 32),
    (
        "A2C",
        "MlpPolicy",
        spaces.Box(-1, 1, (6,), np.float32),
        spaces.Box(-2, 3, (2,), np.float32),
        "policy",
        "predict",
        "continuous",
        16,
    ),
    ("A2C", "MultiInputPolicy", DICT, spaces.Discrete(3), "value", "value", "value", 0),
    ("SAC", "MlpPolicy", "Pendulum-v1", None, "policy", "predict", "continuous", 32),
    ("SAC", "MlpPolicy", "Pendulum-v1", None, "q", "q", "value", 0),
    (
        "TD3",
        "MlpPolicy",
        spaces.Box(-1, 1, (6,), np.float32),
        spaces.Box(-2, 3, (2,), np.float32),
        "policy",
        "predict",
        "continuous",
        32,
    ),
    ("DDPG", "MlpPolicy", "Pendulum-v1", None, "q", "q", "value", 0),
]


@pytest.mark.slow
@pytest.mark.parametrize(
    "algo, kind, obs, act, head, ref, output, steps", CASES, ids=[f"{c[0]}-{c[1]}-{c[4]}" for c in CASES]
)
def test_from_sb3_equals_sb3(algo, kind, obs, act, head, ref, output, steps):
    model = build(algo, kind, obs, act)
    if steps:
        model.learn(steps)
    policy = xairl.from_sb3(model, head=head)
    assert policy.output == output
    x = states(model.observation_space, 12)
    ours = policy.scores(x)
    if ref == "log-probs":  # torch's Categorical keeps normalised logits
        ours = torch.log_softmax(torch.as_tensor(ours), dim=1).numpy()
    np.testing.assert_allclose(ours, sb3_outputs(model, ref, x).reshape(ours.shape), rtol=0, atol=1e-6)
    if output == "actions":
        np.testing.assert_array_equal(policy.act(x), model.predict(x, deterministic=True)[0])
    e = xairl.explain(
        policy,
        {k: v[:2] for k, v in x.items()} if isinstance(x, dict) else x[:2],
        background={k: v[2:] for k, v in x.items()} if isinstance(x, dict) else x[2:],
    )
    assert e.output == output and e.values.shape == (2, policy.n_features, policy.n_actions)
    assert e.additivity_gap.max() <= 1e-5 * max(1.0, np.abs(e.outputs).max())


def test_image_feature_names_and_image_view():
    model = build("DQN", "CnnPolicy", IMAGE, spaces.Discrete(6))
    policy = xairl.from_sb3(model)
    assert policy.feature_names[0] == "obs[0,0,0]" and policy.n_features == 4 * 84 * 84
    x = states(IMAGE, 3)
    e = xairl.explain(policy, x[:1], background=x[1:])
    assert e.image().shape == (1, 4, 84, 84)
    np.testing.assert_allclose(e.image(0).sum(axis=(1, 2, 3)) + e.base_values[:, 0], e.outputs[:, 0], atol=1e-4)


def test_dict_observation_one_hot_and_groups():
    model = build("DQN", "MultiInputPolicy", DICT, spaces.Discrete(4))
    policy = xairl.from_sb3(model)
    assert [f for f in policy.feature_names if f.startswith("mode")] == ["mode=0", "mode=1", "mode=2"]
    x = states(DICT, 6)
    e = xairl.explain(policy, {k: v[:2] for k, v in x.items()}, background={k: v[2:] for k, v in x.items()})
    g = e.grouped(e.groups_by_part())
    assert g.feature_names == ("image", "mode", "vec")  # SB3 sorts Dict keys
    np.testing.assert_allclose(g.values.sum(axis=1), e.values.sum(axis=1), atol=1e-9)
    with pytest.raises(InputError, match=r"states\['mode'\] must hold one integer in 0..2"):
        policy.scores({**x, "mode": np.full(6, 7)})


def test_multidiscrete_is_explained_one_branch_at_a_time():
    model = build("PPO", "MlpPolicy", spaces.Box(-1, 1, (4,), np.float32), spaces.MultiDiscrete([3, 2]))
    with pytest.raises(InputError, match="pick one with branch=0..1"):
        xairl.from_sb3(model)
    x = states(model.observation_space, 8)
    for b, n in ((0, 3), (1, 2)):
        policy = xairl.from_sb3(model, branch=b)
        assert policy.action_names == tuple(f"action_{b}={i}" for i in range(n))
        np.testing.assert_array_equal(policy.act(x), model.predict(x, deterministic=True)[0][:, b])


SIGNALS = ["cart_position", "cart_velocity", "pole_angle", "pole_velocity"]


def verified_and_caught(policy, exp):
    """Decision 0 narrated, every claim verified, and the same words with the first signed number changed caught."""
    n = xairl.narrate(exp, 0, policy=policy, robustness=False)
    assert n.verified and "over the last 4 observations" in n.text, n.text
    assert xairl.verify(n.text, exp, 0, policy).accurate  # (read again as outside prose: nothing false)
    assert xairl.verify(n.text, exp, 0, policy, provenance=n.provenance).ok
    first = next(c for c in n.claims if c.kind == "number" and "+" in c.text)
    assert not xairl.verify(n.text.replace(first.text, "+9.99", 1), exp, 0, policy).ok
    return n


@pytest.fixture(scope="module")
def stacked():
    """PPO trained 256 steps on CartPole behind VecFrameStack(n_stack=4), and 40 states it met (stacked rows)."""
    from stable_baselines3 import PPO
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import VecFrameStack

    env = VecFrameStack(make_vec_env("CartPole-v1", n_envs=1, seed=0), n_stack=4)
    model = PPO("MlpPolicy", env, n_steps=64, batch_size=32, n_epochs=2, seed=0, policy_kwargs={"net_arch": [32]})
    model.learn(256)
    obs = [env.reset()]
    for _ in range(40):
        obs.append(env.step(model.predict(obs[-1], deterministic=True)[0])[0])
    return model, np.concatenate(obs)


def test_a_vec_frame_stack_is_a_stacked_window_explained_narrated_and_verified(stacked):
    """Issue 64: the VecFrameStack is found in the model's environment (or declared with window=4, or with a window
    observation): a window of layout 'stacked', narrated per signal over the last 4 observations, and verified."""
    model, states = stacked
    policy = xairl.from_sb3(model, feature_names=SIGNALS)
    assert policy.window == 4 and policy.observation.parts[0].window.layout == "stacked"
    assert policy.feature_names[:5] == (*(f"{s}[t-3]" for s in SIGNALS), "cart_position[t-2]")
    np.testing.assert_array_equal(policy.act(states), model.predict(states, deterministic=True)[0])
    exp = xairl.explain(policy, states[-3:], background=states[:30])
    assert exp.by_signal().feature_names == tuple(SIGNALS)
    verified_and_caught(policy, exp)
    declared = xairl.Observation.window(SIGNALS, 4, layout="stacked", step_s=0.02)
    assert xairl.from_sb3(model, observation=declared).observation.parts[0].window.step_s == 0.02
    assert xairl.from_sb3(model, window=4).feature_names[0] == "obs_0[t-3]"
    with pytest.raises(InputError, match=r"stacks 4 observations \(VecFrameStack\) but window=3"):
        xairl.from_sb3(model, window=3)
    with pytest.raises(InputError, match=r"number of observations \(k >= 2\); got 0"):
        xairl.from_sb3(model, window=0)
    with pytest.raises(InputError, match="name the signals of one observation"):
        xairl.from_sb3(model, feature_names=SIGNALS[:3])


@pytest.fixture(scope="module")
def recurrent():
    """RecurrentPPO (MlpLstmPolicy) trained 256 steps on CartPole; an episode's observations (at least 8) and the
    LSTM state predict returned after each."""
    from sb3_contrib import RecurrentPPO

    model = RecurrentPPO(
        "MlpLstmPolicy",
        gym.make("CartPole-v1"),
        n_steps=64,
        batch_size=32,
        n_epochs=2,
        seed=0,
        policy_kwargs={"lstm_hidden_size": 16, "net_arch": [16]},
    )
    model.learn(256)
    env = gym.make("CartPole-v1")
    obs, state, seen, states = env.reset(seed=1)[0], None, [], []
    for t in range(12):  # until the episode ends (it lasts 9 steps here), at most 12
        seen.append(obs)
        action, state = model.predict(obs, state=state, episode_start=np.array([t == 0]), deterministic=True)
        states.append(state)
        obs, _, terminated, *_ = env.step(int(action))
        if terminated:
            break
    return model, np.array(seen), states


def test_recurrent_ppo_is_explained_over_a_window_from_a_reset(recurrent):
    """Issue 64: RecurrentPPO explained over its last 4 observations, the LSTM unrolled from a reset, which the
    policy and its explanations say; narrated and verified. Without window= it says what to give."""
    model, seen, _ = recurrent
    with pytest.raises(InputError, match="recurrent: .* give window=k to explain it over the last k observations"):
        xairl.from_sb3(model)
    policy = xairl.from_sb3(model, window=4, feature_names=SIGNALS)  # checked against sb3-contrib's own steps
    assert (
        policy.description
        == "RecurrentPPO's LSTM unrolled over the last 4 observations from a reset (zero) hidden state"
    )
    windows = np.stack([seen[t - 3 : t + 1] for t in range(3, len(seen))])
    exp = xairl.explain(policy, windows[-2:], background=windows, method="kernel_shap", options={"nsamples": 300})
    assert exp.extras["policy"] == policy.description and repr(policy).endswith(f"; {policy.description})")
    verified_and_caught(policy, exp)
    assert xairl.from_sb3(model, window=4, head="value").output == "value"  # the critic's LSTM, checked too


def test_recurrent_ppo_from_the_episode_hidden_state_is_the_decision_it_took(recurrent):
    """With hidden= (the state predict returned one step before the window), the unrolled network's logits are the
    ones sb3-contrib computed at that step of the episode."""
    model, seen, states = recurrent
    t = len(seen) - 1  # the episode's last decision, on the window seen[t-3..t]
    assert t >= 7
    policy = xairl.from_sb3(model, window=4, hidden=states[t - 4])  # the state before the window's first step
    assert policy.description.endswith("from the episode's hidden state before the window (hidden=)")
    p = model.policy
    with torch.no_grad():  # what sb3-contrib computed at step t: its observation after the state of step t - 1
        lstm = tuple(torch.as_tensor(s, dtype=torch.float32) for s in states[t - 1])
        dist = p.get_distribution(p.obs_to_tensor(seen[t])[0], lstm, torch.zeros(1))[0].distribution
    ours = torch.log_softmax(torch.as_tensor(policy.scores(seen[t - 3 : t + 1])), dim=1).numpy()
    np.testing.assert_allclose(ours, dist.logits.numpy(), atol=1e-5)
    reset = xairl.from_sb3(model, window=4).scores(seen[t - 3 : t + 1])  # from a reset: another function
    assert np.abs(reset - policy.scores(seen[t - 3 : t + 1])).max() > 1e-4
    with pytest.raises(InputError, match="hidden is the LSTM's"):
        xairl.from_sb3(model, window=4, hidden=(np.zeros(3), np.zeros(3)))
    with pytest.raises(InputError, match="hidden= is the LSTM state of a recurrent policy"):
        xairl.from_sb3(build("PPO", "MlpPolicy", "CartPole-v1", None), hidden=states[0])


def test_value_head_needs_an_actor_critic():
    with pytest.raises(InputError, match="head='value' is for actor-critics"):
        xairl.from_sb3(build("DQN", "MlpPolicy", "CartPole-v1", None), head="value")
    with pytest.raises(InputError, match="use head='q'"):
        xairl.from_sb3(build("SAC", "MlpPolicy", "Pendulum-v1", None), head="value")


@pytest.mark.parametrize(
    "algo, obs, act, head",
    [
        ("PPO", "CartPole-v1", None, "value"),
        ("TD3", spaces.Box(-1, 1, (6,), np.float32), spaces.Box(-2, 3, (2,), np.float32), "policy"),
    ],
)
def test_narration_of_a_value_head_and_a_2d_actor_verifies(algo, obs, act, head):
    model = build(algo, "MlpPolicy", obs, act)
    policy = xairl.from_sb3(model, head=head)
    x = states(model.observation_space, 24)
    e = xairl.explain(policy, x[:2], background=x[2:])
    n = xairl.narrate(e, 0, policy=policy, robustness=False)
    assert n.verified and n.template == "explain_output" and "chose" not in n.text and "above" not in n.text
    if head == "value":
        assert n.text.startswith(f"The value estimate was {xairl_fmt(e.outputs[0, 0])}")
        assert n.components["margin"] is None
    else:  # each action dimension is narrated on its own, nothing is chosen among them
        assert [s for s in n.text.split(". ") if "was set to" in s][1].startswith(
            "action_1 was set to"
        )  # a declared name, as declared
    # a wrong number in the same words is caught (a continuous action: against its own dimension)
    view, text = (e, n.text) if head == "value" else (e.output_slice(0), n.text.split(" action_1 was set")[0])
    assert xairl.verify(text, view, 0, policy).ok
    first = next(c for c in n.claims if c.kind == "number" and "+" in c.text)
    assert not xairl.verify(text.replace(first.text, "+9.99", 1), view, 0, policy).ok
    with pytest.raises(InputError, match="narrates actions outputs; this policy's output is"):
        xairl.narrate(e, 0, template="why_not")


def xairl_fmt(v):
    from xairl.facts import format_number as fmt

    return fmt(float(v))
