"""Stable-Baselines3 models as :class:`xairl.Policy`: every algorithm, every policy kind, checked against SB3.

The network xairl explains is built from the model's own modules, in the order SB3 applies them, with SB3's
observation preprocessing done in differentiable form (images / 255; a Discrete input arrives one-hot encoded by
:class:`xairl.Observation`), so that every attribution method sees the same function SB3 computes. On construction
the Policy's outputs are compared with SB3's own (``predict(deterministic=True)``, ``q_net``, ``predict_values``,
the critic's ``q1_forward``) on sample states, and a mismatch is refused.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import torch

from xairl.errors import InputError
from xairl.policies.observation import Observation, Part
from xairl.policies.policy import Policy
from xairl.policies.sb3_memory import Unrolled, check_unrolled, describe, start_state, window_observation

HEADS = ("policy", "value", "q")


class _Preprocess(torch.nn.Module):
    """SB3's ``preprocess_obs`` without its non-differentiable one-hot: images / 255, everything else as float
    (Discrete inputs are one-hot encoded already)."""

    xairl_linear = True

    def __init__(self, space, normalize_images: bool):
        super().__init__()
        from gymnasium import spaces
        from stable_baselines3.common.preprocessing import is_image_space

        subspaces = space.spaces if isinstance(space, spaces.Dict) else {"obs": space}
        self.is_dict = isinstance(space, spaces.Dict)
        self.scale = {k: (255.0 if normalize_images and is_image_space(s) else 1.0) for k, s in subspaces.items()}

    def forward(self, obs):
        if not self.is_dict:
            obs = obs["obs"] if isinstance(obs, dict) else obs
            return obs / self.scale["obs"] if self.scale["obs"] != 1.0 else obs
        return {k: (v / self.scale[k] if self.scale[k] != 1.0 else v) for k, v in obs.items()}


class _Scale(torch.nn.Module):
    """Affine map per action dimension: [-1, 1] -> [low, high] (SB3's ``unscale_action``), or the inverse."""

    xairl_linear = True

    def __init__(self, low, high, inverse: bool = False):
        super().__init__()
        low, high = torch.as_tensor(low, dtype=torch.float32), torch.as_tensor(high, dtype=torch.float32)
        half, mid = (high - low) / 2, (high + low) / 2
        self.register_buffer("a", 1 / half if inverse else half)
        self.register_buffer("b", -mid / half if inverse else mid)

    def forward(self, x):
        return x * self.a + self.b


class _SB3Network(torch.nn.Module):
    """preprocess -> features extractor -> the head's layers, as SB3 runs them for deterministic actions."""

    def __init__(self, preprocess, extractor, head):
        super().__init__()
        self.preprocess, self.extractor, self.head = preprocess, extractor, head

    def forward(self, obs):
        return self.head(self.extractor(self.preprocess(obs)))


class _ActorCritic(torch.nn.Module):
    """Actor-critic latent + output layer: ``forward_actor`` / ``forward_critic`` of SB3's MlpExtractor."""

    def __init__(self, mlp_extractor, out, critic: bool):
        super().__init__()
        self.mlp, self.out, self.critic = mlp_extractor, out, critic

    def forward(self, features):
        latent = self.mlp.forward_critic(features) if self.critic else self.mlp.forward_actor(features)
        return self.out(latent)


class _QOfActor(torch.nn.Module):
    """Q(s, actor(s)) of SB3's first critic network, the actor's deterministic action in [-1, 1]."""

    def __init__(self, preprocess, actor_net, critic):
        super().__init__()
        self.preprocess, self.actor_net, self.critic = preprocess, actor_net, critic

    def forward(self, obs):
        prep = self.preprocess(obs)
        action = self.actor_net(prep)
        return self.critic.q_networks[0](torch.cat([self.critic.features_extractor(prep), action], dim=1))


def from_sb3(
    model,
    head: Literal["policy", "value", "q"] = "policy",
    feature_names=None,
    action_names=None,
    branch: int | None = None,
    check: bool = True,
    window: int | None = None,
    hidden=None,
    **kwargs,
) -> Policy:
    """A Stable-Baselines3 model as a :class:`Policy`.

    :param model: any SB3 model (DQN, PPO, A2C, SAC, TD3, DDPG; MlpPolicy, CnnPolicy, MultiInputPolicy), or an
        sb3-contrib one built on the same policies (QR-DQN is not: its output is a distribution); RecurrentPPO
        with ``window=k``.
    :param head: 'policy': what decides the action (DQN's Q-values and PPO/A2C's logits for discrete actions, the
        deterministic action in environment units for continuous ones); 'value': V(s) of an actor-critic;
        'q': Q(s, actor(s)) of SAC/TD3/DDPG's first critic.
    :param feature_names: a name per observation column; of a window, the signals of one observation.
    :param branch: for a MultiDiscrete action space, which sub-action's logits to explain (each is its own
        decision).
    :param check: compare the Policy's outputs with SB3's own on sample states and refuse a mismatch.
    :param window: the observations the policy decides on (:mod:`xairl.policies.sb3_memory`): a ``VecFrameStack`` of k flat
        observations (found in the model's environment by itself when it has one), or the last k observations a
        recurrent policy (RecurrentPPO) is unrolled over. ``observation=xairl.Observation.window(signals, k,
        step_s=...)`` says the same with the signals' names and the time between observations.
    :param hidden: of a recurrent policy, the LSTM's (h, c) before the window's first observation (what
        ``model.predict`` returned one step before it): the explained function is then the decision the policy
        took. Left out, the LSTM starts from a reset (zeros). ``Policy.description`` says which.
    :param kwargs: passed to :class:`Policy` (features, groups, background_sampler, name, ...).
    """
    from gymnasium import spaces

    _refuse_unsupported(model, head, hidden)
    policy, algo = model.policy, type(model).__name__
    recurrent = hasattr(policy, "lstm_actor")
    obs_space, act_space = model.observation_space, model.action_space
    windowed = window_observation(model, window, kwargs.pop("observation", None), feature_names, recurrent)
    observation = windowed or _observation(obs_space)
    prep = _Preprocess(obs_space, getattr(policy, "normalize_images", True))
    if recurrent:
        output, names, network, start = _unrolled(model, policy, head, act_space, prep, branch, hidden, spaces)
        kwargs.setdefault("description", describe(model, observation.parts[0].window.steps, hidden, head))
    else:
        output, names, network = _head(model, policy, head, act_space, prep, branch, spaces)
    if windowed is not None:
        feature_names = None  # the slots' names come from the window's signals
    elif feature_names is None:
        feature_names = observation.feature_names()
    result = Policy(
        network.eval(),
        feature_names,
        action_names or names,
        observation=observation,
        output=output,
        name=kwargs.pop("name", f"{algo.lower()}-{head}"),
        **kwargs,
    )
    if check and recurrent:
        check_unrolled(model, result, head, start)
    elif check:
        _check(model, result, head, branch, spaces)
    return result


def _refuse_unsupported(model, head: str, hidden) -> None:
    """One line for a head that does not exist, an LSTM state given to a policy without one, and a distributional
    output (QR-DQN's quantiles per action)."""
    algo = type(model).__name__
    if head not in HEADS:
        raise InputError(f"head '{head}' is unknown; use one of {', '.join(HEADS)}.")
    if hidden is not None and not hasattr(model.policy, "lstm_actor"):
        raise InputError(f"hidden= is the LSTM state of a recurrent policy (RecurrentPPO); {algo} has none.")
    if hasattr(model.policy, "quantile_net"):
        raise InputError(
            f"{algo} outputs quantiles per action; xairl explains one score per "
            "action: use DQN, or explain a module that averages the quantiles with xairl.Policy."
        )


def _observation(space) -> Observation:
    from gymnasium import spaces

    def part(key, s):
        if isinstance(s, spaces.Discrete):
            if int(s.start) != 0:
                raise InputError(f"observation '{key}' is Discrete with start={s.start}; xairl needs start=0.")
            return Part(key, (), int(s.n))
        if isinstance(s, (spaces.Box, spaces.MultiBinary)):
            return Part(key, tuple(int(d) for d in s.shape))
        raise InputError(
            f"observation '{key}' is {type(s).__name__}; xairl explains Box, Discrete and MultiBinary "
            "observations (and Dicts of them)."
        )

    if isinstance(space, spaces.Dict):
        return Observation("dict", tuple(part(k, s) for k, s in space.spaces.items()))
    p = part("obs", space)
    if p.categories:
        return Observation("dict", (p,))
    return Observation.flat(p.shape[0]) if len(p.shape) == 1 else Observation.array(p.shape)


def _head(model, policy, head, act_space, prep, branch, spaces):
    """(output kind, output names, network) for the requested head."""
    algo = type(model).__name__
    continuous = isinstance(act_space, spaces.Box)
    if head == "value":
        if not hasattr(policy, "value_net"):
            raise InputError(
                f"{algo} has no state-value head; head='value' is for actor-critics (PPO, A2C); "
                f"{'use head=' + repr('q') if hasattr(policy, 'critic') else 'use head=' + repr('policy')}."
            )
        extractor = getattr(policy, "vf_features_extractor", None) or policy.features_extractor
        return (
            "value",
            ["value"],
            _SB3Network(prep, extractor, _ActorCritic(policy.mlp_extractor, policy.value_net, critic=True)),
        )
    if head == "q":
        if not (hasattr(policy, "critic") and hasattr(policy, "actor")):
            raise InputError(f"{algo} has no action-value critic; head='q' is for SAC, TD3 and DDPG.")
        return "value", ["q"], _QOfActor(prep, _actor_net(policy, act_space, env_units=False), policy.critic)
    if hasattr(policy, "q_net"):  # DQN
        n = int(act_space.n)
        return (
            "actions",
            [f"action_{i}" for i in range(n)],
            _SB3Network(prep, policy.q_net.features_extractor, policy.q_net.q_net),
        )
    if hasattr(policy, "actor") and continuous:  # SAC, TD3, DDPG
        return (
            "continuous",
            [f"action_{i}" for i in range(act_space.shape[0])],
            _actor_net(policy, act_space, env_units=True, prep=prep),
        )
    if hasattr(policy, "action_net"):  # PPO, A2C
        extractor = getattr(policy, "pi_features_extractor", None) or policy.features_extractor
        kind, names, out = _action_out(algo, policy, act_space, branch, spaces)
        return kind, names, _SB3Network(prep, extractor, _ActorCritic(policy.mlp_extractor, out, critic=False))
    raise InputError(
        f"unsupported SB3 policy {type(policy).__name__}: expected DQN (q_net), an actor-critic "
        "(action_net) or SAC/TD3/DDPG (actor)."
    )


def _action_out(algo, policy, act_space, branch, spaces):
    """(output kind, output names, layer) of an actor-critic's action head: its ``action_net`` with, for one branch
    of a MultiDiscrete action, that branch's columns, and for a bounded Box, SB3's clipping as modules."""
    out = policy.action_net
    if isinstance(act_space, spaces.Discrete):
        return "actions", [f"action_{i}" for i in range(int(act_space.n))], out
    if isinstance(act_space, spaces.MultiDiscrete):
        nvec = [int(v) for v in act_space.nvec]
        if branch is None or not 0 <= branch < len(nvec):
            raise InputError(
                f"{algo} has a MultiDiscrete action space with {len(nvec)} sub-actions, each its own "
                f"decision; pick one with branch=0..{len(nvec) - 1}."
            )
        start = sum(nvec[:branch])
        out = torch.nn.Sequential(out, _Columns(start, start + nvec[branch]))
        return "actions", [f"action_{branch}={i}" for i in range(nvec[branch])], out
    if isinstance(act_space, spaces.Box):
        if getattr(policy, "squash_output", False):
            raise InputError(f"{algo} with squashed (gSDE) actions is not supported; train without squash_output.")
        # SB3 clips the mean to the bounds: an affine map to [-1, 1], Hardtanh, and back keeps it a module
        low, high = act_space.low, act_space.high
        out = (
            torch.nn.Sequential(out, _Scale(low, high, inverse=True), torch.nn.Hardtanh(), _Scale(low, high))
            if np.all(np.isfinite(low)) and np.all(np.isfinite(high))
            else out
        )
        return "continuous", [f"action_{i}" for i in range(act_space.shape[0])], out
    raise InputError(
        f"{algo}'s action space {act_space} is not supported; xairl explains Discrete, "
        "MultiDiscrete (one branch at a time) and Box actions."
    )


def _unrolled(model, policy, head, act_space, prep, branch, hidden, spaces):
    """(output kind, output names, network, start state) of a recurrent actor-critic (sb3-contrib's RecurrentPPO)
    over a window: :class:`xairl.policies.sb3_memory.Unrolled` with the head's LSTM (the critic's own, the shared one, or
    none) and its layers after it."""
    algo = type(model).__name__
    start = start_state(model, hidden, head)
    if head == "q":
        raise InputError(f"{algo} has no action-value critic; head='q' is for SAC, TD3 and DDPG.")
    if head == "value":
        lstm = (
            policy.lstm_critic if policy.lstm_critic is not None else policy.lstm_actor if policy.shared_lstm else None
        )
        after = _ActorCritic(policy.mlp_extractor, policy.value_net, critic=True)
        net = Unrolled(prep, policy.vf_features_extractor, lstm, after, start, linear=policy.critic)
        return "value", ["value"], net, start
    kind, names, out = _action_out(algo, policy, act_space, branch, spaces)
    after = _ActorCritic(policy.mlp_extractor, out, critic=False)
    return kind, names, Unrolled(prep, policy.pi_features_extractor, policy.lstm_actor, after, start), start


class _Columns(torch.nn.Module):
    xairl_linear = True

    def __init__(self, start: int, stop: int):
        super().__init__()
        self.start, self.stop = start, stop

    def forward(self, x):
        return x[:, self.start : self.stop]


def _actor_net(policy, act_space, env_units: bool, prep=None) -> torch.nn.Module:
    """SAC/TD3/DDPG's deterministic action: tanh(mean) for SAC, mu (ending in Tanh) for TD3/DDPG; in [-1, 1],
    or in environment units (SB3's ``unscale_action``)."""
    actor = policy.actor
    if hasattr(actor, "latent_pi"):  # SAC: the squashing tanh is a function call in SB3; here it is a module
        layers = [actor.latent_pi, actor.mu, torch.nn.Tanh()]
    else:
        layers = [actor.mu]
    if env_units:
        layers.append(_Scale(act_space.low, act_space.high))
    head = torch.nn.Sequential(*layers)
    return (
        _SB3Network(prep, actor.features_extractor, head)
        if prep is not None
        else torch.nn.Sequential(actor.features_extractor, head)
    )


def _check(model, result: Policy, head, branch, spaces) -> None:
    """Compare the Policy's outputs with SB3's own on 16 sample states; refuse a mismatch."""
    space = model.observation_space
    space.seed(0)
    raw = [space.sample() for _ in range(16)]
    if isinstance(space, spaces.Dict):
        batch = {k: np.stack([r[k] for r in raw]) for k in space.spaces}
    else:
        batch = np.stack(raw)
    ours = result.scores(batch)
    decided = ours.argmax(1)
    policy = model.policy
    with torch.no_grad():
        obs_t, _ = policy.obs_to_tensor(batch)
        if head == "value":
            theirs = policy.predict_values(obs_t).cpu().numpy()
        elif head == "q":
            act = policy.actor(obs_t, deterministic=True) if hasattr(policy.actor, "latent_pi") else policy.actor(obs_t)
            theirs = policy.critic.q1_forward(obs_t, act).cpu().numpy()
        elif hasattr(policy, "q_net"):
            theirs = policy.q_net(obs_t).cpu().numpy()
        elif result.output == "actions" and hasattr(policy, "action_net"):
            logits = policy.get_distribution(obs_t).distribution
            logits = logits[branch].logits if isinstance(logits, list) else logits.logits  # normalised by SB3
            theirs = logits.cpu().numpy()
            top = ours.max(1, keepdims=True)
            ours = ours - top - np.log(np.exp(ours - top).sum(1, keepdims=True))
        else:
            theirs = np.asarray(model.predict(batch, deterministic=True)[0], dtype=np.float64)
    theirs = np.asarray(theirs, dtype=np.float64).reshape(ours.shape)
    err = float(np.abs(ours - theirs).max())
    scale = max(1.0, float(np.abs(theirs).max()))
    if not err <= 1e-5 * scale:
        raise InputError(
            f"from_sb3: the explained network's outputs differ from {type(model).__name__}'s own by "
            f"{err:.3g} on sample states; this model's policy is built in a way xairl does not read "
            "(custom policy class?): wrap its forward pass yourself with xairl.Policy."
        )
    if result.output == "actions" and branch is None:
        acts = np.asarray(model.predict(batch, deterministic=True)[0]).reshape(-1)
        if not np.array_equal(decided, acts):
            raise InputError(
                f"from_sb3: the highest score is not the action {type(model).__name__}.predict takes; "
                "refusing to explain a different decision."
            )
