"""deep_shap vs shap.DeepExplainer vs captum DeepLiftShap: time (median of repeats) and agreement of the values.

Models: an MLP of the reference DQN's shape (13-64-64-4), a wider MLP (32-256-256-8), and any registered policy
named with --policy (e.g. --policy uav-dqn, the reference plugin's trained DQN); 100 background states; all actions.
Goal (issue 6): >= 50x shap.DeepExplainer on the reference DQN.
Run: .venv/bin/python benchmarks/bench_deep_shap.py [--sizes 1000,10000] [--device cpu|cuda] [--repeats 3]
     [--policy uav-dqn]
"""

import argparse
import os
import platform
import time

import numpy as np
import torch

import xairl


def mlp_policy(sizes):
    """A seeded ReLU MLP with a standard-normal background."""
    torch.manual_seed(0)
    layers = []
    for i, (a, b) in enumerate(zip(sizes[:-1], sizes[1:])):
        layers += [torch.nn.Linear(a, b)] + ([torch.nn.ReLU()] if i < len(sizes) - 2 else [])
    f, a = sizes[0], sizes[-1]
    return xairl.Policy(
        torch.nn.Sequential(*layers).eval(),
        [f"f{i}" for i in range(f)],
        [f"a{i}" for i in range(a)],
        background_sampler=lambda n, s: np.random.default_rng(s).normal(size=(n, f)),
    )


def models(device, policy_name=None):
    found = {"mlp 13-64-64-4": mlp_policy((13, 64, 64, 4)), "mlp 32-256-256-8": mlp_policy((32, 256, 256, 8))}
    if policy_name:
        found[policy_name] = xairl.get_policy(policy_name)
    for p in found.values():
        p.module.to(device)
    return found


def timed(fn, repeats):
    times, out = [], None
    for _ in range(repeats):
        if torch.cuda.is_available():
            torch.cuda.synchronize()
        t0 = time.perf_counter()
        out = fn()
        if torch.cuda.is_available():
            torch.cuda.synchronize()
        times.append(time.perf_counter() - t0)
    return float(np.median(times)), out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", default="1000,10000")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--peer-repeats", type=int, default=1)
    ap.add_argument("--device", default="cuda" if torch.cuda.is_available() else "cpu")
    ap.add_argument("--peer-max", type=int, default=10000, help="largest size at which shap and captum are timed")
    ap.add_argument("--policy", default=None, help="also a registered policy, e.g. uav-dqn")
    ap.add_argument("--models", default="", help="comma-separated names to run (default all), e.g. uav-dqn")
    args = ap.parse_args()
    import captum
    import shap
    from captum.attr import DeepLiftShap

    dev = torch.device(args.device)
    gpu = torch.cuda.get_device_name(0) if dev.type == "cuda" else "none"
    print(
        f"machine: {platform.machine()}, {os.cpu_count()} cores, GPU {gpu}; torch {torch.__version__}, "
        f"shap {shap.__version__}, captum {captum.__version__}; device {dev}"
    )
    print(
        f"{'model':<20}{'states':>7}{'xairl s':>9}{'shap s':>9}{'captum s':>10}{'x shap':>9}{'x captum':>10}"
        f"{'max|diff| shap':>16}{'captum':>10}"
    )
    wanted = {m for m in args.models.split(",") if m}
    for name, policy in models(dev, args.policy).items():
        if wanted and name not in wanted:
            continue
        bg = torch.as_tensor(policy.background(100, seed=1), device=dev)
        for n in (int(s) for s in args.sizes.split(",")):
            x = torch.as_tensor(policy.background(n, seed=2), device=dev)
            t_ours, ours = timed(
                lambda: xairl.explain(policy, x, background=bg, method="deep_shap").values, args.repeats
            )
            if n > args.peer_max:
                print(f"{name:<20}{n:>7}{t_ours:>9.2f}{'-':>9}{'-':>10}   (peers not timed above --peer-max)")
                continue
            net = policy.module
            t_shap, sv = timed(
                lambda: np.asarray(shap.DeepExplainer(net, bg).shap_values(x, check_additivity=False)),
                args.peer_repeats,
            )
            dls = DeepLiftShap(net)
            t_cap, cv = timed(
                lambda: np.stack(
                    [dls.attribute(x, baselines=bg, target=k).detach().cpu().numpy() for k in range(policy.n_actions)],
                    axis=-1,
                ),
                args.peer_repeats,
            )
            print(
                f"{name:<20}{n:>7}{t_ours:>9.2f}{t_shap:>9.2f}{t_cap:>10.2f}{t_shap / t_ours:>8.1f}x"
                f"{t_cap / t_ours:>9.1f}x{np.abs(ours - sv).max():>16.1e}{np.abs(ours - cv).max():>10.1e}"
            )


if __name__ == "__main__":
    main()
