"""The generated decisions of ``xairl prompts check``'s battery (:mod:`xairl.narrators.battery`): synthetic
:class:`xairl.Explanation` objects (base + sum of contributions = output), built by hand on small policies with
:class:`xairl.FeatureInfo` (units, a capacity, a categorical, an identifier). Every sign pattern of the top three
features, ties, zero contributions, 1, 3 and 50 features, one feature alone favouring the chosen action, none
favouring it, a single available action and a masked best one, on each policy kind (flat, dict, image in regions,
continuous, value), decisions with a counterfactual (what would have changed them), global views over several
states, and every installed plugin's policy."""

from __future__ import annotations

import itertools
import threading
from dataclasses import dataclass, replace
from functools import cache

import numpy as np
import torch

from xairl.counterfactual_facts import CounterfactualFact, said_counterfactual
from xairl.explanations.explanation import Explanation
from xairl.policies.policy import FeatureInfo, Policy
from xairl.policies.regions import in_regions

#: (name, value, what it means, quartiles of the background) of the flat policy's features, in the order the sign
#: patterns use them: a negative value with a unit, a queue with a capacity, a categorical, a high value, an id
_FLAT = (
    ("temperature", -3.5, FeatureInfo(unit="°C", description="the outside temperature"), (-10.0, 0.0, 10.0)),
    ("queue_len", 12.0, FeatureInfo(unit="packets", capacity=40.0), (5.0, 10.0, 20.0)),
    ("mode", 1.0, FeatureInfo(categories=("idle", "busy", "fault")), (0.0, 1.0, 2.0)),
    ("speed", 4.2, FeatureInfo(unit="m/s", description="the speed"), (1.0, 2.0, 3.0)),
    ("cell_id", 17.0, FeatureInfo(kind="identifier", description="the cell's id"), (0.0, 10.0, 20.0)),
)
_ACTIONS = ("turn_left", "turn_right", "hold")
_TOP = (0.9, 0.6, 0.35)  # sizes of the top three contributions to the chosen action's score
_WEIGHTS = (0.1, 0.9, 0.3, 0.5, 0.2)  # the runner-up's contributions are -s * w: the margin's s * (1 + w)
PLUGIN_LOAD_S = 5.0  # a plugin policy that takes longer to load is left out, in one line


@dataclass(frozen=True)
class Case:
    """One generated decision (``index`` 0) or global view (``index`` None), described as ``label``."""

    label: str
    kind: str  # flat, dict, image, continuous, value, global, or a plugin policy's name
    explanation: Explanation
    policy: Policy
    index: int | None = 0
    counterfactual: CounterfactualFact | None = None  # what would have changed the decision, as narration says it


def _signs(s) -> str:
    return ",".join("+" if x > 0 else "-" if x < 0 else "0" for x in s)


def _rest(n: int, start: int = 3) -> np.ndarray:
    """Small contributions of alternating sign for the features past the top ones."""
    return np.array([0.0] * start + [(-1) ** j * 0.05 / (j + 1) for j in range(n - start)])[:n]


def _policy(names, infos=None, actions=_ACTIONS, output="actions", observation=None) -> Policy:
    kw = {"observation": observation} if observation is not None else {"feature_names": list(names)}
    return Policy(torch.nn.Identity(), action_names=list(actions), features=infos or {}, output=output, **kw)


def _decision(policy: Policy, s, states, quartiles=None, w=None, available=None) -> Explanation:
    """One decision of ``policy``. Actions: ``s`` the contributions to the chosen action's score (the first
    available), the runner-up's (the next available) ``-s * w``, the other actions' none, an unavailable action's
    score the highest; continuous or value: ``s`` (n_features, n_outputs) or (n_features,) to each output."""
    s, names, actions = np.asarray(s, float), policy.feature_names, policy.action_names
    if policy.output != "actions":
        values = s.reshape(len(names), -1)
        base = np.full(values.shape[1], 1.5)
        avail = None
    else:
        w = np.resize(np.asarray(w if w is not None else _WEIGHTS, float), len(s))
        avail = np.ones(len(actions), bool) if available is None else np.asarray(available, bool)
        c, *others = np.flatnonzero(avail)
        values, base = np.zeros((len(names), len(actions))), np.where(avail, -5.0, 10.0)
        values[:, c] = s
        out_r = 1.0
        if others:
            values[:, others[0]] = -s * w
            base[others[0]] = 0.4
            out_r = 0.4 + values[:, others[0]].sum()
        base[c] = out_r + 0.42 - s.sum()
    categories = {f: i.categories for f, i in policy.features.items() if i.categories}
    obs = policy.observation.to_dict()
    return Explanation(
        values=values[None],
        base_values=base[None],
        outputs=(base + values.sum(axis=0))[None],
        states=np.asarray(states, float).reshape(1, -1),
        feature_names=names,
        action_names=actions,
        method="battery",
        background_quantiles=None if quartiles is None else np.asarray(quartiles, float).T,
        available=None if avail is None else avail[None],
        output=policy.output,
        observation=None if obs.get("kind") == "flat" else obs,
        categories=categories or None,
    )


def _flat(n: int, output="actions", actions=_ACTIONS):
    """The flat policy of ``n`` features, its state and background quartiles."""
    rows = list(_FLAT[:n]) + [
        (f"sensor_{j}", (-1) ** j * (0.5 + j % 3), FeatureInfo(), (-1.0, 0.0, 1.0)) for j in range(len(_FLAT), n)
    ]
    infos = {name: info for name, _, info, _ in rows if info != FeatureInfo()}
    return _policy([r[0] for r in rows], infos, actions, output), [r[1] for r in rows], [r[3] for r in rows]


def _pattern(n: int, signs, sizes=_TOP) -> np.ndarray:
    s = _rest(n)
    s[: len(signs)] = np.multiply(signs, sizes[: len(signs)])
    return s[:n]


def flat_cases() -> list[Case]:
    """The flat policy: every sign pattern of the top three, ties, zeros, one or no reason, one available action, a
    masked best action, and 1, 3 and 50 features."""
    p, x, q = _flat(5)
    cases = [
        Case(f"flat, signs {_signs(sg)}", "flat", _decision(p, _pattern(5, sg), x, q), p)
        for sg in itertools.product((1, -1), repeat=3)
    ]
    special = {
        "a tie of equal contributions": ([0.5, 0.5, -0.2, 0.04, 0.01], 0.3, None),
        "a tie of opposite contributions": ([0.5, -0.5, 0.2, -0.04, 0.01], 0.3, None),
        "zero contributions but one": ([0.8, 0.0, 0.0, 0.0, 0.0], None, None),
        "all contributions zero": ([0.0] * 5, None, None),
        "one feature alone favours the chosen action": ([0.9, -0.4, -0.3, -0.2, -0.05], None, None),
        "no feature favours the chosen action": ([-0.6, -0.3, -0.2, -0.1, -0.05], None, None),
        "one available action": (_pattern(5, (1, -1, 1)), None, [True, False, False]),
        "the best-scoring action masked": (_pattern(5, (1, -1, 1)), None, [False, True, True]),
    }
    for label, (s, w, avail) in special.items():
        cases.append(Case(f"flat, {label}", "flat", _decision(p, s, x, q, w, avail), p))
    for n, sg in ((1, (1,)), (1, (-1,)), (3, (1, -1, 1)), (50, (-1, 1, 1))):
        p, x, q = _flat(n)
        cases.append(
            Case(
                f"flat, {n} feature{'s' * (n > 1)}, signs {_signs(sg)}", "flat", _decision(p, _pattern(n, sg), x, q), p
            )
        )
    return cases


def kind_cases() -> list[Case]:
    """A dict observation, an image narrated in regions, a continuous action (each dimension on its own) and a value."""
    cases = []
    infos = {
        "pos[0]": FeatureInfo(unit="m"),
        "pos[1]": FeatureInfo(unit="m"),
        "battery[0]": FeatureInfo(unit="%", capacity=100.0),
    }
    d = _policy((), infos, observation={"pos": (2,), "battery": (1,)})
    for sg in ((1, -1, 1), (-1, 1, -1)):
        cases.append(Case(f"dict, signs {_signs(sg)}", "dict", _decision(d, _pattern(3, sg), [12.5, -7.0, 64.0]), d))
    img = _policy((), observation=(1, 12, 12))
    rng = np.random.default_rng(5)
    for sg in ((1, -1, 1), (-1, -1, 1)):
        s = np.zeros(144)
        for (r, c), x in zip(((0, 0), (6, 6), (10, 2)), np.multiply(sg, _TOP)):
            s[[r * 12 + c, r * 12 + c + 1, (r + 1) * 12 + c, (r + 1) * 12 + c + 1]] = x / 4
        exp = in_regions(_decision(img, s, rng.uniform(0, 255, 144)))
        cases.append(Case(f"image in regions, signs {_signs(sg)}", "image", exp, img))
    p, x, q = _flat(5, "continuous", ("steer", "throttle"))
    for sg in ((1, -1, 1), (-1, 1, 1)):
        s = _pattern(5, sg)
        exp = _decision(p, np.stack([s, -0.7 * s[[1, 0, 2, 3, 4]]], axis=1), x, q)
        for j, dim in enumerate(p.action_names):
            cases.append(Case(f"continuous ({dim}), signs {_signs(sg)}", "continuous", exp.output_slice(j), p))
    p, x, q = _flat(5, "value", ("value",))
    for sg in ((1, 1, 1), (-1, -1, -1), (1, -1, 1), (0, 0, 0)):
        cases.append(Case(f"value, signs {_signs(sg)}", "value", _decision(p, _pattern(5, sg), x, q), p))
    return cases


@cache
def counterfactual_cases() -> tuple[Case, ...]:
    """Decisions of the toy robot (a policy that runs: a counterfactual sentence is checked by re-running it) with
    what would have changed them, searched and written as narration writes it: two changes, and one."""
    import xairl
    from xairl.toy import toy_background, toy_policy

    p, background = toy_policy(), toy_background(30)
    exp = xairl.explain(p, toy_background(4, seed=3), background=background, method="exact")
    out = []
    for i in (0, 2):
        cf = said_counterfactual(exp, i, p, True, background)
        if cf is not None and cf.reachable:
            n = len(cf.changes)
            label = f"counterfactual, toy robot, {n} change{'s' * (n > 1)} to {cf.action}"
            out.append(Case(label, "counterfactual", exp, p, i, cf))
    return tuple(out)


def _stack(cases: list[Case]) -> Explanation:
    """One explanation of the states of ``cases`` (same policy)."""
    e = [c.explanation for c in cases]
    cat = {k: np.concatenate([getattr(x, k) for x in e]) for k in ("values", "base_values", "outputs", "states")}
    if e[0].available is not None:
        cat["available"] = np.concatenate([x.available for x in e])
    return replace(e[0], **cat)


def global_cases(decisions: list[Case]) -> list[Case]:
    """Global views (``index`` None) over the generated states of the first flat, dict and value policies."""
    out = []
    for kind in ("flat", "dict", "value"):
        policy = next(c.policy for c in decisions if c.kind == kind)
        same = [c for c in decisions if c.policy is policy]
        out.append(Case(f"global view of {len(same)} {kind} states", "global", _stack(same), policy, None))
    return out


@cache
def _load_plugin_policy(name: str, target: str):
    """(policy, None), or (None, why not) when it fails or takes longer than :data:`PLUGIN_LOAD_S`; once per
    process for a registered ``target``."""
    from xairl.registry.plugins import get_policy

    box: dict = {}

    def load():
        try:
            box["policy"] = get_policy(name)
        except Exception as exc:  # a plugin's own error, whatever it is: one line, and the battery goes on
            box["error"] = f"{type(exc).__name__}: {exc}"

    t = threading.Thread(target=load, daemon=True)
    t.start()
    t.join(PLUGIN_LOAD_S)
    if t.is_alive():
        return None, f"it took longer than {PLUGIN_LOAD_S:.0f} s to load"
    return box.get("policy"), box.get("error")


def plugin_policies() -> tuple[tuple[str, Policy | None, str | None], ...]:
    """(name, policy or None, why not) of every loaded plugin's registered policy."""
    from xairl.registry.plugins import registry

    reg = registry("policy")
    entries = [reg.entry(n) for n in reg.names()]
    return tuple((e.name, *_load_plugin_policy(e.name, repr(e.target))) for e in entries if e.plugin != "xairl")


def plugin_cases(p: Policy, name: str) -> list[Case]:
    """Two states of the plugin's policy (its background sampler's, else zeros), two sign patterns each on its first
    three reasons (no identifier, no member of a group)."""
    states = p.check_states(p.background(2, seed=7)) if p.background_sampler else np.zeros((2, p.n_features))
    members = {f for g in p.reason_groups.values() for f in g}
    info = p.features
    cols = [
        j for j, f in enumerate(p.feature_names) if f not in members and info.get(f, FeatureInfo()).kind != "identifier"
    ][:3] or [0]
    cases = []
    for i, sg in itertools.product(range(len(states)), ((1, -1, 1), (-1, 1, 1))):
        s = _rest(p.n_features, 0) * 0.5
        s[cols] = np.multiply(sg[: len(cols)], _TOP[: len(cols)])
        if p.output != "actions":
            s = np.repeat(s[:, None], p.n_actions, axis=1)
        avail = p.available(states[i : i + 1])[0] if p.output == "actions" else None
        exp = _decision(p, s, states[i], available=avail)
        views = [exp.output_slice(j) for j in range(p.n_actions)] if p.output == "continuous" else [in_regions(exp)]
        cases += [Case(f"{name}, state {i}, signs {_signs(sg)}", name, v, p) for v in views]
    return cases


def cases(outputs=("actions", "continuous", "value"), kind: str = "decision") -> tuple[list[Case], list[str]]:
    """The battery's cases for a template of ``kind`` that narrates ``outputs``, and a line for each plugin policy
    left out."""
    decisions = flat_cases() + kind_cases() + list(counterfactual_cases())
    left_out = []
    for name, policy, why in plugin_policies():
        if policy is None:
            left_out.append(f"note: plugin policy '{name}' left out of the battery: {why}")
            continue
        try:
            decisions += plugin_cases(policy, name)
        except Exception as exc:  # a plugin's data the battery cannot build on: one line, and go on
            left_out.append(f"note: plugin policy '{name}' left out of the battery: {type(exc).__name__}: {exc}")
    chosen = global_cases(decisions) if kind == "global" else decisions
    return [c for c in chosen if c.explanation.output in outputs], left_out
