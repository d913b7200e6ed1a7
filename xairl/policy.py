"""Policy: a trained torch network mapping a batch of states to one score per action, with names and metadata."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

import numpy as np
import torch

from .errors import InputError
from .inputs import as_states


@dataclass(frozen=True)
class FeatureInfo:
    """What a feature means, for plots and narration.

    :param unit: e.g. "dBm", "m"; empty when unitless.
    :param description: a plain-language phrase ("the serving cell's reference signal power").
    :param low: how to describe a low value ("weak signal"); ``high`` likewise.
    :param aliases: other names a text may use for the feature (the verifier recognises them).
    """

    unit: str = ""
    description: str = ""
    low: str = "low"
    high: str = "high"
    aliases: tuple[str, ...] = ()


@dataclass
class Policy:
    """A decision maker with a torch module scoring every action (Q-values or logits).

    :param module: maps a float tensor (batch, n_features) to (batch, n_actions).
    :param feature_names: one unique name per input column.
    :param action_names: one unique name per output column.
    :param features: optional :class:`FeatureInfo` per feature name.
    :param groups: named groups of features, e.g. ``{"position": ("x", "y", "z")}``.
    :param background_sampler: optional ``f(n, seed) -> array (n, n_features)`` of typical states.
    :param name: how the policy is called in reports.
    :param action_aliases: other names of each action in text, e.g. ``{"stay": ["keep the serving BS"]}``.
    :param facts_hook: optional ``f(state, chosen, runner_up) -> xairl.DomainFacts`` adding domain facts that
        templates may cite and the verifier accepts (``chosen`` and ``runner_up`` are action indices).
    :param action_mask: optional ``f(states (n, n_features)) -> bool (n, n_actions)``, True where an action is
        available in that state (invalid-action masking, as in MaskablePPO). The policy acts, and explanations take
        the chosen action and the runner-up, among available actions only; their scores are still explained.
    """

    module: torch.nn.Module
    feature_names: Sequence[str]
    action_names: Sequence[str]
    features: Mapping[str, FeatureInfo] = field(default_factory=dict)
    groups: Mapping[str, Sequence[str]] = field(default_factory=dict)
    background_sampler: Callable[[int, int], np.ndarray] | None = None
    name: str = "policy"
    action_aliases: Mapping[str, Sequence[str]] = field(default_factory=dict)
    facts_hook: Callable[[np.ndarray, int, int], Any] | None = None
    action_mask: Callable[[np.ndarray], np.ndarray] | None = None

    def __post_init__(self) -> None:
        self.feature_names = [str(f) for f in self.feature_names]
        self.action_names = [str(a) for a in self.action_names]
        for what, names in (("feature_names", self.feature_names), ("action_names", self.action_names)):
            if not names:
                raise InputError(f"{what} is empty; name every input column and every action.")
            if len(set(names)) != len(names):
                dup = sorted({n for n in names if names.count(n) > 1})
                raise InputError(f"{what} has duplicates ({', '.join(dup)}); names must be unique.")
        unknown = sorted(set(self.features) - set(self.feature_names))
        unknown += sorted({f for g in self.groups.values() for f in g} - set(self.feature_names))
        if unknown:
            raise InputError(f"metadata names unknown feature(s) {', '.join(unknown)}; use names from feature_names.")
        if not isinstance(self.module, torch.nn.Module):
            raise InputError(f"module must be a torch.nn.Module, got {type(self.module).__name__}.")

    @property
    def n_features(self) -> int:
        return len(self.feature_names)

    @property
    def n_actions(self) -> int:
        return len(self.action_names)

    @property
    def device(self) -> torch.device:
        p = next(self.module.parameters(), None)
        return p.device if p is not None else torch.device("cpu")

    def check_states(self, states, what: str = "states") -> np.ndarray:
        """Validated float32 array (n, n_features); raises :class:`InputError` with a one-line reason."""
        return as_states(states, self.n_features, what)

    def scores(self, states) -> np.ndarray:
        """Scores (n, n_actions) of the module in eval mode, without gradients."""
        x = torch.as_tensor(self.check_states(states), device=self.device)
        was_training = self.module.training
        self.module.eval()
        try:
            with torch.no_grad():
                out = self.module(x)
        finally:
            self.module.train(was_training)
        out = out.detach().cpu().numpy().astype(np.float64)
        if out.ndim != 2 or out.shape[1] != self.n_actions:
            raise InputError(
                f"the module returned shape {tuple(out.shape)} but {self.n_actions} actions are named; "
                "it must map (batch, n_features) to (batch, n_actions)."
            )
        return out

    def available(self, states) -> np.ndarray:
        """Bool (n, n_actions): the actions available in each state (all of them without an ``action_mask``)."""
        x = self.check_states(states)
        if self.action_mask is None:
            return np.ones((len(x), self.n_actions), dtype=bool)
        mask = np.asarray(self.action_mask(x), dtype=bool)
        if mask.shape != (len(x), self.n_actions) or not mask.any(axis=1).all():
            raise InputError(f"policy '{self.name}': action_mask must return a bool array {(len(x), self.n_actions)} "
                             "with at least one available action per state.")
        return mask

    def act(self, states) -> np.ndarray:
        """Index of the highest-scoring available action per state."""
        return np.where(self.available(states), self.scores(states), -np.inf).argmax(axis=1)

    def background(self, n: int = 100, seed: int = 0) -> np.ndarray:
        """`n` typical states from the policy's sampler; raises when it has none."""
        if self.background_sampler is None:
            raise InputError(f"policy '{self.name}' has no background sampler; pass background states explicitly.")
        return self.check_states(self.background_sampler(n, seed), "background")


TorchPolicy = Policy  # the name users of plain torch networks (CleanRL style) look for


class _SB3ActorLogits(torch.nn.Module):
    """An SB3 actor-critic policy seen as states -> action logits (features extractor, actor MLP, action net)."""

    def __init__(self, policy):
        super().__init__()
        self.policy = policy

    def forward(self, x):
        p = self.policy
        extractor = getattr(p, "pi_features_extractor", None) or p.features_extractor
        return p.action_net(p.mlp_extractor.forward_actor(extractor(x)))


def from_sb3(model, feature_names=None, action_names=None, **kwargs) -> Policy:
    """A Stable-Baselines3 model (DQN: Q-values; PPO/A2C: action logits) with discrete actions and a flat Box
    observation, as a :class:`Policy`. Names default to ``obs_0..`` and ``action_0..``."""
    obs, act = model.observation_space, model.action_space
    if not hasattr(act, "n"):
        raise InputError(f"xairl explains discrete actions; this model's action space is {act}.")
    if len(getattr(obs, "shape", ()) or ()) != 1:
        raise InputError(f"xairl needs a flat Box observation; this model's observation space is {obs}.")
    policy = model.policy
    if hasattr(policy, "q_net"):
        module = policy.q_net
    elif hasattr(policy, "action_net"):
        module = _SB3ActorLogits(policy)
    else:
        raise InputError(f"unsupported SB3 policy {type(policy).__name__}: expected DQN (q_net) or actor-critic.")
    n_obs, n_act = obs.shape[0], int(act.n)
    return Policy(module.eval(), feature_names or [f"obs_{i}" for i in range(n_obs)],
                  action_names or [f"action_{i}" for i in range(n_act)], **kwargs)
