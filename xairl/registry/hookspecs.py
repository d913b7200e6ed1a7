"""The hooks a plugin implements. Each receives a ``register`` callback (simonw/llm style).

A plugin is a module (or object) with functions marked ``@xairl.plugin.hookimpl`` and is found through the
``xairl`` entry-point group. Built-ins register through these same hooks. Targets may be given as
``"package.module:attribute"`` strings so that nothing heavy is imported until a name is looked up.
"""

import pluggy

hookspec = pluggy.HookspecMarker("xairl")
hookimpl = pluggy.HookimplMarker("xairl")


@hookspec
def register_policies(register):
    """Register trained policies.

    :param register: ``register(name, factory, description="")``; ``factory()`` (or the ``"module:attr"`` it names)
        returns a :class:`xairl.Policy`, loading its checkpoint through code that knows the architecture.
    """


@hookspec
def register_attributors(register):
    """Register attribution methods.

    :param register: ``register(name, cls, description="")``; ``cls`` is an :class:`xairl.plugin.Attributor` subclass
        or a ``"module:attr"`` string naming one.
    """


@hookspec
def register_narrators(register):
    """Register narrators that turn an Explanation into words.

    :param register: ``register(name, cls, description="")``; ``cls`` (or the ``"module:attr"`` naming it) is an
        :class:`xairl.plugin.Narrator` subclass with an ``Options`` model and a ``_compose`` method.
    """


@hookspec
def register_prompt_dirs(register):
    """Register folders of prompt templates.

    :param register: ``register(path)``; later folders do not override earlier ones (see xairl.templates.prompts).
    """


@hookspec
def register_commands(register):
    """Register CLI sub-commands of ``xairl``.

    :param register: ``register(name, configure, description="")``; ``configure(parser)`` adds arguments to an
        ``argparse`` sub-parser and sets ``parser.set_defaults(run=fn)`` where ``fn(args) -> int`` does the work.
        Keep the plugin module light: ``xairl --help`` imports it, so import torch inside ``fn``.
    """


@hookspec
def register_reports(register):
    """Register reports for ``xairl report --plugin NAME --out DIR``.

    :param register: ``register(name, cls, description="")``; ``cls`` (or the ``"module:attr"`` naming it) is an
        :class:`xairl.plugin.Report` subclass: its ``Options`` model declares the report's own settings
        (``-o key=value``) and ``build(request)`` returns an :class:`xairl.plugin.ReportContent`.
    """
