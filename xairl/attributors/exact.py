"""Exact interventional Shapley values: every coalition of features, each averaged over the background.

v(S) = mean over background r of f(x_S, r_rest). phi_i = sum over S without i of |S|!(F-|S|-1)!/F! (v(S+i) - v(S)).
All 2^F coalitions are evaluated in batched forwards, so this serves as ground truth up to 16 features.

Its cost is known before it runs (:meth:`Exact.cost`): n_states x 2^F x background rows through the network. Above
``max_evaluations`` it refuses before any forward pass, with the cost and the option that raises the limit.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import factorial

import numpy as np
import torch
from pydantic import Field, field_validator

from xairl.attributors.base import EXACT_MAX_FEATURES as MAX_FEATURES
from xairl.attributors.base import Attributor, Options
from xairl.errors import InputError
from xairl.explanations.display import WorkProgress
from xairl.policies.policy import Policy

#: the default limit, 2^24 (one 16-feature state against 256 background rows): see ExactOptions.max_evaluations
MAX_EVALUATIONS = 2**24


class ExactOptions(Options):
    max_rows: int = Field(
        8_192,
        ge=1,
        description="rows per forward batch; bounds memory (8,192: the fastest measured on a CPU)",
    )
    max_evaluations: int = Field(
        MAX_EVALUATIONS,
        ge=1,
        description=(
            "refuse above this many network evaluations (states x 2^F coalitions x background rows) before running; "
            "the default 2^24 takes about 40 s on one CPU core for a 64-unit GRU over 4 steps, 20 s for a "
            "16-256-256-4 MLP, 6 s for a 16-120-84-4 MLP (measured 2026-12-06)"
        ),
    )
    progress: bool | None = Field(
        None,
        description=(
            "show progress: True, a bar; False, nothing; None, a bar past 3 s on a terminal, else a plain line to "
            "stderr every 10 s (a log, a pipe)"
        ),
    )

    @field_validator("max_rows", "max_evaluations", mode="before")
    @classmethod
    def _a_whole_count(cls, v):
        """A count is a whole number however it is written (100000, 1e9, numpy's int64, '2e7' on the command line);
        True is no count (lax pydantic would read it as 1) and 2.5 rows no whole number."""
        if isinstance(v, (bool, np.bool_)):
            raise ValueError("a count is a whole number, not true or false")
        if isinstance(v, str):
            try:
                v = float(v.strip())
            except ValueError:
                return v  # pydantic names what it is not
        if isinstance(v, (float, np.floating, np.integer)):
            if not np.isfinite(v) or not float(v).is_integer():
                raise ValueError(f"a count is a whole number, not {v}")
            return int(v)
        return v


@dataclass(frozen=True)
class ExactCost:
    """What one exact call costs, known before it runs.

    :param evaluations: rows exact runs through the network: states x 2^F coalitions x background rows (every method
        also runs each state once for its outputs: one row per state on top).
    :param bytes: memory of its batches: the rows of one forward (``rows_per_forward`` x F in the network's dtype),
        their outputs, and the (2^F, actions) value table of one state. The network's own activations come on top
        (a recurrent network's are several times its input).
    :param rows_per_forward: rows built at once (whole coalitions against the whole background, about ``max_rows``).
    """

    evaluations: int
    bytes: int
    rows_per_forward: int

    def __str__(self) -> str:
        return f"{self.evaluations:,} network evaluations, batches of about {_size(self.bytes)}"


def _size(n: int) -> str:
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= scale:
            return f"{n / scale:.1f} {unit}"
    return f"{n} bytes"


def coalition_weights(f: int) -> tuple[np.ndarray, np.ndarray]:
    """Masks (2^f, f) as booleans, bit j = feature j, and the Shapley weight of each coalition size 0..f-1."""
    ids = np.arange(2**f)
    masks = ((ids[:, None] >> np.arange(f)) & 1).astype(bool)
    weights = np.array([factorial(s) * factorial(f - s - 1) / factorial(f) for s in range(f)])
    return masks, weights


def shapley(v: np.ndarray, masks: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Shapley values (F, actions) from the coalition values ``v`` (2^F, actions)."""
    k, f = masks.shape
    ids, sizes = np.arange(k), masks.sum(axis=1)
    out = np.empty((f, v.shape[1]))
    for j in range(f):
        without = ids[~masks[:, j]]
        out[j] = (weights[sizes[without]][:, None] * (v[without | (1 << j)] - v[without])).sum(axis=0)
    return out


class Exact(Attributor):
    """Exact Shapley values by enumerating all coalitions (interventional, over the background)."""

    name = "exact"
    Options = ExactOptions

    def _coalitions_per_forward(self, f: int, n_background: int) -> int:
        return max(1, min(2**f, self.options.max_rows // max(n_background, 1)))

    def cost(self, policy: Policy, n_states: int, n_background: int) -> ExactCost:
        """The network evaluations and batch memory of explaining ``n_states`` states against ``n_background``
        background rows, without running anything."""
        for what, count in (("n_states", n_states), ("n_background", n_background)):
            if isinstance(count, (bool, np.bool_)) or not isinstance(count, (int, np.integer)) or count < 1:
                raise InputError(f"Exact.cost: {what} is a whole number of rows, at least 1; got {count!r:.40}.")
        f, a = policy.n_features, policy.n_actions
        item = np.dtype(policy.dtype).itemsize
        rows = self._coalitions_per_forward(f, n_background) * n_background
        out_rows = min(rows, self.options.max_rows)
        memory = rows * f * item + out_rows * a * item + rows * a * 8 + 2**f * (a * 8 + f)
        return ExactCost(n_states * 2**f * n_background, memory, rows)

    def check_cost(self, policy, n_states, n_background):
        f = policy.n_features
        if f > MAX_FEATURES:
            raise InputError(
                f"exact enumerates 2^{f} coalitions; {f} features is more than {MAX_FEATURES}: "
                "use method='deep_shap' or 'kernel_shap'."
            )
        cost, limit = self.cost(policy, n_states, n_background), self.options.max_evaluations
        if cost.evaluations > limit:
            raise InputError(
                f"exact would run {cost.evaluations:,} network evaluations ({n_states} states x 2^{f} coalitions x "
                f"{n_background} background rows) with batches of about {_size(cost.bytes)}, over "
                f"max_evaluations={limit:,}: raise it (options={{'max_evaluations': {cost.evaluations}}}; "
                f"-o max_evaluations={cost.evaluations} on the command line), explain fewer states (a streamed "
                "run: a smaller chunk_size) against a smaller background, or use method='kernel_shap'."
            )

    def _attribute(self, policy, x, bg):
        n, f = x.shape
        masks, weights = coalition_weights(f)
        dev, a, b, k = policy.device, policy.n_actions, len(bg), len(masks)
        mt = torch.as_tensor(masks, device=dev)[:, None, :]
        bt = torch.as_tensor(bg, device=dev)[None, :, :]
        per = self._coalitions_per_forward(f, b)
        starts = range(0, k, per)
        # one state: a bar over its batches of coalitions; several: a bar over the states (and a state's share)
        bar = WorkProgress(self.options.progress, n if n > 1 else len(starts), "exact", "state" if n > 1 else "batch")
        values, v = np.empty((n, f, a)), np.empty((k, a))
        try:
            for i in range(n):
                xi = torch.as_tensor(x[i], device=dev)
                for s in starts:
                    rows = torch.where(mt[s : s + per], xi, bt).reshape(-1, f)
                    out = self._forward(policy, rows, self.options.max_rows)
                    v[s : s + per] = out.reshape(-1, b, a).mean(dim=1).numpy()
                    bar.advance(1 if n == 1 else 1 / len(starts))
                values[i] = shapley(v, masks, weights)
        finally:
            bar.close()
        # the empty coalition is every feature from the background: the base value, the same for every state
        base = v[0].copy() if n else self._forward(policy, bt[0], self.options.max_rows).mean(dim=0).numpy()
        return values, base, {}
