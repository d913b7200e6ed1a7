"""The module as every attributor sees it: flat rows (n, F) in, outputs (n, n_outputs) out, through the
observation's unflatten, with errors of the user's module said in one line."""

from __future__ import annotations

import torch

from .errors import InputError, XairlError
from .observation import Observation


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
