"""A minimal xairl plugin. Installed with pip, found through the entry point group ``xairl``.

Everything heavy is named by ``"module:attr"`` strings or imported inside functions, so ``xairl --help`` stays fast.
"""
from pathlib import Path

import xairl


def thermostat_policy():
    """A hand-written 2-feature Q-network: heat when cold, idle when warm."""
    import torch

    net = torch.nn.Linear(2, 2)
    with torch.no_grad():
        net.weight.copy_(torch.tensor([[-1.0, 0.2], [1.0, -0.2]]))  # columns: temperature, occupancy
        net.bias.copy_(torch.tensor([20.0, -20.0]))
    return xairl.Policy(net, ["temperature", "occupancy"], ["heat", "idle"],
                        features={"temperature": xairl.FeatureInfo("degC", "the room temperature", "cold", "warm")},
                        background_sampler=lambda n, seed: __import__("numpy").random.default_rng(seed).normal(
                            [20.0, 1.0], [3.0, 1.0], size=(n, 2)),
                        name="thermostat")


@xairl.hookimpl
def register_policies(register):
    register("thermostat", "my_xairl_plugin:thermostat_policy", "heat or idle, from temperature and occupancy")


@xairl.hookimpl
def register_prompt_dirs(register):
    register(Path(__file__).parent / "prompts")


@xairl.hookimpl
def register_commands(register):
    def configure(parser):
        parser.add_argument("--temperature", type=float, default=17.0)
        parser.set_defaults(run=run)

    def run(args):
        policy = thermostat_policy()
        exp = xairl.explain(policy, [[args.temperature, 1.0]], method="exact")
        print(xairl.narrate(exp, 0, policy=policy, template="thermostat").text)
        return 0

    register("thermostat", configure, "explain the thermostat's decision at a temperature")
