"""How the DQN acts: its greedy choice among the available actions (refused, in one line, where its Q-values are
NaN or inf), a random available action (exploration), the controller that flies it, and which network a checkpoint
holds. Below policy.py and memory.py, which both act through it (neither imports the other's way back).
"""

from __future__ import annotations

import numpy as np
import torch

import xairl
from xairl import InputError

from .config import SimConfig
from .features import FEATURES, SIGNALS, available_actions
from .features import MEMORY_STEPS as STEPS


def memory_of(meta: dict) -> bool:
    """Whether a checkpoint's network is the DQN with memory (memory.py): its training config says so."""
    tc = meta.get("train_config")
    return bool(tc.get("memory")) if isinstance(tc, dict) else False


def greedy(net: torch.nn.Module, obs: np.ndarray, config: SimConfig) -> np.ndarray:
    """The best available action per state: a handover only to a measured candidate (invalid-action masking)."""
    x = torch.as_tensor(np.asarray(obs), dtype=torch.float32)
    with torch.no_grad():
        q = net(x).numpy()
    bad = ~np.isfinite(q).all(axis=1)
    if bad.any():  # argmax would read a NaN row as action 0 ("stay") and the decision would look sane
        _refuse_q(net, x.numpy(), int(np.flatnonzero(bad)[0]))
    return np.where(available_actions(obs, config.observation), q, -np.inf).argmax(axis=1)


def _refuse_q(net: torch.nn.Module, x: np.ndarray, i: int) -> None:
    """Say why the Q-values of state ``i`` of ``x`` (the network's float32 input) are NaN or inf."""
    where = f"the DQN cannot act on state {i} of {len(x)}"
    if not all(torch.isfinite(p).all() for p in net.parameters()):
        raise xairl.plugin.CheckpointError(
            f"{where}: the Q-network's weights hold NaN or inf (a corrupt checkpoint, or training "
            "that diverged); re-train or re-download it."
        )
    row = x[i].reshape(-1)
    names = FEATURES if len(row) == len(FEATURES) else xairl.Observation.window(SIGNALS, STEPS).feature_names()
    bad = np.flatnonzero(~np.isfinite(row))
    if len(bad):
        j = int(bad[0])
        raise InputError(
            f"{where}: {names[j]} = {row[j]:g} is not a finite number (as float32, the network's "
            "input); fix that state."
        )
    j = int(np.abs(row).argmax())
    raise InputError(
        f"{where}: its Q-values overflow to NaN or inf (largest input {names[j]} = {row[j]:g}, far "
        "beyond any measurement); fix that state."
    )


def random_available(rng: np.random.Generator, obs: np.ndarray, config: SimConfig) -> np.ndarray:
    """A uniformly random available action per state (exploration)."""
    mask = available_actions(obs, config.observation)
    return (rng.uniform(size=mask.shape) * mask).argmax(axis=1)


class DQNController:
    """Acts greedily among available actions with a Q-network, one decision per env step (every
    ``decision_every`` simulator steps)."""

    name = "DQN"
    decision_every = None  # the simulator config's

    def __init__(self, net: torch.nn.Module):
        self.net = net.eval()

    def reset(self, env) -> None:
        pass

    def __call__(self, env) -> np.ndarray:
        return greedy(self.net, env.obs, env.cfg)
