"""What a plugin author builds on: the hook marker, the base classes, report and option types, file helpers, the
errors a plugin raises, and the test corpus for a plugin's own templates.

``import xairl.plugin`` is light: each name is imported on first use, so a plugin module that only needs
``hookimpl`` at import time does not load torch (``xairl --help`` stays fast).

>>> from xairl.plugin import hookimpl, Attributor, Report, Options
"""

from __future__ import annotations

from xairl import lazy_attributes

#: public name -> the module that defines it
_LAZY = {
    # hooks (xairl.registry.hookspecs holds the specifications and their documentation)
    "hookimpl": "xairl.registry.hookspecs",
    "hookspec": "xairl.registry.hookspecs",
    # base classes of what a plugin registers
    "Attributor": "xairl.attributors",
    "Narrator": "xairl.narrators",
    "Report": "xairl.outputs.report",
    "ReportRequest": "xairl.outputs.report",
    "ReportContent": "xairl.outputs.report",
    "table_html": "xairl.outputs.report",
    "StateRecord": "xairl.explanations.explanation_io",
    # options: a plugin's own settings, validated like the built-ins'
    "Options": "xairl.options",
    "parse_options": "xairl.options",
    # files written whole or not at all (a crash never leaves a partial file under its final name)
    "atomic_write": "xairl.runs.files",
    "save_figure": "xairl.runs.files",
    # a progress bar that is quiet in a notebook without ipywidgets
    "progress": "xairl.explanations.display",
    # a long step said on stderr as it starts, every 10 s while it runs, and when it ends (logs and pipes too)
    "heartbeat": "xairl.explanations.display",
    # registries and checks
    "get_attributor": "xairl.registry.plugins",
    "check_template": "xairl.narrators",
    "corpus": "xairl.testing",
    # errors a plugin raises (xairl.XairlError and xairl.InputError are the user-facing ones)
    "UnknownNameError": "xairl.errors",
    "PluginError": "xairl.errors",
    "UnsupportedModelError": "xairl.errors",
    "CheckpointError": "xairl.errors",
    "validation_message": "xairl.errors",
}

__all__ = sorted(_LAZY)
__getattr__, __dir__ = lazy_attributes(__name__, _LAZY)
