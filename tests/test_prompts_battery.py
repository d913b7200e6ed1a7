"""`xairl prompts check` renders a template on a battery of generated decisions and reports each contradicted
rendering with the template's line; direction words a sign test chooses are noted (xairl/narrators/battery.py)."""

import re

import pytest

from xairl.cli import main
from xairl.narrators import battery, battery_cases, check_template
from xairl.registry import plugins
from xairl.templates import prompts

HEAD = "name: t\nkind: decision\noutputs: [actions]\nsentences:\n"
CHOSE = (
    '  - ["{% if runner_up != action %}The policy chose {{ action }} over {{ runner_up }} by {{ q_margin|num }}.'
    '{% else %}The policy chose {{ action }}, the only action.{% endif %}"]\n'
)
GOOD = (
    HEAD
    + CHOSE
    + "  - [\"{% for f in top %}{{ f.label|cap }} {{ f.contribution|dir('raised', 'lowered') }} the score of "
    + "{{ action }} by {{ f.contribution|abs|num }}.{{ ' ' if not loop.last }}{% endfor %}\"]\n"
)
ALWAYS_RAISED = (
    HEAD
    + CHOSE
    + '  - ["{% for f in top %}{{ f.label|cap }} raised the score of {{ action }} by {{ f.contribution|abs|num }}.'
    + "{{ ' ' if not loop.last }}{% endfor %}\"]\n"
)
CROSSED = (
    HEAD
    + CHOSE
    + '  - ["{% if margin_top|length >= 2 %}{% set a = margin_top[0] %}{% set b = margin_top[1] %}On the margin, '
    + '{{ a.label }} contributed {{ b.contribution|signed }} and {{ b.label }} {{ a.contribution|signed }}.{% endif %}"]\n'
)
RUNNER_UP = HEAD + CHOSE + '  - ["In the end it chose {{ runner_up }}."]\n'
LITERAL = (
    'name: t\nkind: decision\nsentences:\n  - ["The output was {{ score|num }}."]\n'
    "  - - \"{% for f in top %}{{ f.label|cap }} {{ 'raised' if f.contribution >= 0 else 'lowered' }} it by "
    "{{ f.contribution|abs|num }}.{{ ' ' if not loop.last }}{% endfor %}\"\n"
)


def write(tmp_path, body, name="t.yaml"):
    path = tmp_path / name
    path.write_text(body)
    return path


def test_a_correct_template_reports_nothing(tmp_path):
    assert check_template(write(tmp_path, GOOD), notes=True) == []


@pytest.mark.parametrize(
    "body, line, words",
    [
        (ALWAYS_RAISED, 6, "'raised' is said of"),
        (CROSSED, 6, "contribution, written as"),
        (RUNNER_UP, 6, "is the runner-up, named as the chosen"),
    ],
    ids=["always_raised", "crossed_numbers", "chose_runner_up"],
)
def test_a_wrong_template_is_reported_with_its_line(tmp_path, body, line, words):
    path = write(tmp_path, body)
    problems = check_template(path)
    assert problems and all(p.startswith(f"{path}:{line}: contradicted on ") for p in problems), problems
    assert any(words in p for p in problems), problems
    assert all("\n" not in p for p in problems)
    assert any(re.search(r"contradicted on flat, signs [+-],[+-],[+-]: '", p) for p in problems)


def test_each_rendering_is_one_line_naming_the_decision(tmp_path):
    problems = check_template(write(tmp_path, ALWAYS_RAISED))
    decisions = [p.split(": contradicted on ")[1].split(": ")[0] for p in problems]
    assert len(decisions) == len(set(decisions))  # one line per contradicted rendering
    assert "flat, signs +,+,+" not in decisions and "flat, signs +,-,+" in decisions  # only what is wrong


@pytest.mark.slow
@pytest.mark.parametrize("path", sorted(prompts.builtin_dir().glob("*.yaml")), ids=lambda p: p.stem)
def test_builtin_templates_report_nothing(path):
    assert check_template(path) == []


def test_literal_direction_words_are_a_note_not_a_problem(tmp_path, capsys):
    path = write(tmp_path, LITERAL)
    assert check_template(path) == []
    (note,) = check_template(path, notes=True)
    assert note == (
        f"note: {path}:5: direction words chosen in the template; write "
        "{{ f.contribution|dir('raised', 'lowered') }} so the verifier knows which feature they are said of"
    )
    assert main(["prompts", "check", str(path)]) == 0
    out = capsys.readouterr().out
    assert note in out and out.rstrip().endswith(f"{path}: ok, 1 note(s)")
    assert main(["prompts", "check", str(write(tmp_path, ALWAYS_RAISED, "bad.yaml"))]) == 1


def test_a_direction_word_not_chosen_by_a_sign_is_no_note(tmp_path):
    body = HEAD + "  - [\"{{ 'Chosen for good reasons: ' if runner_up != action else '' }}{{ action }}.\"]\n"
    assert check_template(write(tmp_path, body), notes=True) == []


def test_a_template_error_on_a_case_is_reported_once_naming_it(tmp_path):
    path = write(tmp_path, HEAD + '  - ["The third feature was {{ top[2].label }}."]\n')
    (line,) = check_template(path)
    assert line.startswith(f"{path}:5: ") and "(on flat, 1 feature, signs + and 1 more case(s))" in line


def test_verbose_prints_the_battery_and_its_time(tmp_path, capsys):
    assert main(["prompts", "check", str(write(tmp_path, GOOD)), "--verbose"]) == 0
    assert re.search(
        r"battery: \d+ cases \(flat, dict, image\), \d+ renderings verified in [\d.]+ s", capsys.readouterr().out
    )


def test_the_battery_covers_every_pattern_and_kind():
    decisions, left_out = battery.cases()
    labels = [c.label for c in decisions]
    assert left_out == []  # (the core alone: no plugin loaded)
    for signs in ("+,+,+", "+,+,-", "+,-,+", "+,-,-", "-,+,+", "-,+,-", "-,-,+", "-,-,-"):
        assert f"flat, signs {signs}" in labels
    for label in (
        "flat, a tie of equal contributions",
        "flat, zero contributions but one",
        "flat, one feature alone favours the chosen action",
        "flat, one available action",
        "flat, 1 feature, signs +",
        "flat, 3 features, signs +,-,+",
        "flat, 50 features, signs -,+,+",
    ):
        assert label in labels
    assert {c.kind for c in decisions} == {"flat", "dict", "image", "continuous", "value"}
    by = {c.label: c.explanation for c in decisions}
    assert by["flat, 50 features, signs -,+,+"].values.shape[1] == 50
    tie = by["flat, a tie of equal contributions"].for_chosen()[0]
    assert tie[0] == tie[1]
    assert (by["flat, zero contributions but one"].for_chosen()[0][1:] == 0).all()
    assert (by["flat, one feature alone favours the chosen action"].margin()[0] > 0).sum() == 1
    assert by["flat, one available action"].runner_up[0] == by["flat, one available action"].chosen[0]
    assert by["image in regions, signs +,-,+"].feature_names[0].startswith("patch ")
    for c in decisions:  # consistent: base + sum of contributions = output
        e = c.explanation
        assert abs(e.base_values + e.values.sum(axis=1) - e.outputs).max() < 1e-9, c.label
    views, _ = battery.cases(kind="global")
    assert {c.index for c in views} == {None} and len(views) == 3
    assert [c.kind for c in battery.cases(("value",))[0]] == ["value"] * 4


def test_a_decision_template_renders_only_on_its_outputs(tmp_path):
    tpl = prompts.parse(write(tmp_path, GOOD))
    report = battery.run(tpl)
    assert {c.explanation.output for c in report.cases} == {"actions"}
    assert report.renderings == len(report.cases) and report.seconds < 10


@pytest.fixture
def uav_plugin(monkeypatch):
    pytest.importorskip("xairl_uav_handover", reason="the UAV plugin (make setup installs it)")
    monkeypatch.setenv(plugins.LOAD_ENV, "uav-handover")
    plugins.reset()
    yield
    monkeypatch.undo()
    plugins.reset()


def test_an_installed_plugins_policy_is_in_the_battery(uav_plugin, tmp_path):
    decisions, left_out = battery.cases(("actions",))
    uav = [c for c in decisions if c.kind == "uav-dqn"]
    assert left_out == [] and len(uav) == 4
    assert all(c.policy.facts_hook is not None for c in uav)
    problems = check_template(write(tmp_path, RUNNER_UP))
    assert any("contradicted on uav-dqn, state 0" in p for p in problems)


def test_a_plugin_policy_that_fails_to_load_is_one_line_and_the_battery_goes_on(monkeypatch):
    monkeypatch.setattr(battery_cases, "plugin_policies", lambda: (("broken", None, "RuntimeError: no checkpoint"),))
    decisions, left_out = battery.cases(("actions",))
    assert left_out == ["note: plugin policy 'broken' left out of the battery: RuntimeError: no checkpoint"]
    assert len(decisions) > 20
