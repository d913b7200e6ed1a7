"""The DQN's network, its safetensors checkpoint, and the xairl Policy registered as ``uav-dqn``.

Checkpoints hold tensors only (safetensors) plus JSON metadata (architecture, training config, seed); nothing is
unpickled. Inputs are standardised by a frozen diagonal Linear layer inside the network, so attributions are in
the features' own units.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

import xairl
from xairl import Policy

from .acting import DQNController as DQNController  # (callers import the controller from here too)
from .acting import greedy, memory_of, random_available
from .baselines import CHM, CHMConfig
from .config import SimConfig
from .env import HandoverVecEnv
from .features import (
    ACTION_ALIASES,
    ACTIONS,
    FEATURES,
    GROUPS,
    SIGNALS,
    HandoverFacts,
    RsrqFeasible,
    available_actions,
    feature_info,
)
from .features import (
    MEMORY_STEPS as STEPS,
)
from .memory import Memory, memory_policy

DEFAULT_CHECKPOINT = Path(__file__).parent / "checkpoints" / "uav-dqn.safetensors"


#: settings issue 53 retired (the uplink spread, the random walk's turns, the fixed resource blocks, the constant
#: antenna gain and its per-flight spread, the fitted fading): a checkpoint
#: trained before it still loads, its simulator read without them
RETIRED = {
    "channel": ("fading_db",),
    "radio": ("ul_activity", "ul_interference_spread_db", "bs_antenna_gain_db", "gain_spread_db"),
    "flight": ("turn_every_s",),
    "buffer": ("rb_per_uav",),
}


def without_retired(data: dict) -> dict:
    """``data`` (a SimConfig as a dict) without the :data:`RETIRED` settings."""
    return {
        k: ({f: x for f, x in v.items() if f not in RETIRED.get(k, ())} if isinstance(v, dict) else v)
        for k, v in data.items()
    }


def build_qnet(mean: np.ndarray, std: np.ndarray, hidden=(64, 64)) -> torch.nn.Sequential:
    """norm (frozen) -> [Linear, ReLU] * len(hidden) -> Linear to one Q-value per action; as many inputs as
    ``mean`` has (13 for the snapshot DQN, 75 for the DQN with memory)."""
    f = len(mean)
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
    from safetensors.torch import save

    data = save(
        {k: v.detach().cpu().contiguous() for k, v in net.state_dict().items()}, metadata={"xairl": json.dumps(meta)}
    )
    with xairl.plugin.atomic_write(path, "wb") as fh:  # a killed training run never leaves half a checkpoint
        fh.write(data)


@dataclass(frozen=True)
class Checkpoint:
    """A loaded checkpoint: the Q-network, its metadata, and the simulator settings it was trained with."""

    path: Path
    net: torch.nn.Sequential
    meta: dict
    sim_config: SimConfig


def load_checkpoint(path: str | Path | None = None) -> Checkpoint:
    """Network and metadata from a safetensors file (default: the plugin's pretrained DQN); any mismatch is a
    :class:`CheckpointError`."""
    from safetensors import SafetensorError
    from safetensors.torch import load_file, safe_open

    path = Path(path or DEFAULT_CHECKPOINT)
    if not path.is_file():
        raise xairl.plugin.CheckpointError(
            f"{path}: no such checkpoint; train one with `xairl uav train --out {path}`."
        )
    try:
        with safe_open(str(path), framework="pt") as fh:
            meta = json.loads((fh.metadata() or {}).get("xairl", "{}"))
        tensors = load_file(str(path))
    except (SafetensorError, OSError, ValueError) as exc:
        raise xairl.plugin.CheckpointError(
            f"{path}: not a readable safetensors checkpoint ({exc}); re-train or re-download it."
        ) from None
    if not isinstance(meta, dict):
        raise xairl.plugin.CheckpointError(f"{path}: its metadata is not a JSON object; re-train or re-download it.")
    for name, tensor in tensors.items():
        if tensor.is_floating_point() and not torch.isfinite(tensor).all():
            raise xairl.plugin.CheckpointError(
                f"{path}: tensor '{name}' holds NaN or inf (a corrupt file, or training that "
                "diverged); re-train or re-download it."
            )
    hidden = _hidden_widths(path, meta, tensors)
    f = STEPS * len(SIGNALS) if memory_of(meta) else len(FEATURES)
    net = build_qnet(np.zeros(f), np.ones(f), hidden)
    try:
        net.load_state_dict(tensors, strict=True)
    except RuntimeError as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise xairl.plugin.CheckpointError(
            f"{path}: does not match the UAV DQN architecture (hidden={hidden}): {first}"
        ) from None
    try:
        config = SimConfig.model_validate(without_retired(meta.get("sim_config", {})))
    except ValueError as exc:
        raise xairl.plugin.CheckpointError(
            f"{path}: its simulator settings are invalid ({str(exc).splitlines()[0]})."
        ) from None
    return Checkpoint(path, net.eval(), meta, config)


def _hidden_widths(path: Path, meta: dict, tensors: dict) -> tuple[int, ...]:
    """The hidden widths the metadata states, checked against the tensors before anything is built (a 200-byte
    file could otherwise ask for a network of 40 GB)."""
    stated = meta.get("hidden", [64, 64])
    # the weights of Linear layers 1, 3, 5, ... (layer 0 is the frozen normalisation), as build_qnet numbers them
    try:
        weights = sorted((k for k in tensors if k.endswith(".weight")), key=lambda k: int(k.split(".")[0]))
        widths = tuple(int(tensors[k].shape[0]) for k in weights[1:-1])
    except (ValueError, IndexError):
        raise xairl.plugin.CheckpointError(
            f"{path}: its tensors are not those of the UAV DQN ({', '.join(list(tensors)[:4])}); "
            "re-train or re-download it."
        ) from None
    if not (isinstance(stated, list) and all(isinstance(h, int) for h in stated) and tuple(stated) == widths):
        raise xairl.plugin.CheckpointError(
            f"{path}: its metadata says hidden={str(stated)[:60]} but its tensors have hidden "
            f"widths {list(widths)}; re-train or re-download it."
        )
    return widths


_BACKGROUND: dict[tuple, np.ndarray] = {}  # (n, seed, settings) -> the states: simulating them takes seconds


def background_states(n: int, seed: int = 0, config: SimConfig | None = None) -> np.ndarray:
    """``n`` states the policy meets in flight: ``n`` simulated UAVs after 10 s under conventional handover (the
    same for the same ``n``, seed and settings: kept in the process, a fresh copy each call)."""
    key = (n, seed, (config or SimConfig()).model_dump_json())
    if key not in _BACKGROUND:
        env = HandoverVecEnv(config, n_flights=n, decision_every=1)
        obs, _ = env.reset(seed=seed)
        chm = CHM()
        chm.reset(env)
        for _ in range(int(round(10.0 / env.sim.dt))):
            obs = env.step(chm(env))[0]
        if len(_BACKGROUND) >= 16:  # (bounded: the oldest goes)
            _BACKGROUND.pop(next(iter(_BACKGROUND)))
        _BACKGROUND[key] = obs
    return _BACKGROUND[key].copy()


def uav_policy(checkpoint: Checkpoint | str | Path | None = None) -> Policy:
    """The trained handover DQN as an xairl Policy (the plugin's ``uav-dqn``)."""
    ckpt = checkpoint if isinstance(checkpoint, Checkpoint) else load_checkpoint(checkpoint)
    if memory_of(ckpt.meta):
        return memory_policy(ckpt)
    config = ckpt.sim_config
    facts = HandoverFacts(config.buffer.q_max_bits, CHMConfig().offset_db, config.observation.detection_rsrq_db)
    return Policy(
        ckpt.net,
        FEATURES,
        ACTIONS,
        features=feature_info(config.buffer.q_max_bits),
        groups=GROUPS,
        background_sampler=lambda n, seed: background_states(n, seed, config),
        name="uav-dqn",
        action_aliases=ACTION_ALIASES,
        facts_hook=facts,
        action_mask=lambda x: available_actions(x, config.observation),
        feasible=RsrqFeasible(config.radio.ue_noise_figure_db, config.observation.detection_rsrq_db),
    )


def dqn_decision_states(
    ckpt: Checkpoint, n: int, seed: int = 0, epsilon: float = 0.0, n_flights: int = 64
) -> np.ndarray:
    """``n`` states at which the DQN decided, sampled from ``n_flights`` held-out flights it flew itself; with
    ``epsilon``, that share of its decisions is random (0.5: the mix of exploration and greedy steps that training
    sees). Flights draw their height uniformly, so a few hundred cover the altitude range to its percentiles."""
    env = HandoverVecEnv(ckpt.sim_config, n_flights=n_flights)
    obs, _ = env.reset(seed=2_000_000 + seed)
    if memory_of(ckpt.meta):  # the DQN with memory decides on its window
        memory = Memory()
        obs = memory.start(env)
    rng = np.random.default_rng(seed)
    seen, truncated = [], np.zeros(n_flights, bool)
    while not truncated.all():
        seen.append(obs)
        act = greedy(ckpt.net, obs, ckpt.sim_config)
        act = np.where(rng.uniform(size=n_flights) < epsilon, random_available(rng, obs, ckpt.sim_config), act)
        obs, _, _, truncated, info = env.step(act)
        obs = memory.step(env, info["handover"]) if memory_of(ckpt.meta) else obs
    states = np.concatenate(seen)
    return states[np.random.default_rng(seed).choice(len(states), size=min(n, len(states)), replace=False)]
