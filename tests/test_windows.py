"""Windows of observations (issue 55): a policy over its last k observations is explained per slot, grouped per
signal and per step exactly, drawn as a signal x time heat map, and narrated with trend sentences whose change,
word and window are tracked facts, so a template that misstates them is contradicted."""

import json
import re

import numpy as np
import pytest
import torch
import yaml

import xairl
import xairl.policies.region_names
from xairl import plots
from xairl.policies.windows import TREND_SHARE, Window, over_time, trend

SIGNALS = ("rsrq", "load")
STEPS = 5


class Falling(torch.nn.Module):
    """Q(go) - Q(stay) = -2 (rsrq[t] - rsrq[t-4]) + 0.3 load[t]: it hands over on a falling RSRQ."""

    def __init__(self):
        super().__init__()
        self.seen = None

    def forward(self, x):
        self.seen = tuple(x.shape)
        seq = x if x.dim() == 3 else x.reshape(len(x), STEPS, len(SIGNALS))
        go = -2.0 * (seq[:, -1, 0] - seq[:, 0, 0]) + 0.3 * seq[:, -1, 1]
        return torch.stack([torch.zeros_like(go), go], dim=1)


def policy(layout="sequence", step_s=0.2):
    obs = xairl.Observation.window(SIGNALS, STEPS, layout=layout, step_s=step_s)
    info = {"rsrq": xairl.FeatureInfo("dB", "the serving RSRQ")}
    return xairl.Policy(Falling(), observation=obs, action_names=["stay", "go"], features=info)


@pytest.fixture(scope="module")
def data():
    rng = np.random.default_rng(0)
    bg = rng.normal(size=(24, STEPS, len(SIGNALS)))
    x = bg[:4].copy()
    x[0, :, 0] = np.linspace(-8.0, -12.0, STEPS)  # the serving RSRQ fell 4 dB over the window
    x[1, :, 0] = -10.0  # held: no trend
    return x, bg


@pytest.fixture(scope="module")
def exp(data):
    x, bg = data
    return xairl.explain(policy(), x, method="exact", background=bg)


def test_slots_are_named_time_major_and_the_module_gets_its_layout(data):
    x, bg = data
    p = xairl.Policy(Falling(), feature_names=list(SIGNALS), window=STEPS)
    assert p.feature_names[:2] == ("rsrq[t-4]", "load[t-4]") and p.feature_names[-2:] == ("rsrq[t]", "load[t]")
    p.scores(x)
    assert p.module.seen == (4, STEPS, 2)
    stacked = policy("stacked")
    stacked.scores(x.reshape(4, -1))
    assert stacked.module.seen == (4, STEPS * 2)
    same = [xairl.explain(q, x, method="exact", background=bg).values for q in (p, stacked)]
    np.testing.assert_allclose(same[0], same[1], atol=1e-6)


def test_a_signal_described_once_describes_its_slots():
    p = policy()
    assert p.features["rsrq[t-2]"].unit == "dB" and p.features["rsrq"].unit == "dB"


def test_grouping_per_signal_and_per_step_is_exact(exp, data):
    x, bg = data
    sig, step = exp.by_signal(), exp.by_step()
    assert sig.feature_names == SIGNALS and step.feature_names == ("t-4", "t-3", "t-2", "t-1", "t")
    for g in (sig, step):
        np.testing.assert_allclose(g.values.sum(axis=1), exp.values.sum(axis=1), atol=1e-12)
    np.testing.assert_allclose(sig.states, x[:, -1, :])  # a signal's value is its newest
    # a linear policy's exact Shapley values: w * (x - background mean), slot by slot
    mean = bg.mean(axis=0)
    want = -2.0 * ((x[:, -1, 0] - mean[-1, 0]) - (x[:, 0, 0] - mean[0, 0]))
    np.testing.assert_allclose(sig.values[:, 0, 1] - sig.values[:, 0, 0], want, atol=1e-5)  # float32 network


def test_heat_map_cells_sum_to_the_groups(exp):
    groups = exp.time_groups()
    cells = over_time(exp.margin(), *groups)
    np.testing.assert_allclose(cells.sum(axis=2), exp.by_signal().margin(), atol=1e-12)
    np.testing.assert_allclose(cells.sum(axis=1), exp.by_step().margin(), atol=1e-12)
    fig = plots.window_heatmap(exp, 0)
    labels = [t.get_text() for t in fig.axes[0].get_yticklabels()]
    assert labels[0] == "rsrq" and set(labels) == set(SIGNALS)
    assert [t.get_text() for t in fig.axes[0].get_xticklabels()] == ["t-4", "t-3", "t-2", "t-1", "t"]
    plots.window_heatmap(exp)  # the mean |contribution| over every state


def test_trend_needs_history_and_a_change():
    assert trend([0, 0, -4], [1, 1, 1]).word == "fell"
    assert trend([0, 0, 4], [0, 0, 1]).word == ""  # the newest step alone pushes: a level, not a trend
    assert trend([2, 2, 2], [1, 1, 1]).word == ""  # no change
    t = trend([0, 1, 3], [TREND_SHARE / 2, TREND_SHARE / 2, 1 - TREND_SHARE])
    assert t.word == "rose" and t.change == 3 and t.history == pytest.approx(TREND_SHARE)


def test_a_falling_signal_is_narrated_as_a_trend_and_verified(exp):
    n = xairl.narrate(exp, 0, policy=policy())
    assert "The serving RSRQ fell 4 dB over the last 0.8 s." in n.text  # its push said once, as the biggest
    assert n.verified, [c for c in n.claims if c.status != "verified"]
    facts = xairl.facts.decision_facts(exp, 0, policy())
    (f,) = facts.trends
    assert (f.name, f.trend, f.change, f.window) == ("rsrq", "fell", pytest.approx(-4.0), "the last 0.8 s")
    assert "fell" not in xairl.narrate(exp, 1, policy=policy()).text  # held still: no trend sentence


def test_a_window_is_summarised_per_signal(exp):
    g = xairl.facts.global_facts(exp, policy())
    assert {r["name"] for r in g.ranking} == set(SIGNALS)


MUTANTS = {  # a template that misstates a trend, or says it in words it did not declare: never verified
    "rose": "{{ f.label|cap }} rose {{ f.change|abs|num }} {{ f.unit }} over {{ f.window }}.",
    "value as change": "{{ f.label|cap }} {{ f.trend }} {{ f.value|abs|num }} {{ f.unit }} over {{ f.window }}.",
    "push as change": "{{ f.label|cap }} {{ f.trend }} {{ f.contribution|abs|num }} {{ f.unit }} over {{ f.window }}.",
    "change as push": "{{ f.label|cap }} pushed {{ action }} by {{ f.change|abs|num }}.",
}


RIGHT = {  # correct ways to say the same trend, each word declared: each must verify
    "right": "{{ f.label|cap }} {{ f.trend }} by {{ f.change|abs|num }} {{ f.unit }} over {{ f.window }}.",
    "went down": "{{ f.label|cap }} {{ f.change|dir('went up', 'went down') }} by {{ f.change|abs|num }} {{ f.unit }} "
    "over {{ f.window }}.",
    "decreased": "{{ f.label|cap }} {{ f.change|dir('increased', 'decreased') }} by about {{ f.change|abs|num }} "
    "{{ f.unit }}.",
    "changed": "{{ f.label|cap }} changed by {{ f.change|num }} {{ f.unit }} over {{ f.window }}.",
}


@pytest.mark.parametrize("mutant", [*MUTANTS, *RIGHT])
def test_a_misstated_trend_is_contradicted(exp, tmp_path, mutant):
    body = MUTANTS.get(mutant) or RIGHT[mutant]
    path = tmp_path / "trend.yaml"
    sentence = "{% for f in trends %}" + body + "{% endfor %}"
    path.write_text(
        yaml.safe_dump({"name": "trend", "kind": "decision", "description": "t", "sentences": [[sentence]]})
    )
    n = xairl.narrate(exp, 0, policy=policy(), template=str(path))
    assert n.verified == (mutant in RIGHT), (n.text, [c for c in n.claims if c.status == "contradicted"])


def test_frame_stack_groups_per_region_and_frame():
    torch.manual_seed(0)
    cnn = torch.nn.Sequential(torch.nn.Conv2d(4, 2, 8, 8), torch.nn.Flatten(), torch.nn.Linear(2 * 3 * 3, 2))
    p = xairl.Policy(cnn, observation=xairl.Observation.array((4, 24, 24), channels="frames"))
    rng = np.random.default_rng(1)
    e = xairl.explain(p, rng.random((2, 4, 24, 24)), method="deep_shap", background=rng.random((6, 4, 24, 24)))
    steps, regions = e.by_step(), e.by_signal()
    assert steps.feature_names == ("frame 0", "frame 1", "frame 2", "frame 3")
    side = 24 // xairl.policies.region_names.region_size(24, 24)
    assert regions.feature_names[0] == "patch A1" and len(regions.feature_names) == side * side
    for g in (steps, regions):
        np.testing.assert_allclose(g.values.sum(axis=1), e.values.sum(axis=1), atol=1e-9)


def test_a_frame_stacked_cnn_is_narrated_in_trends_over_its_frames():
    """Done-when 3's frame stack: SB3's NatureCNN over 4x84x84 frames, grouped per region and per frame (exact), drawn
    as a heat map, and narrated per region over the frames with trend sentences that both readers verify; a region's
    change is its mean pixel value's, newest frame minus oldest."""
    from gymnasium import spaces
    from stable_baselines3.common.torch_layers import NatureCNN

    torch.manual_seed(0)
    cnn = torch.nn.Sequential(
        NatureCNN(spaces.Box(0, 255, (4, 84, 84), np.uint8), features_dim=64), torch.nn.Linear(64, 3)
    )
    p = xairl.Policy(cnn, observation=xairl.Observation.array((4, 84, 84), channels="frames"))
    rng = np.random.default_rng(2)
    frames = rng.uniform(0, 255, (6, 4, 84, 84)).astype(np.float32)
    frames[:, :, :42] += np.linspace(-60, 60, 4)[None, :, None, None]  # the top half brightens frame by frame
    e = xairl.explain(p, frames[:2], background=frames[2:])
    regions = xairl.in_regions(e)
    for g in (e.by_signal(), e.by_step(), regions.by_signal(), regions.by_step()):
        np.testing.assert_allclose(g.values.sum(axis=1), e.values.sum(axis=1), rtol=1e-6, atol=1e-4)
    assert regions.feature_names[0] == "patch A1 of frame 0" and e.by_step().feature_names[-1] == "frame 3"
    patch = [f for f in regions.feature_names if f.endswith(" of frame 0")]
    j = regions.feature_names.index(patch[0])
    size = xairl.policies.region_names.region_size(84, 84)
    np.testing.assert_allclose(regions.states[0, j], frames[0, 0, :size, :size].mean(), rtol=1e-5)
    plots.window_heatmap(e, 0)
    said = 0
    for i in range(2):
        n = xairl.narrate(e, i, policy=p, robustness=False)
        assert n.verified and xairl.verify(n.text, e, i, p).accurate, n.text  # (read again as prose: nothing false)
        said += len(re.findall(r"(?:rose|fell) [\d.]+ over the last 4 frames", n.text))
    assert said >= 2


def test_the_window_survives_json(exp):
    back = xairl.Explanation.from_json(exp.to_json())
    assert back.by_signal().feature_names == SIGNALS
    assert json.loads(exp.to_json())["observation"]["parts"][0]["window"]["step_s"] == 0.2


@pytest.mark.parametrize(
    "make, says",
    [
        (lambda: Window(("a",), 1), "at least 2"),
        (lambda: Window(("a",), 2.7), "whole number"),
        (lambda: Window("rsrq", 3), "list of names"),
        (lambda: Window(("a",), 3, step_s=True), "step_s"),
        (lambda: xairl.Policy(Falling(), feature_names=list(SIGNALS), window=3, groups={"g": ["rsrq"]}), "groups"),
        (lambda: Window(("a", "a"), 3), "duplicates"),
        (lambda: Window(("a",), 3, layout="time"), "layout"),
        (lambda: Window(("a",), 3, step_s=-1), "step_s"),
        (lambda: xairl.Policy(Falling(), window=3), "feature_names"),
        (lambda: xairl.Policy(Falling(), feature_names=["a"], window=3, observation=(3, 1)), "observation"),
    ],
)
def test_bad_windows_are_refused_in_one_line(make, says):
    with pytest.raises(xairl.InputError, match=says) as err:
        make()
    assert "\n" not in str(err.value)


def test_an_explanation_without_time_is_refused_in_one_line():
    p = xairl.Policy(torch.nn.Linear(3, 2), feature_names=["a", "b", "c"])
    e = xairl.explain(p, np.ones((1, 3)), method="exact", background=np.zeros((2, 3)))
    with pytest.raises(xairl.InputError, match="not of a window"):
        e.by_signal()


def test_a_trend_word_about_a_score_is_no_trend(exp, tmp_path):
    """'the margin grew by X' (X a contribution) is no signal's change, with or without a window."""
    body = (
        "{% for f in reasons[:1] %}The margin of {{ action }} {{ f.contribution|dir('grew', 'shrank') }} by "
        "{{ f.contribution|abs|num }} from {{ f.label }}.{% endfor %}"
    )
    path = tmp_path / "m.yaml"
    path.write_text(yaml.safe_dump({"name": "m", "kind": "decision", "description": "m", "sentences": [[body]]}))
    assert xairl.narrate(exp, 0, policy=policy(), template=str(path)).verified
    torch.manual_seed(0)
    flat = xairl.Policy(torch.nn.Linear(3, 2), feature_names=["a", "b", "c"], action_names=["stay", "go"])
    e = xairl.explain(flat, np.eye(3) - np.eye(3)[::-1], method="exact", background=np.zeros((2, 3)))
    said = [xairl.narrate(e, i, policy=flat, template=str(path)) for i in range(3)]
    said = [n for n in said if n.text]  # (a decision with no reason for it says nothing here)
    assert said and all(n.verified for n in said), [n.text for n in said]


def test_the_reader_of_outside_text_reads_a_window_per_signal(exp):
    """xairl.verify on the narrative as text, from the explanation alone (JSON): the same verdict as narrate."""
    n = xairl.narrate(exp, 0, policy=policy())
    again = xairl.verify(n.text, xairl.Explanation.from_json(exp.to_json()), 0, policy())
    assert again.accurate, [(c.text, c.detail) for c in again.claims if c.status == "contradicted"]
    wrong = n.text.replace("fell 4 dB", "fell 7 dB")
    assert not xairl.verify(wrong, exp, 0, policy()).accurate


def test_changes_are_said_in_the_units_a_reader_expects(data):
    x, bg = data
    info = {"rsrq": xairl.FeatureInfo("dBm", "the serving RSRP"), "load": xairl.FeatureInfo("bit", capacity=10.0)}
    obs = xairl.Observation.window(SIGNALS, STEPS, step_s=0.2)
    p = xairl.Policy(Falling(), observation=obs, action_names=["stay", "go"], features=info)
    y = x.copy()
    y[0, :, 1] = np.linspace(2.0, 5.0, STEPS)  # the buffer fills by 3 bit of 10: 30 percentage points
    e = xairl.explain(p, y, method="exact", background=bg)
    facts = {f.name: f for f in xairl.facts.decision_facts(e, 0, p, k=2).margin_top}
    assert (facts["rsrq"].change_unit, facts["load"].change_unit) == ("dB", "percentage points")
    assert facts["load"].change == pytest.approx(30.0)
    assert xairl.narrate(e, 0, policy=p).verified


def test_a_label_has_no_trend(data):
    x, bg = data
    info = {"load": xairl.FeatureInfo(categories=("low", "mid", "high", "x", "y", "z"))}
    p = xairl.Policy(
        Falling(), observation=xairl.Observation.window(SIGNALS, STEPS), action_names=["s", "g"], features=info
    )
    y = np.abs(np.round(x)).clip(0, 5)
    e = xairl.explain(p, y, method="exact", background=np.abs(np.round(bg)).clip(0, 5))
    for i in range(len(y)):
        assert all(f.name != "load" for f in xairl.facts.decision_facts(e, i, p).trends)


def test_a_report_of_a_window_shows_signals_over_time(exp, data, tmp_path):
    from xairl.outputs.report import write_report
    from xairl.plugin import ReportContent, ReportRequest

    x, bg = data
    req = ReportRequest(out=tmp_path, method="exact", n_narrated=1, progress=False, robustness=False)
    content = ReportContent(title="w", policy=policy(), background=bg, datasets=[("sim", x)])
    html = write_report(req, content, explained={"sim": exp}).read_text()
    assert "Signals over the window (sim states)" in html and (tmp_path / "window_3.png").stat().st_size > 5000
    assert plots.readable(exp).feature_names == SIGNALS  # the beeswarm and waterfall per signal


def test_a_signal_named_like_a_score_keeps_its_trend(data, tmp_path):
    """'the gap to the lead vehicle fell by 4 m': a signal's own change, though 'gap' names a score elsewhere."""
    x, bg = data
    info = {"rsrq": xairl.FeatureInfo("m", "the gap to the lead vehicle")}
    obs = xairl.Observation.window(SIGNALS, STEPS)
    p = xairl.Policy(Falling(), observation=obs, action_names=["s", "g"], features=info)
    e = xairl.explain(p, x, method="exact", background=bg)
    body = "{% for f in trends %}{{ f.label|cap }} {{ f.trend }} by {{ f.change|abs|num }} {{ f.unit }}.{% endfor %}"
    path = tmp_path / "g.yaml"
    path.write_text(yaml.safe_dump({"name": "g", "kind": "decision", "description": "g", "sentences": [[body]]}))
    n = xairl.narrate(e, 0, policy=p, template=str(path))
    assert n.text == "The gap to the lead vehicle fell by 4 m." and n.verified, n.claims
