"""The networks of shap's own DeepExplainer test suite (shap ``tests/explainers/test_deep.py``, PyTorch part), rebuilt
with random data in place of MNIST / California housing (nothing is downloaded), plus SB3's NatureCNN and a
dict-input model. Each entry builds (policy, states, background, reference inputs) for the conformance table in
``tests/test_deep_models.py`` and ``benchmarks/conformance_deep.py``."""

from __future__ import annotations

import numpy as np
import torch
from torch import nn

import xairl


def _train(model, make_batch, steps=8):
    """A few SGD steps on random targets, so that weights and BatchNorm statistics are not at their init."""
    opt = torch.optim.SGD(model.parameters(), lr=0.01, momentum=0.5)
    model.train()
    for _ in range(steps):
        x, y = make_batch()
        opt.zero_grad()
        out = model(*x) if isinstance(x, tuple) else model(x)
        torch.nn.functional.mse_loss(out, y).backward()
        opt.step()
    return model.eval()


class MnistCNN(nn.Module):
    """shap test_pytorch_mnist_cnn_call: conv, max-pool, tanh, conv-transpose, adaptive avg-pool, softplus,
    batch-norm, ELU and a final softmax."""

    def __init__(self):
        super().__init__()
        self.conv_layers = nn.Sequential(
            nn.Conv2d(1, 10, 5),
            nn.MaxPool2d(2),
            nn.Tanh(),
            nn.Conv2d(10, 20, 5),
            nn.ConvTranspose2d(20, 20, 1),
            nn.AdaptiveAvgPool2d((4, 4)),
            nn.Softplus(),
            nn.Flatten(),
        )
        self.fc_layers = nn.Sequential(
            nn.Linear(320, 50), nn.BatchNorm1d(50), nn.ReLU(), nn.Linear(50, 10), nn.ELU(), nn.Softmax(dim=1)
        )

    def forward(self, x):
        return self.fc_layers(self.conv_layers(x).view(-1, 320))


class _Nested1(nn.Module):
    def __init__(self, f):
        super().__init__()
        self.net = nn.Sequential(
            nn.Sequential(nn.Identity(), nn.Conv1d(1, 1, 1), nn.ConvTranspose1d(1, 1, 1)), nn.AdaptiveAvgPool1d(f // 2)
        )

    def forward(self, x):
        return self.net(x.unsqueeze(1)).squeeze(1)


class _Nested2(nn.Module):
    def __init__(self, f):
        super().__init__()
        self.net = nn.Sequential(nn.LeakyReLU(), nn.Linear(f // 2, 2))

    def forward(self, x):
        return self.net(x).unsqueeze(1)


class NestedNet(nn.Module):
    """shap test_pytorch_custom_nested_models: nested modules, conv1d, conv-transpose, pooling, max-pool."""

    def __init__(self, f=8):
        super().__init__()
        self.net1, self.net2, self.maxpool2 = _Nested1(f), _Nested2(f), nn.MaxPool1d(2)

    def forward(self, x):
        return self.maxpool2(self.net2(self.net1(x))).squeeze(1)


class SingleOutputNet(nn.Module):
    """shap test_pytorch_single_output: one output through conv1d, conv-transpose, pooling and max-pool."""

    def __init__(self, f=8):
        super().__init__()
        self.linear, self.conv1d, self.convt1d = nn.Linear(f // 2, 2), nn.Conv1d(1, 1, 1), nn.ConvTranspose1d(1, 1, 1)
        self.leaky_relu, self.aapool1d, self.maxpool2 = nn.LeakyReLU(), nn.AdaptiveAvgPool1d(f // 2), nn.MaxPool1d(2)

    def forward(self, x):
        x = self.aapool1d(self.convt1d(self.conv1d(x.unsqueeze(1)))).squeeze(1)
        return self.maxpool2(self.linear(self.leaky_relu(x)).unsqueeze(1)).squeeze(1)


class MultiInputNet(nn.Module):
    """shap test_pytorch_multiple_inputs: two inputs, concatenated or one of them unused, max-pool, activation."""

    def __init__(self, f=8, disconnected=False, activation="relu"):
        super().__init__()
        self.disconnected = disconnected
        self.linear = nn.Linear(f // 2 if disconnected else f, 2)
        self.output = nn.Sequential(
            nn.MaxPool1d(2), {"relu": nn.ReLU(), "selu": nn.SELU(), "gelu": nn.GELU()}[activation]
        )

    def forward(self, x1, x2):
        x = self.linear(x1 if self.disconnected else torch.cat((x1, x2), dim=-1)).unsqueeze(1)
        return self.output(x).squeeze(1)


class NatureQ(nn.Module):
    """SB3's NatureCNN (Atari frames (4, 84, 84)) with a Q head over 6 actions."""

    def __init__(self):
        super().__init__()
        from gymnasium import spaces
        from stable_baselines3.common.torch_layers import NatureCNN

        self.cnn = NatureCNN(spaces.Box(0, 255, (4, 84, 84), np.uint8), features_dim=512)
        self.q = nn.Linear(512, 6)

    def forward(self, x):
        return self.q(self.cnn(x))


class DictNet(nn.Module):
    """A MultiInputPolicy-style network: an image and a vector in a dict (layers shap has rules for, so that shap
    is a reference: it reads SiLU, Mish and others as linear)."""

    def __init__(self):
        super().__init__()
        self.cnn = nn.Sequential(nn.Conv2d(3, 8, 3, stride=2), nn.ReLU(), nn.MaxPool2d(2), nn.Flatten())
        self.vec = nn.Sequential(nn.Linear(5, 16), nn.Tanh())
        self.head = nn.Sequential(nn.Linear(8 * 3 * 3 + 16, 32), nn.ELU(), nn.Linear(32, 4))

    def forward(self, obs):
        return self.head(torch.cat([self.cnn(obs["image"]), self.vec(obs["vec"])], dim=1))


def build(name: str, n_states: int = 2, n_background: int = 10, seed: int = 0):
    """(xairl policy, states, background, shap inputs (states, background)) for network ``name``."""
    torch.manual_seed(seed)
    rng = np.random.default_rng(seed)

    def rand(*shape):
        return rng.normal(size=shape).astype(np.float32)

    if name == "mnist_cnn":
        net = _train(MnistCNN(), lambda: (torch.randn(32, 1, 28, 28), torch.eye(10)[torch.randint(0, 10, (32,))]))
        x, bg = rand(n_states, 1, 28, 28), rand(n_background, 1, 28, 28)
        return xairl.Policy(net, observation=(1, 28, 28)), x, bg, (torch.as_tensor(x), torch.as_tensor(bg))
    if name in ("nested", "single_output"):
        net = NestedNet() if name == "nested" else SingleOutputNet()
        net = _train(net, lambda: (torch.randn(64, 8), torch.randn(64, 1)))
        x, bg = rand(n_states, 8), rand(n_background, 8)
        policy = xairl.Policy(net, [f"x{i}" for i in range(8)], ["y"], output="value")
        return policy, x, bg, (torch.as_tensor(x), torch.as_tensor(bg))
    if name.startswith("multi_input"):
        _, disconnected, act = name.split(":")
        net = _train(
            MultiInputNet(disconnected=disconnected == "disconnected", activation=act),
            lambda: ((torch.randn(64, 4), torch.randn(64, 4)), torch.randn(64, 1)),
        )
        x = [rand(n_states, 4), rand(n_states, 4)]
        bg = [rand(n_background, 4), rand(n_background, 4)]
        policy = xairl.Policy(net, observation=[(4,), (4,)], output="value")
        return policy, x, bg, ([torch.as_tensor(a) for a in x], [torch.as_tensor(a) for a in bg])
    if name == "nature_cnn":
        net = NatureQ().eval()
        x = rng.integers(0, 256, (n_states, 4, 84, 84)).astype(np.float32)
        bg = rng.integers(0, 256, (n_background, 4, 84, 84)).astype(np.float32)
        return xairl.Policy(net, observation=(4, 84, 84)), x, bg, (torch.as_tensor(x), torch.as_tensor(bg))
    if name == "dict":
        net = DictNet().eval()
        x = {"image": rand(n_states, 3, 16, 16), "vec": rand(n_states, 5)}
        bg = {"image": rand(n_background, 3, 16, 16), "vec": rand(n_background, 5)}
        policy = xairl.Policy(net, observation={"image": (3, 16, 16), "vec": (5,)})
        # shap takes no dict inputs: it explains the same network through a wrapper taking the parts as a list
        return policy, x, bg, ([torch.as_tensor(v) for v in x.values()], [torch.as_tensor(v) for v in bg.values()])
    raise KeyError(name)


NAMES = [
    "mnist_cnn",
    "nested",
    "single_output",
    *(f"multi_input:{d}:{a}" for d in ("connected", "disconnected") for a in ("relu", "selu", "gelu")),
    "nature_cnn",
    "dict",
]


def shap_values(policy, inputs) -> np.ndarray:
    """shap.DeepExplainer's values as (n, F, outputs) in xairl's flat column order."""
    import shap

    x, bg = inputs
    net = (
        _TupleToDict(policy.module, [p.key for p in policy.observation.parts])
        if policy.observation.kind == "dict"
        else policy.module
    )
    ex = shap.DeepExplainer(net, bg)
    sv = ex.shap_values(x, check_additivity=False)
    parts = sv if isinstance(x, list) else [sv]
    n, a = len(parts[0]), policy.n_actions
    return np.concatenate([np.asarray(p).reshape(n, -1, a) for p in parts], axis=1)


class _TupleToDict(nn.Module):
    def __init__(self, net, keys):
        super().__init__()
        self.net, self.keys = net, keys

    def forward(self, *parts):
        return self.net(dict(zip(self.keys, parts)))


def captum_values(policy, x, bg) -> np.ndarray:
    """captum DeepLiftShap's values as (n, F, outputs) in xairl's flat column order."""
    from captum.attr import DeepLiftShap

    obs = policy.observation
    xs, bs = (
        obs.unflatten(torch.as_tensor(policy.check_states(x))),
        obs.unflatten(torch.as_tensor(policy.check_states(bg, "background"))),
    )
    net = policy.module
    if obs.kind == "dict":
        net, xs, bs = _TupleToDict(net, list(xs)), tuple(xs.values()), tuple(bs.values())
    elif obs.kind != "tuple":
        xs, bs = (xs,), (bs,)
    dl = DeepLiftShap(net.eval(), multiply_by_inputs=True)
    n = len(xs[0])
    out = []
    for a in range(policy.n_actions):
        attr = dl.attribute(tuple(t.clone() for t in xs), baselines=bs, target=a if policy.n_actions > 1 else None)
        out.append(np.concatenate([t.detach().double().numpy().reshape(n, -1) for t in attr], axis=1))
    return np.stack(out, axis=-1)
