"""Plugin discovery and the registries built from the hooks. Nothing loads until the first lookup."""
from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import Any, Callable

import pluggy

from . import hookspecs
from .errors import PluginError, UnknownNameError

DEFAULT_PLUGINS = ("xairl.builtins",)
BUILTIN_NAME = "xairl"

_pm: pluggy.PluginManager | None = None
_registries: dict[str, "Registry"] = {}


def get_plugin_manager() -> pluggy.PluginManager:
    """The process-wide plugin manager: entry points of group ``xairl``, then the built-ins."""
    global _pm
    if _pm is None:
        pm = pluggy.PluginManager("xairl")
        pm.add_hookspecs(hookspecs)
        try:
            pm.load_setuptools_entrypoints("xairl")
        except Exception as exc:  # a broken third-party plugin must not take the CLI down silently
            raise PluginError(f"a plugin failed to load ({type(exc).__name__}: {exc}); uninstall or fix it.") from exc
        for modname in DEFAULT_PLUGINS:
            pm.register(importlib.import_module(modname), name=BUILTIN_NAME if modname == DEFAULT_PLUGINS[0] else modname)
        pm.check_pending()
        _pm = pm
    return _pm


def reset(pm: pluggy.PluginManager | None = None) -> None:
    """Forget cached registries (tests); optionally install a prepared plugin manager."""
    global _pm
    _pm = pm
    _registries.clear()


def resolve(target: Any) -> Any:
    """Import a ``"module:attr"`` string; anything else is returned as is."""
    if isinstance(target, str) and ":" in target:
        mod, _, attr = target.partition(":")
        obj = importlib.import_module(mod)
        for part in attr.split("."):
            obj = getattr(obj, part)
        return obj
    return target


@dataclass
class Entry:
    """One registered thing: its name, the plugin that registered it, the target and a description."""

    name: str
    plugin: str
    target: Any
    description: str = ""

    def load(self) -> Any:
        try:
            return resolve(self.target)
        except (ImportError, AttributeError) as exc:
            raise PluginError(f"plugin '{self.plugin}' registered '{self.name}' as {self.target!r}, which fails to "
                              f"import ({exc}); reinstall the plugin.") from exc


class Registry:
    """Names registered through one hook, with the plugin that registered each; duplicates are an error."""

    def __init__(self, kind: str, hook: str, list_command: str):
        self.kind, self.hook, self.list_command = kind, hook, list_command
        self.entries: dict[str, Entry] = {}
        pm = get_plugin_manager()
        for impl in getattr(pm.hook, hook).get_hookimpls():
            impl.function(register=self._register_for(impl.plugin_name))

    def _register_for(self, plugin: str) -> Callable:
        def register(name, target, description: str = ""):
            name = str(name)
            if name in self.entries:
                first = self.entries[name].plugin
                raise PluginError(f"{self.kind} '{name}' is registered by both '{first}' and '{plugin}'; "
                                  "uninstall one of them or rename it in the plugin.")
            self.entries[name] = Entry(name, plugin, target, description)

        return register

    def names(self) -> list[str]:
        return sorted(self.entries)

    def entry(self, name: str) -> Entry:
        if name not in self.entries:
            known = ", ".join(self.names()) or "none"
            raise UnknownNameError(f"unknown {self.kind} '{name}'; known: {known} (see `xairl {self.list_command}`).")
        return self.entries[name]

    def load(self, name: str) -> Any:
        return self.entry(name).load()


_HOOKS = {
    "policy": ("register_policies", "plugins"),
    "attributor": ("register_attributors", "attributors"),
    "narrator": ("register_narrators", "plugins"),
    "command": ("register_commands", "--help"),
    "report": ("register_reports", "plugins"),
}


def registry(kind: str) -> Registry:
    """The registry of ``kind``: 'policy', 'attributor', 'narrator', 'command' or 'report'."""
    if kind not in _registries:
        hook, cmd = _HOOKS[kind]
        _registries[kind] = Registry(kind, hook, cmd)
    return _registries[kind]


def prompt_dirs() -> list[tuple[str, str]]:
    """(plugin, folder) pairs registered through ``register_prompt_dirs``, in registration order."""
    dirs: list[tuple[str, str]] = []
    for impl in get_plugin_manager().hook.register_prompt_dirs.get_hookimpls():
        impl.function(register=lambda path, p=impl.plugin_name: dirs.append((p, str(path))))
    return dirs


def get_policy(name: str):
    """Build the registered policy ``name`` (loads its checkpoint)."""
    factory = registry("policy").load(name)
    return factory() if callable(factory) else factory


def get_attributor(name: str):
    """The attributor class registered as ``name``."""
    return registry("attributor").load(name)


def summary() -> dict[str, dict[str, list[str]]]:
    """What each plugin registers: {plugin: {kind: [names]}}."""
    out: dict[str, dict[str, list[str]]] = {}
    for name, _ in get_plugin_manager().list_name_plugin():
        out.setdefault(name, {})
    for kind in ("policy", "attributor", "narrator", "command", "report"):
        for e in registry(kind).entries.values():
            out.setdefault(e.plugin, {}).setdefault(kind, []).append(e.name)
    for plugin, path in prompt_dirs():
        out.setdefault(plugin, {}).setdefault("prompt directory", []).append(path)
    return out
