"""A minimal third-party xairl plugin: a policy, an attribution method, a narrator, a prompt folder, a command.

Installed with pip, found through the entry point group ``xairl``. The hooks below only name their targets
(``"module:attr"`` strings) or define light functions, so ``xairl --help`` imports neither torch nor this
plugin's heavy parts. Everything it uses comes from ``import xairl`` (the public surface), nothing private.
"""

from pathlib import Path

import xairl


@xairl.plugin.hookimpl
def register_policies(register):
    register(
        "thermostat", "my_xairl_plugin.thermostat:thermostat_policy", "heat or idle, from temperature and occupancy"
    )


@xairl.plugin.hookimpl
def register_attributors(register):
    register(
        "occlusion",
        "my_xairl_plugin.occlusion:Occlusion",
        "occlusion: score drop when one feature is replaced by background values (not additive)",
    )


@xairl.plugin.hookimpl
def register_narrators(register):
    register(
        "shortest",
        "my_xairl_plugin.shortest:ShortestNarrator",
        "the shortest phrasing of each sentence, at most max_sentences sentences",
    )


@xairl.plugin.hookimpl
def register_prompt_dirs(register):
    register(Path(__file__).parent / "prompts")


@xairl.plugin.hookimpl
def register_commands(register):
    def configure(parser):
        parser.add_argument("--temperature", type=float, default=17.0)
        parser.set_defaults(run=run)

    def run(args):
        from my_xairl_plugin.thermostat import thermostat_policy

        policy = thermostat_policy()
        exp = xairl.explain(policy, [[args.temperature, 1.0]], method="exact")
        print(xairl.narrate(exp, 0, policy=policy, template="thermostat").text)
        return 0

    register("thermostat", configure, "explain the thermostat's decision at a temperature")
