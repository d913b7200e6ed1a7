"""Prompt templates: YAML files whose sentences are Jinja2 text rendered in a sandbox with strict variables.

A template lists sentences; each sentence has one or more variants (phrasings) that say the same facts. The
template narrator uses the first variant; the language-model narrator chooses among them.

Lookup of ``NAME``: explicit folders (``--prompts DIR``) > ``$XAIRL_USER_PATH/prompts`` > plugin folders
(``register_prompt_dirs``) > the built-ins shipped in the wheel.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Literal

import yaml
from jinja2 import StrictUndefined, TemplateSyntaxError, UndefinedError, meta, nodes
from jinja2.sandbox import ImmutableSandboxedEnvironment, SecurityError
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from .errors import UnknownNameError, XairlError, validation_message
from .paths import user_dir

MAX_OUTPUT = 4000  # characters per rendered sentence
MAX_RANGE = 1000  # items produced by range() in one rendering: templates loop over a handful of features
MAX_LOOP_DEPTH = 2  # nested for-loops; deeper nesting is how a small template hangs a process
MAX_REPEAT = 1000  # 'x' * n and [..] * n

DECISION_VARS = {"index", "action", "runner_up", "score", "runner_up_score", "q_margin", "base_value", "method",
                 "additivity_gap", "top", "margin_top", "comparisons", "extras", "k", "output", "reasons",
                 "concession", "base_margin", "identifiers"}
GLOBAL_VARS = {"n_states", "method", "ranking", "k"}


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


def _fmt(x, signed=False):
    from .narrators.facts import fmt

    return fmt(float(x), signed)


class _Sandbox(ImmutableSandboxedEnvironment):
    """Jinja's immutable sandbox (no private attributes, no mutation of data), plus bounds on loops, repetition
    and powers, so that a template can neither escape nor hang the process."""

    intercepted_binops = frozenset(["*", "**"])

    def call_binop(self, context, operator, left, right):
        if operator == "**" and isinstance(right, (int, float)) and abs(right) > 64:
            raise SecurityError(f"exponent {right} is too large (limit 64)")
        if operator == "*" and any(isinstance(a, (str, list, tuple)) for a in (left, right)):
            n = right if isinstance(left, (str, list, tuple)) else left
            if isinstance(n, int) and n > MAX_REPEAT:
                raise SecurityError(f"repetition by {n} is too large (limit {MAX_REPEAT})")
        return super().call_binop(context, operator, left, right)


def _budgeted_range():
    left = [MAX_RANGE]

    def bounded_range(*args):
        r = range(*args)
        left[0] -= len(r)
        if left[0] < 0:
            raise SecurityError(f"range() would produce more than {MAX_RANGE} items in one rendering")
        return r

    return bounded_range


def loop_depth(ast) -> int:
    def depth(node) -> int:
        inner = max((depth(c) for c in node.iter_child_nodes()), default=0)
        return inner + 1 if isinstance(node, nodes.For) else inner

    return depth(ast)


def environment() -> ImmutableSandboxedEnvironment:
    """A fresh sandbox per rendering (the range() budget is per rendering)."""
    env = _Sandbox(undefined=StrictUndefined, autoescape=False, trim_blocks=True, lstrip_blocks=True)
    env.globals = {"range": _budgeted_range(), "dict": dict, "namespace": env.globals["namespace"]}
    env.filters["num"] = _fmt
    env.filters["signed"] = lambda x: _fmt(x, True)
    env.filters["cap"] = lambda t: str(t)[:1].upper() + str(t)[1:]
    return env


@dataclass
class Template:
    spec: TemplateSpec
    path: Path
    lines: list[list[int]]  # file line of each variant

    @property
    def name(self) -> str:
        return self.spec.name

    def render_variants(self, context: dict) -> list[list[str]]:
        """Every variant of every sentence, rendered; raises :class:`TemplateError` with file and line."""
        env = environment()
        out = []
        for s, variants in enumerate(self.spec.sentences):
            rendered = []
            for v, text in enumerate(variants):
                where = f"{self.path}:{self.lines[s][v]}"
                try:
                    compiled = env.from_string(text)
                    if loop_depth(env.parse(text)) > MAX_LOOP_DEPTH:
                        raise SecurityError(f"loops nested more than {MAX_LOOP_DEPTH} deep")
                    size, chunks = 0, []
                    for chunk in compiled.generate(context):  # stream, so a runaway loop stops at the cap
                        size += len(chunk)
                        if size > MAX_OUTPUT:
                            raise SecurityError(f"output longer than {MAX_OUTPUT} characters")
                        chunks.append(chunk)
                    result = " ".join("".join(chunks).split())
                except SecurityError as exc:
                    raise TemplateError(f"{where}: refused by the sandbox ({exc}).") from None
                except UndefinedError as exc:
                    raise TemplateError(f"{where}: {exc}; see `xairl prompts check` for the variables.") from None
                except RecursionError:
                    raise TemplateError(f"{where}: recursion too deep; templates may not recurse.") from None
                except TemplateSyntaxError as exc:
                    raise TemplateError(f"{where}: syntax error: {exc.message}.") from None
                except Exception as exc:  # a filter or test raising on odd data
                    raise TemplateError(f"{where}: cannot render ({type(exc).__name__}: {exc}).") from None
                rendered.append(result)
            out.append(rendered)
        return out


def builtin_dir() -> Path:
    installed = Path(__file__).parent / "prompts"  # inside the wheel
    return installed if installed.is_dir() else Path(__file__).parent.parent / "prompts"  # source checkout


def search_dirs(extra: Iterable[str | Path] = ()) -> list[Path]:
    from .plugins import prompt_dirs

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
        raise UnknownNameError(f"unknown template '{name_or_path}'; known: {', '.join(sorted(found))} "
                               "(see `xairl prompts list`).")
    return parse(found[str(name_or_path)])


def _variant_lines(text: str) -> list[list[int]]:
    """File line where each variant's text starts (block scalars start on the line after their indicator)."""
    root = yaml.compose(text)
    for key, value in root.value if isinstance(root, yaml.MappingNode) else []:
        if key.value == "sentences" and isinstance(value, yaml.SequenceNode):
            lines = []
            for item in value.value:
                items = item.value if isinstance(item, yaml.SequenceNode) else [item]
                lines.append([n.start_mark.line + 1 + (1 if getattr(n, "style", None) in ("|", ">") else 0)
                              for n in items])
            return lines
    return []


def parse(path: Path) -> Template:
    """Read and validate a template file; raises :class:`TemplateError` naming the file and line."""
    try:
        text = path.read_text()
        data = yaml.safe_load(text)
        lines = _variant_lines(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        line = f":{mark.line + 1}" if mark else ""
        raise TemplateError(f"{path}{line}: YAML error: {getattr(exc, 'problem', exc)}.") from None
    except OSError as exc:
        raise TemplateError(f"{path}: cannot read it ({exc}).") from None
    if not isinstance(data, dict):
        raise TemplateError(f"{path}: a template is a YAML mapping with name, kind and sentences.")
    try:
        spec = TemplateSpec.model_validate(data)
    except ValidationError as exc:
        raise TemplateError(f"{path}: {validation_message(exc, 'template')}") from None
    return Template(spec, path, lines or [[0] * len(s) for s in spec.sentences])


def check(path: str | Path) -> list[str]:
    """Problems of a template file, one line each with file:line: YAML and Jinja syntax, unknown variables,
    private attribute access (refused by the sandbox), and a trial rendering with sample facts."""
    path = Path(path)
    try:
        tpl = parse(path)
    except TemplateError as exc:
        return [str(exc)]
    problems = []
    env = environment()
    allowed = DECISION_VARS if tpl.spec.kind == "decision" else GLOBAL_VARS
    for s, variants in enumerate(tpl.spec.sentences):
        for v, text in enumerate(variants):
            base = tpl.lines[s][v]
            try:
                ast = env.parse(text)
            except TemplateSyntaxError as exc:
                problems.append(f"{path}:{base + (exc.lineno or 1) - 1}: syntax error: {exc.message}")
                continue
            if loop_depth(ast) > MAX_LOOP_DEPTH:
                problems.append(f"{path}:{base}: sandbox violation: loops nested more than {MAX_LOOP_DEPTH} deep")
            assigned = {n.name for a in ast.find_all(nodes.Assign) for n in [a.target, *a.target.find_all(nodes.Name)]
                        if isinstance(n, nodes.Name)}
            for name in sorted(meta.find_undeclared_variables(ast) - allowed - assigned):
                problems.append(f"{path}:{base}: unknown variable '{name}'; a {tpl.spec.kind} template has: "
                                f"{', '.join(sorted(allowed))}")
            for node in ast.find_all((nodes.Getattr, nodes.Getitem)):
                attr = node.attr if isinstance(node, nodes.Getattr) else getattr(node.arg, "value", None)
                if isinstance(attr, str) and attr.startswith("_"):
                    problems.append(f"{path}:{base + node.lineno - 1}: sandbox violation: access to '{attr}' is "
                                    "refused")
    if not problems:
        try:
            tpl.render_variants(sample_context(tpl.spec.kind))
        except TemplateError as exc:
            problems.append(str(exc))
    return problems


class _SampleExtras(dict):
    """Plugin-defined extras are unknown to the core: any key reads as 1 in a trial rendering."""

    def __missing__(self, key):
        return 1


def sample_context(kind: str) -> dict:
    """Plausible facts for trial renderings."""
    from .narrators.facts import Comparison, DecisionFacts, FeatureFact, GlobalFacts

    if kind == "global":
        return GlobalFacts(10, "deep_shap", tuple({"name": f"f{i}", "label": f"feature {i}", "unit": "", "rank": i,
                                                    "mean_abs": 1.0 / i, "high_values": "toward"}
                                                   for i in range(1, 4))).context()
    feats = tuple(FeatureFact(f"f{i}", f"feature {i}", 1.0, "m", 0.5 / i, 30.0, "toward", "high", "high", i,
                              value_text="1.00 m") for i in range(1, 4))
    against = FeatureFact("f4", "feature 4", 2.0, "m", -0.1, 10.0, "against", "low", "low", 4, value_text="2.00 m")
    ident = FeatureFact("f5", "feature 5", 15.0, "", 0.0, 0.0, "toward", "unknown", "", 0, "identifier",
                        value_text="15")
    return DecisionFacts(0, "a", "b", 1.0, 0.5, 0.5, 0.2, "deep_shap", 0.0, feats, feats,
                         (Comparison("x is 1 dB above y", 1.0, "dB"),), {}, reasons=feats, concession=against,
                         base_margin=0.1, identifiers=(ident,)).context() | {"extras": _SampleExtras()}
