"""xairl: explain what a reinforcement-learning policy decided and why.

Names are imported lazily, so ``import xairl`` (and ``xairl --help``) does not load torch, shap or transformers.
"""
from __future__ import annotations

import importlib

from .hookspecs import hookimpl, hookspec

_LAZY = {
    "explain": "xairl.attributors",
    "Attributor": "xairl.attributors",
    "Explanation": "xairl.explanation",
    "Policy": "xairl.policy",
    "TorchPolicy": "xairl.policy",
    "from_sb3": "xairl.policy",
    "FeatureInfo": "xairl.policy",
    "narrate": "xairl.narrators",
    "verify": "xairl.narrators",
    "Narrative": "xairl.narrators",
    "Verification": "xairl.narrators",
    "get_policy": "xairl.plugins",
    "get_attributor": "xairl.plugins",
    "XairlError": "xairl.errors",
    "InputError": "xairl.errors",
    "UnknownNameError": "xairl.errors",
    "PluginError": "xairl.errors",
    "UnsupportedModelError": "xairl.errors",
    "CheckpointError": "xairl.errors",
}

__all__ = sorted([*_LAZY, "hookimpl", "hookspec"])
__version__ = "0.1.0"


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'xairl' has no attribute '{name}'")


def __dir__():
    return __all__
