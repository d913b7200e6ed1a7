"""Issue 64 (hardening round 4), the words: bidirectional control characters never verified nor rendered, unknown
filters and tests named by `xairl prompts check`, templates capped in size and rendering time, tracked values'
bookkeeping hidden from templates, numbers never in scientific notation, the review page's messages by code, and
messages without doubled periods or a verb that disagrees with 'background'."""

import ast
import re
import urllib.request
from pathlib import Path

import numpy as np
import pytest

import xairl
from xairl.cli import main
from xairl.errors import InputError
from xairl.narrators import check_template
from xairl.narrators.samples import sample_context
from xairl.numbers import format_number, written_step
from xairl.templates import prompts, sandbox
from xairl.templates.prompts import TemplateError
from xairl.toy import toy_policy

ROOT = Path(__file__).resolve().parents[1]
RLO, PDF = "\u202e", "\u202c"  # right-to-left override, pop directional formatting


@pytest.fixture(scope="module")
def toy():
    p = toy_policy()
    e = xairl.explain(p, p.background(3, seed=1), background=p.background(50))
    return p, e, xairl.narrate(e, 0, policy=p, robustness=False)


def _template(tmp_path, body: str, name: str = "t") -> Path:
    path = tmp_path / f"{name}.yaml"
    path.write_text(f"name: {name}\nsentences:\n{body}")
    return path


# ---- item 3: bidirectional control characters --------------------------------------------------------------------
def _wrapped(text: str) -> str:
    """The narrative's margin between an override and its pop: a browser shows it reversed."""
    number = re.search(r"a margin of (\d+\.\d+)", text)[1]
    return text.replace(f"a margin of {number}", f"a margin of {RLO}{number}{PDF}")


def test_text_with_a_bidi_override_is_not_verified(toy):
    p, e, n = toy
    assert n.verified and xairl.verify(n.text, e, 0, p).accurate  # the same words without the override: not false
    bad = _wrapped(n.text)
    for check in (xairl.verify(bad, e, 0, p), xairl.verify(bad, e, 0, p, provenance=n.provenance)):
        assert not check.ok and check.status == "contradicted"
        assert "U+202E" in check.note and "bidirectional" in check.note
        assert any(c.kind == "text" and "U+202E" in c.detail for c in check.problems())


@pytest.mark.parametrize("char", ["\u202a", "\u202d", "\u2066", "\u2069", "\u200f"])
def test_every_bidi_control_is_flagged(toy, char):
    p, e, n = toy
    assert not xairl.verify(n.text.replace("turn", f"{char}turn", 1), e, 0, p).ok


def test_cli_verify_shows_the_override_and_fails(toy, tmp_path, capsys):
    p, e, n = toy
    path = tmp_path / "exp.json"
    path.write_text(e.to_json())
    assert main(["verify", _wrapped(n.text), "--explanation", str(path)]) == 1
    out = capsys.readouterr().out
    assert "<U+202E>" in out and RLO not in out and "bidirectional control characters (U+202E, U+202C)" in out


def test_a_template_whose_words_hold_a_bidi_override_is_refused(toy, tmp_path):
    p, e, _ = toy
    path = _template(tmp_path, f'  - ["The margin is {RLO}{{{{ q_margin|num }}}}{PDF}."]\n')
    with pytest.raises(TemplateError, match=r"t\.yaml:3: the rendered words hold bidirectional control") as info:
        xairl.narrate(e, 0, template=str(path))
    assert "\n" not in str(info.value) and "U+202E, U+202C" in str(info.value)


# ---- item 4: an unknown filter or test -----------------------------------------------------------------------------
@pytest.mark.parametrize(
    "variant, said",
    [
        ("{{ action|nosuch }}", "unknown filter 'nosuch'"),
        ("{% if action is nosuch %}x{% endif %}", "unknown test 'nosuch'"),
    ],
)
def test_prompts_check_names_an_unknown_filter_or_test(tmp_path, capsys, variant, said):
    path = _template(tmp_path, f"  - |\n    The policy chose {{{{ action }}}}.\n    {variant}\n")
    assert main(["prompts", "check", str(path)]) == 1  # a problem of the template, listed as the others are
    out, err = capsys.readouterr()
    assert f"{path}:5: {said}; the " in out and "num" in out and "internal error" not in out + err
    with pytest.raises(TemplateError) as info:  # narrating with it: one line too, with no doubled period
        prompts.load(path).render_variants(sample_context("decision"))
    assert "\n" not in str(info.value) and ".." not in str(info.value)


# ---- item 9: templates capped in size and rendering time -------------------------------------------------------------
def test_a_template_of_too_many_sentences_is_refused(tmp_path):
    n = prompts.MAX_SENTENCES + 1
    path = _template(tmp_path, '  - ["The policy chose {{ action }}."]\n' * n)
    with pytest.raises(TemplateError, match=rf"{n} sentences .* at most {prompts.MAX_SENTENCES} sentences"):
        prompts.load(path)
    assert check_template(path) and "at most" in check_template(path)[0]  # listed, before any rendering


def test_a_template_of_too_many_variants_is_refused(tmp_path):
    variants = ", ".join(['"{{ action }} it was."'] * (prompts.MAX_VARIANTS + 1))
    with pytest.raises(TemplateError, match="variants in all"):
        prompts.load(_template(tmp_path, f"  - [{variants}]\n"))


def test_a_template_over_the_byte_limit_is_refused_unread(tmp_path, capsys):
    path = _template(tmp_path, '  - ["{{ action }}' + " " * prompts.MAX_BYTES + '"]\n')
    assert main(["prompts", "check", str(path)]) == 2
    err = capsys.readouterr().err
    assert f"larger than {prompts.MAX_BYTES // 1024} KB" in err and err.count("\n") == 1


def test_a_rendering_past_the_clock_is_refused(monkeypatch):
    monkeypatch.setattr(sandbox, "MAX_SECONDS", 0.0)  # every rendering is then past its time
    with pytest.raises(
        TemplateError, match=r"explain_action\.yaml:\d+: refused by the sandbox \(rendering took over 0 s"
    ):
        prompts.load("explain_action").render_variants(sample_context("decision"))


# ---- low: a tracked value's bookkeeping ------------------------------------------------------------------------------
@pytest.mark.parametrize("attr", ["fact", "transform", "printed"])
def test_a_tracked_values_bookkeeping_is_not_printed(toy, tmp_path, attr):
    p, e, _ = toy
    path = _template(tmp_path, f'  - ["The score is {{{{ score.{attr} }}}}."]\n')
    with pytest.raises(TemplateError, match=f"refused by the sandbox.*'{attr}'") as info:
        xairl.narrate(e, 0, template=str(path))
    assert "Fact(" not in str(info.value)


# ---- wording: no scientific notation, one precision rule ---------------------------------------------------------------
@pytest.mark.parametrize("x, text", [(6.44e-4, "0.00064"), (6.44e-5, "0.000064"), (-1.2e-7, "0"), (0.0999, "0.10")])
def test_small_numbers_are_written_in_plain_decimals(x, text):
    assert format_number(x) == text and "e" not in format_number(x, signed=True)
    assert float(format_number(x)) == pytest.approx(round(x / written_step(x)) * written_step(x))


def test_a_smaller_number_is_never_written_more_precisely_than_a_larger_one():
    """'+0.07 beside +0.00862': below 0.1 every number keeps 2 significant digits, no more and no fewer."""
    assert [format_number(x, True) for x in (0.0712, 0.00862, 0.49, 1.5)] == ["+0.071", "+0.0086", "+0.49", "+1.50"]


def test_a_counterfactual_margin_is_written_as_the_words_write_it():
    from xairl.explanations.display import counterfactual_text

    one = {"changes": [{"feature": "wind", "before_text": "1", "after_text": "2"}], "action": "go", "margin": 6.44e-4}
    (line,) = counterfactual_text({"found": [one | {"distance": 0.5}]})
    assert "margin 0.00064" in line and "e-0" not in line


# ---- low: the review page says only its own messages ------------------------------------------------------------------
def test_the_review_page_does_not_reflect_a_crafted_message(tmp_path):
    from xairl.outputs.feedback import FeedbackStore
    from xairl.outputs.review import serve_in_thread

    server, url = serve_in_thread(FeedbackStore(tmp_path / "fb.sqlite"))
    try:
        crafted = "Your+session+expired%3A+call+555-0100"
        page = urllib.request.urlopen(f"{url}?msg={crafted}", timeout=10).read().decode()
        assert "session expired" not in page and "555-0100" not in page
        page = urllib.request.urlopen(f"{url}?msg=accepted&id=7", timeout=10).read().decode()
        assert "#7 accepted" in page
        page = urllib.request.urlopen(f"{url}?msg=accepted&id=7%3Cb%3E", timeout=10).read().decode()
        assert "accepted" not in page.split("</h1>")[1].split("class=empty")[0]  # no number: no message
    finally:
        server.shutdown()


# ---- low: messages --------------------------------------------------------------------------------------------------
def test_a_background_with_nan_is_said_in_good_grammar():
    p = toy_policy()
    bg = p.background(10)
    bg[2, 1] = np.nan
    with pytest.raises(InputError) as info:
        xairl.explain(p, p.background(2), background=bg)
    assert str(info.value).startswith("background contains 1 NaN/inf value(s)")
    with pytest.raises(InputError, match="^states contain 1 NaN"):
        xairl.explain(p, bg, background=p.background(10))


def test_a_message_built_around_another_has_one_period():
    assert str(InputError("cannot read it (bad header.).")) == "cannot read it (bad header.)."
    assert str(InputError("cannot read it: bad header..")) == "cannot read it: bad header."
    assert str(InputError("rows 0..99 hold text...")) == "rows 0..99 hold text..."


def _raised_literals():
    """(file:line, the literal text) of every message raised with a literal or an f-string in xairl's source."""
    for path in sorted((ROOT / "xairl").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Raise) and isinstance(node.exc, ast.Call) and node.exc.args:
                arg = node.exc.args[0]
                parts = arg.values if isinstance(arg, ast.JoinedStr) else [arg]
                text = "\x00".join(str(p.value) for p in parts if isinstance(p, ast.Constant))
                yield f"{path.relative_to(ROOT)}:{node.lineno}", text


def test_no_raised_message_has_a_doubled_period_or_background_contain():
    bad = [
        where
        for where, text in _raised_literals()
        if re.search(r"(?<![.\d])\.\.(?![.\d])", text) or "background contain " in text
    ]
    assert not bad, bad


# ---- house: one options object for a narration ------------------------------------------------------------------------
def test_narrate_takes_one_options_object_and_the_keywords_alike(toy):
    p, e, _ = toy
    bg = p.background(20)
    how = xairl.NarrationOptions(policy=p, background=bg, robustness=False)
    by_object = xairl.narrate(e, 1, narration=how)
    by_keywords = xairl.narrate(e, 1, policy=p, background=bg, robustness=False)
    assert by_object.text == by_keywords.text and by_object.components == by_keywords.components
    assert xairl.narrate(e, 1, narration=how, k=1).text != by_object.text  # a keyword beside it wins
    with pytest.raises(InputError, match=r"narration options \(polcy: unknown option\); options: template, policy"):
        xairl.narrate(e, 1, polcy=p)


def test_the_confidence_reads_the_narrations_options(toy):
    from xairl.narrators.confidence import confidence

    p, e, n = toy
    measured = confidence(e, 0, True, xairl.NarrationOptions(policy=p, background=p.background(20)))[1]
    assert measured["agreement"] is not None and measured["stability"] is not None
    assert confidence(e, 0, True)[1]["agreement"] is None  # no policy: the robustness parts are not measured


# ---- wording: names as declared, level words, a contradiction said once ----------------------------------------------
def test_a_snake_case_name_is_not_capitalised_into_a_new_word():
    import torch

    torch.manual_seed(0)
    net = torch.nn.Linear(2, 2)
    policy = xairl.Policy(net, ["cart_velocity", "pole_angle"], ["left", "right"])
    states = np.random.default_rng(0).normal(size=(12, 2)).astype(np.float32)
    exp = xairl.explain(policy, states[:4], background=states[4:], method="exact")
    texts = [xairl.narrate(exp, i, template="why_not", policy=policy, robustness=False).text for i in range(4)]
    assert any(re.search(r"(^|\. )(cart_velocity|pole_angle) \(", t) for t in texts), texts  # at a sentence start
    assert not any(re.search(r"Cart_velocity|Pole_angle", t) for t in texts), texts
    assert prompts.environment().filters["cap"]("pole angle") == "Pole angle"


def test_the_toys_level_words_say_a_level_not_a_state(toy):
    """'(0.60, full)' for 0.6 standard deviations: the toy's battery is standardised, so its words say high or low."""
    from xairl.facts import decision_facts

    p, e, _ = toy
    infos = p.features["battery"]
    assert (infos.low, infos.high) == ("low", "high")  # words of a level, which a standardised value has
    levels = {f.level_text for i in range(3) for f in decision_facts(e, i, p, k=5).top if f.name == "battery"}
    assert levels and not levels & {"full", "nearly empty"}


def test_a_contradicted_direction_word_is_said_once_by_prompts_check(tmp_path):
    from xairl.narrators.battery import run

    # (a literal direction word: named as undeclared once, with the filter to use; unchecked at render time)
    source = prompts.load("explain_action").path.read_text().replace("{{ f|dir('toward', 'against') }}", "opposing")
    path = tmp_path / "opposed.yaml"
    path.write_text(source)
    lines = run(prompts.parse(path)).problems
    assert any(
        line.endswith(
            "'opposing' is a claim the template wrote itself; write it with dir('favouring', 'going against')"
        )
        for line in lines
    ), lines[:2]
    assert sum("'opposing'" in line for line in lines) == 1, lines[:3]
    assert not [line for line in lines if "'opposing' 'opposing'" in line], lines[:2]


def test_the_clock_is_the_renderings_cpu_time_not_a_busy_machines(monkeypatch, tmp_path):
    """A rendering waiting on a loaded machine (here: a value that sleeps as it prints) is not refused by the clock;
    one that computes past it is (test_a_rendering_past_the_clock_is_refused)."""
    import time

    class Slow(str):
        def __str__(self):
            time.sleep(0.3)
            return "slow"

    monkeypatch.setattr(sandbox, "MAX_SECONDS", 0.2)
    path = _template(tmp_path, '  - ["The action was {{ slow }}."]\n')
    tpl = prompts.parse(path)
    assert str(tpl.render_variants({**sample_context("decision"), "slow": Slow("x")})[0][0]) == "The action was slow."
