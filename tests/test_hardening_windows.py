"""Windows and observations under hostile input (issue 64): an explanation read back whose observation contradicts
its names or its own kind, empty window states, absurd window lengths and slot-like signal names are each refused
in one line."""

import json
import time

import numpy as np
import pytest
import torch

import xairl
from xairl.policies.observation import Observation
from xairl.policies.windows import MAX_SLOTS, Window


class Sum(torch.nn.Module):
    def forward(self, *xs):
        x = torch.cat([x.reshape(len(x), -1) for x in xs], dim=1)
        return torch.stack([x.sum(1), -0.5 * x.sum(1)], 1)


@pytest.fixture(scope="module")
def window_json():
    """An explanation of a window of 4 steps x a, b, c, as JSON."""
    p = xairl.Policy(Sum(), feature_names=["a", "b", "c"], window=4)
    rng = np.random.default_rng(0)
    e = xairl.explain(p, rng.normal(size=(2, 4, 3)), method="kernel_shap", background=rng.normal(size=(5, 4, 3)))
    return json.loads(e.to_json())


def part(shape, key="obs", **more):
    return {"key": key, "shape": shape, "categories": None} | more


EDITS = {  # an observation edited into one that contradicts the names or its kind -> what the line says
    "3 steps x a, b, c, d": (
        {
            "kind": "window",
            "parts": [part([3, 4], window={"signals": ["a", "b", "c", "d"], "steps": 3, "layout": "sequence"})],
        },
        "column 0 is named 'a[t-3]'",
    ),
    "flat [12, 1]": ({"kind": "flat", "parts": [part([12, 1])]}, "one vector"),
    "array [12]": ({"kind": "array", "parts": [part([12])]}, "2 axes or more"),
    "tuple of one part": ({"kind": "tuple", "parts": [part([12], "input0")]}, "has one part"),
    "dict of a key twice": ({"kind": "dict", "parts": [part([6], "x"), part([6], "x")]}, "names key 'x' twice"),
    "dict of one part, names of two": ({"kind": "dict", "parts": [part([12], "x")]}, "column 6 is named 'y[0]'"),
}


@pytest.mark.parametrize("edit", EDITS)
def test_an_observation_that_contradicts_the_names_is_refused_when_read(window_json, edit):
    """Was: accepted, regrouped, and narrated verified ('D fell 0.06 over the last 3 observations')."""
    observation, says = EDITS[edit]
    data = dict(window_json, observation=observation)
    if edit.startswith("dict of one part"):
        data["feature_names"] = [f"x[{i}]" for i in range(6)] + [f"y[{i}]" for i in range(6)]
    with pytest.raises(xairl.InputError, match=says.replace("[", r"\[")) as err:
        xairl.Explanation.from_json(json.dumps(data))
    assert "\n" not in str(err.value)


def test_a_key_given_twice_in_the_json_is_refused(window_json):
    text = json.dumps(window_json)
    twice = text.replace('"method": ', '"method": "exact", "method": ', 1)
    with pytest.raises(xairl.InputError, match="key 'method' is given twice"):
        xairl.Explanation.from_json(twice)


def test_consistent_observations_still_read_back(window_json):
    back = xairl.Explanation.from_json(json.dumps(window_json))
    assert back.by_signal().feature_names == ("a", "b", "c")
    own = dict(window_json, feature_names=[f"slot {j}" for j in range(12)])  # names of one's own say nothing
    assert xairl.Explanation.from_json(json.dumps(own)).feature_names[0] == "slot 0"
    two = xairl.Policy(Sum(), observation=[(4,), (2,)])
    rng = np.random.default_rng(1)
    e = xairl.explain(two, rng.normal(size=(2, 6)), method="exact", background=rng.normal(size=(4, 6)))
    assert xairl.Explanation.from_json(e.to_json()).observation["kind"] == "tuple"


@pytest.mark.parametrize(
    "make, says",
    [
        (lambda: Observation.array((5,)), "Observation.flat"),
        (lambda: Observation.several([(5,)]), "2 shapes or more"),
        (lambda: xairl.Policy(torch.nn.Linear(5, 2), observation=[(5,)]), "2 shapes or more"),
    ],
)
def test_a_one_axis_array_and_a_one_input_tuple_are_refused_when_made(make, says):
    """What a saved explanation may not hold, no policy makes: it would be refused when read back."""
    with pytest.raises(xairl.InputError, match=says):
        make()


def test_empty_window_states_are_one_line(tmp_path, capsys):
    """Was: 'internal error: ValueError: cannot reshape array of size 0', exit 1; now as for empty flat states."""
    p = xairl.Policy(Sum(), feature_names=["a", "b", "c"], window=4)
    bg = np.zeros((3, 4, 3))
    for states in (np.zeros((0, 4, 3)), np.zeros((0, 12))):
        with pytest.raises(xairl.InputError, match="states are empty: give at least one state"):
            xairl.explain(p, states, method="exact", background=bg)
    d = xairl.Observation.dict({"image": (2, 3, 3), "v": (1,)}, categories={"v": 3})
    with pytest.raises(xairl.InputError, match="is empty"):
        d.flatten({"image": np.zeros((0, 2, 3, 3)), "v": np.zeros((0, 1))})
    np.save(tmp_path / "empty.npy", np.zeros((0, 4, 3)))
    np.save(tmp_path / "bg.npy", bg)
    (tmp_path / "pol.py").write_text(
        "import torch, xairl\n"
        "def make():\n"
        "    return xairl.Policy(torch.nn.Sequential(torch.nn.Flatten(), torch.nn.Linear(12, 2)),\n"
        "                        feature_names=['a', 'b', 'c'], window=4)\n"
    )
    from xairl.cli import main

    args = ["explain", "--policy", f"{tmp_path / 'pol.py'}:make", "--states", str(tmp_path / "empty.npy")]
    assert main([*args, "--background", str(tmp_path / "bg.npy"), "--method", "exact"]) == 2
    err = capsys.readouterr().err.strip()
    assert "states are empty" in err and "internal error" not in err and len(err.splitlines()) == 1


@pytest.mark.parametrize("steps, signals", [(10**8, ("a",)), (MAX_SLOTS // 2 + 1, ("a", "b"))])
def test_an_absurd_window_length_is_refused_at_once(steps, signals):
    """Was: window=10**8 built every slot's name until MemoryError."""
    start = time.perf_counter()
    with pytest.raises(xairl.InputError, match="slots, more than the 1,000,000") as err:
        xairl.Policy(Sum(), feature_names=list(signals), window=steps)
    assert time.perf_counter() - start < 1 and "\n" not in str(err.value)
    assert Window(signals, MAX_SLOTS // len(signals)).steps == MAX_SLOTS // len(signals)  # the cap itself is taken


def test_slot_like_names_are_refused():
    """'a[t-1]' beside signal 'a' named two columns alike ambiguously: a signal named as a slot, and a column named as
    another slot than it holds, are both refused."""
    with pytest.raises(xairl.InputError, match="named like a slot"):
        xairl.Policy(Sum(), feature_names=["a", "a[t-1]"], window=3)
    with pytest.raises(xairl.InputError, match="named like a slot"):
        Window(("patch A1 of frame 2", "b"), 2)
    obs = xairl.Observation.window(["a", "b"], 2)
    with pytest.raises(xairl.InputError, match=r"column 0 is named 'a\[t\]' but, .* it holds a\[t-1\]"):
        xairl.Policy(Sum(), observation=obs, feature_names=["a[t]", "x", "y", "z"])
    own = xairl.Policy(Sum(), observation=obs, feature_names=["a old", "b old", "a[t]", "b[t]"])
    assert own.feature_names[2] == "a[t]"  # a slot's own name at its own column is fine


class Mean(torch.nn.Module):
    """Q(go) - Q(stay) = -(the mean of rsrq over the window) + 0.1 load[t]: every step pushes."""

    def forward(self, x):
        seq = x.reshape(len(x), 5, 2)
        go = -seq[:, :, 0].mean(dim=1) + 0.1 * seq[:, -1, 1]
        return torch.stack([torch.zeros_like(go), go], dim=1)


def test_a_frame_stacks_padding_after_a_reset_is_no_trend():
    """Was: SB3's VecFrameStack fills the steps before an episode's first observations with zeros, and a signal
    'fell' from them ('Pole_angle fell 0.04'). The trend is said over the observed steps only, and both readers
    check it there; a window whose newest step alone is observed says no trend."""
    obs = xairl.Observation.window(["rsrq", "load"], 5, step_s=0.2)
    info = {"rsrq": xairl.FeatureInfo("dB", "the serving RSRQ")}
    p = xairl.Policy(Mean(), observation=obs, action_names=["stay", "go"], features=info)
    x = np.zeros((2, 5, 2))
    x[0, 2:, 0], x[0, 2:, 1] = [-10.0, -11.0, -12.0], 1.0  # two steps of padding, then 3 observations
    x[1, 4] = [-12.0, 1.0]  # just reset: only the newest step observed
    bg = np.random.default_rng(0).normal(-10.0, 1.0, size=(8, 5, 2))
    e = xairl.explain(p, x, method="exact", background=bg)
    (f,) = xairl.facts.decision_facts(e, 0, p).trends
    assert (f.trend, f.change, f.window) == ("fell", pytest.approx(-2.0), "the last 0.4 s")  # not 12 over 0.8 s
    n = xairl.narrate(e, 0, policy=p)
    assert "The serving RSRQ fell 2 dB over the last 0.4 s" in n.text and n.verified, n.text
    again = xairl.verify(n.text, xairl.Explanation.from_json(e.to_json()), 0, p)
    assert again.accurate, [(c.text, c.detail) for c in again.claims if c.status == "contradicted"]
    wrong = n.text.replace("fell 2 dB over the last 0.4 s", "fell 5 dB over the last 0.4 s")
    assert not xairl.verify(wrong, e, 0, p).accurate  # the change is checked over the observed steps
    assert xairl.facts.decision_facts(e, 1, p).trends == () and " fell " not in xairl.narrate(e, 1, policy=p).text


def test_a_trends_push_is_said_once(tmp_path):
    """Was: 'The biggest push ... came from the serving RSRQ (-12 dB), by +7.40. The serving RSRQ fell 4 dB over the
    last 0.8 s (now -12 dB), which favoured go by 7.40.': the same push twice. A trend already said as a reason (or
    as the concession) says its change only; one said nowhere else keeps its push."""
    obs = xairl.Observation.window(["rsrq", "load"], 5, step_s=0.2)
    info = {"rsrq": xairl.FeatureInfo("dB", "the serving RSRQ")}
    p = xairl.Policy(Mean(), observation=obs, action_names=["stay", "go"], features=info)
    x = np.zeros((1, 5, 2))
    x[0, :, 0], x[0, :, 1] = np.linspace(-8.0, -12.0, 5), 1.0
    bg = np.random.default_rng(0).normal(size=(8, 5, 2))
    e = xairl.explain(p, x, method="exact", background=bg)
    facts = xairl.facts.decision_facts(e, 0, p)
    (f,) = facts.trends
    assert f.name == facts.reasons[0].name
    n = xairl.narrate(e, 0, policy=p)
    assert "fell 4 dB over the last 0.8 s." in n.text and "which favoured go" not in n.text and n.verified, n.text
    body = "{% for f in trends %}{{ f.label|cap }} {{ f.trend }} {{ f.change|abs|num }} {{ f.unit }} over {{ f.window }}, which {{ f|dir('favoured', 'went against') }} {{ action }} by {{ f.contribution|abs|num }}.{% endfor %}"
    (tmp_path / "t.yaml").write_text(json.dumps({"name": "t", "kind": "decision", "sentences": [[body]]}))
    alone = xairl.narrate(e, 0, policy=p, template=str(tmp_path / "t.yaml"))  # a trend said nowhere else: its push
    assert "which favoured go by" in alone.text and alone.verified, alone.text


class Cancels(torch.nn.Module):
    """Over 3 steps of a, b, c, d, e: a, b and c push go at their newest step, d against it, and e's two newest steps
    push hard both ways (3 e[t] - 2.8 e[t-1]): its slots are the heat map's darkest, its sum the smallest."""

    def forward(self, x):
        s = x.reshape(len(x), 3, 5)
        go = 1.0 * s[:, -1, 0] + 0.8 * s[:, -1, 1] + 0.6 * s[:, -1, 2] - 0.5 * s[:, -1, 3]
        go = go + 3.0 * s[:, -1, 4] - 2.8 * s[:, -2, 4]
        return torch.stack([torch.zeros_like(go), go], dim=1)


def test_a_signal_whose_steps_cancel_is_said_to_pull_both_ways():
    """Was: a signal whose sum was 6 % of its slots' sizes was ranked last, unexplained, while the heat map showed it
    darkest. Its steps 'pulled both ways', a fact (FeatureFact.steps, DecisionFacts.both_ways) the template says
    and both readers accept; a signal whose steps agree is never said so."""
    names = ["a", "b", "c", "d", "e"]
    p = xairl.Policy(Cancels(), feature_names=names, window=3, action_names=["stay", "go"])
    x = np.ones((1, 3, 5))
    x[0, :, 4] = [1.0, 2.0, 2.0]
    e = xairl.explain(p, x, method="exact", background=np.zeros((3, 3, 5)))
    facts = xairl.facts.decision_facts(e, 0, p)
    (f,) = facts.both_ways
    slots = e.margin()[0, 4::5]
    assert f.name == "e" and f.steps == "pulled both ways" and abs(slots.sum()) < 0.1 * np.abs(slots).sum()
    assert f.rank == 5 and all(not g.steps for g in facts.margin_top)
    n = xairl.narrate(e, 0, policy=p)
    assert "E's steps pulled both ways: they nearly cancelled, together +0.40 to the margin." in n.text, n.text
    assert n.verified, [(c.text, c.detail) for c in n.claims if c.status != "verified"]
    again = xairl.verify(n.text, xairl.Explanation.from_json(e.to_json()), 0, p)
    assert again.accurate, [(c.text, c.detail) for c in again.claims if c.status == "contradicted"]
    x[0, :, 4] = [1.0, 1.0, 2.0]  # e's newest step outweighs: its steps no longer cancel
    agree = xairl.explain(p, x, method="exact", background=np.zeros((3, 3, 5)))
    assert xairl.facts.decision_facts(agree, 0, p).both_ways == ()
