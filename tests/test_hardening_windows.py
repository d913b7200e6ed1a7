"""Windows and observations under hostile input (issue 64): an explanation read back whose observation contradicts
its names or its own kind, empty window states, absurd window lengths and slot-like signal names are each refused
in one line."""

import json
import time

import numpy as np
import pytest
import torch

import xairl
from xairl.observation import Observation
from xairl.windows import MAX_SLOTS, Window


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
        with pytest.raises(xairl.InputError, match="states is empty: give at least one state"):
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
    assert "states is empty" in err and "internal error" not in err and len(err.splitlines()) == 1


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
    wrong = n.text.replace("fell 2 dB over the last 0.4 s", "fell 12 dB over the last 0.8 s")
    assert not xairl.verify(wrong, e, 0, p).accurate  # the padding's 'change' is refused
    assert xairl.facts.decision_facts(e, 1, p).trends == () and " fell " not in xairl.narrate(e, 1, policy=p).text
