"""A long run says what it is doing (issue 64, the newcomer's first hour: `make demo` printed nothing for 97 s, then
for 124 s): a report's long steps are said on stderr, so that it is never silent for more than 10 s, whether stderr
is a terminal or not; a quick step says nothing (its error stays one line). (The UAV report's own steps: plugins/xairl-uav-handover/tests/test_uav_real_data.py.)"""

import re
import time

import pytest
import torch

import xairl
from xairl.explanations import display
from xairl.explanations.display import heartbeat
from xairl.outputs.report import ReportContent, ReportRequest, write_report
from xairl.toy import ACTIONS, FEATURES, toy_background, toy_network


def test_a_long_step_is_said_and_then_every_interval_a_quick_one_is_not(capsys):
    assert display.EVERY == 10.0  # the demo's "at least every 10 s"
    with heartbeat("a quick step", every=0.5):
        pass
    with heartbeat("an outer step", every=0.05):
        with heartbeat("an inner step", every=0.05):
            time.sleep(0.5)
        time.sleep(0.3)
    lines = capsys.readouterr().err.splitlines()
    assert lines[0] == "xairl: an inner step ..." and not any("quick" in line for line in lines), lines
    inner = next(i for i, line in enumerate(lines) if line.startswith("xairl: an inner step: done in "))
    assert sum(line.startswith("xairl: still an inner step (") for line in lines[:inner]) >= 3, lines
    assert not any("outer" in line for line in lines[:inner])  # the innermost step alone speaks
    assert lines[inner + 1] == "xairl: an outer step ..." and lines[-1].startswith("xairl: an outer step: done in ")


def test_nothing_is_said_when_disabled_and_a_step_that_fails_is_not_said_done(capsys):
    with heartbeat("quiet", enabled=False, every=0.01):
        time.sleep(0.1)
    with pytest.raises(ValueError), heartbeat("failing at once", every=0.05):
        raise ValueError("no")  # an error in a quick step: its line alone on stderr
    with pytest.raises(ValueError), heartbeat("failing", every=0.05):
        time.sleep(0.2)
        raise ValueError("no")
    err = capsys.readouterr().err
    assert "quiet" not in err and "at once" not in err and "xairl: failing ..." in err and "done" not in err


class _Slow(torch.nn.Module):
    """The toy network, 20 ms a forward pass: every step of the report lasts long beyond its heartbeat's interval
    however loaded the machine (a thread that must be scheduled in time is not what this test is about)."""

    def __init__(self):
        super().__init__()
        self.net = toy_network()

    def forward(self, x):
        time.sleep(0.02)
        return self.net(x)


@pytest.mark.slow
def test_a_report_says_each_of_its_long_steps(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(display, "EVERY", 0.01)  # every step is long at this scale
    policy = xairl.Policy(_Slow(), FEATURES, ACTIONS)
    content = ReportContent("toy", policy, toy_background(20), [("sampled", toy_background(40, seed=1))])
    write_report(ReportRequest(out=tmp_path, narrate=True, n_narrated=2), content)
    err = capsys.readouterr().err
    for step in ("explaining (deep_shap) 40 sampled states", "drawing the figures", "narrating 2 decisions"):
        assert f"xairl: {step} ..." in err and re.search(rf"xairl: {re.escape(step)}: done in \d+ s", err), step
    write_report(ReportRequest(out=tmp_path, narrate=False, progress=False), content)
    assert "xairl:" not in capsys.readouterr().err
