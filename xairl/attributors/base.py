"""The shared base of every attributor: checks, eval mode, hook clean-up, one Explanation out.

Subclasses implement :meth:`Attributor._attribute` only (the public/private split of SB3's predict/_predict).
"""
from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
import torch

from ..errors import InputError
from ..explanation import Explanation
from ..options import Options, parse_options
from ..policy import Policy


class Attributor:
    """Turns (policy, states, background) into an :class:`Explanation` for all actions at once.

    :param options: a dict or an instance of the subclass's ``Options`` model.
    """

    name: ClassVar[str] = ""
    Options: ClassVar[type[Options]] = Options

    def __init__(self, options: dict | Options | None = None):
        self.options = parse_options(self.Options, options, f"{self.name} options")
        self._handles: list[Any] = []

    def explain(self, policy: Policy, states, background=None) -> Explanation:
        """Explain ``states`` against ``background`` (default: 100 states from the policy's sampler).

        The module runs in eval mode; its training flag and every hook this attributor added are restored
        even when attribution fails.
        """
        if not isinstance(policy, Policy):
            raise InputError(f"expected an xairl.Policy, got {type(policy).__name__}; wrap a network with "
                             "xairl.TorchPolicy(module, feature_names, action_names).")
        x = policy.check_states(states)
        bg = policy.background() if background is None else policy.check_states(background, "background")
        outputs = policy.scores(x)
        module = policy.module
        was_training = module.training
        module.eval()
        try:
            values, base, extras = self._attribute(policy, x, bg)
        finally:
            for handle in self._handles:
                handle.remove()
            self._handles.clear()
            module.train(was_training)
        n, f, a = len(x), policy.n_features, policy.n_actions
        return Explanation(
            values=np.asarray(values, dtype=np.float64).reshape(n, f, a),
            base_values=np.broadcast_to(np.asarray(base, dtype=np.float64), (n, a)).copy(),
            outputs=outputs,
            states=x.astype(np.float64),
            feature_names=tuple(policy.feature_names),
            action_names=tuple(policy.action_names),
            method=self.name,
            options=self.options.model_dump(),
            extras=extras,
            background_quantiles=np.percentile(bg, [25, 50, 75], axis=0).astype(np.float64),
            available=None if policy.action_mask is None else policy.available(x),
        )

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
            parts = [policy.module(rows[i:i + chunk]).double().cpu() for i in range(0, len(rows), chunk)]
        return torch.cat(parts)
