"""DeepSHAP: DeepLIFT multipliers averaged over a background, batched over all (state, background) pairs.

A forward hook on each nonlinear layer ties its output to its input through a custom backward (:class:`_Rule`)
that gives the DeepLIFT multiplier of its own call (so a module used twice is handled per call): the rescale rule
Δout/Δin for elementwise layers (and Softmax / LogSoftmax as a final layer), the max-pool rule shap uses for MaxPool.
Linear layers (Linear, Conv, ConvTranspose, average pooling, BatchNorm in eval mode, reshapes) keep their exact
gradients (the rules, and which layer takes which: deeplift_rules.py). One backward pass per output gives the multipliers: the values of shap.DeepExplainer and captum's
DeepLiftShap.

Layouts: *split* (the default) runs the background through the network once and records each nonlinear call's
activations; the batch then holds only the state side of every pair, and only it is back-propagated (half of shap's
forward and backward work; every rule but Softmax's gives both sides of a pair the same gradient). *Joint* (as shap:
the batch is ``[state sides; reference sides]``, both back-propagated) serves networks with Softmax / LogSoftmax and
networks whose calls depend on their input. A pure Sequential MLP on flat states takes a faster path
(:func:`chain_multipliers`). What is left is the work no exact method skips, a backward pass per output and pair:
``benchmarks/bench_cnn.py`` times that floor.
"""

from __future__ import annotations

import contextlib

import numpy as np
import torch
from pydantic import Field

from xairl.attributors.base import Attributor, Options, alternatives
from xairl.attributors.deeplift_rules import (
    CONTAINERS,
    EPS,
    LINEAR,
    MAXPOOL,
    NONLINEAR,
    SOFTMAX,
    _local_grad,
    _maxpool,
    _rescale,
    _rescale_multiplier,
)
from xairl.errors import UnsupportedModelError


class DeepShapOptions(Options):
    max_pairs: int = Field(65_536, ge=1, description="(state, background) pairs per batch; bounds memory")
    check_additivity: bool = Field(True, description="refuse results whose contributions do not add up")


class _Rule(torch.autograd.Function):
    """Identity on the layer's output in the forward pass; the DeepLIFT rule in the backward pass, straight to the
    layer's input: a multiplier computed once (elementwise layers), or a rule applied to each output's gradient.

    Two layouts. Joint (``ref_in`` is None): the batch is ``[state rows; reference rows]`` and both halves are
    back-propagated, as shap does (needed when a rule is not the same on both sides, e.g. Softmax's local Jacobian).
    Split: the batch holds the state side of every pair and ``ref_in``/``ref_out`` the reference side's activations
    of the same call (from one forward pass of the background); only the state side is back-propagated, with the
    rules' gradient taken as the same on both sides."""

    @staticmethod
    def forward(ctx, inp, out, ref_in, ref_out, layer, rule):
        joint = ref_in is None
        if joint:
            p = len(inp) // 2
            xi, xo, ri, ro = inp[:p], out[:p], inp[p:], out[p:]
        else:
            xi, xo, ri, ro = inp, out, ref_in, ref_out
        if rule is _rescale_multiplier:
            m = _rescale_multiplier(layer, xi, xo, ri, ro)
            ctx.save_for_backward(torch.cat([m, _rescale_multiplier(layer, ri, ro, xi, xo)]) if joint else m)
        else:
            ctx.save_for_backward(xi, xo, ri, ro)
        ctx.layer, ctx.rule, ctx.joint = layer, rule, joint
        return out.clone()

    @staticmethod
    def backward(ctx, g):
        if ctx.rule is _rescale_multiplier:
            return g * ctx.saved_tensors[0], None, None, None, None, None
        xi, xo, ri, ro = ctx.saved_tensors
        if not ctx.joint:
            return ctx.rule(ctx.layer, xi, xo, ri, ro, g, g), None, None, None, None, None
        gx, gr = g[: len(xi)], g[len(xi) :]
        return (
            torch.cat([ctx.rule(ctx.layer, xi, xo, ri, ro, gx, gr), ctx.rule(ctx.layer, ri, ro, xi, xo, gr, gx)]),
            None,
            None,
            None,
            None,
            None,
        )


@contextlib.contextmanager
def _hooked(rules, make_hook):
    """The forward hook ``make_hook(rule)`` on each nonlinear layer while the block runs; removed whatever happens."""
    handles = [layer.register_forward_hook(make_hook(rule)) for layer, rule in rules]
    try:
        yield
    finally:
        for h in handles:
            h.remove()


def _recorder(calls: list):
    """A forward hook that records (layer, input, output) of each call, in call order."""

    def hook(module, inputs, output):
        if isinstance(output, torch.Tensor) and inputs and isinstance(inputs[0], torch.Tensor):
            calls.append((module, inputs[0].detach(), output.detach()))

    return hook


class _Mismatch(Exception):
    """The network's calls on the pairs differ from its calls on the background (control flow): use the joint
    layout."""


def _hook(rule, calls=None, m: int = 0):
    """The forward hook of one nonlinear layer. With ``calls`` (the reference side's (input, output) of each call,
    recorded on the background in call order; consumed) and ``m`` (how many states the batch pairs with the
    background), the split layout; else the joint one."""

    def hook(module, inputs, output):
        if not isinstance(output, torch.Tensor) or not inputs or not isinstance(inputs[0], torch.Tensor):
            return None
        if calls is None:
            return _Rule.apply(inputs[0], output, None, None, module, rule)
        if not calls or calls[0][0] is not module or calls[0][2].shape[1:] != output.shape[1:]:
            raise _Mismatch()
        _, ri, ro = calls.pop(0)
        ri, ro = (t.unsqueeze(0).expand(m, *t.shape).reshape(m * t.shape[0], *t.shape[1:]) for t in (ri, ro))
        return _Rule.apply(inputs[0], output, ri, ro, module, rule)

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
                raise UnsupportedModelError(
                    f"deep_shap does not support '{name}' (MaxPool with return_indices); {suggest}"
                )
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
    if (
        len(children) != 1
        or not isinstance(children[0], torch.nn.Sequential)
        or any(True for _ in module.parameters(recurse=False))
        or any(True for _ in module.buffers(recurse=False))
    ):
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
        elif isinstance(
            layer, (torch.nn.Linear, torch.nn.BatchNorm1d, torch.nn.Identity, torch.nn.Dropout, torch.nn.AlphaDropout)
        ) or isinstance(layer, NONLINEAR):
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
                steps.append(
                    ("scale", (layer.weight if layer.affine else 1.0) / torch.sqrt(layer.running_var + layer.eps))
                )
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
    gap_reason = (
        "the network computes something deep_shap cannot see: a functional nonlinearity (torch.tanh, "
        "F.relu, ...), a product of two activations, or a softmax before the last layer; make such "
        "operations nn modules"
    )

    def _attribute(self, policy, x, bg):
        layers = chain(_only_child(policy, x)) if policy.observation.kind == "flat" else None
        if layers is not None:
            return self._attribute_chain(policy, layers, x, bg)
        rules = check_supported(policy.network, alternatives(policy, self.name))
        xt = torch.as_tensor(x, device=policy.device)
        bt = torch.as_tensor(bg, device=policy.device)
        if not any(rule is _rescale for _, rule in rules):  # every rule is the same on both sides of a pair
            try:
                return self._attribute_pairs(policy.network, rules, xt, bt, policy.n_actions, split=True)
            except _Mismatch:
                pass  # the network's calls depend on its input: back-propagate both sides instead
        return self._attribute_pairs(policy.network, rules, xt, bt, policy.n_actions, split=False)

    def _attribute_pairs(self, module, rules, xt, bt, a, split: bool):
        """Every (state, background) pair as a row; one forward pass and one backward pass per output. Split: the
        rows are the state sides, the reference sides' activations come from one pass over the background. Joint:
        the rows are ``[state sides; reference sides]``."""
        n, f = xt.shape
        b = len(bt)
        per = max(1, min(self.options.max_pairs, max(1, 2**22 // f)) // b)  # bounds the batch
        values = np.empty((n, f, a))
        calls: list = []
        if split:
            with _hooked(rules, lambda rule: _recorder(calls)), torch.no_grad():
                base = module(bt).double().mean(dim=0).cpu().numpy()
        for s in range(0, n, per):
            xs = xt[s : s + per]
            m = len(xs)
            xp = xs[:, None, :].expand(m, b, f).reshape(m * b, f)
            rp = bt[None, :, :].expand(m, b, f).reshape(m * b, f)
            rows = (xp if split else torch.cat([xp, rp])).detach().requires_grad_(True)
            queue = list(calls)
            with _hooked(rules, (lambda rule: _hook(rule, queue, m)) if split else _hook):
                out = module(rows)
            if queue:
                raise _Mismatch()
            if not split:
                base = out[m * b :].detach().double().mean(dim=0).cpu().numpy()
            delta = (xp - rp).reshape(m, b, f)
            for j in range(a):
                grad = torch.autograd.grad(out[:, j].sum(), rows, retain_graph=j + 1 < a)[0]
                contrib = (grad[: m * b].reshape(m, b, f) * delta).mean(dim=1).double()
                values[s : s + m, :, j] = contrib.cpu().numpy()
        return values, base, {}

    def _attribute_chain(self, policy, layers, x, bg):
        dev = policy.device
        xt, bt = torch.as_tensor(x, device=dev), torch.as_tensor(bg, device=dev)
        n, f = xt.shape
        b, a = len(bt), policy.n_actions
        widest = max([f] + [getattr(layer, "out_features", 0) for layer in layers])
        # ~4 MB of multipliers per batch: they stay in the CPU's cache (3x faster than 64 MB batches on 2 cores,
        # with half the peak memory; benchmarks/bench_stream.py)
        per = max(1, min(self.options.max_pairs, 2**20 // (a * widest)) // b)
        values = np.empty((n, f, a))
        outputs = np.empty((n, a))
        base = None
        for s in range(0, n, per):
            xs = xt[s : s + per]
            m = len(xs)
            mult, ox, orr = chain_multipliers(layers, xs, bt)
            delta = (xs[:, None, :] - bt[None, :, :]).reshape(m * b, 1, f)
            contrib = (mult * delta).reshape(m, b, a, f).mean(dim=1).double()
            values[s : s + m] = contrib.transpose(1, 2).cpu().numpy()
            outputs[s : s + m] = ox.double().cpu().numpy()
            base = orr.double().mean(dim=0).cpu().numpy()
        return values, base, {}
