"""The public plotting module: each function returns a matplotlib Figure labelled with its view, and a decision's
waterfall shows the numbers of the narrative's evidence card."""

import numpy as np
import pytest
from matplotlib.figure import Figure

import xairl
from xairl import plots
from xairl.evidence import evidence
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
