"""Explanation: the one result type of every attributor, shaped (states, features, actions)."""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, Mapping, Sequence

import numpy as np
from pydantic import BaseModel, ConfigDict

from .errors import InputError


@dataclass(frozen=True)
class Explanation:
    """Per-state, per-feature, per-action contributions.

    For every state i and action a: ``base_values[i, a] + values[i, :, a].sum() ≈ outputs[i, a]``;
    ``additivity_gap[i, a]`` is the absolute difference.

    :param values: (n_states, n_features, n_actions) contributions.
    :param base_values: (n_states, n_actions) expected score over the background (or the baseline's score).
    :param outputs: (n_states, n_actions) the policy's scores for the explained states.
    :param states: (n_states, n_features) the explained inputs (None after :meth:`grouped`).
    :param method: attributor name; ``options`` the validated options it ran with.
    :param extras: method-specific diagnostics (e.g. IG's convergence delta).
    :param background_quantiles: (3, n_features) 25th, 50th and 75th percentiles of the background, so that a
        value can be called low, typical or high.
    :param available: (n_states, n_actions) bool, the actions available in each state (the policy's
        ``action_mask``); None: all. The chosen action and the runner-up are taken among available ones.
    """

    values: np.ndarray
    base_values: np.ndarray
    outputs: np.ndarray
    states: np.ndarray | None
    feature_names: tuple[str, ...]
    action_names: tuple[str, ...]
    method: str
    options: Mapping[str, Any] = field(default_factory=dict)
    extras: Mapping[str, Any] = field(default_factory=dict)
    background_quantiles: np.ndarray | None = None
    available: np.ndarray | None = None

    def __post_init__(self) -> None:
        n, f, a = self.values.shape
        for name, arr, shape in (
            ("base_values", self.base_values, (n, a)),
            ("outputs", self.outputs, (n, a)),
        ):
            if arr.shape != shape:
                raise InputError(f"Explanation.{name} has shape {arr.shape}, expected {shape}.")
        if self.available is not None and self.available.shape != (n, a):
            raise InputError(f"Explanation.available has shape {self.available.shape}, expected {(n, a)}.")
        if self.states is not None and self.states.shape != (n, f):
            raise InputError(f"Explanation.states has shape {self.states.shape}, expected {(n, f)}.")
        if len(self.feature_names) != f or len(self.action_names) != a:
            raise InputError("Explanation names do not match the values' shape.")
        for arr in (self.values, self.base_values, self.outputs, self.available):
            if arr is not None:
                arr.setflags(write=False)

    @property
    def shape(self) -> tuple[int, int, int]:
        return self.values.shape

    def _ranked(self) -> np.ndarray:
        """Actions per state, best available first (unavailable ones last)."""
        scores = self.outputs if self.available is None else np.where(self.available, self.outputs, -np.inf)
        return np.argsort(-scores, axis=1, kind="stable")

    @property
    def chosen(self) -> np.ndarray:
        """Index of the best-scoring available action per state."""
        return self._ranked()[:, 0]

    @property
    def runner_up(self) -> np.ndarray:
        """Index of the second-best available action per state (the chosen one again when it is the only one)."""
        ranked = self._ranked()
        if ranked.shape[1] < 2:
            return ranked[:, 0]
        if self.available is None:
            return ranked[:, 1]
        return np.where(self.available.sum(axis=1) < 2, ranked[:, 0], ranked[:, 1])

    @property
    def additivity_gap(self) -> np.ndarray:
        """|base + sum of contributions − output| per state and action."""
        return np.abs(self.base_values + self.values.sum(axis=1) - self.outputs)

    def for_chosen(self) -> np.ndarray:
        """Contributions (n_states, n_features) to the chosen action's score."""
        return self.values[np.arange(len(self.values)), :, self.chosen]

    def margin(self) -> np.ndarray:
        """Contributions (n_states, n_features) to Q(best) − Q(runner-up): why this action and not the next best."""
        idx = np.arange(len(self.values))
        return self.values[idx, :, self.chosen] - self.values[idx, :, self.runner_up]

    def grouped(self, groups: Mapping[str, Sequence[str]]) -> "Explanation":
        """Sum the contributions of each group into one feature named after it; other features stay as they are.

        Groups must not overlap. The result keeps outputs and base values, so additivity is unchanged.
        """
        seen: dict[str, str] = {}
        for g, members in groups.items():
            for m in members:
                if m not in self.feature_names:
                    raise InputError(f"group '{g}' names unknown feature '{m}'; known: {', '.join(self.feature_names)}.")
                if m in seen:
                    raise InputError(f"feature '{m}' is in groups '{seen[m]}' and '{g}'; groups must not overlap.")
                seen[m] = g
        names: list[str] = []
        cols: list[np.ndarray] = []
        for i, f in enumerate(self.feature_names):
            g = seen.get(f)
            if g is None:
                names.append(f)
                cols.append(self.values[:, i, :])
            elif g not in names:
                names.append(g)
                idx = [self.feature_names.index(m) for m in groups[g]]
                cols.append(self.values[:, idx, :].sum(axis=1))
        return replace(self, values=np.stack(cols, axis=1), feature_names=tuple(names), states=None,
                       background_quantiles=None)

    def records(self, dataset: str | None = None) -> list["StateRecord"]:
        """One :class:`StateRecord` per explained state (the JSON-lines form); ``dataset`` labels where the states
        came from (e.g. 'simulated', 'real')."""
        gap, chosen, runner = self.additivity_gap, self.chosen, self.runner_up
        acts = self.action_names
        out = []
        for i in range(len(self.values)):
            out.append(StateRecord(
                index=i,
                dataset=dataset,
                method=self.method,
                state=None if self.states is None else dict(zip(self.feature_names, self.states[i].tolist())),
                chosen=acts[chosen[i]],
                runner_up=acts[runner[i]],
                scores=dict(zip(acts, self.outputs[i].tolist())),
                base_values=dict(zip(acts, self.base_values[i].tolist())),
                values={f: dict(zip(acts, self.values[i, j].tolist())) for j, f in enumerate(self.feature_names)},
                additivity_gap=dict(zip(acts, gap[i].tolist())),
            ))
        return out

    def to_json(self) -> str:
        """JSON text (see :class:`ExplanationRecord` for the schema)."""
        return ExplanationRecord.from_explanation(self).model_dump_json()

    @classmethod
    def from_json(cls, text: str) -> "Explanation":
        return ExplanationRecord.model_validate_json(text).to_explanation()


class ExplanationRecord(BaseModel):
    """The JSON form of an :class:`Explanation` (nested lists, names, method and options)."""

    model_config = ConfigDict(extra="forbid")

    values: list[list[list[float]]]
    base_values: list[list[float]]
    outputs: list[list[float]]
    states: list[list[float]] | None
    feature_names: list[str]
    action_names: list[str]
    method: str
    options: dict[str, Any] = {}
    extras: dict[str, Any] = {}
    background_quantiles: list[list[float]] | None = None
    available: list[list[bool]] | None = None

    @classmethod
    def from_explanation(cls, e: Explanation) -> "ExplanationRecord":
        return cls(
            values=e.values.tolist(),
            base_values=e.base_values.tolist(),
            outputs=e.outputs.tolist(),
            states=None if e.states is None else e.states.tolist(),
            feature_names=list(e.feature_names),
            action_names=list(e.action_names),
            method=e.method,
            options=dict(e.options),
            extras={k: np.asarray(v).tolist() for k, v in e.extras.items()},
            background_quantiles=None if e.background_quantiles is None else e.background_quantiles.tolist(),
            available=None if e.available is None else e.available.tolist(),
        )

    def to_explanation(self) -> Explanation:
        return Explanation(
            values=np.asarray(self.values, dtype=np.float64).reshape(
                len(self.outputs), len(self.feature_names), len(self.action_names)
            ),
            base_values=np.asarray(self.base_values, dtype=np.float64),
            outputs=np.asarray(self.outputs, dtype=np.float64),
            states=None if self.states is None else np.asarray(self.states, dtype=np.float64),
            feature_names=tuple(self.feature_names),
            action_names=tuple(self.action_names),
            method=self.method,
            options=self.options,
            extras={k: np.asarray(v) for k, v in self.extras.items()},
            background_quantiles=None if self.background_quantiles is None else np.asarray(self.background_quantiles),
            available=None if self.available is None else np.asarray(self.available, dtype=bool),
        )


class StateRecord(BaseModel):
    """One explained state, as written to ``explanations.jsonl`` and by ``xairl explain --format jsonl``."""

    model_config = ConfigDict(extra="forbid")

    index: int
    dataset: str | None = None
    method: str
    state: dict[str, float] | None
    chosen: str
    runner_up: str
    scores: dict[str, float]
    base_values: dict[str, float]
    values: dict[str, dict[str, float]]
    additivity_gap: dict[str, float]
