"""DeepSHAP: DeepLIFT multipliers averaged over a background, batched over all (state, background) pairs.

Every pair is one row of a doubled batch ``[x_pairs; r_pairs]``. A forward hook on each nonlinear layer ties its
output to its input through a custom backward (:class:`_Rule`) that gives the DeepLIFT multiplier of its own call
(so a module used twice is handled per call): the rescale rule Δout/Δin for elementwise layers (and Softmax /
LogSoftmax as a final layer), the max-pool rule shap uses for MaxPool. Linear layers (Linear, Conv, ConvTranspose,
average pooling, BatchNorm in eval mode, reshapes) keep their exact gradients. One backward pass per output gives
the multipliers. This gives the values of shap.DeepExplainer and captum's DeepLiftShap. A pure Sequential MLP on
flat states takes a faster path (:func:`chain_multipliers`).
"""
from __future__ import annotations

import numpy as np
import torch
from pydantic import Field

from ..errors import UnsupportedModelError
from .base import Attributor, Options, alternatives

nn = torch.nn
#: layers whose gradient already is the DeepLIFT multiplier (linear in eval mode)
LINEAR = (nn.Linear, nn.Identity, nn.Flatten, nn.Unflatten, nn.Dropout, nn.Dropout1d, nn.Dropout2d, nn.Dropout3d,
          nn.AlphaDropout, nn.BatchNorm1d, nn.BatchNorm2d, nn.BatchNorm3d, nn.Conv1d, nn.Conv2d, nn.Conv3d,
          nn.ConvTranspose1d, nn.ConvTranspose2d, nn.ConvTranspose3d, nn.AvgPool1d, nn.AvgPool2d, nn.AvgPool3d,
          nn.AdaptiveAvgPool1d, nn.AdaptiveAvgPool2d, nn.AdaptiveAvgPool3d, nn.ZeroPad1d, nn.ZeroPad2d,
          nn.ZeroPad3d, nn.ConstantPad1d, nn.ConstantPad2d, nn.ConstantPad3d)
#: elementwise nonlinearities handled with the rescale rule
NONLINEAR = (nn.ReLU, nn.LeakyReLU, nn.ELU, nn.SiLU, nn.GELU, nn.Tanh, nn.Sigmoid, nn.Softplus, nn.ReLU6,
             nn.Hardtanh, nn.SELU, nn.CELU, nn.Mish, nn.Softsign, nn.Tanhshrink)
#: the rescale rule per element, as shap applies it; additive only as the network's final layer (checked)
SOFTMAX = (nn.Softmax, nn.LogSoftmax)
MAXPOOL = (nn.MaxPool1d, nn.MaxPool2d, nn.MaxPool3d)
CONTAINERS = (nn.Sequential, nn.ModuleList, nn.ModuleDict)
EPS = 1e-6  # below this |Δin| the local gradient is used, as shap does


class DeepShapOptions(Options):
    max_pairs: int = Field(65_536, ge=1, description="(state, background) pairs per batch; bounds memory")
    check_additivity: bool = Field(True, description="refuse results whose contributions do not add up")


def _vjp(layer, h, g):
    """g times the layer's local Jacobian at h (its own forward, without our hooks)."""
    with torch.enable_grad():
        leaf = h.detach().requires_grad_(True)
        return torch.autograd.grad(layer.forward(leaf), leaf, g)[0]


def _local_grad(layer, h):
    """The derivative of an elementwise layer at h."""
    return _vjp(layer, h, torch.ones_like(h))


def _ratio(inp, out):
    """Δout/Δin per element for both halves of each pair (rows i and i + P), and where |Δin| is too small for it."""
    p = len(inp) // 2
    d_in = inp[:p] - inp[p:]
    ratio = (out[:p] - out[p:]) / torch.where(d_in == 0, torch.ones_like(d_in), d_in)
    small = d_in.abs() < EPS
    return torch.cat([ratio, ratio]), torch.cat([small, small])


def _rescale_multiplier(layer, inp, out):
    """Rescale rule of an elementwise layer: the multiplier Δout/Δin per element, the local gradient where |Δin| is
    tiny, as shap does. Computed once per forward call, used by every output's backward pass."""
    ratio, small = _ratio(inp, out)
    return torch.where(small, _local_grad(layer, inp), ratio) if small.any() else ratio


def _rescale(layer, inp, out, g):
    """Rescale rule for a layer that mixes elements (Softmax, LogSoftmax), per element as shap applies it; the
    true local Jacobian where |Δin| is tiny."""
    ratio, small = _ratio(inp, out)
    return torch.where(small, _vjp(layer, inp, g), g * ratio) if small.any() else g * ratio


def _maxpool(layer, inp, out, g):
    """DeepLIFT's max-pool rule as shap implements it: the change of each window's max is split between the
    state's and the reference's arg-max positions, then divided by Δin there."""
    p = len(inp) // 2
    y, r = out[:p], out[p:]
    cross = torch.max(y, r)
    routed = _vjp(layer, inp, g * torch.cat([cross - r, y - cross]))  # the pooling's own routing to the arg-max
    d_in = inp[:p] - inp[p:]
    m = torch.where(d_in.abs() < 1e-7, torch.zeros_like(d_in), (routed[:p] + routed[p:]) / d_in)
    return torch.cat([m, m])


class _Rule(torch.autograd.Function):
    """Identity on the layer's output in the forward pass; the DeepLIFT rule in the backward pass: a multiplier
    computed once (elementwise layers), or a rule applied to each output's gradient."""

    @staticmethod
    def forward(ctx, inp, out, layer, rule):
        if rule is _rescale_multiplier:
            ctx.save_for_backward(_rescale_multiplier(layer, inp, out))
        else:
            ctx.save_for_backward(inp, out)
        ctx.layer, ctx.rule = layer, rule
        return out.clone()

    @staticmethod
    def backward(ctx, g):
        if ctx.rule is _rescale_multiplier:
            return g * ctx.saved_tensors[0], None, None, None
        inp, out = ctx.saved_tensors
        return ctx.rule(ctx.layer, inp, out, g), None, None, None


def _hook(rule):
    def hook(module, inputs, output):
        if not isinstance(output, torch.Tensor) or not inputs or not isinstance(inputs[0], torch.Tensor):
            return None
        return _Rule.apply(inputs[0], output, module, rule)
    return hook


def check_supported(module: torch.nn.Module, suggest: str = "") -> list[tuple[torch.nn.Module, object]]:
    """(layer, rule) for the nonlinear layers of ``module``; raises for any leaf layer without a DeepLIFT rule.

    A user module whose forward is affine in its input (a scaling, a reshape, a column slice) may set the class
    attribute ``xairl_linear = True``; the additivity check still guards the claim."""
    rules = []
    for name, sub in module.named_modules():
        if isinstance(sub, NONLINEAR):
            rules.append((sub, _rescale_multiplier))
        elif isinstance(sub, SOFTMAX):
            rules.append((sub, _rescale))
        elif isinstance(sub, MAXPOOL):
            if sub.return_indices:
                raise UnsupportedModelError(f"deep_shap does not support '{name}' (MaxPool with return_indices); "
                                            f"{suggest}")
            rules.append((sub, _maxpool))
        elif isinstance(sub, LINEAR + CONTAINERS) or getattr(sub, "xairl_linear", False):
            continue  # a module may declare itself linear (an affine map, a reshape): its gradient is its multiplier
        elif not any(True for _ in sub.children()):
            raise UnsupportedModelError(
                f"deep_shap does not support layer '{name or type(sub).__name__}' ({type(sub).__name__}); {suggest}"
            )
    return rules


def _only_child(policy, x: np.ndarray) -> torch.nn.Module:
    """The Sequential inside a wrapper module (CleanRL's ``QNetwork.network``) when the wrapper has that one child
    and gives its outputs on these states (checked), else the policy's module itself."""
    module = policy.module
    if isinstance(module, torch.nn.Sequential):
        return module
    children = list(module.children())
    if len(children) != 1 or not isinstance(children[0], torch.nn.Sequential) or \
            any(True for _ in module.parameters(recurse=False)) or any(True for _ in module.buffers(recurse=False)):
        return module
    t = torch.as_tensor(x[:256], device=policy.device)
    with torch.no_grad():
        same = torch.equal(policy.network(t), children[0](t))
    return children[0] if same else module


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
    tolerance = 1e-5  # float32 rounding stays near 1e-6 of the output scale on the networks we test
    gap_reason = ("the network computes something deep_shap cannot see: a functional nonlinearity (torch.tanh, "
                  "F.relu, ...), a product of two activations, or a softmax before the last layer; make such "
                  "operations nn modules")

    def _attribute(self, policy, x, bg):
        layers = chain(_only_child(policy, x)) if policy.observation.kind == "flat" else None
        if layers is not None:
            return self._attribute_chain(policy, layers, x, bg)
        module = policy.network
        for layer, rule in check_supported(module, alternatives(policy, self.name)):
            self._add_hook(layer.register_forward_hook(_hook(rule)))
        dev = policy.device
        xt = torch.as_tensor(x, device=dev)
        bt = torch.as_tensor(bg, device=dev)
        n, f = xt.shape
        b, a = len(bt), policy.n_actions
        per = max(1, min(self.options.max_pairs, max(1, 2 ** 22 // f)) // b)  # bounds the doubled batch
        values = np.empty((n, f, a))
        base = None
        for s in range(0, n, per):
            xs = xt[s:s + per]
            m = len(xs)
            xp = xs[:, None, :].expand(m, b, f).reshape(m * b, f)
            rp = bt[None, :, :].expand(m, b, f).reshape(m * b, f)
            rows = torch.cat([xp, rp]).requires_grad_(True)
            out = module(rows)
            delta = (xp - rp).reshape(m, b, f)
            base = out[m * b:].detach().double().mean(dim=0).cpu().numpy()
            for j in range(a):
                # both halves get the output gradient, as in shap: the max-pool rule mixes them
                grad = torch.autograd.grad(out[:, j].sum(), rows, retain_graph=j + 1 < a)[0]
                contrib = (grad[: m * b].reshape(m, b, f) * delta).mean(dim=1).double()
                values[s:s + m, :, j] = contrib.cpu().numpy()
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
