"""The module as every attributor sees it: flat rows (n, F) in, outputs (n, n_outputs) out, through the
observation's unflatten, with errors of the user's module said in one line."""

from __future__ import annotations

import contextlib
import sys
import warnings
import weakref
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import torch

from xairl.errors import InputError, XairlError
from xairl.policies.observation import Observation


class PolicyNetwork(torch.nn.Module):
    """The module as every attributor sees it: flat rows (n, F) -> outputs (n, n_outputs).

    It unflattens the rows into what the module takes (a view and a split: linear, so attributions see through
    it), calls the module, reads a (n,) output as one column, and turns an exception raised inside the user's
    module into one line that names the module and the input's shape.
    """

    def __init__(self, module: torch.nn.Module, observation: Observation, policy_name: str):
        super().__init__()
        self.module = module
        self.observation = observation
        self.policy_name = policy_name

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        inp = self.observation.unflatten(x)
        try:
            out = self.module(*inp) if isinstance(inp, tuple) else self.module(inp)
        except XairlError:
            raise
        except Exception as exc:  # the user's code: say where, in one line, without its traceback
            detail = " ".join(str(exc).split())[:300]
            own = module_dtype(self.module)
            if own is not None and own != x.dtype:  # e.g. a float16 network: the dtype, not the shape, is wrong
                own, given = (str(t).removeprefix("torch.") for t in (own, x.dtype))
                raise InputError(
                    f"policy '{self.policy_name}': its module {type(self.module).__name__} computes in "
                    f"{own} and failed on {given} states ({type(exc).__name__}: {detail[:160]}); xairl "
                    "explains float32 and float64 networks: convert it with module.float() or "
                    "module.double()."
                ) from None
            shape = (
                tuple(x.shape[:1]) + tuple(inp.shape[1:])
                if isinstance(inp, torch.Tensor)
                else f"{self.observation.describe().replace('(n', f'({len(x)}')}"
            )
            raise InputError(
                f"policy '{self.policy_name}': its module {type(self.module).__name__} raised "
                f"{type(exc).__name__} ({detail}) on input {shape}; check that it takes "
                f"{self.observation.describe()}."
            ) from None
        if not isinstance(out, torch.Tensor):
            raise InputError(
                f"policy '{self.policy_name}': its module {type(self.module).__name__} returned a "
                f"{type(out).__name__}, not a tensor; wrap it so that it returns one (batch, n_outputs) "
                "tensor (e.g. the logits or Q-values only)."
            )
        if out.dim() == 1 and len(out) == len(x):
            out = out[:, None]
        if out.dim() != 2 or len(out) != len(x):
            raise InputError(
                f"policy '{self.policy_name}': the module returned shape {tuple(out.shape)} for "
                f"{len(x)} states; it must return (batch, n_outputs)."
            )
        return out


def module_dtype(module: torch.nn.Module) -> torch.dtype | None:
    """The dtype of the module's first floating-point parameter or buffer; None when it has none."""
    for t in (*module.parameters(), *module.buffers()):
        if t.is_floating_point():
            return t.dtype
    return None


#: layers that compute differently in training mode: dropout drops units, a norm layer with running statistics
#: normalises by the batch's own (and updates its running ones)
_DROPOUT, _NORM = torch.nn.modules.dropout._DropoutNd, torch.nn.modules.batchnorm._NormBase
#: policies already told that their layers in training mode are explained in eval mode (told once each)
_TOLD: weakref.WeakSet = weakref.WeakSet()


def training_layers(module: torch.nn.Module) -> list[str]:
    """Names (``name (type)``) of the layers of ``module`` left in training mode whose output eval mode changes."""
    return [
        f"{name or '(the module)'} ({type(m).__name__})"
        for name, m in module.named_modules()
        if m.training and (isinstance(m, _DROPOUT) or (isinstance(m, _NORM) and m.track_running_stats))
    ]


def _outside() -> int:
    """The ``stacklevel`` of the first caller outside xairl (and contextlib, and a dataclass's generated
    ``__init__``), counted from the function that calls this one: a warning then points at the user's line."""
    level, frame = 1, sys._getframe(1)
    while frame is not None and (
        frame.f_code.co_filename.startswith(_PACKAGE) or frame.f_code.co_filename in (contextlib.__file__, "<string>")
    ):
        level, frame = level + 1, frame.f_back
    return level


_PACKAGE = str(Path(__file__).resolve().parents[1])  # xairl/: a frame inside it is not the user's


@contextmanager
def eval_mode(module: torch.nn.Module, policy=None) -> Iterator[None]:
    """Run ``module`` in eval mode, each layer's own training flag put back after (even on an error). Layers left
    in training mode that eval mode changes (BatchNorm, Dropout) are named in a warning, once per ``policy``: a
    policy acts in eval mode when deployed, and that is the function explained."""
    layers = training_layers(module)
    if layers and policy is not None and policy not in _TOLD:
        _TOLD.add(policy)
        shown = ", ".join(layers[:4]) + (f" and {len(layers) - 4} more" if len(layers) > 4 else "")
        warnings.warn(
            f"policy '{getattr(policy, 'name', '?')}': {'layer' if len(layers) == 1 else 'layers'} {shown} "
            f"{'is' if len(layers) == 1 else 'are'} in training mode; xairl explains the network in eval mode "
            "(running statistics, no dropout), as it acts when deployed: call module.eval() first to say that is "
            "meant, and this warning goes",
            UserWarning,
            stacklevel=_outside(),
        )
    flags = [(m, m.training) for m in module.modules()]
    module.eval()
    try:
        yield
    finally:
        for m, flag in flags:
            m.training = flag


#: a network with fewer parameters runs attributions on one torch thread: its forward passes are many small matrix
#: products (a GRU's steps, an MLP's 64-unit layers), which a second thread slows down more than it splits them.
#: Measured on 2 cores (issue 64): the memory doc's GRU (3.6 k parameters) took 37 s a state with torch's 2 threads
#: and 7.4 s with one; a 64-unit MLP's 8,192-row forward 76 ms and 7 ms. Larger networks keep torch's own choice.
SMALL_NETWORK = 100_000


@contextmanager
def torch_threads(policy) -> Iterator[int]:
    """Run an attribution of ``policy`` on the torch threads that suit its network: one for a small network on the
    CPU (fewer than :data:`SMALL_NETWORK` parameters), torch's own count otherwise; the count is put back after."""
    before = torch.get_num_threads()
    small = sum(p.numel() for p in policy.module.parameters()) < SMALL_NETWORK
    threads = 1 if small and policy.device.type == "cpu" else before
    if threads != before:
        torch.set_num_threads(threads)
    try:
        yield threads
    finally:
        if threads != before:
            torch.set_num_threads(before)
