"""The public plotting module: each function returns a matplotlib Figure labelled with its view, and a decision's
waterfall shows the numbers of the narrative's evidence card."""

import numpy as np
import pytest
from matplotlib.figure import Figure

import xairl
from xairl import plots
from xairl.explanations.evidence import evidence
from xairl.toy import toy_policy


@pytest.fixture(scope="module")
def exp():
    p = toy_policy()
    return xairl.explain(p, p.background(12, seed=1), background=p.background(40, seed=2))


def _texts(fig) -> str:
    return " ".join(
        t.get_text()
        for ax in fig.axes
        for t in [ax.xaxis.label, ax.yaxis.label, ax.title] + ax.get_yticklabels() + ax.texts
    )


def test_each_figure_names_its_view(exp):
    for make in (plots.beeswarm, plots.importance, plots.waterfall, plots.timeline):
        margin, score = make(exp), make(exp, view="score")
        assert isinstance(margin, Figure) and isinstance(score, Figure)
        assert "margin" in _texts(margin) and "chosen action's score" in _texts(score), make.__name__


def test_waterfall_steps_are_the_cards_contributions(exp):
    i = 3
    narrative = xairl.narrate(exp, i)
    card = evidence(exp, narrative)
    fig = plots.waterfall(exp, i, shown=20)
    drawn = [float(t.get_text()) for t in fig.axes[0].texts]
    assert drawn == pytest.approx([float(f"{f['contribution']:.3g}") for f in card["features"]])
    assert f"{card['base']:.3g}" in fig.axes[0].get_xlabel() and f"{card['output']:.3g}" in fig.axes[0].get_xlabel()


def test_side_by_side_panels_share_one_order_and_save_writes_png(exp, tmp_path):
    fig = plots.beeswarm([("first half", exp), ("again", exp)])
    assert [ax.get_title() for ax in fig.axes[:2]] == ["first half", "again"]
    names = [[t.label1.get_text() for t in ax.yaxis.get_major_ticks()] for ax in fig.axes[:2]]
    assert names[0] == names[1] and len(names[0]) == 5
    assert fig.axes[1].get_yticklabels() == []  # the shared order's names once, at the left
    path = plots.save(fig, tmp_path / "b.png")
    assert path.read_bytes()[:4] == b"\x89PNG"


def test_image_needs_an_image_and_a_valid_index(exp):
    with pytest.raises(xairl.InputError, match="image observation"):
        plots.image(exp)
    with pytest.raises(xairl.InputError):
        plots.waterfall(exp, 99)
    with pytest.raises(xairl.InputError, match="margin, score"):
        plots.beeswarm(exp, view="chosen")


def test_contributions_in_the_margin_view_add_up_to_the_margin(exp):
    c = plots.contributions(exp)
    idx = np.arange(len(c))
    margin = exp.outputs[idx, exp.chosen] - exp.outputs[idx, exp.runner_up]
    expected = exp.base_values[idx, exp.chosen] - exp.base_values[idx, exp.runner_up]
    assert np.allclose(expected + c.sum(axis=1), margin, atol=1e-4)


def _inside(fig) -> bool:
    """Whether everything drawn lies within the figure (a clipped label runs past an edge of the PNG)."""
    fig.canvas.draw()
    box = fig.get_tightbbox(fig.canvas.get_renderer())
    return box.x0 >= -0.01 and box.x1 <= fig.get_figwidth() + 0.01 and box.y0 >= -0.01


def test_a_waterfalls_axis_label_is_never_clipped(exp):
    """The UAV DQN's waterfall label ('margin of handover_to_candidate_1 over stay: expected -28.7 -> this state
    5.62') ran past the figure's right edge: the figure widens to hold it."""
    import dataclasses

    long = dataclasses.replace(exp, action_names=[f"handover_to_candidate_{k}_of_the_neighbour_list" for k in range(3)])
    for e in (exp, long):
        assert _inside(plots.waterfall(e, 3)), e.action_names


def test_side_by_side_beeswarms_share_one_x_scale(exp):
    p = toy_policy()
    calm = np.repeat(p.background(40, seed=2).mean(axis=0, keepdims=True), 6, axis=0)  # small contributions
    near = xairl.explain(p, calm + 0.01 * np.arange(6)[:, None], background=p.background(40, seed=2))
    fig = plots.beeswarm([("spread", exp), ("calm", near)])
    lims = [ax.get_xlim() for ax in fig.axes[:2]]
    assert lims[0] == lims[1] and np.abs(contributions_of(near)).max() < 0.5 * np.abs(contributions_of(exp)).max()


def contributions_of(e):
    return plots.contributions(e)


def test_a_beeswarm_greys_an_identifier_and_colours_quantities(exp):
    """An id (a serving cell's number) has no low or high: its dots are one grey, a quantity's run blue to red."""
    from types import SimpleNamespace

    ident = exp.feature_names[0]
    policy = SimpleNamespace(features={ident: xairl.FeatureInfo("", "the cell's id", kind="identifier")})
    fig = plots.beeswarm(exp, policy=policy)
    ax = fig.axes[0]
    rows = [t.get_text() for t in ax.get_yticklabels()]
    colours = {rows[k]: np.unique(c.get_facecolors().round(3), axis=0) for k, c in enumerate(ax.collections)}
    assert len(colours[ident]) == 1 and all(len(v) > 1 for f, v in colours.items() if f != ident)
    assert ident in fig.axes[-1].get_ylabel()  # the colour bar says which is grey
