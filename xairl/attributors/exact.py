"""Exact interventional Shapley values: every coalition of features, each averaged over the background.

v(S) = mean over background r of f(x_S, r_rest). phi_i = sum over S without i of |S|!(F-|S|-1)!/F! (v(S+i) - v(S)).
All 2^F coalitions are evaluated in batched forwards, so this serves as ground truth up to 16 features.
"""

from __future__ import annotations

from math import factorial

import numpy as np
import torch
from pydantic import Field

from ..errors import InputError
from .base import EXACT_MAX_FEATURES as MAX_FEATURES
from .base import Attributor, Options


class ExactOptions(Options):
    max_rows: int = Field(1_048_576, ge=1, description="rows per forward batch; bounds memory")


def coalition_weights(f: int) -> tuple[np.ndarray, np.ndarray]:
    """Masks (2^f, f) as booleans, bit j = feature j, and the Shapley weight of each coalition size 0..f-1."""
    ids = np.arange(2**f)
    masks = ((ids[:, None] >> np.arange(f)) & 1).astype(bool)
    weights = np.array([factorial(s) * factorial(f - s - 1) / factorial(f) for s in range(f)])
    return masks, weights


class Exact(Attributor):
    """Exact Shapley values by enumerating all coalitions (interventional, over the background)."""

    name = "exact"
    Options = ExactOptions

    def _attribute(self, policy, x, bg):
        n, f = x.shape
        if f > MAX_FEATURES:
            raise InputError(
                f"exact enumerates 2^{f} coalitions; {f} features is more than {MAX_FEATURES}: "
                "use method='deep_shap' or 'kernel_shap'."
            )
        masks, weights = coalition_weights(f)
        dev = policy.device
        mt = torch.as_tensor(masks, device=dev)[:, None, :]
        bt = torch.as_tensor(bg, device=dev)[None, :, :]
        k, b = len(masks), len(bg)
        values = np.empty((n, f, policy.n_actions))
        ids = np.arange(k)
        sizes = masks.sum(axis=1)
        for i in range(n):
            rows = torch.where(mt, torch.as_tensor(x[i], device=dev), bt).reshape(k * b, f)
            v = self._forward(policy, rows, self.options.max_rows).reshape(k, b, -1).mean(dim=1).numpy()
            for j in range(f):
                without = ids[~masks[:, j]]
                w = weights[sizes[without]][:, None]
                values[i, j] = (w * (v[without | (1 << j)] - v[without])).sum(axis=0)
        base = self._forward(policy, bt[0], self.options.max_rows).mean(dim=0).numpy()
        return values, base, {}
