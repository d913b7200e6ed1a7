"""Integrated Gradients through captum, from one baseline (the background mean by default) to each state."""

from __future__ import annotations

from typing import Literal

import numpy as np
import torch
from pydantic import Field

from xairl.attributors.base import Attributor, Options


class IntegratedGradientsOptions(Options):
    n_steps: int = Field(64, ge=2, le=100_000, description="points on the path from baseline to state")
    method: Literal["gausslegendre", "riemann_trapezoid", "riemann_middle", "riemann_left", "riemann_right"] = Field(
        "gausslegendre", description="integral approximation"
    )
    baseline: Literal["mean", "zeros"] = Field("mean", description="background mean, or the all-zero state")
    internal_batch_size: int = Field(4096, ge=1, description="path points per forward batch")


class IntegratedGradients(Attributor):
    """Integrated Gradients (Sundararajan et al.); the additivity gap is captum's convergence delta."""

    name = "integrated_gradients"
    Options = IntegratedGradientsOptions
    tolerance = 0.1  # of the change explained: a coarse quadrature stays well under it, zero gradients do not
    gap_of_change = True
    gap_reason = (
        "the path integral did not converge: the network is not differentiable along the path from the "
        "baseline (one-hot or integer inputs, argmax, embedding lookups, steps) or needs more n_steps; "
        "raise n_steps"
    )

    def _attribute(self, policy, x, bg):
        from captum.attr import IntegratedGradients as CaptumIG

        dev = policy.device
        xt = torch.as_tensor(x, device=dev)
        ref = bg.mean(axis=0) if self.options.baseline == "mean" else np.zeros(x.shape[1], dtype=x.dtype)
        baseline = torch.as_tensor(ref, device=dev)[None, :].expand_as(xt).contiguous()
        ig = CaptumIG(policy.network)
        values = np.empty((len(x), x.shape[1], policy.n_actions))
        delta = np.empty((len(x), policy.n_actions))
        for a in range(policy.n_actions):
            attr, d = ig.attribute(
                xt,
                baselines=baseline,
                target=a,
                n_steps=self.options.n_steps,
                method=self.options.method,
                internal_batch_size=self.options.internal_batch_size,
                return_convergence_delta=True,
            )
            values[:, :, a] = attr.detach().double().cpu().numpy()
            delta[:, a] = d.detach().double().cpu().numpy()
        base = self._forward(policy, baseline[:1], 1)[0].numpy()
        return values, base, {"convergence_delta": delta}
