"""Outputs of several kinds in one network (a parametrised action space: discrete actions' logits and their
continuous parameters): refused as one policy, whose chosen action would be taken among parameters' values ("chose
kick_power"), and split into one policy per kind by :meth:`xairl.Policy.heads`."""

from __future__ import annotations

import re
from collections.abc import Sequence

import torch

from xairl.errors import InputError


def heads(cls, module: torch.nn.Module, output: Sequence[str], action_names: Sequence[str] | None, **kwargs) -> dict:
    """:meth:`xairl.Policy.heads`: one ``cls`` policy per kind of output, each on its own columns of the module."""
    kinds = [str(k) for k in output]
    names = [f"action_{i}" for i in range(len(kinds))] if action_names is None else [str(a) for a in action_names]
    if len(names) != len(kinds):
        raise InputError(f"output gives {len(kinds)} kinds but action_names {len(names)} names; one per column.")
    out = {}
    for kind in dict.fromkeys(kinds):
        cols = [i for i, k in enumerate(kinds) if k == kind]
        out[kind] = cls(_Head(module, cols, len(kinds)), action_names=[names[i] for i in cols], output=kind, **kwargs)
    return out


#: the last word of an output's name that makes it a parameter of the action it starts with ('kick_power' of 'kick')
PARAMETER_WORDS = {
    "power",
    "angle",
    "strength",
    "force",
    "magnitude",
    "amount",
    "duration",
    "param",
    "parameter",
    "arg",
}


def check_kinds(policy, kinds: tuple[str, ...] | None, declared: bool = True) -> None:
    """Refuse outputs of mixed kinds, declared (``output=[...]``) or, where no output kind is declared, named so
    (``kick_power`` beside ``kick``): the chosen action would be taken among parameters' values ("chose
    kick_power"). A declared ``output`` (also the one ``dataclasses.replace`` passes on) is taken at its word."""
    names = policy.action_names
    if kinds is not None and len(kinds) != len(names):
        raise InputError(
            f"policy '{policy.name}': output gives {len(kinds)} kinds for {len(names)} outputs; give "
            "one kind per output column."
        )
    if not declared:
        for a in names:
            head, _, word = re.sub(r"[-. ]", "_", a).rpartition("_")
            if word.lower() in PARAMETER_WORDS and head in names:
                raise InputError(
                    f"policy '{policy.name}': output '{a}' reads as a parameter of action '{head}', "
                    "whose value would be ranked against the actions' scores; declare each output's "
                    "kind, e.g. output=['actions', ..., 'continuous', ...], and explain each kind with "
                    "xairl.Policy.heads(module, output=[...]); if all are discrete actions, say so: "
                    "output='actions'."
                )
    if kinds is not None and len(set(kinds)) > 1:
        by_kind = "; ".join(
            f"{k}: {', '.join(a for a, q in zip(names, kinds) if q == k)[:80]}" for k in dict.fromkeys(kinds)
        )
        raise InputError(
            f"policy '{policy.name}': its outputs are of mixed kinds ({by_kind}); a parameter's value is "
            "never ranked against the actions' scores: explain each kind on its own, "
            "xairl.Policy.heads(module, output=[...], action_names=[...], ...) gives one policy per kind."
        )


class _Head(torch.nn.Module):
    """The columns of one kind of a module's outputs (:meth:`Policy.heads`): a selection, linear, so every
    attribution method sees through it."""

    def __init__(self, module: torch.nn.Module, columns: Sequence[int], width: int):
        super().__init__()
        self.module, self.columns, self.width = module, list(columns), width

    def forward(self, *inputs):
        out = self.module(*inputs)
        if isinstance(out, torch.Tensor) and out.dim() == 2 and out.shape[1] != self.width:
            raise InputError(
                f"the module returned {out.shape[1]} outputs but output= gives {self.width} kinds; "
                "give one kind per output column."
            )
        return out[:, self.columns] if isinstance(out, torch.Tensor) and out.dim() == 2 else out
