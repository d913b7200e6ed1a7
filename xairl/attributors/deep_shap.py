"""DeepSHAP: DeepLIFT rescale-rule multipliers averaged over a background, batched over all (state, background) pairs.

Every pair is one row of a doubled batch ``[x_pairs; r_pairs]``. A forward hook on each elementwise nonlinearity
replaces its gradient with the rescale ratio Δout/Δin of its own call (so a module used twice is handled per call),
and one backward pass per action gives the multipliers. Linear layers keep their exact gradients. This gives the
values of shap.DeepExplainer and captum's DeepLiftShap.
"""
from __future__ import annotations

import numpy as np
import torch
from pydantic import Field

from ..errors import UnsupportedModelError
from .base import Attributor, Options

#: layers whose gradient already is the DeepLIFT multiplier (linear in eval mode)
LINEAR = (torch.nn.Linear, torch.nn.Identity, torch.nn.Flatten, torch.nn.Unflatten, torch.nn.Dropout,
          torch.nn.AlphaDropout, torch.nn.BatchNorm1d)
#: elementwise nonlinearities handled with the rescale rule
NONLINEAR = (torch.nn.ReLU, torch.nn.LeakyReLU, torch.nn.ELU, torch.nn.SiLU, torch.nn.GELU, torch.nn.Tanh,
             torch.nn.Sigmoid, torch.nn.Softplus, torch.nn.ReLU6, torch.nn.Hardtanh, torch.nn.SELU, torch.nn.CELU,
             torch.nn.Mish, torch.nn.Softsign, torch.nn.Tanhshrink)
CONTAINERS = (torch.nn.Sequential, torch.nn.ModuleList, torch.nn.ModuleDict)
EPS = 1e-6  # below this |Δin| the local gradient is used, as shap does


class DeepShapOptions(Options):
    max_pairs: int = Field(65_536, ge=1, description="(state, background) pairs per batch; bounds memory")
    check_additivity: bool = Field(True, description="refuse results whose contributions do not add up")


def _local_grad(layer, h):
    with torch.enable_grad():
        leaf = h.detach().requires_grad_(True)
        return torch.autograd.grad(layer.forward(leaf).sum(), leaf)[0]


def _rescale_hook(module, inputs, output):
    """Keep the output's value but give it the gradient Δout/Δin (pairs are rows i and i + P)."""
    inp = inputs[0]
    p = inp.shape[0] // 2
    d_in = inp[:p].detach() - inp[p:].detach()
    ratio = (output[:p].detach() - output[p:].detach()) / torch.where(d_in == 0, torch.ones_like(d_in), d_in)
    small = d_in.abs() < EPS
    if small.any():  # rare: there the local gradient stands in for the ratio, per half as shap does
        local = _local_grad(module, inp)
        ratio = torch.cat([torch.where(small, local[:p], ratio), torch.where(small, local[p:], ratio)])
    else:
        ratio = torch.cat([ratio, ratio])
    return output.detach() + (inp - inp.detach()) * ratio


def check_supported(module: torch.nn.Module) -> list[torch.nn.Module]:
    """The nonlinear layers of ``module``; raises for any leaf layer whose multipliers we cannot compute."""
    nonlinear = []
    for name, sub in module.named_modules():
        if isinstance(sub, NONLINEAR):
            nonlinear.append(sub)
        elif isinstance(sub, LINEAR) or isinstance(sub, CONTAINERS):
            continue
        elif not any(True for _ in sub.children()):
            raise UnsupportedModelError(
                f"deep_shap does not support layer '{name or type(sub).__name__}' ({type(sub).__name__}); "
                "use method='kernel_shap' or 'exact' for this network."
            )
    return nonlinear


def chain(module: torch.nn.Module) -> list[torch.nn.Module] | None:
    """The layers of a pure Sequential chain (nested Sequentials flattened), or None when the network is not one."""
    if not isinstance(module, torch.nn.Sequential):
        return None
    out: list[torch.nn.Module] = []
    for layer in module:
        if isinstance(layer, torch.nn.Sequential):
            inner = chain(layer)
            if inner is None:
                return None
            out += inner
        elif isinstance(layer, (torch.nn.Linear, torch.nn.BatchNorm1d, torch.nn.Identity, torch.nn.Dropout,
                                torch.nn.AlphaDropout)) or isinstance(layer, NONLINEAR):
            out.append(layer)
        else:
            return None
    return out


def chain_multipliers(layers, xs: torch.Tensor, bg: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Rescale-rule multipliers of every output w.r.t. the input for every (state, background) pair, by explicit
    back-propagation through the chain: (states * background, actions, features), plus the outputs of the states
    and of the background. The forward passes run on the states and the background once each (a pair's rows are
    broadcast from them); no autograd work on the background half, all actions in one sweep."""
    hx, hr = xs, bg
    m, b = len(xs), len(bg)
    steps = []
    with torch.no_grad():
        for layer in layers:
            if isinstance(layer, NONLINEAR):
                ox, orr = layer(hx), layer(hr)
                d = (hx[:, None, :] - hr[None, :, :]).reshape(m * b, -1)
                ratio = (ox[:, None, :] - orr[None, :, :]).reshape(m * b, -1).div_(d)
                small = d.abs_() < EPS  # rare: patch those with the local gradient
                if small.any():
                    local = _local_grad(layer, hx)[:, None, :].expand(m, b, -1).reshape(m * b, -1)
                    ratio = torch.where(small, local, ratio)
                steps.append(("scale", ratio))
                hx, hr = ox, orr
            elif isinstance(layer, torch.nn.Linear):
                steps.append(("matmul", layer.weight))
                hx, hr = layer(hx), layer(hr)
            elif isinstance(layer, torch.nn.BatchNorm1d):  # eval mode: an affine map per feature
                steps.append(("scale", (layer.weight if layer.affine else 1.0)
                              / torch.sqrt(layer.running_var + layer.eps)))
                hx, hr = layer(hx), layer(hr)
        mult = torch.eye(hx.shape[1], dtype=hx.dtype, device=hx.device)[None]  # (1, actions, width)
        for kind, t in reversed(steps):
            mult = mult @ t if kind == "matmul" else mult * (t[:, None, :] if t.dim() == 2 else t)
    return mult.expand(m * b, -1, -1), hx, hr


class DeepShap(Attributor):
    """DeepSHAP (DeepLIFT rescale rule averaged over background states), all actions in one pass."""

    name = "deep_shap"
    Options = DeepShapOptions

    def _attribute(self, policy, x, bg):
        module = policy.module
        layers = chain(module)
        if layers is not None:
            return self._attribute_chain(policy, layers, x, bg)
        for layer in check_supported(module):
            self._add_hook(layer.register_forward_hook(_rescale_hook))
        dev = policy.device
        xt = torch.as_tensor(x, device=dev)
        bt = torch.as_tensor(bg, device=dev)
        n, f = xt.shape
        b = len(bt)
        per = max(1, self.options.max_pairs // b)
        values = np.empty((n, f, policy.n_actions))
        outputs = np.empty((n, policy.n_actions))
        for s in range(0, n, per):
            xs = xt[s:s + per]
            m = len(xs)
            xp = xs[:, None, :].expand(m, b, f).reshape(m * b, f)
            rp = bt[None, :, :].expand(m, b, f).reshape(m * b, f)
            rows = torch.cat([xp, rp]).requires_grad_(True)
            out = module(rows)
            delta = (xp - rp).reshape(m, b, f)
            outputs[s:s + m] = out[: m * b : b].detach().double().cpu().numpy()
            base = out[m * b:].detach().double().mean(dim=0).cpu().numpy()
            for a in range(policy.n_actions):
                grad = torch.autograd.grad(out[: m * b, a].sum(), rows, retain_graph=a + 1 < policy.n_actions)[0]
                contrib = (grad[: m * b].reshape(m, b, f) * delta).double().mean(dim=1)
                values[s:s + m, :, a] = contrib.cpu().numpy()
        if self.options.check_additivity:
            gap = np.abs(base + values.sum(axis=1) - outputs).max()
            scale = max(1.0, float(np.abs(base).max()))
            if gap > 1e-3 * scale:
                raise UnsupportedModelError(
                    f"deep_shap values do not add up to the output (gap {gap:.3g}): the network likely uses functional "
                    "nonlinearities (torch.relu, F.softmax, ...) that deep_shap cannot see; make them nn modules or "
                    "use method='kernel_shap' or 'exact'."
                )
        return values, base, {}

    def _attribute_chain(self, policy, layers, x, bg):
        dev = policy.device
        xt, bt = torch.as_tensor(x, device=dev), torch.as_tensor(bg, device=dev)
        n, f = xt.shape
        b, a = len(bt), policy.n_actions
        widest = max([f] + [getattr(layer, "out_features", 0) for layer in layers])
        per = max(1, min(self.options.max_pairs, 2 ** 24 // (a * widest)) // b)  # bounds the multiplier tensor
        values = np.empty((n, f, a))
        outputs = np.empty((n, a))
        base = None
        for s in range(0, n, per):
            xs = xt[s:s + per]
            m = len(xs)
            mult, ox, orr = chain_multipliers(layers, xs, bt)
            delta = (xs[:, None, :] - bt[None, :, :]).reshape(m * b, 1, f)
            contrib = (mult * delta).reshape(m, b, a, f).mean(dim=1).double()
            values[s:s + m] = contrib.transpose(1, 2).cpu().numpy()
            outputs[s:s + m] = ox.double().cpu().numpy()
            base = orr.double().mean(dim=0).cpu().numpy()
        return values, base, {}
