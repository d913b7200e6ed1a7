"""The language model fills, it does not retype: ``local_lm``'s ``fill`` mode.

The model rewords the template's text one sentence at a time, and its decoding is constrained by
:class:`SpanKeeper`: every tracked span of the sentence (a name, a number, an action, a direction the facts gave) is
a *slot* it must fill, in order, exactly once. It cannot write a digit of its own; the first token of the next slot's
text starts that slot and the rest is written for it; a slot it withholds too long is written for it; it cannot stop
before the last slot. So no number can be invented and none can drift; a name it writes outside the slots that the
template did not write is refused afterwards (a try of :func:`fill` returns None). The slots keep their spans and
facts, and the model's own words between them are judged by :mod:`xairl.verification.own` against those facts.
"""

from __future__ import annotations

import re
import unicodedata
from functools import lru_cache

from xairl.templates.tracking import Rendered, Span

INSTRUCTION = (
    "Reword this sentence so that it reads well for an operator. Keep every name and number exactly as written, "
    "in the same order, with the words that say what each one is.\n\nSentence: "
)
#: added to the logit of every token of the template's own words: the model rewords, it does not write anew
COPY_BIAS = 1.0
#: added to the logit of the next slot's first token: the model is drawn to the next fact, not to words of its own
SLOT_BIAS = 2.0
#: the share of a stretch of the template's words a rewording keeps
MIN_KEPT = 0.5
#: words a rewording may add between two facts
LINKING = frozenset({"and", "then", "also", "while", "with", "so"})
#: words that cannot end a stretch before a fact unless the template's does ('a 0.45')
DANGLING = frozenset({"a", "an", "the", "of", "to", "by", "at", "for", "with"})


@lru_cache(maxsize=4)
def _vocabulary(tok) -> frozenset[int]:
    """Token ids the model may not write freely: digits (any script), brackets, line breaks."""
    banned = set()
    for i in range(len(tok)):
        piece = tok.decode([i])
        if re.search(r"[\d\[\]{}<>|\n\ufffd]", piece) or any(
            unicodedata.numeric(c, None) is not None or unicodedata.category(c)[0] in "CS" for c in piece
        ):  # (a digit of any script, a symbol, a control or format character, a broken byte)
            banned.add(i)
    return frozenset(banned)


@lru_cache(maxsize=4)
def _percent(tok) -> frozenset[int]:
    return frozenset(i for i in range(len(tok)) if "%" in tok.decode([i]))


class SpanKeeper:
    """A logits processor that keeps the slots (module doc). ``slots``: the token ids of each span's text, as it
    would follow a space and as it would follow no space; ``gaps``: the template's number of tokens before each slot
    and after the last one: the model may write twice as many, plus eight, before the next slot is written for it."""

    def __init__(self, tok, slots, gaps: list[int], prompt_len: int, own=(), ending: list[int] = ()):
        banned = _vocabulary(tok)
        if "%" not in tok.decode(list(own)):  # no percentage the template did not write
            banned = banned | _percent(tok)
        # the slots' own tokens that the template's words do not have ('standardised', 'typical'): only in a slot
        self.banned = banned | ({t for a, b in slots for t in a + b} - set(own))
        self.slots, self.eos, self.seen = slots, tok.eos_token_id, prompt_len
        self.limits, self.ending = [2 * g + 8 for g in gaps], list(ending)
        self.own = sorted(set(own) - self.banned)
        self.next, self.free, self.queue = 0, 0, []
        self.placed: list[tuple[int, int]] = []  # (first, last + 1) generated token of each slot

    def _advance(self, ids: list[int]) -> None:
        for k in range(self.seen, len(ids)):
            t = ids[k]
            if self.queue:
                self.queue.pop(0)
            elif self.next < len(self.slots) and t in (self.slots[self.next][0][0], self.slots[self.next][1][0]):
                form = self.slots[self.next][0] if t == self.slots[self.next][0][0] else self.slots[self.next][1]
                self.queue = list(form[1:])
                self.placed.append((k, k + len(form)))
            else:
                self.free += 1
                continue
            if not self.queue:  # the slot is complete
                self.next, self.free = self.next + 1, 0
        self.seen = len(ids)

    def __call__(self, input_ids, scores):
        import torch

        self._advance(input_ids[0].tolist())
        only = None
        if self.queue:
            only = self.queue[0]
        elif self.next < len(self.slots) and self.free >= self.limits[self.next]:
            only = self.slots[self.next][0][0]
        elif self.next >= len(self.slots):  # the template's own ending ('.'), then the end
            only = self.ending[self.free] if self.free < len(self.ending) else self.eos
        if only is not None:
            forced = torch.full_like(scores, float("-inf"))
            forced[:, only] = 0.0
            return forced
        allowed = scores.clone()
        scores[:, self.own] += COPY_BIAS
        scores[:, list(self.banned)] = float("-inf")
        for form in self.slots[self.next]:  # the next slot may start (a number only through it)
            scores[:, form[0]] = allowed[:, form[0]] + SLOT_BIAS
        scores[:, self.eos] = float("-inf")
        return scores


def _stretches(text: Rendered) -> list[str]:
    """The literal words of ``text`` before each tracked span, and after the last."""
    cuts = [0] + [x for sp in text.spans for x in (sp.start, sp.end)] + [len(text)]
    return [text[a:b] for a, b in zip(cuts[::2], cuts[1::2])]


def _new_names(words: Rendered, sentence: Rendered, context: dict) -> list[str]:
    """Feature and action names the model wrote outside the slots more often than the template's own words do."""
    names = {context.get("action"), context.get("runner_up")}
    for key in ("top", "margin_top", "ranking", "identifiers"):
        for f in context.get(key) or ():
            names |= {f.get("name"), f.get("label")}

    mine, template = " ".join(_stretches(words)), " ".join(_stretches(sentence))
    return [
        str(name)
        for name in filter(None, names)
        if len(re.findall(rf"(?<!\w){re.escape(str(name))}(?!\w)", mine, re.I))
        > len(re.findall(rf"(?<!\w){re.escape(str(name))}(?!\w)", template, re.I))
    ]


#: broken output: empty brackets, punctuation repeated, a dangling word before a stop
_JUNK = re.compile(r"\(\s*\)|[.,;:]\s*[.,;:]|\s{2,}|\b(?:and|by|of|the|a)\s*[.;]")


def _is_subsequence(small: list[str], big: list[str]) -> bool:
    it = iter(big)
    return all(w in it for w in small)


def _rewording(words: Rendered, sentence: Rendered) -> bool:
    """The model's words between the slots are a rewording of the template's: in each stretch between two slots it
    may drop words and add linking words (:data:`LINKING`), but not add others nor change their order (a tiny
    model moves 'candidate' past its number: 'a handover to 1 candidate 51.0'); it may not end a stretch on a word
    that wants its noun ('a 0.45'), nor break the punctuation."""
    if _JUNK.search(str(words)) and not _JUNK.search(str(sentence)):
        return False
    for mine, theirs in zip(_stretches(words), _stretches(sentence)):
        a, b = re.findall(r"[\w'’-]+", mine.lower()), re.findall(r"[\w'’-]+", theirs.lower())
        if not _is_subsequence([w for w in a if w not in LINKING], b):
            return False
        if a and a[-1] in DANGLING and (not b or b[-1] != a[-1]):
            return False
        if len(a) < MIN_KEPT * len(b):
            return False
    return True


def fill(model, tok, prefix, sentences: list[Rendered], attempt: int, context: dict) -> Rendered | None:
    """One try: the model's rewording of each sentence around its tracked spans (greedy on the first try, sampled
    after); a sentence whose rewording is refused (its words wander from the template's, break, or name something
    the template did not) keeps the template's words. None when no sentence's rewording was accepted. The result's
    ``reworded`` is (sentences the model reworded, sentences whose words it kept or reworded and were accepted,
    sentences with facts)."""
    from xairl.narrators.base import join_sentences

    out, accepted, reworded, total = [], 0, 0, 0
    for sentence in sentences:
        words = _reword(model, tok, prefix, sentence, attempt) if sentence.spans else None
        total += bool(sentence.spans)
        ok = words is not None and not _new_names(words, sentence, context) and _rewording(words, sentence)
        accepted += ok
        reworded += ok and str(words) != str(sentence)
        out.append(words if ok else sentence)
    if not accepted:  # (the model kept no sentence's facts: the template's text is no try of the model's)
        return None
    result = join_sentences(out)
    result.reworded = (reworded, accepted, total)
    return result


def _reword(model, tok, prefix, sentence: Rendered, attempt: int) -> Rendered | None:
    """The model's rewording of one sentence, its slots in place (None when a slot's text did not come out whole)."""
    import torch
    from transformers import LogitsProcessorList

    prompt = prefix(INSTRUCTION + sentence + "\nRewrite:")
    slots = [
        (tok.encode(" " + sp.text, add_special_tokens=False), tok.encode(sp.text, add_special_tokens=False))
        for sp in sentence.spans
    ]
    stretches = [tok.encode(words, add_special_tokens=False) for words in _stretches(sentence)]
    own = tok.encode(" ".join(_stretches(sentence)), add_special_tokens=False)
    keeper = SpanKeeper(tok, slots, [len(t) for t in stretches], len(prompt), own, stretches[-1])
    ids = torch.tensor([prompt])
    torch.manual_seed(attempt)
    with torch.no_grad():
        out = model.generate(
            ids,
            attention_mask=torch.ones_like(ids),
            logits_processor=LogitsProcessorList([keeper]),
            do_sample=attempt > 0,
            temperature=0.3 if attempt else None,
            top_p=None,
            top_k=None,
            max_new_tokens=sum(keeper.limits) + sum(len(s[0]) for s in slots) + 8,
            pad_token_id=tok.pad_token_id,
        )
    generated = out[0, len(prompt) :].tolist()
    keeper._advance(out[0].tolist())
    if keeper.next < len(slots):
        return None
    text, spans, pos = "", [], 0
    for (a, b), sp in zip(keeper.placed, sentence.spans):
        text += tok.decode(generated[pos : a - len(prompt)], skip_special_tokens=True)
        piece = tok.decode(generated[a - len(prompt) : b - len(prompt)])
        text += piece[: len(piece) - len(piece.lstrip())]
        if piece.strip() != sp.text:
            return None
        spans.append(Span(len(text), len(text) + len(sp.text), sp.text, sp.fact, sp.transform))
        text, pos = text + sp.text, b - len(prompt)
    text += tok.decode(generated[pos:], skip_special_tokens=True)
    cut = len(text.split("\n")[0].rstrip())
    if any(sp.end > cut for sp in spans):
        return None
    return Rendered(text[:cut], tuple(spans))
