"""The four domains of the held-out narrative corpus (``benchmarks/data/narratives``): two tabular models that are
not RL (a house-price regressor, a credit-default classifier with categorical features, one output each), the UAV
handover DQN and the toy discrete policy.

The tabular models are small torch MLPs fitted to synthetic data with a known shape (bigger houses cost more, late
payments raise the default risk), so their SHAP values read like a real model's. ``policy(domain)`` gives the
Policy whose metadata (names, descriptions, units, categories, aliases, domain facts) a verifier may use; the
corpus stores the explanations themselves, so re-fitting a model never changes a label.
"""

from __future__ import annotations

import numpy as np
import torch

import xairl

DOMAINS = ("housing", "credit", "uav", "toy")

HOUSING = {  # name: (description, unit, categories)
    "living_area": ("above-ground living area", "sq ft", ()),
    "overall_quality": ("overall material and finish quality, 1 to 10", "", ()),
    "year_built": ("original construction year", "", ()),
    "lot_area": ("lot size", "sq ft", ()),
    "garage_cars": ("garage capacity in cars", "cars", ()),
    "neighborhood": ("neighbourhood", "", ("CollgCr", "OldTown", "NridgHt", "Edwards", "Somerst")),
    "central_air": ("central air conditioning", "", ("N", "Y")),
    "kitchen_quality": ("kitchen quality", "", ("Fa", "TA", "Gd", "Ex")),
}
CREDIT = {
    "age": ("applicant's age", "years", ()),
    "annual_income": ("annual income", "$", ()),
    "debt_to_income": ("debt-to-income ratio", "", ()),
    "late_payments": ("number of late payments in the last two years", "", ()),
    "credit_history_years": ("length of credit history", "years", ()),
    "employment": ("employment type", "", ("salaried", "self-employed", "unemployed", "retired")),
    "housing": ("housing status", "", ("own", "rent", "free")),
    "loan_purpose": ("purpose of the loan", "", ("car", "education", "business", "home improvement")),
}
SPECS = {"housing": HOUSING, "credit": CREDIT}
OUTPUT_NAME = {"housing": "price", "credit": "default_probability"}


def sample(domain: str, n: int, seed: int) -> np.ndarray:
    """``n`` synthetic rows of a tabular domain, in raw units (categorical features as integer codes)."""
    r = np.random.default_rng(seed)
    if domain == "housing":
        cols = [
            r.normal(1500, 450, n).clip(500, 4000),
            r.integers(3, 11, n),
            r.integers(1920, 2011, n),
            r.lognormal(9.1, 0.35, n),
            r.integers(0, 4, n),
            r.integers(0, 5, n),
            r.integers(0, 2, n),
            r.integers(0, 4, n),
        ]
    else:
        cols = [
            r.integers(21, 76, n),
            r.lognormal(10.8, 0.45, n),
            r.uniform(0.05, 0.75, n),
            r.poisson(0.8, n),
            r.integers(0, 31, n),
            r.integers(0, 4, n),
            r.integers(0, 3, n),
            r.integers(0, 4, n),
        ]
    return np.column_stack(cols).astype(np.float32)


def _truth(domain: str, x: np.ndarray) -> np.ndarray:
    """The synthetic ground truth the MLP is fitted to (dollars; log-odds of default)."""
    if domain == "housing":
        nb = np.array([0.0, -18e3, 35e3, -12e3, 20e3])[x[:, 5].astype(int)]
        kq = np.array([-15e3, 0.0, 12e3, 30e3])[x[:, 7].astype(int)]
        return (
            40e3
            + 62 * x[:, 0]
            + 9e3 * x[:, 1]
            + 420 * (x[:, 2] - 1970)
            + 1.4 * x[:, 3]
            + 7e3 * x[:, 4]
            + nb
            + 9e3 * x[:, 6]
            + kq
        )
    emp = np.array([0.0, 0.4, 1.3, -0.2])[x[:, 5].astype(int)]
    hous = np.array([-0.3, 0.25, 0.1])[x[:, 6].astype(int)]
    purp = np.array([0.0, 0.2, 0.6, -0.1])[x[:, 7].astype(int)]
    return (
        -1.2
        - 0.02 * (x[:, 0] - 40)
        - 0.9 * (np.log(x[:, 1]) - 10.8)
        + 3.0 * (x[:, 2] - 0.35)
        + 0.55 * x[:, 3]
        - 0.04 * x[:, 4]
        + emp
        + hous
        + purp
    )


class _Tabular(torch.nn.Module):
    """Standardises raw columns, one-hot encodes the categorical codes, then a 2-layer MLP; the credit model ends
    in a sigmoid (a probability of default)."""

    def __init__(self, domain: str):
        super().__init__()
        spec = list(SPECS[domain].values())
        self.cat = [j for j, s in enumerate(spec) if s[2]]
        self.num = [j for j, s in enumerate(spec) if not s[2]]
        self.sizes = [len(spec[j][2]) for j in self.cat]
        self.register_buffer("mean", torch.zeros(len(self.num)))
        self.register_buffer("std", torch.ones(len(self.num)))
        self.register_buffer("out_scale", torch.ones(()))
        self.register_buffer("out_shift", torch.zeros(()))
        self.net = torch.nn.Sequential(
            torch.nn.Linear(len(self.num) + sum(self.sizes), 32), torch.nn.ReLU(), torch.nn.Linear(32, 1)
        )
        self.sigmoid = domain == "credit"

    def raw(self, x: torch.Tensor) -> torch.Tensor:
        """The standardised output (before scaling and the sigmoid)."""
        parts = [(x[:, self.num] - self.mean) / self.std]
        for j, k in zip(self.cat, self.sizes):
            parts.append((x[:, j : j + 1] == torch.arange(k, dtype=x.dtype)).to(x.dtype))
        return self.net(torch.cat(parts, dim=1))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        y = self.raw(x) * self.out_scale + self.out_shift
        return torch.sigmoid(y) if self.sigmoid else y


def fitted(domain: str, seed: int = 0) -> torch.nn.Module:
    """The domain's MLP fitted to 4,000 synthetic rows (deterministic on one thread)."""
    torch.manual_seed(seed)
    net = _Tabular(domain)
    x = sample(domain, 4000, seed)
    y = _truth(domain, x)
    xt = torch.tensor(x)
    with torch.no_grad():
        net.mean.copy_(xt[:, net.num].mean(0))
        net.std.copy_(xt[:, net.num].std(0))
        net.out_scale.fill_(float(y.std()))
        net.out_shift.fill_(float(y.mean()))
    yt = torch.tensor((y - y.mean()) / y.std(), dtype=torch.float32)[:, None]
    opt = torch.optim.Adam(net.net.parameters(), lr=1e-2)
    for _ in range(600):
        opt.zero_grad()
        loss = torch.nn.functional.mse_loss(net.raw(xt), yt)
        loss.backward()
        opt.step()
    return net.eval()


def policy(domain: str, module: torch.nn.Module | None = None) -> xairl.Policy:
    """The domain's Policy (with an unfitted network unless ``module`` is given: its metadata is what a verifier
    reads)."""
    if domain == "uav":
        from xairl_uav_handover.policy import uav_policy

        return uav_policy()
    if domain == "toy":
        from xairl.toy import toy_policy

        return toy_policy()
    spec = SPECS[domain]
    features = {f: xairl.FeatureInfo(unit, desc, categories=cats) for f, (desc, unit, cats) in spec.items()}
    return xairl.Policy(
        module if module is not None else _Tabular(domain),
        list(spec),
        [OUTPUT_NAME[domain]],
        features=features,
        output="value",
        name=domain,
        background_sampler=lambda n, seed: sample(domain, n, seed),
    )
