"""Counterfactuals under hostile input and the researcher's papercuts (issue 64): bounds at a float32's edge, nothing
that may change, a feasible callback that raises, memory per chunk of decisions, the CLI's Parquet path, small
images, masked margins, binary inputs flipped whole, a window's newest step, and words at a declared bound. Every
counterfactual returned still flips when re-run alone."""

import dataclasses
import tracemalloc

import numpy as np
import pytest
import torch

import xairl
from tests.conftest import one_line_error, run
from tests.counterfactual_cases import said
from tests.test_counterfactuals import assert_valid, flat_policy, normal
from xairl import FeatureInfo, InputError
from xairl.counterfactuals import search
from xairl.toy import toy_background, toy_policy


def flips_alone(policy, results):
    """Each counterfactual, run through the policy on its own (a batch of one), takes another action than the
    chosen one, by a finite margin."""
    for r in results:
        for cf in r.found:
            assert np.isfinite(cf.margin) and cf.margin > 0, cf
            assert policy.action_names[policy.act(cf.state[None])[0]] == cf.action != r.chosen, cf


@pytest.mark.parametrize("edge", [3.4e38, 1e39])
def test_bounds_at_the_dtypes_edge_return_only_flips(edge):
    """±3.4e38 on float32: scores overflowed to inf inside the check batch and 4 of 20 were returned with margin inf,
    keeping the original action alone; ±1e39 failed the whole search ('states contain NaN/inf')."""
    toy = toy_policy()
    policy = dataclasses.replace(toy, features={f: FeatureInfo(bounds=(-edge, edge)) for f in toy.feature_names})
    x = toy_background(20, 5)
    results = xairl.counterfactual(policy, x, index=None, background=toy_background(200, 0))
    assert sum(r.reachable for r in results) >= 10
    flips_alone(policy, results)
    assert_valid(policy, results, x)
    top = float(np.finfo(np.float32).max)
    assert all(abs(c.after) <= top for r in results for cf in r.found for c in cf.changes)


def test_inf_inf_bounds_are_refused_in_one_line():
    for bad in ((np.inf, np.inf), (-np.inf, -np.inf)):
        with pytest.raises(InputError, match="hold no value") as info:
            FeatureInfo(bounds=bad)
        assert "\n" not in str(info.value)
    assert FeatureInfo(bounds=(-np.inf, np.inf)).bounds == (-np.inf, np.inf)


def test_nothing_that_may_change_is_the_searchs_own_answer():
    policy = flat_policy(
        features={f: FeatureInfo(immutable=True) for f in "abc"} | {"d": FeatureInfo(kind="identifier")}
    )
    results = xairl.counterfactual(policy, normal(3), index=None, background=normal(50))
    assert all(not r.reachable and r.reason.startswith("no feature may change") for r in results)


def _raises(states):
    raise ValueError("the map is not loaded")


#: a --policy file.py:make whose feasible callback raises
RAISING = """import dataclasses
from xairl.toy import toy_policy


def _raises(states):
    raise ValueError("the map is not loaded")


def make():
    return dataclasses.replace(toy_policy(), feasible=_raises)
"""


def test_a_feasible_that_raises_is_one_line_naming_it(capsys, tmp_path):
    policy = flat_policy(feasible=_raises)
    with pytest.raises(InputError) as info:
        xairl.counterfactual(policy, normal(2), background=normal(50))
    words = str(info.value)
    assert "feasible callback raised ValueError: the map is not loaded" in words and "\n" not in words
    (tmp_path / "raising.py").write_text(RAISING)
    rc, _, err = run(capsys, "explain", "--policy", f"{tmp_path / 'raising.py'}:make", "--n", "2", "--counterfactual")
    one_line_error(rc, err, "feasible callback raised ValueError")


def test_memory_is_held_per_chunk_of_decisions(monkeypatch):
    """Every decision's pair grids were built at once (about 1.15 MB a decision: 6,000 toy states ran out of memory);
    searched CHUNK decisions at a time, 4 times the decisions peak at about the same memory."""
    monkeypatch.setattr(search, "CHUNK", 8, raising=False)
    policy, bg = flat_policy(), normal(200)
    x = normal(32, seed=11)
    exp = xairl.explain(policy, x, bg[:50], method="integrated_gradients")

    def peak(k: int) -> int:
        tracemalloc.start()
        xairl.counterfactual(policy, x[:k], index=None, background=bg, explanation=exp[:k])
        top = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        return top

    one, four = peak(8), peak(32)
    assert four < 1.5 * one, (one, four)


def test_the_cli_refuses_counterfactuals_it_would_not_search(capsys, tmp_path):
    """--counterfactual was silently ignored with --format parquet (and so --out above 50,000 states), and a bad
    --counterfactual-target with it: refused in one line, the target in every format."""
    rc, _, err = run(
        capsys, "explain", "--n", "3", "--format", "parquet", "--out", str(tmp_path / "p"), "--counterfactual"
    )
    one_line_error(rc, err, "--counterfactual", "Parquet")
    for fmt in (["--format", "table"], ["--format", "jsonl"], ["--format", "parquet", "--out", str(tmp_path / "q")],
                ["--out", str(tmp_path / "r")]):  # fmt: skip
        rc, _, err = run(capsys, "explain", "--n", "2", *fmt, "--counterfactual-target", "jump")
        one_line_error(rc, err, "action 'jump' is unknown")
    assert not (tmp_path / "r" / "report.html").exists()
    # --counterfactual-past alone turns the search on (was: silently ignored), and is refused with Parquet too
    rc, out, _ = run(capsys, "explain", "--n", "2", "--counterfactual-past")
    assert rc == 0 and "what would have changed it" in out, out
    rc, _, err = run(
        capsys, "explain", "--n", "2", "--format", "parquet", "--out", str(tmp_path / "s"), "--counterfactual-past"
    )
    one_line_error(rc, err, "--counterfactual", "Parquet")


def test_a_small_image_takes_the_regions_path():
    """A 1x32x32 image (1,024 columns) took the narrow state's 41x41 pair grids over its regions: 79,857 forward
    passes a decision."""
    torch.manual_seed(1)
    net = torch.nn.Sequential(
        torch.nn.Conv2d(1, 4, 4, 4), torch.nn.ReLU(), torch.nn.Flatten(), torch.nn.Linear(4 * 8 * 8, 3)
    ).eval()
    policy = xairl.Policy(net, observation=(1, 32, 32), name="small")
    frames = np.random.default_rng(2).uniform(0, 1, (41, 1, 32, 32)).astype(np.float32)
    r = xairl.counterfactual(policy, frames[:1], background=frames[1:], target="any")
    assert r.evaluations < 10_000, r.evaluations
    assert_valid(policy, r)


def test_a_masked_counterfactuals_margin_is_over_an_allowed_action():
    """Where the mask left one action, the margin was its lead over the masked ones: negative. A flip now leaves
    at least two allowed, and its margin is over the best other allowed one."""
    mask = lambda s: np.stack([s[:, 0] >= 0, s[:, 0] >= 0, np.ones(len(s), bool)], axis=1)  # noqa: E731
    policy = flat_policy(action_mask=mask)
    x = normal(20, seed=1)
    results = xairl.counterfactual(policy, x, index=None, background=normal(200), target="any", n=3)
    assert any(r.reachable for r in results)
    for r in results:
        for cf in r.found:
            allowed = policy.available(cf.state[None])[0]
            scores = np.where(allowed, policy.scores(cf.state[None])[0], -np.inf)
            a = policy.action_names.index(cf.action)
            assert allowed.sum() >= 2 and cf.margin == pytest.approx(scores[a] - np.delete(scores, a).max(), abs=1e-5)
            assert cf.margin > 0
    assert_valid(policy, results, x)


def binary_policy():
    """'go' wins where 2 leg + 0.3 u - 1.2 > 0: with the leg off, u would need to exceed 4, so the leg matters."""
    lin = torch.nn.Linear(3, 2).double()
    with torch.no_grad():
        lin.weight.copy_(torch.tensor([[0.0, 0.0, 0.0], [2.0, 0.3, 0.1]], dtype=torch.float64))
        lin.bias.copy_(torch.tensor([0.0, -1.2], dtype=torch.float64))
    return xairl.Policy(lin, feature_names=["leg", "u", "v"], action_names=["stop", "go"])


def test_a_binary_input_flips_only_whole():
    """A leg contact went 0 -> 0.85 in 53 of 100 LunarLander decisions: a feature whose background takes two values
    moves only from one to the other."""
    rng = np.random.default_rng(3)
    bg = np.stack([rng.random(300) < 0.2, rng.normal(size=300), rng.normal(size=300)], 1).astype(float)
    x = np.stack([np.zeros(15), rng.normal(size=15), rng.normal(size=15)], 1)
    policy = binary_policy()
    results = xairl.counterfactual(policy, x, index=None, background=bg, n=3)
    legs = [c.after for r in results for cf in r.found for c in cf.changes if c.feature == "leg"]
    assert len(legs) >= 10 and set(legs) == {1.0}, legs
    assert_valid(policy, results, x)


def window_policy():
    """An MLP over 3 steps of (speed, gap), weighing the oldest step most."""
    lin = torch.nn.Linear(6, 2)
    with torch.no_grad():
        lin.weight.copy_(torch.tensor([[3.0, -3.0, 0.5, 0.0, 0.5, -0.5], [-3.0, 3.0, 0.0, 0.5, -0.5, 0.5]]))
        lin.bias.zero_()
    return xairl.Policy(torch.nn.Sequential(torch.nn.Flatten(), lin), feature_names=["speed", "gap"], window=3)


def test_a_window_changes_its_newest_step_unless_asked():
    """13 of 20 window counterfactuals changed only a past slot: a history the present cannot have."""
    policy = window_policy()
    w, wbg = normal(20, 6, seed=10), normal(200, 6)
    now = xairl.counterfactual(policy, w, index=None, background=wbg, target="any")
    assert sum(r.reachable for r in now) >= 10
    assert {c.feature for r in now for cf in r.found for c in cf.changes} <= {"speed[t]", "gap[t]"}
    assert_valid(policy, now, w)
    back = xairl.counterfactual(policy, w, index=None, background=wbg, target="any", past=True)
    assert any(c.feature.endswith("[t-2]") for r in back for cf in r.found for c in cf.changes)
    assert_valid(policy, back, w)
    named = xairl.counterfactual(policy, w, index=0, background=wbg, target="any", features=["speed[t-1]"])
    assert {c.feature for cf in named.found for c in cf.changes} <= {"speed[t-1]"}  # a past slot named is asked for
    with pytest.raises(InputError, match="past is True"):
        xairl.counterfactual(policy, w, background=wbg, past="yes")


def test_a_value_at_its_declared_bound_is_said_at_it():
    """'had the serving BS's RSRQ been below -34 dB' where the bounds stop at -34 dB: a value rounded onto its bound
    is said at it, with no direction word, and still verified by the re-run."""
    from xairl.counterfactual_facts import counterfactual_fact

    lin = torch.nn.Linear(2, 2).double()
    with torch.no_grad():  # 'go' wins where rsrq < -33.985, within 0.015 dB of the floor
        lin.weight.copy_(torch.tensor([[0.0, 0.0], [-1.0, 0.0]], dtype=torch.float64))
        lin.bias.copy_(torch.tensor([0.0, -33.985], dtype=torch.float64))
    info = {"rsrq": FeatureInfo("dB", "the serving RSRQ", bounds=(-34.0, -3.0)), "load": FeatureInfo(immutable=True)}
    policy = xairl.Policy(lin, ["rsrq", "load"], ["stay", "go"], features=info, name="lin")
    rng = np.random.default_rng(0)
    bg, x = np.stack([rng.uniform(-34, -3, 300), rng.normal(size=300)], 1), np.array([[-20.0, 0.0]])
    exp = xairl.explain(policy, x, bg[:50])
    fact = counterfactual_fact(exp, 0, policy, xairl.counterfactual(policy, x, background=bg, explanation=exp, n=3))
    (change,) = fact.changes
    assert change.after == -34.0 and change.direction == "" and change.after_text == "-34 dB"
    text, status, _ = said(exp, 0, policy, fact, alone=True)
    assert "been -34 dB" in text and "below -34" not in text and status == "verified", text


#: a --policy file.py:make of :func:`window_policy`
WINDOW = """import torch, xairl


def make():
    lin = torch.nn.Linear(6, 2)
    with torch.no_grad():
        lin.weight.copy_(torch.tensor([[3.0, -3.0, 0.5, 0.0, 0.5, -0.5], [-3.0, 3.0, 0.0, 0.5, -0.5, 0.5]]))
        lin.bias.zero_()
    return xairl.Policy(torch.nn.Sequential(torch.nn.Flatten(), lin), feature_names=["speed", "gap"], window=3)
"""


def test_the_cli_changes_a_windows_past_only_when_asked(capsys, tmp_path):
    import json

    (tmp_path / "w.py").write_text(WINDOW)
    rng = np.random.default_rng(0)
    np.save(tmp_path / "s.npy", rng.normal(size=(6, 3, 2)).astype(np.float32))
    np.save(tmp_path / "bg.npy", rng.normal(size=(100, 3, 2)).astype(np.float32))
    common = ["explain", "--policy", f"{tmp_path / 'w.py'}:make", "--states", str(tmp_path / "s.npy")]
    common += ["--background", str(tmp_path / "bg.npy"), "--counterfactual-target", "any", "--format", "jsonl"]
    changed = {}
    for flag in ([], ["--counterfactual-past"]):
        rc, out, err = run(capsys, *common, *flag)
        assert rc == 0, err
        lines = [json.loads(line)["counterfactual"] for line in out.splitlines()]
        changed[bool(flag)] = {c["feature"] for d in lines for f in d["found"] for c in f["changes"]}
    assert changed[False] and changed[False] <= {"speed[t]", "gap[t]"}
    assert {"speed[t-2]", "gap[t-2]"} <= changed[True]


def test_a_decision_whose_outputs_are_not_finite_is_refused_in_one_line(monkeypatch):
    """As explain refuses it: a state that overflows the float32 network has no decision to change (named by its row,
    not its place in its chunk)."""
    monkeypatch.setattr(search, "CHUNK", 2)
    policy, bg = toy_policy(), toy_background(100, 0)
    x = toy_background(3, 1)
    x[2] = 3e38
    exp = xairl.explain(policy, x[:2], bg)
    with pytest.raises(InputError, match="NaN or infinite for 1 state.* first state 2:") as info:
        xairl.counterfactual(policy, x, index=None, background=bg, explanation=exp[[0, 1, 1]])
    assert "\n" not in str(info.value)
