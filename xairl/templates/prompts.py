"""Prompt templates: YAML files whose sentences are Jinja2 text rendered in a sandbox with strict variables.

A template lists sentences; each sentence has one or more variants (phrasings) that say the same facts. The
template narrator uses the first variant; the language-model narrator chooses among them.

Lookup of ``NAME``: explicit folders (``--prompts DIR``) > ``$XAIRL_USER_PATH/prompts`` > plugin folders
(``register_prompt_dirs``) > the built-ins shipped in the wheel.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import yaml
from jinja2 import TemplateSyntaxError, UndefinedError, meta, nodes
from jinja2.sandbox import ImmutableSandboxedEnvironment, SecurityError
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from xairl.errors import UnknownNameError, XairlError, validation_message
from xairl.numbers import format_number
from xairl.runs.paths import user_dir
from xairl.templates import choices, sandbox
from xairl.templates.claim_filters import FILTERS as CLAIM_FILTERS
from xairl.templates.sandbox import MAX_LOOP_DEPTH, loop_depth
from xairl.templates.tracking import Rendered, TrackedFloat, TrackedInt, recording, untangle

DECISION_VARS = {
    "index",
    "action",
    "runner_up",
    "score",
    "runner_up_score",
    "q_margin",
    "base_value",
    "method",
    "additivity_gap",
    "top",
    "margin_top",
    "comparisons",
    "extras",
    "k",
    "output",
    "reasons",
    "concession",
    "base_margin",
    "identifiers",
    "trends",
    "both_ways",
    "counterfactual",
}
GLOBAL_VARS = {"n_states", "method", "ranking", "view", "target", "k"}
#: the size of a template: every variant is compiled and rendered on every narration, and `xairl prompts check`
#: verifies each on ~100 decisions (the built-ins: under 5 KB, at most 7 sentences and 14 variants)
MAX_BYTES = 32 * 1024
MAX_SENTENCES = 30
MAX_VARIANTS = 60


#: bidirectional overrides, embeddings, isolates and marks: invisible, and they reorder what a reader sees ('by
#: U+202E 5.03 U+202C' is shown as 'by 30.5'), so words holding one are never shown nor passed as verified
_BIDI = re.compile("[\u061c\u200e\u200f\u202a-\u202e\u2066-\u2069]")


def bidi_controls(text: str) -> str:
    """The bidirectional control characters in ``text``, named ('U+202E, U+202C'); '' when it has none."""
    return ", ".join(dict.fromkeys(f"U+{ord(c):04X}" for c in _BIDI.findall(text)))


def bidi_visible(text: str) -> str:
    """``text`` with each bidirectional control character written out ('<U+202E>'), for a terminal to show as is."""
    return _BIDI.sub(lambda m: f"<U+{ord(m.group()):04X}>", text)


class TemplateError(XairlError):
    """A template that cannot be read, parsed or rendered; the message names the file and line."""


class TemplateSpec(BaseModel):
    model_config = ConfigDict(extra="forbid")

    name: str
    kind: Literal["decision", "global"] = "decision"
    description: str = ""
    #: the output kinds this template narrates (``Policy.output``): a choice among discrete actions needs words
    #: other than a value estimate or the dimensions of a continuous action
    outputs: list[Literal["actions", "continuous", "value"]] = ["actions", "continuous", "value"]
    sentences: list[list[str]] = Field(min_length=1)

    @field_validator("sentences", mode="before")
    @classmethod
    def _single_variant(cls, v):
        return [[s] if isinstance(s, str) else s for s in v] if isinstance(v, list) else v


def _num(x, signed: bool = False) -> str:
    text = format_number(x, signed)
    return x.printed(text) if isinstance(x, (TrackedFloat, TrackedInt)) else text


def _cap(t) -> str:
    """The first letter capitalised (past a tracked value's markers) when the first word is a plain lowercase word
    ('pole angle' -> 'Pole angle'); a name as declared is kept ('cart_velocity', 'rsrp_1', 'dQ' are not words to
    capitalise: 'Cart_velocity' names nothing)."""
    s = str(t)
    if (point := choices.capitalised(s, _cap)) is not None:  # ('{{ pick(...)|cap }}': each wording capitalised)
        return point
    i = next((n for n, c in enumerate(s) if not "\ue000" <= c <= "\ue01f"), len(s))
    word = "".join(c for c in s[i:].split(maxsplit=1)[0] if not "\ue000" <= c <= "\ue01f") if s[i:].strip() else ""
    plain = word.rstrip(".,;:!?)").replace("-", "").replace("'", "")
    return s[:i] + s[i : i + 1].upper() + s[i + 1 :] if plain.isalpha() and plain.islower() else s


def _join(value, d: str = "", attribute=None) -> str:
    """Jinja's ``join``, with each item as it prints (a tracked value keeps its fact)."""
    items = list(value)
    if attribute is not None:
        for part in str(attribute).split("."):
            items = [x.get(part) if isinstance(x, dict) else getattr(x, part) for x in items]
    return str(d).join(str(x) for x in items)


#: a tracked value's bookkeeping (:mod:`xairl.templates.tracking`): '{{ score.fact }}' would print an internal record
TRACKING = ("fact", "transform", "printed")


def environment() -> ImmutableSandboxedEnvironment:
    """A fresh bounded sandbox (:mod:`xairl.templates.sandbox`) with the template filters: ``num`` and ``signed`` write numbers
    as :func:`format_number` does, ``cap`` capitalises the first letter, and the claim filters
    (:mod:`xairl.templates.claim_filters`) write the author's word for a claim: ``dir('raised', 'lowered')`` the first
    word for a number >= 0 and the second for a negative one, ``level('low', 'typical', 'high')``, ``rank('first',
    'second', other='')``, ``cmp(other, 'more', 'less')`` and ``role('chose', 'came second')``. Each keeps the fact
    of a tracked value (:mod:`xairl.templates.tracking`). The global ``pick('came from', 'was due to')`` offers
    wordings of the same words for the language model to choose among (:mod:`xairl.templates.choices`)."""
    env = sandbox.environment(
        {"num": _num, "signed": lambda x: _num(x, True), "cap": _cap, "join": _join} | CLAIM_FILTERS,
        hidden=TRACKING,
    )
    env.globals["pick"] = choices.pick
    return env


@dataclass
class Template:
    spec: TemplateSpec
    path: Path
    lines: list[list[int]]  # file line of each variant

    @property
    def name(self) -> str:
        return self.spec.name

    def render_variants(self, context: dict) -> list[list[Rendered]]:
        """Every variant of every sentence, rendered in one sandbox (one budget), each with the spans of the tracked
        values it printed (:func:`xairl.templates.tracking.track_decision` tracks a context); raises :class:`TemplateError`
        with file and line."""
        env = environment()
        return [
            [self._render(env, text, f"{self.path}:{self.lines[s][v]}", context) for v, text in enumerate(variants)]
            for s, variants in enumerate(self.spec.sentences)
        ]

    @staticmethod
    def _render(env: ImmutableSandboxedEnvironment, text: str, where: str, context: dict) -> Rendered:
        try:
            with recording() as record, choices.choosing() as points:
                marked = sandbox.render(env, text, context)
            if bidi := bidi_controls(marked + "".join(w for p in points for w in p)):
                raise TemplateError(
                    f"{where}: the rendered words hold bidirectional control characters ({bidi}), which reorder "
                    "what a reader sees; remove them from the template and from the names and descriptions it prints."
                )
            if not points:
                return Rendered(*untangle(marked, record))
            draft = choices.Draft.of(marked, points, record)
            rendered = draft.render(0)
            rendered.draft = draft
            return rendered
        except TemplateError:
            raise
        except SecurityError as exc:
            raise TemplateError(f"{where}: refused by the sandbox ({exc}).") from None
        except choices.ChoiceError as exc:
            raise TemplateError(f"{where}: {exc}.") from None
        except UndefinedError as exc:
            raise TemplateError(f"{where}: {exc}; see `xairl prompts check` for the variables.") from None
        except RecursionError:  # parsing deep nesting, or a macro calling itself
            raise TemplateError(
                f"{where}: refused by the sandbox (nesting or recursion deeper than Python's stack "
                "allows; templates may not recurse)."
            ) from None
        except TemplateSyntaxError as exc:
            raise TemplateError(f"{where}: syntax error: {exc.message.rstrip('.')}.") from None
        except Exception as exc:  # a filter or test raising on odd data
            raise TemplateError(f"{where}: cannot render ({type(exc).__name__}: {exc}).") from None


def builtin_dir() -> Path:
    package = Path(__file__).parents[1]  # xairl/
    installed = package / "prompts"  # inside the wheel
    return installed if installed.is_dir() else package.parent / "prompts"  # source checkout


def search_dirs(extra: Iterable[str | Path] = ()) -> list[Path]:
    from xairl.registry.plugins import prompt_dirs

    return [Path(d) for d in extra] + [user_dir() / "prompts"] + [Path(d) for _, d in prompt_dirs()] + [builtin_dir()]


def available(extra: Iterable[str | Path] = ()) -> dict[str, Path]:
    """{template name: file that wins the lookup}."""
    found: dict[str, Path] = {}
    for d in search_dirs(extra):
        for f in sorted(d.glob("*.yaml")) if d.is_dir() else []:
            found.setdefault(f.stem, f)
    return found


def load(name_or_path: str | Path, extra: Iterable[str | Path] = ()) -> Template:
    """A template by name (lookup order in the module doc) or by path to a .yaml file."""
    p = Path(name_or_path)
    if p.suffix in (".yaml", ".yml") and p.is_file():
        return parse(p)
    found = available(extra)
    if str(name_or_path) not in found:
        raise UnknownNameError(
            f"unknown template '{name_or_path}'; known: {', '.join(sorted(found))} (see `xairl prompts list`)."
        )
    return parse(found[str(name_or_path)])


def _variant_lines(text: str) -> list[list[int]]:
    """File line where each variant's text starts (block scalars start on the line after their indicator)."""
    root = yaml.compose(text)
    for key, value in root.value if isinstance(root, yaml.MappingNode) else []:
        if key.value == "sentences" and isinstance(value, yaml.SequenceNode):
            lines = []
            for item in value.value:
                items = item.value if isinstance(item, yaml.SequenceNode) else [item]
                lines.append(
                    [n.start_mark.line + 1 + (1 if getattr(n, "style", None) in ("|", ">") else 0) for n in items]
                )
            return lines
    return []


def _read(path: Path) -> str:
    """The file's text; a file that cannot be read, is larger than :data:`MAX_BYTES` or is not UTF-8 text is no
    template to list problems of."""
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_BYTES + 1)
        if len(data) > MAX_BYTES:
            raise TemplateError(
                f"{path}: larger than {MAX_BYTES // 1024} KB, the most a template may be (the built-ins are under "
                "5 KB); say less in it, or split it into templates of their own."
            )
        return data.decode("utf-8")
    except OSError as exc:
        raise TemplateError(f"{path}: cannot read it ({exc}).") from None
    except UnicodeDecodeError as exc:
        raise TemplateError(
            f"{path}: not UTF-8 text (byte {exc.object[exc.start]:#04x} at offset {exc.start}); a "
            "template is a YAML text file."
        ) from None


def _parse_text(path: Path, text: str) -> Template:
    try:
        data = yaml.safe_load(text)
        lines = _variant_lines(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        line = f":{mark.line + 1}" if mark else ""
        raise TemplateError(f"{path}{line}: YAML error: {getattr(exc, 'problem', exc)}.") from None
    except RecursionError:  # YAML nested thousands deep
        raise TemplateError(f"{path}: YAML nested deeper than the parser can follow.") from None
    if not isinstance(data, dict):
        raise TemplateError(f"{path}: a template is a YAML mapping with name, kind and sentences.")
    try:
        spec = TemplateSpec.model_validate(data)
    except ValidationError as exc:
        raise TemplateError(f"{path}: {validation_message(exc, 'template')}") from None
    variants = sum(map(len, spec.sentences))
    if len(spec.sentences) > MAX_SENTENCES or variants > MAX_VARIANTS:
        raise TemplateError(
            f"{path}: {len(spec.sentences)} sentences with {variants} variants; a template may have at most "
            f"{MAX_SENTENCES} sentences and {MAX_VARIANTS} variants in all (each is rendered and verified on every "
            "narration): keep the sentences that say most, or split it into templates of their own."
        )
    return Template(spec, path, lines or [[0] * len(s) for s in spec.sentences])


def parse(path: Path) -> Template:
    """Read and validate a template file; raises :class:`TemplateError` naming the file and line."""
    return _parse_text(path, _read(path))


def _unknown_callables(env: ImmutableSandboxedEnvironment, ast) -> list[tuple[int, str]]:
    """(line in the variant, problem) for each filter or test the sandbox does not have ('x|nosuch', 'x is nosuch')."""
    out = []
    for node in ast.find_all((nodes.Filter, nodes.Test)):
        kind, known = ("filter", env.filters) if isinstance(node, nodes.Filter) else ("test", env.tests)
        if node.name not in known:
            out.append((node.lineno, f"unknown {kind} '{node.name}'; the {kind}s are: {', '.join(sorted(known))}"))
    return out


def check(path: str | Path, sample: Callable[[str], dict] | None = None) -> list[str]:
    """Problems of a template file, one line each with file:line: YAML and Jinja syntax, unknown variables,
    private attribute access (refused by the sandbox), and, given ``sample`` (template kind -> a context of sample
    facts), a trial rendering. :func:`xairl.narrators.check_template` gives it the narrators' sample facts. A file
    that is not UTF-8 text, or nests too deep to analyse, raises :class:`TemplateError` instead."""
    path = Path(path)
    text = _read(path)
    try:
        tpl = _parse_text(path, text)
    except TemplateError as exc:
        return [str(exc)]
    problems = []
    env = environment()
    allowed = DECISION_VARS if tpl.spec.kind == "decision" else GLOBAL_VARS
    for s, variants in enumerate(tpl.spec.sentences):
        for v, text in enumerate(variants):
            base = tpl.lines[s][v]
            try:
                ast = sandbox.parse_variant(env, text)
            except TemplateSyntaxError as exc:
                problems.append(f"{path}:{base + (exc.lineno or 1) - 1}: syntax error: {exc.message}")
                continue
            except SecurityError as exc:  # too deep to analyse: an error, not a problem to list
                raise TemplateError(f"{path}:{base}: refused by the sandbox ({exc}).") from None
            if loop_depth(ast) > MAX_LOOP_DEPTH:
                problems.append(f"{path}:{base}: sandbox violation: loops nested more than {MAX_LOOP_DEPTH} deep")
            assigned = {
                n.name
                for a in ast.find_all(nodes.Assign)
                for n in [a.target, *a.target.find_all(nodes.Name)]
                if isinstance(n, nodes.Name)
            }
            unknown = _unknown_callables(env, ast)
            problems += [f"{path}:{base + line - 1}: {problem}" for line, problem in unknown]
            # (Jinja compiles the variant to find its variables, and fails at an unknown filter or test)
            for name in sorted(
                set() if unknown else meta.find_undeclared_variables(ast) - allowed - assigned - {"pick"}
            ):
                problems.append(
                    f"{path}:{base}: unknown variable '{name}'; a {tpl.spec.kind} template has: "
                    f"{', '.join(sorted(allowed))}"
                )
            for node in ast.find_all((nodes.Getattr, nodes.Getitem)):
                attr = node.attr if isinstance(node, nodes.Getattr) else getattr(node.arg, "value", None)
                if isinstance(attr, str) and attr.startswith("_"):
                    problems.append(
                        f"{path}:{base + node.lineno - 1}: sandbox violation: access to '{attr}' is refused"
                    )
    if not problems and sample is not None:
        try:
            tpl.render_variants(sample(tpl.spec.kind))
        except TemplateError as exc:
            problems.append(str(exc))
    return problems
