"""Explanation: the one result type of every attributor, shaped (states, features, actions)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from xairl.errors import InputError
from xairl.explanations.explanation_io import state_rows

#: the ``extras`` that hold one entry per state, cut with the states when an Explanation is sliced; every other
#: extra describes the run and is kept whole
PER_STATE_EXTRAS = {"convergence_delta"}


@dataclass(frozen=True)
class Explanation:
    """Per-state, per-feature, per-action contributions.

    For every state i and action a: ``base_values[i, a] + values[i, :, a].sum() ≈ outputs[i, a]``;
    ``additivity_gap[i, a]`` is the absolute difference.
    ``exp[:n]``, ``exp[mask]``, ``exp[[i, j]]`` and ``exp[i]`` are the Explanation of those states (an episode out of
    a run; an int gives a one-state Explanation), ``len(exp)`` their number.

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
    :param output: what the outputs are (``Policy.output``): 'actions' (discrete scores: a chosen action and a
        runner-up), 'continuous' (action dimensions, each explained on its own) or 'value' (one output).
    :param observation: the policy's input structure (``Observation.to_dict()``), so that values can be viewed as
        images (:meth:`image`); None for flat states.
    :param categories: feature name -> the label of each integer code, for categorical features
        (``FeatureInfo.categories``); :attr:`value_labels` reads the states through it.
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
    output: str = "actions"
    observation: Mapping[str, Any] | None = None
    categories: Mapping[str, Sequence[str]] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "feature_names", tuple(self.feature_names))  # normalised, as the JSON reads back
        object.__setattr__(self, "action_names", tuple(self.action_names))
        if self.categories:
            object.__setattr__(self, "categories", {str(k): tuple(v) for k, v in self.categories.items()})
        for name in ("values", "base_values", "outputs"):
            if not isinstance(getattr(self, name), np.ndarray):
                raise InputError(f"Explanation.{name} must be a numpy array, not {type(getattr(self, name)).__name__}.")
        if self.values.ndim != 3:
            raise InputError(f"Explanation.values has shape {self.values.shape}; expected (states, features, actions).")
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
        if self.output not in ("actions", "continuous", "value"):
            raise InputError(f"Explanation.output '{str(self.output)[:40]}' is not one of actions, continuous, value.")
        from xairl.explanations.explanation_io import check_observation, check_quartiles

        if self.observation is not None:  # narration and images read it: checked here, not when it is used
            object.__setattr__(self, "observation", check_observation(self.observation, self.feature_names))
        if self.background_quantiles is not None:  # (its NaN: a region's unknown quartiles, no level words)
            check_quartiles(self.background_quantiles, f)
        for name in ("values", "base_values", "outputs", "states"):  # (a missing quartile: no level words)
            arr = getattr(self, name)
            if arr is not None and not np.isfinite(arr).all():
                raise InputError(
                    f"Explanation.{name} holds NaN or infinity ({int((~np.isfinite(arr)).sum())} "
                    "value(s)): the network's outputs or contributions overflowed; nothing here can be "
                    "trusted. Check the states' scale (a float32 network overflows beyond ~1e38)."
                )
        for arr in (self.values, self.base_values, self.outputs, self.available):
            if arr is not None:
                arr.setflags(write=False)

    def __repr__(self) -> str:  # counts and the first few names, never every feature (the arrays are the fields)
        from xairl.policies.observation import names_preview

        feats, acts = (
            names_preview(self.feature_names, "features"),
            names_preview(self.action_names, "actions" if self.output == "actions" else "outputs"),
        )
        return (
            f"Explanation({self.method!r}, {len(self.values)} states; {feats}; {acts}; output {self.output}, "
            f"largest additivity gap {self.additivity_gap.max(initial=0.0):.2g})"
        )

    def _repr_html_(self) -> str:
        """Jupyter's view (:func:`xairl.explanations.display.explanation_html`): the first decisions and what decided them."""
        from xairl.explanations.display import explanation_html

        return explanation_html(self)

    @property
    def shape(self) -> tuple[int, int, int]:
        return self.values.shape

    def check_index(self, index) -> int:
        """``index`` as the position of one explained state; a one-line :class:`InputError` for anything else (a
        float, a string, a bool, a position outside the states)."""
        if isinstance(index, bool) or not isinstance(index, (int, np.integer)):
            raise InputError(f"a state index is a whole number, not {type(index).__name__} {str(index)[:40]!r}.")
        if not 0 <= index < len(self.values):
            raise InputError(f"index {index} is out of range: the explanation has {len(self.values)} state(s).")
        return int(index)

    def __len__(self) -> int:
        """The number of explained states."""
        return len(self.values)

    def __getitem__(self, key) -> Explanation:
        """The explanation of some of the states, e.g. an episode out of a run: ``exp[:200]``, ``exp[t0:t1]``,
        ``exp[::10]``, ``exp[mask]`` (bools, one per state), ``exp[[3, 7]]`` (positions; negative count from the end).

        Always an Explanation, never an array: an int gives the one-state Explanation ``exp[i:i + 1]`` (so that
        plots, ``narrate(exp[i], 0)`` and ``verify`` take it as they take any). Every per-state array is cut alike:
        values, base values, outputs, states, available actions, and the ``extras`` named in
        :data:`PER_STATE_EXTRAS` (IG's convergence delta; an attributor of a plugin adds its own there); per-run fields (names, method, options, background quartiles,
        observation) are kept. The states are renumbered from 0 (:meth:`records`). Refused in one line: a
        selection of no state, a mask of another length, positions out of range, or an index into features or
        actions (``exp[:, j]``: use :meth:`grouped` or :meth:`output_slice`).
        """
        n = len(self.values)
        rows = state_rows(key, n)
        if not rows.size:
            raise InputError(f"the selection holds no state (of {n}); an Explanation explains at least one.")

        def cut(arr):
            return None if arr is None else np.asarray(arr)[rows].copy()

        extras = {
            k: cut(v)
            if isinstance(v, np.ndarray) and k in PER_STATE_EXTRAS
            else [v[i] for i in rows]
            if isinstance(v, (list, tuple)) and k in PER_STATE_EXTRAS  # (read from JSON)
            else v  # per run: kept whatever its length (one entry per feature may number as many as the states)
            for k, v in self.extras.items()
        }
        return replace(
            self,
            values=cut(self.values),
            base_values=cut(self.base_values),
            outputs=cut(self.outputs),
            states=cut(self.states),
            available=cut(self.available),
            extras=extras,
        )

    def _ranked(self) -> np.ndarray:
        """Actions per state, best available first (unavailable ones last)."""
        scores = self.outputs if self.available is None else np.where(self.available, self.outputs, -np.inf)
        return np.argsort(-scores, axis=1, kind="stable")

    @property
    def chosen(self) -> np.ndarray:
        """Index of the best-scoring available action per state (meaningful for discrete actions; 0 for a value)."""
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
    def focus(self) -> np.ndarray:
        """Index per state of the output a one-output view shows (plots, images): the chosen action for discrete
        actions, else the first output."""
        return self.chosen if self.output == "actions" else np.zeros(len(self.values), dtype=int)

    @property
    def image_shape(self) -> tuple[int, ...] | None:
        """(C, H, W) or (H, W) when the states are images, else None."""
        from xairl.policies.observation import Observation

        return None if self.observation is None else Observation.from_dict(self.observation).image_shape()

    @property
    def value_labels(self) -> np.ndarray | None:
        """(n_states, n_features) object array: the label of each categorical feature's value, None elsewhere
        (None altogether when there are no states or no categorical features)."""
        if self.states is None or not self.categories:
            return None
        out = np.full(self.states.shape, None, dtype=object)
        for j, f in enumerate(self.feature_names):
            labels = self.categories.get(f)
            if labels:
                codes = np.round(self.states[:, j]).astype(int)
                out[:, j] = [labels[c] if 0 <= c < len(labels) else None for c in codes]
        return out

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

    @property
    def decides(self) -> bool:
        """True when the policy chooses among several actions: its decisions have a margin over a runner-up."""
        return self.output == "actions" and self.values.shape[2] > 1

    def contributions(self, view: str = "margin") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(contributions (n_states, n_features), expected, value (n_states,)) to the 'margin' (chosen minus
        runner-up score) or the chosen 'score'; the first output when nothing is chosen. expected + sum = value."""
        if view not in ("margin", "score"):
            raise InputError(f"view {view!r} is not one of margin, score.")
        idx, c = np.arange(len(self.values)), self.focus
        expected, value = self.base_values[idx, c], self.outputs[idx, c]
        if view == "margin" and self.decides:  # (focus is the chosen action here)
            r = self.runner_up
            return self.margin(), expected - self.base_values[idx, r], value - self.outputs[idx, r]
        return self.values[idx, :, c], expected, value

    def grouped(self, groups: Mapping[str, Sequence[str] | np.ndarray]) -> Explanation:
        """Sum the contributions of each group into one feature named after it; other features stay as they are.

        :param groups: group name -> member feature names, or member column indices (e.g. from
            :func:`xairl.patches` for image patches, or :meth:`groups_by_part` for dict keys). Groups must not
            overlap. The result keeps outputs and base values, so additivity is unchanged.
        """
        index = {f: i for i, f in enumerate(self.feature_names)}
        owner = np.full(len(self.feature_names), -1)
        names = list(groups)
        for k, (g, members) in enumerate(groups.items()):
            members = np.asarray(members)
            if members.dtype.kind in "iu":
                idx = members.astype(int)
                if idx.size and (idx.min() < 0 or idx.max() >= len(owner)):
                    raise InputError(f"group '{g}' has column indices outside 0..{len(owner) - 1}.")
            else:
                unknown = [m for m in members.tolist() if m not in index]
                if unknown:
                    raise InputError(
                        f"group '{g}' names unknown feature '{unknown[0]}'; known: "
                        f"{', '.join(self.feature_names[:20])}{' ...' if len(index) > 20 else ''}."
                    )
                idx = np.array([index[m] for m in members.tolist()], dtype=int)
            clash = idx[owner[idx] >= 0]
            if clash.size:
                raise InputError(
                    f"feature '{self.feature_names[clash[0]]}' is in groups '{names[owner[clash[0]]]}' "
                    f"and '{g}'; groups must not overlap."
                )
            owner[idx] = k
        # one column per group (at its first member's place) and per ungrouped feature, in feature order
        order, out_names, seen = [], [], set()
        for i in range(len(owner)):
            k = int(owner[i])
            if k < 0:
                order.append(("f", i))
                out_names.append(self.feature_names[i])
            elif k not in seen:
                seen.add(k)
                order.append(("g", k))
                out_names.append(names[k])
        sums = np.zeros((len(self.values), len(names), self.values.shape[2]))
        grouped = owner >= 0
        np.add.at(sums.transpose(1, 0, 2), owner[grouped], self.values[:, grouped, :].transpose(1, 0, 2))
        cols = [self.values[:, i, :] if kind == "f" else sums[:, i, :] for kind, i in order]
        return replace(
            self,
            values=np.stack(cols, axis=1),
            feature_names=tuple(out_names),
            states=None,
            background_quantiles=None,
            observation=None,
        )

    def time_groups(self) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
        """(per signal, per step) column groups of a policy that sees time (:mod:`xairl.policies.windows`): a window's signals
        over their steps and its steps ('t-3' ... 't') over their signals; a frame stack's regions over its frames
        and its frames ('frame 0' ...). A one-line error for any other explanation."""
        from xairl.policies.observation import Observation

        groups = None if self.observation is None else Observation.from_dict(self.observation).time_groups()
        if groups is None:
            raise InputError(
                "this explanation is not of a window or a frame stack: give the policy window=k (or "
                "observation=xairl.Observation.window(...), or an image with channels='frames')."
            )
        return groups

    def by_signal(self) -> Explanation:
        """Per signal (:meth:`time_groups`): each one's contribution summed over the window's steps, exact by
        additivity. A window's states are each signal's newest value (a frame stack's none)."""
        signals, _ = self.time_groups()
        out = self.grouped(signals)
        if self.observation["kind"] != "window" or self.states is None:
            return out
        newest = np.array([cols[-1] for cols in signals.values()])
        q = self.background_quantiles
        return replace(out, states=self.states[:, newest], background_quantiles=None if q is None else q[:, newest])

    def by_step(self) -> Explanation:
        """Per time step (:meth:`time_groups`): the contributions of its signals summed."""
        return self.grouped(self.time_groups()[1])

    def output_slice(self, j: int) -> Explanation:
        """The explanation of output ``j`` alone (one dimension of a continuous action, narrated on its own)."""
        if not 0 <= j < self.values.shape[2]:
            raise InputError(f"output {j} is out of range: the explanation has {self.values.shape[2]} output(s).")
        cut = slice(j, j + 1)
        return replace(
            self,
            values=self.values[:, :, cut],
            base_values=self.base_values[:, cut],
            outputs=self.outputs[:, cut],
            action_names=(self.action_names[j],),
            available=None if self.available is None else self.available[:, cut],
        )

    def groups_by_part(self) -> dict[str, np.ndarray]:
        """Column indices of each input part (the keys of a dict observation, the inputs of a multi-input module),
        for :meth:`grouped`."""
        from xairl.policies.observation import Observation

        if self.observation is None:
            return {}
        return {k: np.arange(s.start, s.stop) for k, s in Observation.from_dict(self.observation).slices().items()}

    def image(self, action: int | str | None = None) -> np.ndarray:
        """Contributions as images: (n_states, *image_shape) for one output (default: the chosen action for
        discrete actions, else output 0)."""
        shape = self.image_shape
        if shape is None:
            raise InputError("this explanation is not of an image observation; give the policy observation=(C, H, W).")
        n = len(self.values)
        if action is None:
            a = self.focus
        else:
            a = np.full(n, self.action_names.index(action) if isinstance(action, str) else int(action))
        return self.values[np.arange(n), :, a].reshape(n, *shape)

    def records(self, dataset: str | None = None) -> list:
        """One :class:`xairl.plugin.StateRecord` per explained state (the JSON-lines form); ``dataset`` labels where
        the states came from (e.g. 'simulated', 'real')."""
        from xairl.explanations.explanation_io import records

        return records(self, dataset)

    def to_json(self) -> str:
        """JSON text: each field of this class under its own name, arrays as nested lists (:func:`from_json` reads
        it back)."""
        from xairl.explanations.explanation_io import to_json

        return to_json(self)

    @classmethod
    def from_json(cls, text: str | bytes) -> Explanation:
        """The explanation :meth:`to_json` wrote; raises :class:`InputError` with a one-line reason on anything
        else (not JSON, NaN or infinity, nesting too deep, wrong fields, shapes that disagree)."""
        from xairl.explanations.explanation_io import from_json

        return from_json(cls, text)
