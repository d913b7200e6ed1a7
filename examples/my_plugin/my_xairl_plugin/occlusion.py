"""An attribution method as a plugin: occlusion (leave one feature out).

Contribution of feature j to action a: f_a(x) minus the mean over background states r of f_a(x with x_j := r_j).
Unlike Shapley values these need not add up to f(x) - E[f]; the base class reports that as the additivity gap.
xairl's ``Attributor.explain`` does the shared work (checks, eval mode, hook clean-up, the Explanation); this
class only implements ``_attribute`` and declares its options.
"""

import numpy as np
import torch
from pydantic import Field

import xairl


class OcclusionOptions(xairl.plugin.Options):
    max_rows: int = Field(65_536, ge=1, description="rows per forward batch")


class Occlusion(xairl.plugin.Attributor):
    """Score drop when one feature at a time takes the background's values."""

    name = "occlusion"
    Options = OcclusionOptions

    def _attribute(self, policy, x, bg):
        n, f = x.shape
        m = len(bg)
        dev = policy.device
        rows = np.repeat(x[:, None, None, :], f, axis=1).repeat(m, axis=2)  # (n, f, m, f)
        for j in range(f):
            rows[:, j, :, j] = bg[None, :, j]
        flat = torch.as_tensor(rows.reshape(-1, f), dtype=torch.float32, device=dev)
        out = self._forward(policy, flat, self.options.max_rows).numpy().reshape(n, f, m, -1).mean(axis=2)
        full = self._forward(policy, torch.as_tensor(x, device=dev), self.options.max_rows).numpy()
        base = self._forward(policy, torch.as_tensor(bg, device=dev), self.options.max_rows).numpy().mean(axis=0)
        return full[:, None, :] - out, base, {"note": "occlusion is not additive"}
