"""xairl: explain what a reinforcement-learning policy decided and why.

Names are imported lazily, so ``import xairl`` (and ``xairl --help``) does not load torch, shap or transformers.
"""
from __future__ import annotations

import importlib

from .hookspecs import hookimpl, hookspec

#: public name -> module. This is the whole surface a plugin author needs; everything else is internal.
_LAZY = {
    # policies and results
    "Policy": "xairl.policy",
    "TorchPolicy": "xairl.policy",
    "from_sb3": "xairl.sb3",
    "Observation": "xairl.observation",
    "patches": "xairl.observation",
    "in_regions": "xairl.regions",
    "FeatureInfo": "xairl.policy",
    "Explanation": "xairl.explanation",
    "StateRecord": "xairl.explanation",
    # attribution
    "explain": "xairl.attributors",
    "Attributor": "xairl.attributors",
    # streaming: any number of states, chunk by chunk, to a resumable Parquet dataset
    "explain_chunks": "xairl.stream",
    "explain_to_parquet": "xairl.stream",
    "read_parquet": "xairl.stream",
    # options (attributors, narrators, reports and plugins' own settings)
    "Options": "xairl.options",
    "parse_options": "xairl.options",
    # narration: facts (the template variables), narrators, verification
    "narrate": "xairl.narrators",
    "verify": "xairl.narrators",
    "Narrative": "xairl.narrators",
    "Narrator": "xairl.narrators",
    "Verification": "xairl.narrators",
    "DecisionFacts": "xairl.narrators.facts",
    "GlobalFacts": "xairl.narrators.facts",
    "FeatureFact": "xairl.narrators.facts",
    "Comparison": "xairl.narrators.facts",
    "DomainFacts": "xairl.narrators.facts",
    "decision_facts": "xairl.narrators.facts",
    "narration_units": "xairl.narrators.facts:units",  # each group narrated as one reason, then the other features
    "format_number": "xairl.prompts:fmt",  # how every narrated number is written
    "check_template": "xairl.narrators",  # a template file's problems, one line each (`xairl prompts check`)
    "value_level": "xairl.narrators.facts:level",  # 'low' / 'moderate' / 'high' of a value, and its words
    # reports
    "Report": "xairl.report",
    "ReportRequest": "xairl.report",
    "ReportContent": "xairl.report",
    "table_html": "xairl.report",
    # files written whole or not at all (a crash never leaves a partial file under its final name)
    "atomic_write": "xairl.files",
    "save_figure": "xairl.files",
    # registries
    "get_policy": "xairl.plugins",
    "get_attributor": "xairl.plugins",
    # errors a user can cause, and the one-line message of a pydantic validation error
    "XairlError": "xairl.errors",
    "InputError": "xairl.errors",
    "UnknownNameError": "xairl.errors",
    "PluginError": "xairl.errors",
    "UnsupportedModelError": "xairl.errors",
    "CheckpointError": "xairl.errors",
    "validation_message": "xairl.errors",
}

__all__ = sorted([*_LAZY, "hookimpl", "hookspec"])
__version__ = "0.1.0"


def __getattr__(name: str):
    if name in _LAZY:
        module, _, attr = _LAZY[name].partition(":")  # 'module' or 'module:attr' (a public name of its own)
        value = getattr(importlib.import_module(module), attr or name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'xairl' has no attribute '{name}'")


def __dir__():
    return __all__
