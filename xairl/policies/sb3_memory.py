"""Stable-Baselines3 policies with memory, as windows of observations (:mod:`xairl.policies.windows`).

- **A vector frame stack** (``VecFrameStack`` over a flat observation): the network takes the last k observations as
  one flat row, time-major, oldest first, zeros before the episode's first observation. It is a window of layout
  'stacked': its features are the slots ``obs_0[t-3]`` ... ``obs_3[t]``, narrated per signal and as trends.
- **A recurrent policy** (sb3-contrib's ``RecurrentPPO``): the action depends on the LSTM's hidden state, which
  carries the whole episode. It is explained as a function of the last k observations: the LSTM unrolled over them
  from a fixed start state, a reset (zeros, as at an episode's start) or the episode's own state before the window
  (``hidden=``), with which the function is exactly the decision the policy took.

:func:`xairl.from_sb3` builds both; this module knows the windows and the unrolled network, not the Policy.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import torch

from xairl.errors import InputError
from xairl.policies.observation import Observation


def window_observation(model, window, observation, feature_names, recurrent: bool) -> Observation | None:
    """The window a model's policy is explained over (None: no window). ``window=k`` or a window ``observation``
    declares it; a ``VecFrameStack`` of a flat observation in the model's environment is found by itself. The layout
    is the network's: 'stacked' for a frame stack (it takes the flat rows), 'sequence' for a recurrent policy (each
    step's observation apart)."""
    algo = type(model).__name__
    if observation is not None and not (isinstance(observation, Observation) and observation.kind == "window"):
        raise InputError(
            f"from_sb3 builds {algo}'s observation from its observation space; observation= declares a window "
            "only (xairl.Observation.window(signals, k)): leave it out otherwise."
        )
    declared = observation.parts[0].window if observation is not None else None
    steps = _steps(model, window, declared, recurrent)
    if steps is None:
        return None
    signals = _signals(model, steps, declared, feature_names, recurrent)
    layout = "sequence" if recurrent else "stacked"
    if declared is not None:  # its signals, steps and step_s, laid out as the network takes them
        laid_out = dataclasses.replace(declared, layout=layout)
        return Observation("window", (dataclasses.replace(observation.parts[0], window=laid_out),))
    return Observation.window(signals, steps, layout)


def _steps(model, window, declared, recurrent: bool) -> int | None:
    """The window's observations: given (``window=k`` or the declared window's), else the model's VecFrameStack's."""
    algo = type(model).__name__
    if declared is not None and window is not None and window != declared.steps:
        raise InputError(
            f"window={window!r:.20} and the observation's {declared.steps} steps differ; give one of them."
        )
    stacked = _frame_stack(model)
    steps = window if window is not None else declared.steps if declared is not None else stacked
    if steps is None and recurrent:
        raise InputError(
            f"{algo} is recurrent: its action depends on the LSTM's hidden state, which carries the whole "
            "episode; give window=k to explain it over the last k observations, the LSTM unrolled over them "
            "from a reset (or from the episode's own state with hidden=(h, c))."
        )
    if steps is not None and (isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or steps < 2):
        raise InputError(f"window is the number of observations (k >= 2); got {steps!r:.40}.")
    if steps is not None and stacked is not None and not recurrent and steps != stacked:
        raise InputError(
            f"{algo}'s environment stacks {stacked} observations (VecFrameStack) but window={steps}; give "
            f"window={stacked} or leave it out."
        )
    return None if steps is None else int(steps)


def _signals(model, steps: int, declared, feature_names, recurrent: bool) -> tuple[str, ...]:
    """The names of the signals of one observation, checked against the model's flat observation space."""
    algo, space = type(model).__name__, model.observation_space
    if not (getattr(space, "shape", None) is not None and len(space.shape) == 1 and space.dtype.kind == "f"):
        raise InputError(
            f"a window of {algo}'s observations needs a flat Box observation space; this one is {space}"
            + (" (a stack of images is an image: explain it as frames without window=)." if not recurrent else ".")
        )
    size = int(space.shape[0])
    width = size if recurrent else size // steps
    if width * steps != size and not recurrent:
        raise InputError(f"{algo}'s observations have {size} values: not {steps} stacked observations of one size.")
    if declared is not None and feature_names is not None and tuple(map(str, feature_names)) != declared.signals:
        raise InputError("the window names its signals; give them once (leave feature_names out).")
    signals = declared.signals if declared is not None else feature_names or [f"obs_{i}" for i in range(width)]
    if len(signals) != width:
        raise InputError(
            f"{len(signals)} signal names for observations of {width} values; name the signals of one observation "
            f"({'each of the ' + str(steps) + ' stacked ones' if not recurrent else 'each step'}) once."
        )
    return tuple(map(str, signals))


def _frame_stack(model) -> int | None:
    """The observations a ``VecFrameStack`` in the model's environment stacks into its flat observation, or None."""
    from stable_baselines3.common.vec_env import VecEnvWrapper, VecFrameStack

    env = model.get_env()
    while isinstance(env, VecEnvWrapper):
        if isinstance(env, VecFrameStack):
            same = env.observation_space == model.observation_space and len(model.observation_space.shape or ()) == 1
            return int(env.stacked_obs.n_stack) if same else None
        env = env.venv
    return None


class Unrolled(torch.nn.Module):
    """A recurrent SB3 policy over a window (n, k, signals): each step's features, the LSTM over them (in SB3's
    (sequence, batch, features) order) from a fixed start state, and the head on the last step's output.

    :param lstm: the LSTM the head reads (None: a critic without one, which reads the last step's features through
        ``linear``).
    :param start: (h, c), each (layers, 1, hidden): the state before the window's first observation.
    """

    def __init__(self, preprocess, extractor, lstm, head, start, linear=None):
        super().__init__()
        self.preprocess, self.extractor, self.lstm, self.head, self.linear = preprocess, extractor, lstm, head, linear
        self.register_buffer("h0", torch.as_tensor(start[0], dtype=torch.float32))
        self.register_buffer("c0", torch.as_tensor(start[1], dtype=torch.float32))

    def forward(self, window):
        n, k = window.shape[:2]
        features = self.extractor(self.preprocess(window.reshape(n * k, *window.shape[2:]))).reshape(n, k, -1)
        if self.lstm is None:
            return self.head(self.linear(features[:, -1]))
        h0, c0 = (s.to(features.dtype).expand(-1, n, -1).contiguous() for s in (self.h0, self.c0))
        out, _ = self.lstm(features.transpose(0, 1), (h0, c0))
        return self.head(out[-1])


def start_state(model, hidden, head: str) -> tuple[np.ndarray, np.ndarray]:
    """(h, c) the LSTM starts the window from: zeros (a reset) or ``hidden``, the (h, c) ``model.predict`` returned
    one step before the window's first observation (each (layers, 1, hidden) or (layers, hidden))."""
    shape = tuple(model.policy.lstm_hidden_state_shape)
    if hidden is None:
        return np.zeros(shape, np.float32), np.zeros(shape, np.float32)
    try:
        h, c = (np.asarray(s, dtype=np.float32).reshape(shape) for s in hidden)
    except (TypeError, ValueError):
        raise InputError(
            f"hidden is the LSTM's (h, c) before the window, each of shape {shape} (what {type(model).__name__}"
            f".predict returns for one environment); got {type(hidden).__name__}."
        ) from None
    if not (np.isfinite(h).all() and np.isfinite(c).all()):
        raise InputError("hidden holds NaN or infinite values; give the (h, c) model.predict returned.")
    return h, c


def describe(model, steps: int, hidden, head: str) -> str:
    """What a recurrent policy's explanation is of, in words (the Policy's and the Explanation's description)."""
    lstm = "critic's LSTM" if head == "value" and model.policy.lstm_critic is not None else "LSTM"
    start = (
        "a reset (zero) hidden state" if hidden is None else "the episode's hidden state before the window (hidden=)"
    )
    return f"{type(model).__name__}'s {lstm} unrolled over the last {steps} observations from {start}"


def check_unrolled(model, policy, head: str, start, seed: int = 0) -> None:
    """Compare the unrolled network with sb3-contrib stepping its own policy through the same windows from the same
    start state (16 random windows); refuse a mismatch, and (discrete actions) a different action."""
    p, space = model.policy, model.observation_space
    steps = policy.window
    space.seed(seed)
    windows = np.stack([np.stack([space.sample() for _ in range(steps)]) for _ in range(16)]).astype(np.float32)
    n = len(windows)
    ours = policy.scores(windows)
    from sb3_contrib.common.recurrent.type_aliases import RNNStates

    with torch.no_grad():
        state = tuple(torch.as_tensor(np.repeat(s, n, axis=1)) for s in start)
        states = RNNStates(state, state)  # the critic's start: the same (zeros, or the state the caller gave)
        go = torch.zeros(n)
        for t in range(steps - 1):
            obs, _ = p.obs_to_tensor(windows[:, t])
            states = p.forward(obs, states, go)[3]
        obs, _ = p.obs_to_tensor(windows[:, -1])
        if head == "value":
            theirs = p.predict_values(obs, states.vf if p.lstm_critic is not None else states.pi, go).numpy()
        else:
            dist = p.get_distribution(obs, states.pi, go)[0].distribution
            theirs = dist.logits.numpy() if hasattr(dist, "logits") else dist.mean.numpy()
            if policy.output == "actions":  # torch's Categorical keeps normalised logits
                ours = torch.log_softmax(torch.as_tensor(ours), dim=1).numpy()
            else:  # the deterministic action, clipped to the bounds as predict does
                theirs = np.clip(theirs, model.action_space.low, model.action_space.high)
    theirs = np.asarray(theirs, dtype=np.float64).reshape(ours.shape)
    err = float(np.abs(ours - theirs).max())
    if not err <= 1e-5 * max(1.0, float(np.abs(theirs).max())):
        raise InputError(
            f"from_sb3: the unrolled network's outputs differ from {type(model).__name__}'s own by {err:.3g} on "
            "sample windows; this recurrent policy is built in a way xairl does not read: wrap its forward pass "
            "yourself with xairl.Policy(window=k)."
        )
