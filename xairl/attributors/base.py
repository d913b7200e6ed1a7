"""The shared base of every attributor: checks, eval mode, hook clean-up, one Explanation out.

Subclasses implement :meth:`Attributor._attribute` only (the public/private split of SB3's predict/_predict).
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
import torch

from xairl.errors import InputError, UnsupportedModelError
from xairl.explanations.explanation import Explanation
from xairl.options import Options, parse_options
from xairl.policies.network import eval_mode, torch_threads
from xairl.policies.policy import Policy

#: background states drawn from the policy's sampler when none are given
DEFAULT_BACKGROUND = 100
#: the most features exact Shapley values enumerate (2^16 coalitions); here so that refusals can name it
EXACT_MAX_FEATURES = 16


class Attributor:
    """Turns (policy, states, background) into an :class:`Explanation` for all actions at once.

    :param options: a dict or an instance of the subclass's ``Options`` model.
    """

    name: ClassVar[str] = ""
    Options: ClassVar[type[Options]] = Options
    #: largest additivity gap accepted, relative to the output scale (max |output| and |base value|), or with
    #: ``gap_of_change`` to the largest change the contributions explain (max |output - base value|)
    tolerance: ClassVar[float] = 1e-4
    gap_of_change: ClassVar[bool] = False
    #: why a result over the tolerance happens with this method (the refusal says it)
    gap_reason: ClassVar[str] = "the network is not what this method assumes"

    def __init__(self, options: dict | Options | None = None):
        self.options = parse_options(self.Options, options, f"{self.name} options")
        self._handles: list[Any] = []

    def explain(self, policy: Policy, states, background=None) -> Explanation:
        """Explain ``states`` against ``background`` (default: 100 states from the policy's sampler).

        The module runs in eval mode; its training flags and every hook this attributor added are restored
        even when attribution fails. A small network runs on one torch thread (:func:`xairl.policies.network.torch_threads`).
        """
        if not isinstance(policy, Policy):
            raise InputError(
                f"expected an xairl.Policy, got {type(policy).__name__}; wrap a network with "
                "xairl.Policy(module, feature_names, action_names)."
            )
        x = policy.check_states(states)
        if background is None:  # before the sampler, which may fly the policy: a refusal costs nothing
            self.check_cost(policy, len(x), DEFAULT_BACKGROUND)
        bg = (
            policy.background(DEFAULT_BACKGROUND)
            if background is None
            else policy.check_states(background, "background")
        )
        self.check_cost(policy, len(x), len(bg))  # before any forward pass
        outputs = policy.scores(x)
        bad = ~np.isfinite(outputs).all(axis=1)
        if bad.any():
            kind = np.dtype(policy.dtype)
            raise InputError(
                f"the policy's outputs are NaN or infinite for {int(bad.sum())} state(s), first state "
                f"{int(np.argmax(bad))}: nothing can be explained; check the states' scale (a "
                f"{kind.name} network overflows beyond ~{np.finfo(kind).max:.0e})."
            )
        try:
            with eval_mode(policy.module, policy), torch_threads(policy):
                values, base, extras = self._attribute(policy, x, bg)
        finally:
            for handle in self._handles:
                handle.remove()
            self._handles.clear()
        n, f, a = len(x), policy.n_features, policy.n_actions
        values = np.asarray(values, dtype=np.float64).reshape(n, f, a)
        base = np.broadcast_to(np.asarray(base, dtype=np.float64), (n, a))
        if getattr(self.options, "check_additivity", True):
            self._check_additivity(policy, values, base, outputs)
        return Explanation(
            values=values,
            base_values=base.copy(),
            outputs=outputs,
            states=x.astype(np.float64),
            feature_names=tuple(policy.feature_names),
            action_names=tuple(policy.action_names),
            method=self.name,
            options=self.options.model_dump(),
            extras=dict(extras) | ({"policy": policy.description} if policy.description else {}),
            background_quantiles=np.percentile(bg, [25, 50, 75], axis=0).astype(np.float64),
            available=None if policy.action_mask is None else policy.available(x),
            output=policy.output,
            observation=policy.observation.to_dict(),
            categories={f: tuple(i.categories) for f, i in policy.features.items() if i.categories} or None,
        )

    def _check_additivity(self, policy: Policy, values, base, outputs) -> None:
        """Refuse a result whose contributions do not add up to output - base value (no silent wrong answer)."""
        gap = float(np.abs(base + values.sum(axis=1) - outputs).max())
        if self.gap_of_change:
            scale, what = float(np.abs(outputs - base).max()), "the explained change"
        else:
            # float32 rounding is absolute below 1: the scale does not fall under it
            scale, what = max(float(np.abs(outputs).max()), float(np.abs(base).max()), 1.0), "the output scale"
        scale = max(scale, 1e-6)
        if not gap <= self.tolerance * scale:  # NaN is refused too
            raise UnsupportedModelError(
                f"{self.name} contributions do not add up to the output (gap {gap:.3g}, {what} {scale:.3g}, "
                f"tolerance {self.tolerance:g} of it): {self.gap_reason}; otherwise {alternatives(policy, self.name)}"
            )

    def check_cost(self, policy: Policy, n_states: int, n_background: int) -> None:
        """Refuse, with an :class:`InputError`, work this method cannot do or should not start; nothing has run yet.
        The default accepts everything."""

    def _attribute(self, policy: Policy, x: np.ndarray, bg: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict]:
        """The subclass's method: contributions of ``x`` (n, f) against ``bg`` (m, f), module already in eval mode.

        :returns: values (n, f, a), base values (n, a) or (a,), and a dict of diagnostics (kept as
            ``Explanation.extras``). Register torch hooks with :meth:`_add_hook` so they are always removed.
        """
        raise NotImplementedError

    def _add_hook(self, handle) -> None:
        """Keep a torch hook handle so :meth:`explain` removes it whatever happens."""
        self._handles.append(handle)

    @staticmethod
    def _forward(policy: Policy, rows: torch.Tensor, chunk: int) -> torch.Tensor:
        """Scores of many rows in chunks, without gradients (float64 on the CPU)."""
        with torch.no_grad():
            parts = [policy.network(rows[i : i + chunk]).double().cpu() for i in range(0, len(rows), chunk)]
        return torch.cat(parts)


def alternatives(policy: Policy, exclude: str) -> str:
    """What to use instead of method ``exclude``: only methods that accept this network, exact first where all its
    coalitions cost no more network evaluations than kernel_shap's default samples (2^F <= 2F + 2048: up to 11
    features), where it gives the true values for less (measured 4.3x faster on a small window)."""
    f = policy.n_features
    options = [m for m in ("deep_shap", "integrated_gradients", "kernel_shap") if m != exclude]
    cheap = 2**f <= kernel_auto_samples(f)
    if f <= EXACT_MAX_FEATURES and exclude != "exact":
        options.insert(0 if cheap else len(options), "exact")
    hint = " (kernel_shap: model-agnostic but sampled; give it a small background)" if f > 64 else ""
    if cheap and exclude != "exact":
        hint = f" (exact: true Shapley values from all 2^{f} coalitions, fewer evaluations than kernel_shap's samples)"
    return f"use method={' or '.join(repr(o) for o in options)}{hint}."


def kernel_auto_samples(f: int) -> int:
    """kernel_shap's coalitions per state with ``nsamples='auto'``: 2F + 2048."""
    return 2 * f + 2048
