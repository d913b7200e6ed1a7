"""The reference plugin's hooks: the pretrained DQN, its prompt folder and the ``xairl uav`` commands.

Registered by the entry point ``uav-handover`` in group ``xairl``. Targets are ``"module:attr"`` strings, so
``xairl --help`` imports nothing heavy from here.
"""

from pathlib import Path

import xairl


@xairl.plugin.hookimpl
def register_policies(register):
    register(
        "uav-dqn",
        "xairl_uav_handover.policy:uav_policy",
        "DQN handover policy for UAVs (Meer et al.), pretrained on the TR 36.777 simulator",
    )


@xairl.plugin.hookimpl
def register_prompt_dirs(register):
    register(Path(__file__).parent / "prompts")


@xairl.plugin.hookimpl
def register_commands(register):
    register("uav", "xairl_uav_handover.cli:configure", "UAV handover: train the DQN, evaluate Table I")


@xairl.plugin.hookimpl
def register_reports(register):
    register(
        "uav-handover",
        "xairl_uav_handover.report:UAVReport",
        "Table I, real-flight replay (-o real=PATH, or -o real=ukm to fetch the UKM flights), handover rate vs altitude, SHAP figures, narrated handovers",
    )
