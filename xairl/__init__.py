"""xairl: explain what a reinforcement-learning policy decided and why.

Names are imported lazily, so ``import xairl`` (and ``xairl --help``) does not load torch, shap or transformers.
This namespace holds what a user calls; a plugin author's building blocks are in :mod:`xairl.plugin`, the
narration facts (the template variables) in :mod:`xairl.facts`, the figures in :mod:`xairl.plots`.
"""

from __future__ import annotations

import importlib
import sys

#: public name -> module (or 'module:attr' where the module's name for it differs)
_LAZY = {
    # policies and results
    "Policy": "xairl.policies.policy",
    "FeatureInfo": "xairl.policies.policy",
    "from_sb3": "xairl.policies.sb3",
    "Observation": "xairl.policies.observation",
    "patches": "xairl.policies.region_names",
    "in_regions": "xairl.policies.regions",
    "Explanation": "xairl.explanations.explanation",
    "get_policy": "xairl.registry.plugins",
    # attribution, in memory or streamed chunk by chunk to a resumable Parquet dataset
    "explain": "xairl.attributors",
    "explain_chunks": "xairl.runs.stream",
    # counterfactuals: what would have had to differ for another decision, each checked by running the policy
    "counterfactual": "xairl.counterfactuals.search",
    "Counterfactual": "xairl.counterfactuals.result",
    "Counterfactuals": "xairl.counterfactuals.result",
    "Threshold": "xairl.counterfactuals.result",
    "explain_to_parquet": "xairl.runs.stream",
    "read_parquet": "xairl.runs.stream",
    # narration and verification
    "narrate": "xairl.narrators",
    "NarrationOptions": "xairl.narrators",
    "verify": "xairl.verification",
    "Narrative": "xairl.narrators",
    "Verification": "xairl.verification",
    # errors a user can cause (every one is an XairlError; the others are in xairl.errors)
    "XairlError": "xairl.errors",
    "InputError": "xairl.errors",
}
#: old public names -> their successors: an old script gets an error that says what to write instead
_RENAMED = {"TorchPolicy": "Policy"}
#: submodules reachable as attributes after a bare ``import xairl`` (``xairl.plots.beeswarm(exp)``)
_SUBMODULES = ("errors", "facts", "plots", "plugin")

__all__ = sorted([*_LAZY, *_SUBMODULES])
__version__ = "0.1.0"


def lazy_attributes(
    module: str, table: dict[str, str], submodules: tuple[str, ...] = (), renamed: dict[str, str] | None = None
):
    """``__getattr__`` and ``__dir__`` for ``module``, whose names in ``table`` (name -> 'module' or 'module:attr')
    and ``submodules`` are imported on first use and then kept as ordinary attributes; a name in ``renamed`` (old
    name -> new) gives its successor with a FutureWarning that names it."""
    names = sorted([*table, *submodules])

    def __getattr__(name: str):
        if name in submodules:
            value = importlib.import_module(f"{module}.{name}")
        elif name in table:
            source, _, attr = table[name].partition(":")
            value = getattr(importlib.import_module(source), attr or name)
        elif name in (renamed or {}):  # an old script runs on, told the new name (an error would be lost to
            # ``from xairl import OldName``, which Python turns into a bare ImportError)
            import warnings

            warnings.warn(
                f"{module}.{name} was renamed {module}.{renamed[name]}, which takes the same arguments; the old name "
                "will go",
                FutureWarning,
                stacklevel=2,
            )
            return __getattr__(renamed[name])
        else:
            raise AttributeError(f"module '{module}' has no attribute '{name}'")
        setattr(sys.modules[module], name, value)
        return value

    return __getattr__, lambda: names


__getattr__, __dir__ = lazy_attributes(__name__, _LAZY, _SUBMODULES, _RENAMED)
