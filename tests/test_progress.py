"""A long run says what it is doing (issue 64, the newcomer's first hour: `make demo` printed nothing for 97 s, then
for 124 s): each step of a report is said on stderr as it starts, every 10 s while it runs, and when it ends, whether
stderr is a terminal or not. (The UAV report's own steps: plugins/xairl-uav-handover/tests/test_uav_real_data.py.)"""

import inspect
import re
import time

import pytest

from xairl.display import heartbeat
from xairl.report import ReportContent, ReportRequest, write_report
from xairl.toy import toy_policy


def test_a_step_is_said_as_it_starts_while_it_runs_and_as_it_ends(capsys):
    assert inspect.signature(heartbeat).parameters["every"].default == 10.0  # the demo's "at least every 10 s"
    with heartbeat("an outer step", every=0.05):
        with heartbeat("an inner step", every=0.05):
            time.sleep(0.4)
        time.sleep(0.2)
    lines = capsys.readouterr().err.splitlines()
    assert lines[:2] == ["xairl: an outer step ...", "xairl: an inner step ..."]
    inner = lines.index("xairl: an inner step: done in 0 s")
    assert sum(line.startswith("xairl: still an inner step (") for line in lines[:inner]) >= 3
    assert not any("still an outer" in line for line in lines[:inner])  # the innermost step alone speaks
    assert any("still an outer step" in line for line in lines[inner:]) and lines[-1].startswith(
        "xairl: an outer step: done"
    )


def test_nothing_is_said_when_disabled_and_an_error_is_not_said_done(capsys):
    with heartbeat("quiet", enabled=False, every=0.01):
        time.sleep(0.05)
    with pytest.raises(ValueError), heartbeat("failing", every=0.01):
        raise ValueError("no")
    err = capsys.readouterr().err
    assert "quiet" not in err and "xairl: failing ..." in err and "failing: done" not in err


def test_a_report_says_each_of_its_steps(tmp_path, capsys):
    policy = toy_policy()
    content = ReportContent("toy", policy, policy.background(20), [("sampled", policy.background(8, seed=1))])
    write_report(ReportRequest(out=tmp_path, narrate=True, n_narrated=2), content)
    err = capsys.readouterr().err
    for step in ("explaining (deep_shap) 8 sampled states", "drawing the figures", "narrating 2 decisions"):
        assert f"xairl: {step} ..." in err and re.search(rf"xairl: {re.escape(step)}: done in \d+ s", err), step
    write_report(ReportRequest(out=tmp_path, narrate=False, progress=False), content)
    assert "xairl:" not in capsys.readouterr().err
