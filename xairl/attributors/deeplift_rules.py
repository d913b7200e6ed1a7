"""DeepLIFT's rules, layer by layer: which layers keep their exact gradient, which take the rescale rule (and how
it computes its multiplier), and the max-pool rule shap uses. Used by the DeepSHAP attributor (deep_shap.py), both
through its hooks and on its sequential-chain path."""

from __future__ import annotations

import torch

nn = torch.nn
#: layers whose gradient already is the DeepLIFT multiplier (linear in eval mode)
LINEAR = (
    nn.Linear,
    nn.Identity,
    nn.Flatten,
    nn.Unflatten,
    nn.Dropout,
    nn.Dropout1d,
    nn.Dropout2d,
    nn.Dropout3d,
    nn.AlphaDropout,
    nn.BatchNorm1d,
    nn.BatchNorm2d,
    nn.BatchNorm3d,
    nn.Conv1d,
    nn.Conv2d,
    nn.Conv3d,
    nn.ConvTranspose1d,
    nn.ConvTranspose2d,
    nn.ConvTranspose3d,
    nn.AvgPool1d,
    nn.AvgPool2d,
    nn.AvgPool3d,
    nn.AdaptiveAvgPool1d,
    nn.AdaptiveAvgPool2d,
    nn.AdaptiveAvgPool3d,
    nn.ZeroPad1d,
    nn.ZeroPad2d,
    nn.ZeroPad3d,
    nn.ConstantPad1d,
    nn.ConstantPad2d,
    nn.ConstantPad3d,
)
#: elementwise nonlinearities handled with the rescale rule
NONLINEAR = (
    nn.ReLU,
    nn.LeakyReLU,
    nn.ELU,
    nn.SiLU,
    nn.GELU,
    nn.Tanh,
    nn.Sigmoid,
    nn.Softplus,
    nn.ReLU6,
    nn.Hardtanh,
    nn.SELU,
    nn.CELU,
    nn.Mish,
    nn.Softsign,
    nn.Tanhshrink,
)
#: the rescale rule per element, as shap applies it; additive only as the network's final layer (checked)
SOFTMAX = (nn.Softmax, nn.LogSoftmax)
MAXPOOL = (nn.MaxPool1d, nn.MaxPool2d, nn.MaxPool3d)
CONTAINERS = (nn.Sequential, nn.ModuleList, nn.ModuleDict)
EPS = 1e-6  # below this |Δin| the local gradient is used, as shap does


def _vjp(layer, h, g):
    """g times the layer's local Jacobian at h (its own forward, without our hooks)."""
    with torch.enable_grad():
        leaf = h.detach().requires_grad_(True)
        return torch.autograd.grad(layer.forward(leaf), leaf, g)[0]


def _local_grad(layer, h):
    """The derivative of an elementwise layer at h."""
    return _vjp(layer, h, torch.ones_like(h))


def _ratio(xi, xo, ri, ro):
    """Δout/Δin per element of a pair (state side xi/xo, reference side ri/ro), and where |Δin| is too small."""
    d_in = xi - ri
    ratio = (xo - ro) / torch.where(d_in == 0, torch.ones_like(d_in), d_in)
    return ratio, d_in.abs() < EPS


def _rescale_multiplier(layer, xi, xo, ri, ro):
    """Rescale rule of an elementwise layer: the multiplier Δout/Δin per element, the local gradient where |Δin| is
    tiny, as shap does. Computed once per forward call, used by every output's backward pass."""
    ratio, small = _ratio(xi, xo, ri, ro)
    return torch.where(small, _local_grad(layer, xi), ratio) if small.any() else ratio


def _rescale(layer, xi, xo, ri, ro, g, g_ref):
    """Rescale rule for a layer that mixes elements (Softmax, LogSoftmax), per element as shap applies it; the
    true local Jacobian where |Δin| is tiny."""
    ratio, small = _ratio(xi, xo, ri, ro)
    return torch.where(small, _vjp(layer, xi, g), g * ratio) if small.any() else g * ratio


def _maxpool(layer, xi, xo, ri, ro, g, g_ref):
    """DeepLIFT's max-pool rule as shap implements it: the change of each window's max is split between the
    state's and the reference's arg-max positions (each routed with its own side's gradient), then divided by Δin
    there. The same multiplier holds for both sides of the pair."""
    cross = torch.max(xo, ro)
    routed = _vjp(layer, xi, g * (cross - ro)) + _vjp(layer, ri, g_ref * (xo - cross))
    d_in = xi - ri
    return torch.where(d_in.abs() < 1e-7, torch.zeros_like(d_in), routed / d_in)
