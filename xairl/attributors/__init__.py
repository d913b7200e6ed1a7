"""Attribution methods behind one interface; :func:`explain` is the entry point."""

from __future__ import annotations

from xairl.attributors.base import Attributor, Options
from xairl.explanations.explanation import Explanation
from xairl.policies.policy import Policy


def explain(policy: Policy, states, background=None, method: str = "deep_shap", options=None) -> Explanation:
    """Explain a policy's decisions on ``states``.

    :param policy: an :class:`xairl.Policy` (see :func:`xairl.Policy`).
    :param states: array-like (n, n_features) or one state (n_features,).
    :param background: typical states the contributions are measured against; default: the policy's sampler.
    :param method: a registered attributor name (``xairl attributors`` lists them).
    :param options: dict of the method's options (validated; unknown keys are an error).
    """
    from xairl.registry.plugins import get_attributor

    return get_attributor(method)(options).explain(policy, states, background)


__all__ = ["Attributor", "Options", "explain"]
