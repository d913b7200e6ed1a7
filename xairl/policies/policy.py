"""Policy: a trained torch network mapping a batch of states to its outputs (action scores, continuous actions or a
value), with names, metadata and the structure of its input."""

from __future__ import annotations

import hashlib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import torch

from xairl.errors import InputError
from xairl.policies.features import FeatureInfo
from xairl.policies.heads import check_kinds, heads
from xairl.policies.network import PolicyNetwork, eval_mode, module_dtype
from xairl.policies.observation import Observation, names_preview
from xairl.policies.windows import check_slot_names, slot_features

#: what a policy's outputs are: scores of discrete actions (the highest available one is taken; a runner-up exists),
#: the dimensions of a continuous action (each explained on its own; nothing is chosen among them), or one value
OUTPUT_KINDS = ("actions", "continuous", "value")


_TORCH = {np.float32: torch.float32, np.float64: torch.float64}


@dataclass(frozen=True, eq=False)  # eq=False: two policies are the same object or different ones
class Policy:
    """A decision maker: a torch module and what its inputs and outputs mean. Built normalised (names as tuples of
    str, metadata copied, ``observation`` as an :class:`Observation`) and frozen: change a field
    with ``dataclasses.replace(policy, facts_hook=...)``, which checks the new policy again.

    :param module: maps a batch of states to (batch, n_outputs) (a (batch,) output is read as one column). Its
        input is one tensor (batch, *shape), a dict of tensors, or several tensors, as ``observation`` says.
    :param feature_names: one unique name per flat input column; default: generated from ``observation``
        (``obs_0..``, ``frame[c,h,w]``, ``key[i]``, ``key=v`` for a categorical key).
    :param action_names: one unique name per output column; default: ``action_0..`` (``value`` for a value).
    :param observation: the input's structure: an :class:`xairl.Observation`, or a shape tuple ``(4, 84, 84)``,
        a dict of shapes ``{"image": (3, 64, 64), "speed": (1,)}`` or a list of shapes (several inputs). Default:
        flat, one column per feature name.
    :param output: 'actions' (discrete action scores: Q-values or logits), 'continuous' (one column per action
        dimension) or 'value' (one column: V(s), Q(s, a) or any regressor); or one of them per output column. Outputs
        of mixed kinds (a parametrised action space: action logits and their continuous parameters) are refused,
        since a parameter's value would be ranked against the actions' scores: :meth:`heads` makes one policy per
        kind. Left out (None), it is 'actions', and an output named as a parameter of another (``kick_power`` beside
        ``kick``) is refused; say ``output="actions"`` where such names really are actions.
    :param features: optional :class:`FeatureInfo` per feature name, and per group name for a group narrated as
        one reason (``kind='group'``).
    :param groups: named groups of features, e.g. ``{"position": ("x", "y", "z")}``: plots show each as one bar, and
        narratives name each as one reason (:attr:`reason_groups`), unless each of its members is described.
    :param background_sampler: optional ``f(n, seed) -> states`` of typical states (any form ``observation`` takes).
    :param name: how the policy is called in reports.
    :param action_aliases: other names of each action in text, e.g. ``{"stay": ["keep the serving BS"]}``.
    :param facts_hook: optional ``f(state, chosen, runner_up, history=None) -> xairl.facts.DomainFacts`` adding domain
        facts that templates may cite and the verifier accepts (``chosen`` and ``runner_up`` are action indices;
        ``history``, when the caller knows it, the states before this one in the same episode, oldest first, as an
        array (h, n_features): for facts such as "the neighbour has been stronger for 4 steps"). A hook without a
        ``history`` parameter is called without it.
    :param action_mask: optional ``f(states (n, n_features)) -> bool (n, n_actions)``, True where an action is
        available in that state (invalid-action masking, as in MaskablePPO). The policy acts, and explanations take
        the chosen action and the runner-up, among available actions only; their scores are still explained.
    :param window: for a module whose input is its last ``window`` observations, (n, window, signals): an MLP over a
        window, a GRU/LSTM with ``batch_first``. ``feature_names`` then name the signals of one observation and the
        features are their slots, ``signal[t-3]`` ... ``signal[t]``; ``features`` may describe a signal once. The
        same as ``observation=xairl.Observation.window(signals, window)``, which also takes a flat layout and the
        seconds between observations (:mod:`xairl.policies.windows`).
    :param feasible: optional ``f(states (n, n_features)) -> bool (n,)``, True for the states the world allows
        (coupled constraints, such as an RSRQ its RSRP makes possible): a counterfactual it rejects is never returned.
    :param description: what is explained, where the module alone does not say it (from_sb3: a recurrent policy's
        LSTM unrolled over a window, and from which state); its explanations keep it as ``extras['policy']``.
    """

    module: torch.nn.Module
    feature_names: Sequence[str] | None = None
    action_names: Sequence[str] | None = None
    features: Mapping[str, FeatureInfo] = field(default_factory=dict)
    groups: Mapping[str, Sequence[str]] = field(default_factory=dict)
    background_sampler: Callable[[int, int], Any] | None = None
    name: str = "policy"
    action_aliases: Mapping[str, Sequence[str]] = field(default_factory=dict)
    facts_hook: Callable[[np.ndarray, int, int], Any] | None = None
    action_mask: Callable[[np.ndarray], np.ndarray] | None = None
    observation: Any = None
    output: Literal["actions", "continuous", "value"] | Sequence[str] | None = None
    window: int | None = None
    feasible: Callable[[np.ndarray], np.ndarray] | None = None
    description: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.module, torch.nn.Module):
            raise InputError(f"module must be a torch.nn.Module, got {type(self.module).__name__}.")

        def normalise(name: str, value) -> None:  # a frozen dataclass sets its own fields only here
            object.__setattr__(self, name, value)

        declared = self.output is not None  # undeclared: discrete actions, unless the names say otherwise
        kinds = None if isinstance(self.output, str) or not declared else tuple(str(k) for k in self.output)
        if not declared:
            normalise("output", "actions")
        elif kinds is not None:  # one kind per output column: checked against the names below
            normalise("output", kinds[0] if kinds else "")
        if self.output not in OUTPUT_KINDS or (kinds and not set(kinds) <= set(OUTPUT_KINDS)):
            raise InputError(
                f"output {self.output if kinds is None else list(kinds)!r} is unknown; use one of "
                f"{', '.join(OUTPUT_KINDS)}, or one of them per output column."
            )

        observation, names = _with_window(self.window, self.observation, self.feature_names)
        normalise("observation", observation)
        normalise("feature_names", names)
        window = self.observation.parts[0].window if self.observation.kind == "window" else None
        normalise("window", window.steps if window else None)
        normalise("name", str(self.name))
        normalise("description", str(self.description))
        normalise("network", PolicyNetwork(self.module, self.observation, self.name))
        if self.action_names is None:  # count the outputs on one all-zero state
            n = 1 if self.output == "value" else self._raw_scores(np.zeros((1, self.observation.n_features))).shape[1]
            normalise("action_names", ["value"] if self.output == "value" else [f"action_{i}" for i in range(n)])
        names = self.observation.feature_names() if self.feature_names is None else self.feature_names
        normalise("feature_names", tuple(str(f) for f in names))
        normalise("action_names", tuple(str(a) for a in self.action_names))
        normalise("features", slot_features(dict(self.features), window))  # copies: the caller's dicts stay theirs
        normalise("groups", {str(g): tuple(m) for g, m in dict(self.groups).items()})
        normalise("action_aliases", {str(a): tuple(v) for a, v in dict(self.action_aliases).items()})
        for what, names in (("feature_names", self.feature_names), ("action_names", self.action_names)):
            if not names:
                raise InputError(f"{what} is empty; name every input column and every output.")
            if len(set(names)) != len(names):
                dup = sorted({n for n in names if names.count(n) > 1})
                raise InputError(f"{what} has duplicates ({', '.join(dup)}); names must be unique.")
        if len(self.feature_names) != self.observation.n_features:
            raise InputError(
                f"{len(self.feature_names)} feature names for an observation of "
                f"{self.observation.n_features} columns {self.observation.describe()}; name each column."
            )
        check_kinds(self, kinds, declared)
        if self.feasible is not None and not callable(self.feasible):
            raise InputError(f"feasible must be a function of flat states (n, {self.n_features}) -> bool (n,).")
        if self.output == "value" and len(self.action_names) != 1:
            raise InputError("a 'value' policy has one output; give one name in action_names (e.g. ['value']).")
        _check_metadata(self, window)

    def __repr__(self) -> str:
        """Counts and the first few names, never thousands: ``Policy('cnn', 12288 features: obs[0,0,0], ... ;
        4 actions: ...; output actions, observation (n, 3, 64, 64))``."""
        return (
            f"Policy({self.name!r}, {names_preview(self.feature_names, 'features')}; "
            f"{names_preview(self.action_names, 'actions' if self.output == 'actions' else 'outputs')}; "
            f"output {self.output}, observation {self.observation.describe()}"
            f"{'; ' + self.description if self.description else ''})"
        )

    @classmethod
    def heads(
        cls, module: torch.nn.Module, output: Sequence[str], action_names: Sequence[str] | None = None, **kwargs
    ) -> dict[str, Policy]:
        """One policy per kind of output, for a network whose outputs are of several kinds (a parametrised action
        space, P-DQN style: the discrete actions' logits and their continuous parameters in one tensor).

        :param output: the kind of each output column, e.g. ``['actions'] * 3 + ['continuous'] * 3``.
        :param action_names: a name per output column (default ``action_0..``).
        :param kwargs: the other :class:`Policy` arguments (feature names, observation, ...), shared by the heads.
        :returns: ``{kind: Policy}`` in the order the kinds first appear, each on its own columns of the module's
            output: ``heads['actions']`` chooses among the actions, ``heads['continuous']`` explains each parameter.
        """
        return heads(cls, module, output, action_names, **kwargs)

    @property
    def n_features(self) -> int:
        return len(self.feature_names)

    @property
    def reason_groups(self) -> dict[str, tuple[str, ...]]:
        """Groups narrated as one reason: those described with ``FeatureInfo(kind='group')``, then every other
        declared group, except one whose members all have words of their own (a :class:`FeatureInfo` each: they keep
        them, and the group sums them in figures and the report's grouped summary) or that shares a member with a
        group before it."""
        out = {g: tuple(self.groups[g]) for g, i in self.features.items() if i.kind == "group"}
        taken = {f for members in out.values() for f in members}
        for g, members in self.groups.items():
            if g in out or taken.intersection(members) or all(f in self.features for f in members):
                continue
            out[g] = tuple(members)
            taken.update(members)
        return out

    @property
    def n_actions(self) -> int:
        """Number of output columns (actions, action dimensions, or 1 for a value)."""
        return len(self.action_names)

    @property
    def device(self) -> torch.device:
        p = next(self.module.parameters(), None)
        return p.device if p is not None else torch.device("cpu")

    @property
    def dtype(self) -> type:
        """The numpy dtype the network computes in, as its first floating-point parameter: float64 for a float64
        network (its states are explained in float64), float32 otherwise (a float16 network is refused in one line
        when it runs)."""
        return np.float64 if module_dtype(self.module) == torch.float64 else np.float32

    def check_states(self, states, what: str = "states") -> np.ndarray:
        """States in any form the observation takes -> validated (n, n_features) in the network's :attr:`dtype`;
        raises :class:`InputError` with a one-line reason."""
        return self.observation.flatten(states, what, self.dtype)

    def scores(self, states) -> np.ndarray:
        """Outputs (n, n_actions) of the module in eval mode, without gradients."""
        out = self._raw_scores(self.check_states(states))
        if out.shape[1] != self.n_actions:
            raise InputError(
                f"the module returned shape {tuple(out.shape)} but {self.n_actions} outputs are named; "
                f"it must map {self.observation.describe()} to (batch, {self.n_actions})."
            )
        return out

    def _raw_scores(self, x: np.ndarray) -> np.ndarray:
        """The module's outputs for checked flat states, in eval mode, without gradients (its flags restored; layers
        left in training mode that eval mode changes are named in a warning, once per policy)."""
        with eval_mode(self.module, self), torch.no_grad():
            out = self.network(torch.as_tensor(x, dtype=_TORCH[self.dtype], device=self.device))
        return out.detach().cpu().numpy().astype(np.float64)

    def available(self, states) -> np.ndarray:
        """Bool (n, n_actions): the actions available in each state (all of them without an ``action_mask``)."""
        x = self.check_states(states)
        if self.action_mask is None:
            return np.ones((len(x), self.n_actions), dtype=bool)
        if self.output != "actions":
            raise InputError(f"policy '{self.name}': an action_mask needs discrete actions (output='actions').")
        mask = np.asarray(self.action_mask(x), dtype=bool)
        if mask.shape != (len(x), self.n_actions) or not mask.any(axis=1).all():
            raise InputError(
                f"policy '{self.name}': action_mask must return a bool array {(len(x), self.n_actions)} "
                "with at least one available action per state."
            )
        return mask

    def act(self, states) -> np.ndarray:
        """Index of the highest-scoring available action per state (discrete actions only)."""
        if self.output != "actions":
            raise InputError(
                f"policy '{self.name}' outputs {self.output}, not discrete actions: nothing is chosen; use scores()."
            )
        return np.where(self.available(states), self.scores(states), -np.inf).argmax(axis=1)

    def background(self, n: int = 100, seed: int = 0) -> np.ndarray:
        """`n` typical states from the policy's sampler; raises when it has none."""
        if self.background_sampler is None:
            raise InputError(
                f"policy '{self.name}' has no background sampler; give background states: --background FILE "
                "on the command line, background=array in Python."
            )
        return self.check_states(self.background_sampler(n, seed), "background")


def model_hash(module) -> str:
    """Short SHA-256 of a torch module's parameters and buffers (which network said it)."""
    h = hashlib.sha256()
    for name, tensor in sorted(module.state_dict().items()):
        h.update(name.encode())
        h.update(tensor.detach().cpu().contiguous().numpy().tobytes())
    return h.hexdigest()[:16]


def _check_metadata(policy: Policy, window) -> None:
    """Features, groups and their kinds name known features (of a window: its signals too), groups narrated as one
    reason are groups and do not overlap, and a window policy has none."""
    names = set(policy.feature_names) | set(window.signals if window else ())
    described = {f for f, i in policy.features.items() if i.kind != "group"}
    unknown = sorted(described - names) + sorted({str(f) for g in policy.groups.values() for f in g} - names)
    if unknown:
        raise InputError(
            f"metadata names unknown feature(s) {', '.join(unknown[:5])}; use names from "
            "feature_names (column indices, as xairl.patches gives, go to Explanation.grouped)."
        )
    for g, info in policy.features.items():
        if info.kind == "group" and g not in policy.groups:
            raise InputError(f"features['{g}'] has kind 'group' but '{g}' is not in groups; add it to groups.")
    if window is not None and policy.groups:
        raise InputError(
            "groups of a window policy are not narrated (its signals are: each over its steps); leave groups "
            "out and sum your own with Explanation.grouped on exp.by_signal()."
        )
    members = [f for g, i in policy.features.items() if i.kind == "group" for f in policy.groups[g]]
    if len(members) != len(set(members)):
        raise InputError("a feature belongs to two groups narrated as one reason (kind='group'); keep them apart.")


def _with_window(window, observation, feature_names) -> tuple[Observation, Sequence[str] | None]:
    """(observation, feature names) of a policy given ``window=k`` or a window observation: the signals' names
    become slot names (generated, so ``None``); any other observation as :func:`_observation` makes it."""
    if window is not None:
        if isinstance(window, bool) or not isinstance(window, (int, np.integer)):
            raise InputError(f"window is the number of observations the module takes (k >= 2); got {window!r:.40}.")
        if observation is not None or feature_names is None:
            raise InputError(
                "window=k takes the signals' names as feature_names and no observation; for another layout "
                "give observation=xairl.Observation.window(signals, k, layout) instead."
            )
        observation = Observation.window(feature_names, window)
    observation = _observation(observation, feature_names)
    if observation.kind == "window" and feature_names is not None:
        if tuple(map(str, feature_names)) == observation.parts[0].window.signals:
            feature_names = None  # the signals' names: the slots' are generated from them
        else:  # names of the slots: none may say another slot than its column holds ('a[t-1]' beside signal 'a')
            check_slot_names(observation.parts[0].window, list(map(str, feature_names)))
    return observation, feature_names


def _observation(obs, feature_names) -> Observation:
    if isinstance(obs, Observation):
        return obs
    if obs is None:
        if feature_names is None:
            raise InputError("give feature_names or an observation shape, e.g. observation=(4, 84, 84).")
        return Observation.flat(len(list(feature_names)))
    if isinstance(obs, Mapping):
        return Observation.dict(obs)
    if isinstance(obs, (list, tuple)) and obs and all(isinstance(s, (list, tuple)) for s in obs):
        return Observation.several(obs)
    if isinstance(obs, (list, tuple, int)):
        shape = (obs,) if isinstance(obs, int) else tuple(obs)
        return Observation.flat(shape[0]) if len(shape) == 1 else Observation.array(shape)
    raise InputError(f"observation must be a shape, a dict of shapes or a list of shapes; got {type(obs).__name__}.")
