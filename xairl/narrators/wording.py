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

Several decisions are worded together (:meth:`Chooser.choose_many`, which the CLI uses): their walks advance in
step, and each step's choices, one per decision, are scored in one batched forward pass (each decision's text so far
left-padded to the longest).

``length``: 'medium' (the default) keeps the most probable wording per token; 'short' and 'long' add a bonus per
token against or for longer wordings, so the model's choice leans to the shorter or the fuller wordings.
"""

from __future__ import annotations

import inspect
from collections.abc import Generator
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
    """The text so far: its keys and values per layer (each (1, heads, tokens, dim)), and the log-probabilities of
    the next token. Never changed in place: a step makes a new one."""

    kv: list
    last: object  # (vocabulary,) log-probabilities after the text so far

    @property
    def length(self) -> int:
        return self.kv[0][0].shape[2] if self.kv else 0


@dataclass
class _Ask:
    """Rows of tokens to score after a state: each row's mean log-probability past its first ``skip`` tokens."""

    state: _State
    rows: list[list[int]]
    skip: int


def _pieces(sentence: Rendered) -> tuple[list[str], list[tuple[str, ...]]]:
    """(the fixed stretches, the choice points' wordings) of a rendered sentence; one stretch when it has none."""
    return sentence.draft.pieces() if sentence.draft is not None else ([str(sentence)], [])


def _layers(cache) -> list:
    """(keys, values) per layer of a transformers cache (``layers`` since transformers 4.56, lists before)."""
    if hasattr(cache, "layers"):
        return [(layer.keys, layer.values) for layer in cache.layers]
    return list(zip(cache.key_cache, cache.value_cache))


class Chooser:
    """Chooses a template's wordings with a causal language model after a prompt; ``plain`` is the prompt without a
    reader, for the wordings' fit to the one ``prompt`` names. The local_lm narrator keeps one per model, prompt and
    length in its process."""

    def __init__(self, model, tok, prompt: list[int], length: str = "medium", plain: list[int] | None = None):
        self.model, self.tok, self.bonus = model, tok, LENGTH_BONUS[length]
        params = inspect.signature(model.forward).parameters
        self._cache_arg = "cache" if "cache" in params else "past_key_values"  # (transformers 5 renamed it)
        self._ids: dict[str, list[int]] = {}
        self._fit: dict[str, float] = {}
        empty = _State([], None)
        self._prompt = self._extend(empty, prompt)
        self._plain = None if plain is None else self._extend(empty, plain)
        self.ready: dict[str, Rendered] = {}  # decisions worded ahead (choose_many), by their template text

    def ids(self, text: str) -> list[int]:
        """The tokens of ``text`` (cached: a template's wordings recur on every decision; bounded, as its fixed
        words carry each decision's names and numbers)."""
        if text not in self._ids:
            if len(self._ids) > 16384:
                self._ids.clear()
            self._ids[text] = self.tok.encode(text, add_special_tokens=False) if text else []
        return self._ids[text]

    def fit(self, wordings: list[str]) -> list[float]:
        """How much likelier the model finds each wording for the prompt's reader than for none: the mean token
        log-probability of the wording right after the prompt, less the same after the plain prompt (0 without an
        audience). Cached per wording: a template's wordings recur on every decision."""
        if self._plain is None:
            return [0.0] * len(wordings)
        new = [w for w in dict.fromkeys(wordings) if w not in self._fit]
        if new:
            rows = [self.ids(w.strip()) or [self.tok.eos_token_id] for w in new]
            (asked, _), (plain, _) = self._score([_Ask(self._prompt, rows, 0), _Ask(self._plain, rows, 0)])
            if len(self._fit) > 4096:  # (openings carry a decision's names: bounded)
                self._fit.clear()
            self._fit.update({w: a - b for w, a, b in zip(new, asked, plain)})
        return [self._fit[w] for w in wordings]

    def choose(self, variants: list[list[Rendered]]) -> Rendered:
        """The text with the model's choice at every place the template offers one; its ``chosen`` is (sentences
        whose wording the model chose, sentences with a choice, sentences)."""
        return self.choose_many([variants])[0]

    def choose_many(self, many: list[list[list[Rendered]]]) -> list[Rendered]:
        """:meth:`choose` for several decisions, their choices scored together, step by step."""
        # every wording's fit to the reader, in one batch (most are cached after the first decision)
        self.fit([w for variants in many for vs in variants for o in vs if o for p in _pieces(o)[1] for w in p])
        walks = [self._walk(variants) for variants in many]
        asks, done = {}, [None] * len(many)
        answers: dict[int, tuple | None] = dict.fromkeys(range(len(many)))
        while answers:
            for i, answer in answers.items():
                try:
                    asks[i] = walks[i].send(answer)
                except StopIteration as stop:
                    done[i] = stop.value
            answers = dict(zip(asks, self._score(list(asks.values())))) if asks else {}
            asks = {}
        return done

    def _walk(self, variants: list[list[Rendered]]) -> Generator[_Ask, tuple, Rendered]:
        from xairl.narrators.base import join_sentences

        state = self._prompt
        out, pending, counts = [], [], [0, 0, 0]
        for options in variants:
            options = [o for o in options if o]
            if not options:
                continue
            sep = ("\n" if "\n" in out[-1] + options[0] else " ") if out else ""
            sentence, state, pending, chose = yield from self._sentence(state, options, sep, pending)
            out.append(sentence)
            offers = len(options) > 1 or any(len(words) > 1 for words in _pieces(options[0])[1])
            counts = [counts[0] + chose, counts[1] + offers, counts[2] + 1]
        text = join_sentences(out)
        text.chosen = tuple(counts)
        return text

    def _sentence(self, state: _State, options: list[Rendered], sep: str, pending: list[int]):
        """(the chosen rendering of one sentence, the state after it, the tokens not yet in it, whether the model
        chose)."""
        chose = False
        if len(options) > 1:  # the variant first: each scored on its opening, with its first wordings
            paths = []
            for o in options:
                fixed, points = _pieces(o)
                path = self.ids(sep + fixed[0])
                for words, after in zip(points, fixed[1:]):
                    path = path + self.ids(words[0]) + self.ids(after)
                paths.append(path[:OPENING])
            fit = self.fit([_pieces(o)[0][0].strip() for o in options])
            opening = [len(self.ids(sep + _pieces(o)[0][0])) for o in options]
            best, state = yield from self._pick(state, pending, paths, fit, [min(n, OPENING) for n in opening])
            v = options[best]
            pending, chose = self.ids(sep + _pieces(v)[0][0])[OPENING:], True
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
            rows = [self.ids(w) + self.ids(after)[:LOOKAHEAD] for w in words]
            best, state = yield from self._pick(state, pending, rows, self.fit(list(words)), [len(r) for r in rows])
            choices.append(best)
            pending, chose = self.ids(after)[LOOKAHEAD:], True
        return (v.draft.render(choices) if v.draft is not None else v), state, pending, chose

    def _pick(self, state: _State, pending: list[int], rows: list[list[int]], fit: list[float], keep: list[int]):
        """(the best row, the state after ``pending`` and its first ``keep`` tokens): the row the model finds most
        probable on average after ``pending``, plus the length bonus per token and :data:`FIT` times its fit to the
        reader. Long fixed words before the choice go into the state first, once, not once per row."""
        if len(pending) > SHARED:
            state, pending = self._extend(state, pending), []
        means, kept = yield _Ask(state, [pending + r for r in rows], len(pending))
        scores = [m + self.bonus * len(r) + FIT * f for m, r, f in zip(means, rows, fit)]
        best = max(range(len(rows)), key=scores.__getitem__)
        return best, kept(best, len(pending) + keep[best])

    def _forward(self, ids, mask, kv: list, positions=None):
        from transformers import DynamicCache

        cache = DynamicCache()
        for n, (k, v) in enumerate(kv):
            cache.update(k, v, n)
        out = self.model(
            input_ids=ids, attention_mask=mask, position_ids=positions, use_cache=True, **{self._cache_arg: cache}
        )
        return out, _layers(getattr(out, self._cache_arg))

    def _extend(self, state: _State, tokens: list[int]) -> _State:
        """The state after ``tokens``."""
        import torch

        with torch.no_grad():
            mask = torch.ones(1, state.length + len(tokens), dtype=torch.long)
            out, kv = self._forward(torch.tensor([tokens]), mask, state.kv)
        return _State(kv, torch.log_softmax(out.logits[0, -1].float(), -1))

    def _score(self, asks: list[_Ask]) -> list[tuple[list[float], object]]:
        """Per ask: (each row's mean log-probability past its first ``skip`` tokens, ``kept(row, n)``: the state
        after that row's first n tokens), all asks in one forward pass; each ask's text so far is left-padded to
        the longest (masked, its positions its own)."""
        import torch
        import torch.nn.functional as F

        rows = []
        for a in asks:  # an empty wording at the very end: judged by the end of the text
            end = any(len(r) == a.skip for r in a.rows)
            rows.append([r + [self.tok.eos_token_id] if end else r for r in a.rows])
        past, width = max(a.state.length for a in asks), max(len(r) for rs in rows for r in rs)
        total = sum(map(len, rows))
        ids = torch.full((total, width), self.tok.pad_token_id, dtype=torch.long)
        mask = torch.zeros(total, past + width, dtype=torch.long)
        positions = torch.zeros(total, width, dtype=torch.long)
        first, n = [], 0
        for a, rs in zip(asks, rows):
            first.append(n)
            for r in rs:
                ids[n, : len(r)] = torch.tensor(r, dtype=torch.long)
                mask[n, past - a.state.length : past + len(r)] = 1
                positions[n] = a.state.length + torch.arange(width)
                n += 1
        kv = [
            tuple(
                torch.cat(
                    [
                        F.pad(a.state.kv[layer][j], (0, 0, past - a.state.length, 0)).expand(len(rs), -1, -1, -1)
                        for a, rs in zip(asks, rows)
                    ]
                )
                for j in (0, 1)
            )
            for layer in range(len(asks[0].state.kv))
        ]
        with torch.no_grad():
            out, kv = self._forward(ids, mask, kv, positions)
        logp = torch.log_softmax(out.logits.float(), -1)
        answers = []
        for a, rs, row0 in zip(asks, rows, first):
            means = []
            for i, r in enumerate(rs):
                before = torch.cat([a.state.last[None], logp[row0 + i, : len(r) - 1]])  # each token's distribution
                means.append(float(before[torch.arange(a.skip, len(r)), torch.tensor(r[a.skip :])].mean()))
            answers.append((means, _Kept(kv, logp, row0, past, a.state)))
        return answers


@dataclass
class _Kept:
    """The state after one row of a batched pass (``kept(row, n)``: after its first n tokens)."""

    kv: list
    logp: object
    row0: int
    past: int
    before: _State

    def __call__(self, row: int, n: int) -> _State:
        if n == 0:
            return self.before
        r, pad = self.row0 + row, self.past - self.before.length
        kv = [
            (k[r : r + 1, :, pad : self.past + n].clone(), v[r : r + 1, :, pad : self.past + n].clone())
            for k, v in self.kv
        ]
        return _State(kv, self.logp[r, n - 1])
