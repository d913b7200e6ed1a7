"""The shared base of every attributor: checks, eval mode, hook clean-up, one Explanation out.

Subclasses implement :meth:`Attributor._attribute` only (the public/private split of SB3's predict/_predict).
"""
from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
import torch
from pydantic import BaseModel, ConfigDict, ValidationError

from ..errors import InputError
from ..explanation import Explanation
from ..policy import Policy


class Options(BaseModel):
    """Base of every attributor's options: unknown keys are an error."""

    model_config = ConfigDict(extra="forbid")


def validation_message(exc: ValidationError, what: str) -> str:
    """One line naming each bad field, from a pydantic error."""
    parts = []
    for err in exc.errors():
        loc = ".".join(str(p) for p in err["loc"]) or "value"
        msg = "unknown option" if err["type"] == "extra_forbidden" else err["msg"]
        parts.append(f"{loc}: {msg}")
    return f"invalid {what} ({'; '.join(parts)})."


class Attributor:
    """Turns (policy, states, background) into an :class:`Explanation` for all actions at once.

    :param options: a dict or an instance of the subclass's ``Options`` model.
    """

    name: ClassVar[str] = ""
    Options: ClassVar[type[Options]] = Options
    #: the Shapley efficiency property holds, so the additivity gap must be ~0
    exact_additivity: ClassVar[bool] = True

    def __init__(self, options: dict | Options | None = None):
        if isinstance(options, self.Options):
            self.options = options
        else:
            try:
                self.options = self.Options.model_validate(dict(options or {}))
            except ValidationError as exc:
                known = ", ".join(self.Options.model_fields) or "none"
                raise InputError(f"{validation_message(exc, self.name + ' options')[:-1]}; options: {known}.") from None
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
        )

    def _attribute(self, policy: Policy, x: np.ndarray, bg: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict]:
        """Return values (n, f, a), base values (n, a) or (a,), and a dict of diagnostics."""
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
