"""Plugin discovery and the registries built from the hooks. Nothing loads until the first lookup."""

from __future__ import annotations

import importlib
import importlib.metadata
import os
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import pluggy

from xairl.errors import InputError, PluginError, UnknownNameError, XairlError, one_line
from xairl.registry import hookspecs

DEFAULT_PLUGINS = ("xairl.registry.builtins",)
BUILTIN_NAME = "xairl"
#: comma-separated entry-point names to load (like simonw/llm's LLM_LOAD_PLUGINS); "" loads none; unset loads all
LOAD_ENV = "XAIRL_LOAD_PLUGINS"

_pm: pluggy.PluginManager | None = None
_registries: dict[str, Registry] = {}
_failures: dict[str, str] = {}


def _selected() -> set[str] | None:
    raw = os.environ.get(LOAD_ENV)
    return None if raw is None else {n.strip() for n in raw.split(",") if n.strip()}


def _load_entry_points(pm: pluggy.PluginManager) -> None:
    """Register every selected entry point of group ``xairl``; one that fails is recorded, not raised."""
    wanted = _selected()
    seen: set[str] = set()
    for ep in importlib.metadata.entry_points(group="xairl"):
        if ep.name in seen or (wanted is not None and ep.name not in wanted):
            continue
        seen.add(ep.name)
        try:
            plugin = ep.load()
            pm.register(plugin, name=ep.name)
        except Exception as exc:  # a broken plugin must not take the other plugins and commands down
            _failures[ep.name] = f"fails to load ({type(exc).__name__}: {exc}); reinstall or fix it"
            continue
        try:
            pm.check_pending()
        except pluggy.PluginValidationError as exc:
            pm.unregister(plugin)
            _failures[ep.name] = f"implements an unknown hook ({exc}); update it for this xairl"
    for name in sorted((wanted or set()) - seen):
        _failures[name] = f"is named in ${LOAD_ENV} but not installed"


def distributions() -> list[tuple[str, str]]:
    """(distribution, version) of each installed plugin, read from its metadata without importing it."""
    found = {(ep.dist.name, ep.dist.version) for ep in importlib.metadata.entry_points(group="xairl") if ep.dist}
    return sorted(found)


def get_plugin_manager() -> pluggy.PluginManager:
    """The process-wide plugin manager: the selected entry points of group ``xairl``, then the built-ins."""
    global _pm
    if _pm is None:
        pm = pluggy.PluginManager("xairl")
        pm.add_hookspecs(hookspecs)
        _load_entry_points(pm)
        for modname in DEFAULT_PLUGINS:
            pm.register(
                importlib.import_module(modname), name=BUILTIN_NAME if modname == DEFAULT_PLUGINS[0] else modname
            )
        _pm = pm
    return _pm


def failures() -> dict[str, str]:
    """{plugin: why it was left out}: plugins that failed to load or to register, and selected ones not installed."""
    get_plugin_manager()
    return dict(_failures)


def reset(pm: pluggy.PluginManager | None = None) -> None:
    """Forget cached registries (tests); optionally install a prepared plugin manager."""
    global _pm
    _pm = pm
    _registries.clear()
    _failures.clear()


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
            raise PluginError(
                f"plugin '{self.plugin}' registered '{self.name}' as {self.target!r}, which fails to "
                f"import ({exc}); reinstall the plugin."
            ) from exc


class Registry:
    """Names registered through one hook, with the plugin that registered each; duplicates are an error."""

    def __init__(self, kind: str, hook: str, list_command: str):
        self.kind, self.hook, self.list_command = kind, hook, list_command
        self.entries: dict[str, Entry] = {}
        pm = get_plugin_manager()
        for impl in getattr(pm.hook, hook).get_hookimpls():
            self._collect(impl.plugin_name, impl.function)

    def _collect(self, plugin: str, hook_function: Callable) -> None:
        """Call one plugin's hook; keep its entries only when the whole call succeeds."""
        new: list[Entry] = []

        def register(name, target, description: str = ""):
            new.append(Entry(str(name), plugin, target, description))

        try:
            hook_function(register=register)
        except Exception as exc:  # the plugin's own bug: leave it out, keep the others working
            _failures[plugin] = f"failed in {self.hook} ({type(exc).__name__}: {exc}); fix or uninstall it"
            return
        for entry in new:
            if entry.name in self.entries:
                first = self.entries[entry.name].plugin
                raise PluginError(
                    f"{self.kind} '{entry.name}' is registered by both '{first}' and '{plugin}'; "
                    "uninstall one of them or rename it in the plugin."
                )
            self.entries[entry.name] = entry

    def names(self) -> list[str]:
        return sorted(self.entries)

    def entry(self, name: str) -> Entry:
        if name not in self.entries:
            known = ", ".join(self.names()) or "none"
            broken = f"; left out: {', '.join(sorted(_failures))} (see `xairl plugins`)" if _failures else ""
            raise UnknownNameError(
                f"unknown {self.kind} '{name}'; known: {known} (see `xairl {self.list_command}`){broken}."
            )
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
        mine: list[tuple[str, str]] = []
        try:
            impl.function(register=lambda path, p=impl.plugin_name: mine.append((p, str(path))))
        except Exception as exc:  # as in Registry._collect: the plugin is left out, the others keep working
            _failures[impl.plugin_name] = f"failed in register_prompt_dirs ({type(exc).__name__}: {exc})"
            continue
        dirs += mine
    return dirs


def get_policy(name: str):
    """Build the registered policy ``name`` (loads its checkpoint)."""
    factory = registry("policy").load(name)
    return factory() if callable(factory) else factory


def load_policy(spec: str, kwargs: dict | None = None, observation=None):
    """A policy by registered name, or without any plugin: ``package.module:attr`` or ``path/to/file.py:attr``.

    ``attr`` is an :class:`xairl.Policy`, a torch module, or a callable returning either, called with ``kwargs``
    (``xairl explain --policy-arg key=value``). A bare torch module becomes a Policy whose observation is
    ``observation`` (the shape of one state, taken from the states file by the CLI).
    """
    kwargs = dict(kwargs or {})
    if ":" not in spec:
        if kwargs:
            raise InputError(f"--policy-arg is for a module:attr policy; '{spec}' is a registered name.")
        return get_policy(spec)
    where, _, attr = spec.rpartition(":")
    module = _user_module(where)
    if not hasattr(module, attr):
        raise UnknownNameError(f"'{where}' has no attribute '{attr}'.")
    return _as_policy(spec, getattr(module, attr), attr, kwargs, observation)


def _user_module(where: str):
    """The user's module ``where``: a .py file's path or a dotted name; one line, no traceback, when it fails."""
    import importlib
    import importlib.util
    from pathlib import Path

    try:
        if where.endswith(".py"):
            path = Path(where)
            if not path.is_file():
                raise InputError(f"{where}: no such file; give --policy path/to/file.py:attr or package.module:attr.")
            mod_spec = importlib.util.spec_from_file_location(path.stem, path)
            module = importlib.util.module_from_spec(mod_spec)
            mod_spec.loader.exec_module(module)
        else:
            module = importlib.import_module(where)
    except XairlError:
        raise
    except Exception as exc:  # the user's module: one line, no traceback
        raise InputError(f"cannot import '{where}' ({one_line(exc, 200)}).") from None
    return module


def _as_policy(spec: str, obj, attr: str, kwargs: dict, observation):
    """``obj`` (a Policy, a torch module, or a callable building either with ``kwargs``) as a Policy."""
    import torch

    from xairl.policies.policy import Policy

    if callable(obj) and not isinstance(obj, (Policy, torch.nn.Module)):
        try:
            obj = obj(**kwargs)
        except XairlError:
            raise
        except Exception as exc:
            raise InputError(
                f"{spec}({', '.join(f'{k}={v!r}' for k, v in kwargs.items())}) raised {one_line(exc, 200)}."
            ) from None
    elif kwargs:
        raise InputError(f"{spec} is not callable; --policy-arg needs a function that builds the policy.")
    if isinstance(obj, torch.nn.Module):
        if observation is None:
            raise InputError(
                f"{spec} is a bare torch module: give --states so that its input shape is known, or "
                "return an xairl.Policy."
            )
        obj = Policy(obj.eval(), observation=tuple(observation), name=attr)
    if not isinstance(obj, Policy):
        raise InputError(
            f"{spec} gave a {type(obj).__name__}; it must be an xairl.Policy, a torch module, or a "
            "function returning one."
        )
    return obj


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
