"""pick(): the wordings a template offers between its facts (xairl/templates/choices.py), for the language model to
choose among; the template narrator shows the first. Every wording is rendered, verified and checked for its form
by `xairl prompts check`."""

import pytest

import xairl
from xairl.facts import decision_facts
from xairl.narrators import check_template
from xairl.narrators.battery import malformed
from xairl.templates import prompts
from xairl.templates.prompts import TemplateError
from xairl.templates.tracking import Rendered, Span, track_decision
from xairl.toy import toy_policy

HEAD = "name: t\nkind: decision\noutputs: [actions]\nsentences:\n"
CHOSE = (
    "  - [\"{% if runner_up != action %}{{ pick('The policy', 'The agent') }} {{ action|role('chose') }} "
    "{{ action }} {{ runner_up|role('', 'over') }} {{ runner_up }}{{ pick(', a margin of ', ' by ') }}"
    "{{ q_margin|num }}.{% else %}The policy {{ action|role('chose') }} {{ action }}, "
    "{{ action|role('', only='the only action') }}.{% endif %}\"]\n"
)


@pytest.fixture(scope="module")
def decision():
    p = toy_policy()
    exp = xairl.explain(p, p.background(3, seed=5), background=p.background(40))
    return p, exp, track_decision(decision_facts(exp, 0, p).context())


def write(tmp_path, body, name="t.yaml"):
    path = tmp_path / name
    path.write_text(body)
    return path


def test_a_rendering_keeps_its_choice_points_and_each_wording_keeps_its_facts(tmp_path, decision):
    p, exp, context = decision
    tpl = prompts.parse(write(tmp_path, HEAD + CHOSE))
    r = tpl.render_variants(context)[0][0]
    assert r.draft is not None and [len(w) for w in r.draft.points] == [2, 2]
    assert str(r) == str(r.draft.render(0)) and str(r).startswith("The policy ")
    second = r.draft.render([1, 1])
    assert str(second).startswith("The agent ") and " by " in str(second) and "margin" not in str(second)
    for text in (r, second, r.draft.render([0, 1])):
        assert [s.fact for s in text.spans] == [s.fact for s in r.spans]
        assert all(text[s.start : s.end] == s.text for s in text.spans)
    # the template narrator shows the first wordings, verified
    n = xairl.narrate(exp, 0, policy=p, template=str(tpl.path))
    assert n.text == str(r) and n.verified


def test_a_wording_may_print_facts_and_claim_filters(tmp_path, decision):
    _, _, context = decision
    body = HEAD + (
        "  - [\"{% set f = top[0] %}{{ f.label|cap }} {{ pick(f|dir('raised', 'lowered') ~ ' it', "
        "'moved it ' ~ f|dir('up', 'down')) }} by {{ f.contribution|abs|num }}.\"]\n"
    )
    r = prompts.parse(write(tmp_path, body)).render_variants(context)[0][0]
    words = [r.draft.render(c) for c in range(2)]
    assert all(any(s.fact.quantity == "contribution" and s.transform for s in w.spans) for w in words)
    assert {s.text for w in words for s in w.spans} >= {"raised", "up"} or {"lowered", "down"} <= {
        s.text for w in words for s in w.spans
    }


def test_cap_capitalises_every_wording(tmp_path, decision):
    _, _, context = decision
    body = HEAD + "  - [\"{{ pick('the policy', 'an agent')|cap }} {{ action|role('chose') }} {{ action }}.\"]\n"
    r = prompts.parse(write(tmp_path, body)).render_variants(context)[0][0]
    assert [str(r.draft.render(c)).split()[0] for c in range(2)] == ["The", "An"]


@pytest.mark.parametrize(
    "call, message",
    [
        ("pick()", "pick() needs at least one wording"),
        ("pick('a', 'b', 'c', 'd', 'e', 'f', 'g')", "pick() offers 7 wordings; at most 6"),
        ("pick('a', pick('b', 'c'))", "pick() inside pick()"),
        ("pick('x' * 300)", "longer than 200 characters"),
    ],
)
def test_a_pick_the_template_cannot_make_is_one_line_naming_its_line(tmp_path, decision, call, message):
    _, _, context = decision
    path = write(tmp_path, HEAD + f'  - ["The policy {{{{ {call} }}}} {{{{ action }}}}."]\n')
    with pytest.raises(TemplateError) as err:
        prompts.parse(path).render_variants(context)
    assert str(err.value).startswith(f"{path}:5: ") and message in str(err.value) and "\n" not in str(err.value)


def test_a_bidi_control_in_any_wording_is_refused(tmp_path, decision):
    _, _, context = decision
    path = write(tmp_path, HEAD + "  - [\"The policy {{ pick('chose', 'pi\\u202eked') }} {{ action }}.\"]\n")
    with pytest.raises(TemplateError, match="U\\+202E"):
        prompts.parse(path).render_variants(context)


def test_prompts_check_reads_every_wording(tmp_path):
    """A literal claim word in a later wording is named; a later wording that prints the wrong fact is contradicted;
    pick is a known name, not an unknown variable."""
    literal = (
        HEAD
        + CHOSE
        + "  - [\"{% set f = top[0] %}{{ f.label|cap }} {{ pick('mattered', 'was the main reason') }}.\"]\n"
    )
    problems = check_template(write(tmp_path, literal))
    assert any("'main' is a claim the template wrote itself" in p for p in problems), problems
    assert not any("unknown variable 'pick'" in p for p in problems)
    crossed = HEAD + CHOSE + '  - ["{{ action|cap }} (score {{ pick(score|num, runner_up_score|num) }})."]\n'
    problems = check_template(write(tmp_path, crossed, "crossed.yaml"))
    assert problems and any(": contradicted on " in p for p in problems), problems
    assert check_template(write(tmp_path, HEAD + CHOSE, "good.yaml")) == []


@pytest.mark.parametrize(
    "body, fault",
    [
        (
            "The policy {{ action|role('chose') }} {{ action }}{{ pick('', ' at once') }} .",
            "a space before punctuation",
        ),
        ("The policy {{ action|role('chose') }}{{ action }}.", "is glued to the words beside it"),
        ("The policy {{ action|role('chose') }} {{ action }}{{ pick('.', '..') }}", "punctuation doubled"),
        ("The policy {{ action|role('chose') }} {{ pick('the', 'the the') }} {{ action }}.", "a word written twice"),
    ],
)
def test_prompts_check_names_a_malformed_wording_once_with_its_line(tmp_path, body, fault):
    path = write(tmp_path, HEAD + f'  - ["{body}"]\n')
    problems = [p for p in check_template(path) if "malformed" in p]
    assert len(problems) == 1 and problems[0].startswith(f"{path}:5: malformed on ") and fault in problems[0], problems


def test_malformed_reads_the_form_of_a_sentence():
    fact = Span(0, 0, "", None).fact
    text = "Wind raised it by +0.5."
    assert malformed(Rendered(text, (Span(0, 4, "Wind", fact), Span(18, 22, "+0.5", fact)))) is None
    glued = "overhandover_to_candidate_1 now."
    assert "glued" in malformed(Rendered(glued, (Span(4, 27, "handover_to_candidate_1", fact),)))
    assert malformed(Rendered("It rose (), then fell.")) == "empty brackets"
    assert malformed(Rendered("It rose,then fell.")) == "no space after punctuation"
