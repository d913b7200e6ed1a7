"""The language model chooses the template's wordings; it never writes words of its own.

A template offers wordings in two places: a sentence's variants (phrasings that say the same facts) and, inside a
sentence, ``pick('came from', 'was due to')`` between its tracked values (:mod:`xairl.templates.choices`). The text
is decoded under that grammar: left to right, at each place where the template offers a choice, every wording is
scored by the model after the text chosen so far, each followed by the first fixed words after it (so the model
judges how it joins them), and the wording whose tokens it finds most probable on average is kept, give or take its
fit to the reader the prompt names (:meth:`Chooser.fit`) and the length asked for. What can come
out is exactly the set of sentences the template can write, each tracked value in its place; so the text verifies
by its facts like the template's, and a choice is never a claim of the model's.

Why not token-level constrained generation (outlines, llguidance, lm-format-enforcer, a logits processor): the grammar
here is a finite choice among short wordings, so scoring each one whole is exact where token-by-token masking is
greedy within a wording, and a batched forward pass per choice is cheaper than a generation loop; it needs nothing
but the model's forward pass with its key-value cache (transformers' ``DynamicCache``: the prompt is encoded once
per process, each choice adds only its wordings).

``length``: 'medium' (the default) keeps the most probable wording per token; 'short' and 'long' add a bonus per
token against or for longer wordings, so the model's choice leans to the shorter or the fuller wordings.
"""

from __future__ import annotations

import copy
import inspect
from dataclasses import dataclass

from xairl.templates.tracking import Rendered

#: the tokens of the fixed words after a wording that its score reads (how the wording joins them); the rest are
#: scored with the next choice
LOOKAHEAD = 8
#: the tokens of a sentence's variant that its score reads (where the phrasings differ most: their start)
OPENING = 16
#: fixed words longer than this go into the cache on their own before a choice (once, not once per wording)
SHARED = 12
#: the weight of a wording's fit to the reader the prompt names (:meth:`Chooser.fit`) in its score
FIT = 1.0
#: the score added per token of a wording (its mean token log-probability is the score): against or for length
LENGTH_BONUS = {"short": -0.25, "medium": 0.0, "long": 0.25}


@dataclass
class _State:
    """The model's key-value cache of the text so far, and its log-probabilities of the next token."""

    cache: object
    last: object  # (vocabulary,) log-probabilities after the text so far


def _pieces(sentence: Rendered) -> tuple[list[str], list[tuple[str, ...]]]:
    """(the fixed stretches, the choice points' wordings) of a rendered sentence; one stretch when it has none."""
    return sentence.draft.pieces() if sentence.draft is not None else ([str(sentence)], [])


class Chooser:
    """Chooses a template's wordings with a causal language model after a prompt; ``plain`` is the prompt without a
    reader, for the wordings' fit to the one ``prompt`` names. The local_lm narrator keeps one per model, prompt and
    length in its process."""

    def __init__(self, model, tok, prompt: list[int], length: str = "medium", plain: list[int] | None = None):
        self.model, self.tok, self.bonus = model, tok, LENGTH_BONUS[length]
        params = inspect.signature(model.forward).parameters
        self._cache_arg = "cache" if "cache" in params else "past_key_values"  # (transformers 5 renamed it)
        self._ids: dict[str, list[int]] = {}
        self._prompt = self._start(prompt)
        self._plain = None if plain is None else self._start(plain)
        self._fit: dict[str, float] = {}

    def _start(self, prompt: list[int]) -> _State:
        import torch

        with torch.no_grad():
            out = self._forward(torch.tensor([prompt]), torch.ones(1, len(prompt), dtype=torch.long), None)
        return _State(self._cache_of(out), torch.log_softmax(out.logits[0, -1].float(), -1))

    def fit(self, wordings: list[str]) -> list[float]:
        """How much likelier the model finds each wording for the prompt's reader than for none: the mean token
        log-probability of the wording right after the prompt, less the same after the plain prompt (0 without an
        audience). Cached per wording: a template's wordings recur on every decision."""
        if self._plain is None:
            return [0.0] * len(wordings)
        new = [w for w in dict.fromkeys(wordings) if w not in self._fit]
        if new:
            rows = [self.ids(w.strip()) or [self.tok.eos_token_id] for w in new]
            asked, plain = (
                self._score(_State(copy.deepcopy(s.cache), s.last), rows, 0)[0] for s in (self._prompt, self._plain)
            )
            if len(self._fit) > 4096:  # (openings carry a decision's names: bounded)
                self._fit.clear()
            self._fit.update({w: a - b for w, a, b in zip(new, asked, plain)})
        return [self._fit[w] for w in wordings]

    def _forward(self, ids, mask, cache):
        from transformers import DynamicCache

        cache = DynamicCache() if cache is None else cache
        return self.model(input_ids=ids, attention_mask=mask, use_cache=True, **{self._cache_arg: cache})

    def _cache_of(self, out):
        return getattr(out, self._cache_arg)

    def ids(self, text: str) -> list[int]:
        """The tokens of ``text`` (cached: a template's wordings recur on every decision; bounded, as its fixed
        words carry each decision's names and numbers)."""
        if text not in self._ids:
            if len(self._ids) > 16384:
                self._ids.clear()
            self._ids[text] = self.tok.encode(text, add_special_tokens=False) if text else []
        return self._ids[text]

    def choose(self, variants: list[list[Rendered]]) -> Rendered:
        """The text with the model's choice at every place the template offers one; its ``chosen`` is (sentences
        whose wording the model chose, sentences with a choice, sentences)."""
        from xairl.narrators.base import join_sentences

        state = _State(copy.deepcopy(self._prompt.cache), self._prompt.last)
        # every wording's fit to the reader, in one batch (most are cached after the first decision)
        self.fit([w for options in variants for o in options if o for p in _pieces(o)[1] for w in p])
        out, pending, counts = [], [], [0, 0, 0]
        for options in variants:
            options = [o for o in options if o]
            if not options:
                continue
            sep = ("\n" if "\n" in out[-1] + options[0] else " ") if out else ""
            sentence, pending, chose = self._sentence(state, options, sep, pending)
            out.append(sentence)
            counts = [counts[0] + chose, counts[1] + (len(options) > 1 or bool(_pieces(options[0])[1])), counts[2] + 1]
        text = join_sentences(out)
        text.chosen = tuple(counts)
        return text

    def _sentence(self, state: _State, options: list[Rendered], sep: str, pending: list[int]):
        """(the chosen rendering of one sentence, the tokens not yet in the cache, whether the model chose)."""
        chose = False
        if len(options) > 1:  # the variant first: each scored on its opening, with its first wordings
            paths = []
            for o in options:
                fixed, points = _pieces(o)
                path = self.ids(sep + fixed[0])
                for words, after in zip(points, fixed[1:]):
                    path = path + self.ids(words[0]) + self.ids(after)
                paths.append(path)
            fit = self.fit([_pieces(o)[0][0].strip() for o in options])
            best, kept = self._pick(state, [pending + p[:OPENING] for p in paths], len(pending), fit)
            v = options[best]
            opening = self.ids(sep + _pieces(v)[0][0])
            self._keep(state, best, len(pending) + min(len(opening), OPENING), kept)
            pending, chose = opening[OPENING:], True
        else:
            v = options[0]
            pending = pending + self.ids(sep + _pieces(v)[0][0])
        fixed, points = _pieces(v)
        choices = []
        for words, after in zip(points, fixed[1:]):
            if len(words) == 1:
                choices.append(0)
                pending = pending + self.ids(words[0]) + self.ids(after)
                continue
            rows = [pending + self.ids(w) + self.ids(after)[:LOOKAHEAD] for w in words]
            best, kept = self._pick(state, rows, len(pending), self.fit(list(words)))
            self._keep(state, best, len(rows[best]), kept)
            choices.append(best)
            pending, chose = self.ids(after)[LOOKAHEAD:], True
        return (v.draft.render(choices) if v.draft is not None else v), pending, chose

    def _pick(self, state: _State, rows: list[list[int]], skip: int, fit: list[float]):
        """(the best row, what :meth:`_keep` takes): the row whose tokens after the first ``skip`` the model finds
        most probable on average, plus the length bonus per token and :data:`FIT` times its fit to the reader. Long
        fixed words before the choice are put in the cache once, not once per row."""
        shared = skip if skip > SHARED else 0
        if shared:
            self._extend(state, rows[0][:shared])
        means, kept = self._score(state, [r[shared:] for r in rows], skip - shared)
        scores = [m + self.bonus * (len(r) - skip) + FIT * f for m, r, f in zip(means, rows, fit)]
        return max(range(len(rows)), key=scores.__getitem__), (*kept, shared)

    def _extend(self, state: _State, tokens: list[int]) -> None:
        """``state`` after ``tokens``."""
        import torch

        past = state.cache.get_seq_length()
        with torch.no_grad():
            out = self._forward(
                torch.tensor([tokens]), torch.ones(1, past + len(tokens), dtype=torch.long), state.cache
            )
        state.cache, state.last = self._cache_of(out), torch.log_softmax(out.logits[0, -1].float(), -1)

    def _score(self, state: _State, rows: list[list[int]], skip: int):
        """(each row's mean log-probability of its tokens after the first ``skip``, the batched forward pass's
        (cache, log-probabilities)); the rows follow ``state``, whose cache the pass takes."""
        import torch

        if any(len(r) == skip for r in rows):  # an empty wording at the very end: judged by the end of the text
            rows = [r + [self.tok.eos_token_id] for r in rows]
        width, past = max(map(len, rows)), state.cache.get_seq_length()
        ids = torch.full((len(rows), width), self.tok.pad_token_id, dtype=torch.long)
        mask = torch.zeros(len(rows), past + width, dtype=torch.long)
        mask[:, :past] = 1
        for i, r in enumerate(rows):
            ids[i, : len(r)] = torch.tensor(r, dtype=torch.long)
            mask[i, past : past + len(r)] = 1
        state.cache.batch_repeat_interleave(len(rows))
        with torch.no_grad():
            out = self._forward(ids, mask, state.cache)
        logp = torch.log_softmax(out.logits.float(), -1)
        scores = []
        for i, r in enumerate(rows):
            before = torch.cat([state.last[None], logp[i, : len(r) - 1]])  # the distribution each token is drawn from
            lp = before[torch.arange(skip, len(r)), torch.tensor(r[skip:], dtype=torch.long)]
            scores.append(float(lp.mean()))
        return scores, (self._cache_of(out), logp)

    @staticmethod
    def _keep(state: _State, row: int, length: int, kept) -> None:
        """The state after ``row``'s first ``length`` tokens of the batched pass ``kept``."""
        cache, logp, shared = kept
        length -= shared
        base = cache.get_seq_length() - logp.shape[1]
        cache.batch_select_indices([row])
        if cache.get_seq_length() > base + length:  # (a negative count removes from the end, in transformers 4 and 5)
            cache.crop(base + length - cache.get_seq_length())
        state.cache = cache
        state.last = logp[row, length - 1] if length else state.last
