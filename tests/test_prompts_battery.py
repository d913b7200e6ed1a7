"""`xairl prompts check` names each claim word a template writes as literal text (with its line and the filter to
use), renders the template on a battery of generated decisions and reports each contradicted rendering with the
template's line (xairl/narrators/battery.py)."""

import re

import pytest

from xairl.cli import main
from xairl.narrators import battery, battery_cases, check_template
from xairl.registry import plugins
from xairl.templates import prompts

HEAD = "name: t\nkind: decision\noutputs: [actions]\nsentences:\n"
CHOSE = (
    "  - [\"{% if runner_up != action %}The policy {{ action|role('chose') }} {{ action }} "
    "{{ runner_up|role('', 'over') }} {{ runner_up }} by "
    "{{ q_margin|num }}.{% else %}The policy {{ action|role('chose') }} {{ action }}, "
    "{{ action|role('', only='the only action') }}.{% endif %}\"]\n"
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

CF = (
    '  - ["{% if counterfactual and counterfactual.changes %}{% set cf = counterfactual %}Had {% for c in cf.changes %}'
    "{{ ' and ' if not loop.first }}{{ c.label }} been {{ c.direction ~ ' ' if c.direction }}{{ c.after_text }} (it was "
    '{{ c.value_text }}){% endfor %}, the policy would have chosen {{ cf.action }} (margin {{ cf.margin|num }}).{% endif %}"]\n'
)


def write(tmp_path, body, name="t.yaml"):
    path = tmp_path / name
    path.write_text(body)
    return path


def test_a_correct_template_reports_nothing(tmp_path):
    assert check_template(write(tmp_path, GOOD), notes=True) == []


def test_a_wrong_template_is_reported_with_its_line(tmp_path):
    """A value printed beside another feature's name is never contradicted by its position, but each rendering
    left unchecked is a problem with its line and why (issue 65: 'unchecked' is never passed as fine)."""
    path = write(tmp_path, CROSSED)
    problems = check_template(path)
    assert problems and all(p.startswith(f"{path}:6: unchecked on ") for p in problems), problems
    assert any("contribution, written next to" in p for p in problems), problems
    assert all("\n" not in p for p in problems)
    assert any(re.search(r"unchecked on flat, signs [+-],[+-],[+-]: '", p) for p in problems)
    path = write(tmp_path, HEAD + CHOSE + '  - ["{{ action }} (score {{ runner_up_score|num }})."]\n', "role.yaml")
    problems = check_template(path)
    assert problems and all(p.startswith(f"{path}:6: contradicted on ") for p in problems), problems


@pytest.mark.parametrize(
    "body, word, use",
    [(ALWAYS_RAISED, "raised", "dir('raised', 'lowered')"), (RUNNER_UP, "chose", "action|role('chose')")],
    ids=["always_raised", "chose_runner_up"],
)
def test_a_literal_claim_word_is_a_problem_naming_its_line_and_filter(tmp_path, body, word, use):
    path = write(tmp_path, body)
    problems = check_template(path)
    line = f"{path}:6: {word!r} is a claim the template wrote itself; write it with {use}"
    assert problems[0] == line, problems


def test_each_rendering_is_one_line_naming_the_decision(tmp_path):
    problems = check_template(write(tmp_path, CROSSED))
    decisions = [p.split(": unchecked on ")[1].split(": ")[0] for p in problems]
    assert len(decisions) == len(set(decisions))  # one line per rendering left unchecked
    assert "flat, 1 feature, signs +" not in decisions and "flat, signs +,-,+" in decisions  # only what is wrong


@pytest.mark.slow
@pytest.mark.parametrize("path", sorted(prompts.builtin_dir().glob("*.yaml")), ids=lambda p: p.stem)
def test_builtin_templates_report_nothing(path):
    assert check_template(path) == []


def test_direction_words_chosen_by_a_sign_test_are_literal_claims(tmp_path, capsys):
    path = write(tmp_path, LITERAL)
    said = "is a claim the template wrote itself; write it with dir('raised', 'lowered')"
    assert check_template(path) == [f"{path}:5: 'raised' {said}", f"{path}:5: 'lowered' {said}"]
    assert main(["prompts", "check", str(path)]) == 1
    out = capsys.readouterr().out
    assert f"{path}:5: 'lowered' {said}" in out and out.rstrip().endswith(f"{path}: 2 problem(s)")


def test_names_and_identifiers_written_literally_are_claims(tmp_path):
    # (issue 65: "...came from obstacle (+0.46), helped by cell_load." was verified 39 times of 39)
    body = HEAD + '  - ["{{ top[0].label|cap }} did it, with the speed and cell_load."]\n'
    problems = check_template(write(tmp_path, body))
    assert [p.split(": ")[1] for p in problems[:2]] == [
        "'the speed' is a claim the template wrote itself; write it with {{ f.label }} (or {{ f.name }}) for a feature, {{ action }} or {{ runner_up }} for an action",
        "'cell_load' is a claim the template wrote itself; write it with {{ f.label }} or {{ action }} from the facts (a name no fact holds is an invented one)",
    ]


def test_words_in_tests_comparisons_and_claim_filters_are_not_literal_claims(tmp_path):
    body = HEAD + (
        '  - ["{% if runner_up != action and top[0].contribution >= 0 %}{{ top[0].label|cap }} '
        "{{ top[0]|dir('aumentó', 'raised it, not lowered') }} it{% endif %}{{ '.' if 'hold' != action }}\"]\n"
    )
    assert check_template(write(tmp_path, body)) == []


def test_a_counterfactual_phrasing_is_left_to_the_counterfactual_check(tmp_path):
    report = battery.run(prompts.parse(write(tmp_path, HEAD + CF)))
    assert report.problems == [] and battery.undeclared(prompts.parse(write(tmp_path, HEAD + CF))) == []
    cases = [c for c in report.cases if c.counterfactual is not None]
    assert len(cases) == 2 and report.renderings == len(report.cases)
    context, _ = battery._facts(cases[0])
    (variants,) = prompts.parse(write(tmp_path, HEAD + CF)).render_variants(context)
    assert variants[0].startswith("Had ") and any(s.fact.quantity == "cf_margin" for s in variants[0].spans)
    # its literal words are claims anywhere else, and in a phrasing that only tests the counterfactual
    tested = HEAD + '  - ["{% if counterfactual or true %}The policy chose {{ action }}.{% endif %}"]\n'
    assert "'chose' is a claim" in battery.undeclared(prompts.parse(write(tmp_path, tested)))[0]
    plain = HEAD + '  - ["Had it been slower, the policy would have chosen {{ runner_up }}."]\n'
    assert [p.split(": ", 1)[1] for p in battery.undeclared(prompts.parse(write(tmp_path, plain)))][0] == (
        "'would have' is a claim the template wrote itself; write it with the counterfactual facts "
        "({{ counterfactual.action }}): their sentence is checked by re-running the policy"
    )


def test_a_template_error_on_a_case_is_reported_once_naming_it(tmp_path):
    path = write(tmp_path, HEAD + '  - ["A feature was {{ top[2].label }}."]\n')
    (line,) = check_template(path)
    assert line.startswith(f"{path}:5: ") and "(on flat, 1 feature, signs + and 1 more case(s))" in line


def test_verbose_prints_the_battery_and_its_time(tmp_path, capsys):
    assert main(["prompts", "check", str(write(tmp_path, GOOD)), "--verbose"]) == 0
    out = capsys.readouterr().out
    assert re.search(
        r"battery: \d+ cases \(flat, dict, image, counterfactual\), \d+ renderings, no problem, in [\d.]+ s", out
    )
    assert main(["prompts", "check", str(write(tmp_path, CROSSED, "bad.yaml")), "--verbose"]) == 1
    first = capsys.readouterr().out.splitlines()[0]  # (issue 65: '28 renderings verified' above '27 problems')
    assert "verified" not in first and re.search(r"\d+ renderings, \d+ problem\(s\)", first)


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
    assert {c.kind for c in decisions} == {"flat", "dict", "image", "continuous", "value", "counterfactual"}
    cfs = [c for c in decisions if c.kind == "counterfactual"]
    assert len(cfs) == 2 and all(c.counterfactual.reachable and c.counterfactual.changes for c in cfs)
    assert {len(c.counterfactual.changes) for c in cfs} == {1, 2}
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
    problems = check_template(
        write(tmp_path, HEAD + CHOSE + '  - ["{{ action }} (score {{ runner_up_score|num }})."]\n')
    )
    assert any("contradicted on uav-dqn, state 0" in p for p in problems), problems


@pytest.mark.slow
def test_the_uav_template_reports_nothing_with_every_wording(uav_plugin):
    """Issue 66: every gap of the plugin's template, in every wording pick() offers, verified and well formed on the
    UAV DQN's decisions (the built-ins: test_builtin_templates_report_nothing)."""
    path = ROOT / "plugins" / "xairl-uav-handover" / "xairl_uav_handover" / "prompts" / "handover.yaml"
    report = battery.run(prompts.parse(path))
    assert report.problems == []
    assert report.renderings >= 4 * 3  # (four UAV decisions, three wordings at most of a choice)


def test_a_plugin_policy_that_fails_to_load_is_one_line_and_the_battery_goes_on(monkeypatch):
    monkeypatch.setattr(battery_cases, "plugin_policies", lambda: (("broken", None, "RuntimeError: no checkpoint"),))
    decisions, left_out = battery.cases(("actions",))
    assert left_out == ["note: plugin policy 'broken' left out of the battery: RuntimeError: no checkpoint"]
    assert len(decisions) > 20


ROOT = prompts.builtin_dir().parent
SHIPPED = sorted(
    [
        *prompts.builtin_dir().glob("*.yaml"),
        *(ROOT / "examples" / "custom_prompt" / "prompts").glob("*.yaml"),
        *(ROOT / "examples" / "my_plugin" / "my_xairl_plugin" / "prompts").glob("*.yaml"),
        *(ROOT / "plugins" / "xairl-uav-handover" / "xairl_uav_handover" / "prompts").glob("*.yaml"),
    ]
)


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.stem)
def test_every_shipped_template_declares_every_claim(path):
    names = battery.names(battery_cases.flat_cases() + battery_cases.kind_cases())
    try:
        from xairl_uav_handover.features import ACTIONS, FEATURE_INFO

        names += [*FEATURE_INFO, *ACTIONS, *(i.description for i in FEATURE_INFO.values() if i.description)]
    except ImportError:  # (the plugin is not installed: its names are left out)
        pass
    assert len(SHIPPED) >= 9
    assert battery.undeclared(prompts.parse(path), names) == []


def test_a_template_in_its_authors_own_words_passes(tmp_path):
    # (issue 65: dir('aumentó', 'redujo') and dir('grew', 'shrank') were contradicted in 119 true renderings)
    body = HEAD + (
        "  - [\"{% if runner_up != action %}La política {{ action|role('eligió') }} {{ action }} "
        "{{ runner_up|role('', 'y no') }} {{ runner_up }}"
        "{% else %}La política {{ action|role('eligió', only='la única acción posible') }}{% endif %}.\"]\n"
        "  - [\"{% for f in top %}{{ f.label|cap }} {{ f|dir('aumentó', 'redujo') }} la puntuación en "
        "{{ f.contribution|abs|num }}{{ ', ' if not loop.last else '.' }}{% endfor %}\"]\n"
        "  - [\"{% if reasons %}{{ reasons[0].label|cap }}: {{ reasons[0].rank_same_way|rank('el mayor empuje', "
        "other='un empuje') }}, {{ reasons[0]|level('con valor bajo', 'con valor normal', 'con valor alto') }}"
        '{% endif %}"]\n'
    )
    assert check_template(write(tmp_path, body)) == []


def _wordings(r) -> int:
    return r.draft.wordings if r.draft else 1


@pytest.mark.parametrize("path", sorted(prompts.builtin_dir().glob("*.yaml")), ids=lambda p: p.stem)
def test_a_builtins_renderings_hold_no_literal_claim_word(path):
    """What the static pass promises holds at render time: with every tracked span blanked, the words left over in
    each rendering (but a counterfactual sentence's) hold no claim word of the lexicon nor any name of the case."""
    from xairl.verification.claims import checked_by_counterfactual, claim_words

    tpl = prompts.parse(path)
    outputs = tpl.spec.outputs if tpl.spec.kind == "decision" else ("actions", "continuous", "value")
    rendered = 0
    for case in battery.cases(outputs, tpl.spec.kind)[0]:
        context, _ = battery._facts(case)
        names = battery.names([case])
        firsts = [r for variants in tpl.render_variants(context) for r in variants if r]
        for r in (f.draft.render(c) if f.draft else f for f in firsts for c in range(_wordings(f))):
            if checked_by_counterfactual(r.spans):
                continue
            text = list(str(r))
            for s in r.spans:
                text[s.start : s.end] = " " * (s.end - s.start)
            assert claim_words("".join(text), names) == [], (case.label, str(r))
            rendered += 1
    assert rendered >= 8
