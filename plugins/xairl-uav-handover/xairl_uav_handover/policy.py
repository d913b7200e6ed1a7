"""The DQN's network, its safetensors checkpoint, and the xairl Policy registered as ``uav-dqn``.

Checkpoints hold tensors only (safetensors) plus JSON metadata (architecture, training config, seed); nothing is
unpickled. Inputs are standardised by a frozen diagonal Linear layer inside the network, so attributions are in
the features' own units.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import torch

from xairl.errors import CheckpointError
from xairl.policy import Policy

from .config import SimConfig
from .features import ACTION_ALIASES, ACTIONS, FEATURE_INFO, FEATURES, GROUPS, handover_facts
from .simulator import Simulator

DEFAULT_CHECKPOINT = Path(__file__).parent / "checkpoints" / "uav-dqn.safetensors"


def build_qnet(mean: np.ndarray, std: np.ndarray, hidden=(64, 64)) -> torch.nn.Sequential:
    """norm (frozen) -> [Linear, ReLU] * len(hidden) -> Linear to one Q-value per action."""
    f = len(FEATURES)
    norm = torch.nn.Linear(f, f)
    with torch.no_grad():
        norm.weight.copy_(torch.diag(torch.as_tensor(1.0 / std, dtype=torch.float32)))
        norm.bias.copy_(torch.as_tensor(-mean / std, dtype=torch.float32))
    norm.requires_grad_(False)
    layers: list[torch.nn.Module] = [norm]
    width = f
    for h in hidden:
        layers += [torch.nn.Linear(width, h), torch.nn.ReLU()]
        width = h
    layers.append(torch.nn.Linear(width, len(ACTIONS)))
    return torch.nn.Sequential(*layers)


def save_checkpoint(net: torch.nn.Module, path: str | Path, meta: dict) -> None:
    from safetensors.torch import save_file

    save_file({k: v.detach().cpu().contiguous() for k, v in net.state_dict().items()}, str(path),
              metadata={"xairl": json.dumps(meta)})


def load_checkpoint(path: str | Path) -> tuple[torch.nn.Sequential, dict]:
    """Network and metadata from a safetensors file; any mismatch is a :class:`CheckpointError`."""
    from safetensors import SafetensorError
    from safetensors.torch import load_file, safe_open

    path = Path(path)
    if not path.is_file():
        raise CheckpointError(f"{path}: no such checkpoint; train one with `xairl uav train --out {path}`.")
    try:
        with safe_open(str(path), framework="pt") as fh:
            meta = json.loads((fh.metadata() or {}).get("xairl", "{}"))
        tensors = load_file(str(path))
    except (SafetensorError, OSError, ValueError) as exc:
        raise CheckpointError(f"{path}: not a readable safetensors checkpoint ({exc}); re-train or re-download it.")
    hidden = tuple(meta.get("hidden", (64, 64)))
    f = len(FEATURES)
    net = build_qnet(np.zeros(f), np.ones(f), hidden)
    try:
        net.load_state_dict(tensors, strict=True)
    except RuntimeError as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise CheckpointError(f"{path}: does not match the UAV DQN architecture (hidden={hidden}): {first}")
    return net.eval(), meta


def background_states(n: int, seed: int = 0, config: SimConfig | None = None) -> np.ndarray:
    """``n`` states the policy meets in flight: ``n`` simulated UAVs after 10 s under conventional handover."""
    from .baselines import CHM

    sim = Simulator(config, n_uavs=n, seed=seed)
    chm = CHM()
    chm.reset(sim)
    for _ in range(int(round(10.0 / sim.dt))):
        sim.step(chm(sim))
    return sim.observe()[0]


def uav_policy(path: str | Path | None = None) -> Policy:
    """The trained handover DQN as an xairl Policy (the plugin's ``uav-dqn``)."""
    net, meta = load_checkpoint(path or DEFAULT_CHECKPOINT)
    config = SimConfig.model_validate(meta["sim_config"]) if "sim_config" in meta else SimConfig()
    return Policy(net, FEATURES, ACTIONS, features=FEATURE_INFO, groups=GROUPS,
                  background_sampler=lambda n, seed: background_states(n, seed, config), name="uav-dqn",
                  action_aliases=ACTION_ALIASES, facts_hook=handover_facts)


class DQNController:
    """Acts greedily with a Q-network every ``decision_every`` steps and stays in between."""

    name = "DQN"

    def __init__(self, net: torch.nn.Module):
        self.net = net.eval()

    def reset(self, sim: Simulator) -> None:
        self.every = sim.cfg.decision_every

    def __call__(self, sim: Simulator) -> np.ndarray:
        if sim.t % self.every:
            return sim.serving
        obs, cand = sim.observe()
        with torch.no_grad():
            act = self.net(torch.as_tensor(obs)).argmax(dim=1).numpy()
        return cand[np.arange(sim.K), act]
