"""Prompt templates: YAML files whose sentences are Jinja2 text rendered in a sandbox with strict variables.

A template lists sentences; each sentence has one or more variants (phrasings) that say the same facts. The
template narrator uses the first variant; the language-model narrator chooses among them.

Lookup of ``NAME``: explicit folders (``--prompts DIR``) > ``$XAIRL_USER_PATH/prompts`` > plugin folders
(``register_prompt_dirs``) > the built-ins shipped in the wheel.
"""
from __future__ import annotations

import functools
import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterable, Literal

import yaml
from jinja2 import StrictUndefined, TemplateSyntaxError, UndefinedError, meta, nodes
from jinja2.runtime import LoopContext, Macro
from jinja2.sandbox import ImmutableSandboxedEnvironment, SandboxedFormatter, SecurityError
from jinja2.visitor import NodeTransformer
from markupsafe import EscapeFormatter, Markup
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from .errors import UnknownNameError, XairlError, validation_message
from .paths import user_dir

MAX_OUTPUT = 4000  # characters per rendered sentence
MAX_RANGE = 1000  # items produced by range() in one rendering: templates loop over a handful of features
MAX_LOOP_DEPTH = 2  # nested for-loops; deeper nesting is how a small template hangs a process
MAX_VALUE = 100_000  # characters of a string, items of a list (counting its items' own): a sentence needs hundreds
MAX_STEPS = 10_000  # loop iterations and macro calls in one rendering: the built-ins take a few dozen
MAX_WORK = 1_000_000  # characters and items built, read by calls or output in one rendering: a few MB, well under 1 s
MAX_INT_BITS = 10_000  # an integer built by * or ** (3,000 digits): larger ones are slow to build and cannot be printed
MAX_NESTING = 64  # depth of a variant's syntax tree: deeper ones would overflow Python's stack while compiling
RESERVED = "xairl_"  # names of the sandbox's own helpers, which the rewritten template calls

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


def fmt(x: float, signed: bool = False) -> str:
    """How every number in a narrative is written (the ``num`` and ``signed`` filters, and the facts' own texts):
    0 decimals from 100, 1 from 10, else 2 (3 significant digits below 0.01)."""
    x = float(x)
    a = abs(x)
    if x.is_integer() and a < 1e6:  # ids, counts
        s = f"{x:.0f}"
    elif a >= 100:
        s = f"{x:.0f}"
    elif a >= 10:
        s = f"{x:.1f}"
    elif a >= 0.01 or a == 0:
        s = f"{x:.2f}"
    else:
        s = f"{x:.3g}"
    if s.startswith("-") and float(s) == 0:
        s = s[1:]
    return ("+" + s) if signed and not s.startswith("-") else s


def _size(value) -> int:
    """Characters of a string, items of a container plus its items' own sizes; stops counting past MAX_VALUE."""
    total, todo = 0, [value]
    while todo and total <= MAX_VALUE:
        v = todo.pop()
        if isinstance(v, (str, bytes, bytearray)):
            total += len(v)
        elif isinstance(v, (list, tuple, set, frozenset, dict)):
            total += len(v)
            if total <= MAX_VALUE:  # a list of one long string repeated is as large as its printed text
                todo.extend(v.items() if isinstance(v, dict) else v)
    return total


def _fits(size: int, what: str) -> None:
    if size > MAX_VALUE:
        raise SecurityError(f"{what} would build {size} characters or items (limit {MAX_VALUE})")


def _int(x) -> int:
    return x if isinstance(x, int) else 0  # a width of another type makes the operation itself fail


def _spec_widths(spec: str) -> int:
    """Upper bound on the padding a format spec adds: the sum of its numbers (width, precision)."""
    return sum(int(d) if len(d) <= 12 else 10 ** 12 for d in re.findall(r"\d+", spec))


_PRINTF_SPEC = re.compile(r"%(?:\([^)]*\))?([-#0 +*\d.]*)")


def _printf_size(fmt, args) -> int:
    """Upper bound on len(fmt % args): the text plus, per conversion, its width and precision and the largest
    argument ('*' takes the width from the arguments)."""
    values = tuple(args.values()) if isinstance(args, dict) else args if isinstance(args, tuple) else (args,)
    largest = max((_size(v) for v in values), default=0)
    star = max((_int(v) for v in values), default=0)
    specs = _PRINTF_SPEC.findall(fmt if isinstance(fmt, str) else fmt.decode("latin-1"))
    return len(fmt) + sum(_spec_widths(s) + s.count("*") * star + largest for s in specs)


def _iter_size(iterable) -> tuple[list, int]:
    items = list(iterable)  # a generator is listed once so that it can be sized
    return items, sum(_size(x) for x in items)


def _replace_size(s, old, new, count=-1) -> int:
    s, old, new = (x if isinstance(x, (str, bytes)) else str(x) for x in (s, old, new))
    n = s.count(old) if old else len(s) + 1
    n = min(n, count) if isinstance(count, int) and count >= 0 else n
    return len(s) + n * max(len(new) - len(old), 0)


def _method_size(method, args: list, kwargs: dict) -> int:
    """Predicted size of a str or bytes method that pads or repeats, or of int.to_bytes; 0 for any other call.
    Lists `args[0]` in place when it is join's iterable."""
    owner, name = getattr(method, "__self__", None), getattr(method, "__name__", "")
    if isinstance(owner, int) and name == "to_bytes":
        return _int(args[0] if args else kwargs.get("length", 1))
    if not isinstance(owner, (str, bytes, bytearray)):
        return 0
    if name == "expandtabs":
        tabs = owner.count("\t" if isinstance(owner, str) else b"\t")
        return len(owner) + tabs * max(_int(args[0] if args else kwargs.get("tabsize", 8)), 0)
    if not args:
        return 0
    if name in ("center", "ljust", "rjust", "zfill"):
        return max(len(owner), _int(args[0]))
    if name == "replace" and len(args) >= 2:
        return _replace_size(owner, *args[:3])
    if name == "join":
        args[0], size = _iter_size(args[0])
        return size + len(owner) * len(args[0])
    if name == "translate":
        return len(owner) * (1 + _size(args[0]))
    return 0


class _Budget:
    """What one rendering may still spend: steps (loop iterations, macro calls) and work (sizes built or read)."""

    def __init__(self):
        self.steps, self.work = MAX_STEPS, MAX_WORK

    def step(self, work: int = 0) -> None:
        self.steps -= 1
        if self.steps < 0:
            raise SecurityError(f"more than {MAX_STEPS} loop iterations and macro calls in one rendering")
        self.spend(work)

    def spend(self, work: int) -> None:
        self.work -= work
        if self.work < 0:
            raise SecurityError(f"more than {MAX_WORK} characters and items built in one rendering")

    def checked(self, value):
        """`value`, once sized and paid for; every value a template builds passes through here."""
        size = _size(value)
        if size > MAX_VALUE:
            raise SecurityError(f"a value of more than {MAX_VALUE} characters or items")
        self.spend(size)
        return value

    def iterate(self, iterable, text: int = 0):
        """A for-loop's items, each a step plus the template text its body outputs."""
        for item in iterable:
            self.step(text)
            yield item

    def concat(self, *pieces) -> str:
        """The `~` operator, sized before it joins."""
        texts = [p if isinstance(p, str) else str(p) for p in pieces]
        _fits(sum(map(len, texts)), "'~'")
        return self.checked("".join(texts))


def _binop_size(operator: str, left, right) -> int:
    """Predicted size of a string or list built by *, + or %."""
    seqs = (str, bytes, list, tuple)
    if operator == "*" and isinstance(left, seqs) and isinstance(right, int):
        return _size(left) * max(right, 0)
    if operator == "*" and isinstance(right, seqs) and isinstance(left, int):
        return _size(right) * max(left, 0)
    if operator == "+" and isinstance(left, seqs):
        return _size(left) + _size(right)
    if operator == "%" and isinstance(left, (str, bytes)):
        return _printf_size(left, right)
    return 0


def _int_bits(operator: str, left, right) -> int:
    """Predicted bit length of an integer built by * or **."""
    if not (isinstance(left, int) and isinstance(right, int)):
        return 0
    return left.bit_length() * max(right, 0) if operator == "**" else left.bit_length() + right.bit_length()


class _BoundedFormatter(SandboxedFormatter):
    """str.format's formatter, refusing fields whose widths and values add up past MAX_VALUE."""

    built = 0

    def format_field(self, value, format_spec):
        self.built += _spec_widths(format_spec) + _size(value)  # nested '{:{}}' widths are filled in by now
        _fits(self.built, "str.format()")
        return super().format_field(value, format_spec)


class _BoundedEscapeFormatter(_BoundedFormatter, EscapeFormatter):
    pass


class _Sandbox(ImmutableSandboxedEnvironment):
    """Jinja's immutable sandbox (no private attributes, no mutation of data) with bounds for the whole rendering:
    every value built is sized (before it is built where the size can be predicted), and loops, macro calls and
    the work done spend a budget, so that a template can neither escape nor hang the process nor fill memory."""

    intercepted_binops = frozenset(["*", "**", "+", "%"])

    def __init__(self, budget: _Budget, **options):
        super().__init__(**options)
        self.budget = budget

    def call_binop(self, context, operator, left, right):
        _fits(_binop_size(operator, left, right), f"'{operator}'")
        if (bits := _int_bits(operator, left, right)) > MAX_INT_BITS:
            raise SecurityError(f"'{operator}' would build a {bits}-bit integer (limit {MAX_INT_BITS})")
        return self.budget.checked(super().call_binop(context, operator, left, right))

    def call(__self, __context, __obj, *args, **kwargs):  # noqa: N805 (Jinja's signature: keywords stay free)
        """Every call a template makes: a macro call spends a step, a recursive loop's items spend steps, padding
        methods are sized first, and every result and argument is sized and paid for."""
        budget, args = __self.budget, list(args)
        if isinstance(__obj, (Macro, LoopContext)):
            budget.step()
        if isinstance(__obj, LoopContext) and args:
            args[0] = budget.iterate(args[0])  # the next level of a recursive loop
        _fits(_method_size(__obj, args, kwargs), f"{getattr(__obj, '__name__', 'a call')}()")
        budget.spend(_size(getattr(__obj, "__self__", None)) + sum(map(_size, args)))
        return budget.checked(super().call(__context, __obj, *args, **kwargs))

    def wrap_str_format(self, value):
        """str.format and format_map as Jinja's sandbox has them, with each field sized before it is padded."""
        if super().wrap_str_format(value) is None:
            return None
        owner, is_map = value.__self__, value.__name__ == "format_map"

        def bounded_format(*args, **kwargs):
            if is_map and (kwargs or len(args) != 1):
                raise TypeError("format_map() takes exactly one argument")
            args, kwargs = ((), args[0]) if is_map else (args, kwargs)
            formatter = (_BoundedEscapeFormatter(self, escape=owner.escape) if isinstance(owner, Markup)
                         else _BoundedFormatter(self))
            return type(owner)(formatter.vformat(owner, args, kwargs))

        return bounded_format


def _budgeted_range():
    left = [MAX_RANGE]

    def bounded_range(*args):
        r = range(*args)
        left[0] -= len(r)
        if left[0] < 0:
            raise SecurityError(f"range() would produce more than {MAX_RANGE} items in one rendering")
        return r

    return bounded_range


def _pad(width) -> int:
    return len(width) if isinstance(width, str) else _int(width)  # indent and tojson take a string too


# Predicted result sizes of the built-in filters that pad, repeat or fill by an argument (pass-arg removed).
_FILTER_SIZES = {
    "center": lambda value, width=80: max(_size(value), _int(width)),
    "indent": lambda s, width=4, *_, **__: _size(s) + (len(str(s).splitlines()) + 2) * _pad(width),
    "wordwrap": lambda s, width=79, breaks=True, wrapstring=None, *_, **__: _size(s) * (1 + len(wrapstring or "\n")),
    "truncate": lambda s, length=255, killwords=False, end="...", *_, **__: _size(s) + len(str(end)),
    "format": lambda value, *args, **kwargs: _printf_size(str(value), kwargs or args),
    "replace": lambda s, old, new, count=None: _replace_size(s, old, new, -1 if count is None else count),
    "join": lambda value, d="", attribute=None: _size(value) * (1 + len(str(d))),
    "batch": lambda value, linecount, fill_with=None: _size(value) + (
        0 if fill_with is None else _int(linecount) * (1 + _size(fill_with))),
    "slice": lambda value, slices, fill_with=None: _size(value) + _int(slices) * (1 + _size(fill_with)),
    # adding n lists one by one copies the running total n times
    "sum": lambda iterable, attribute=None, start=0: 0 if isinstance(start, (int, float)) else
    _size(iterable) * len(iterable) + _size(start),
    "tojson": lambda value, indent=None: (_size(value) + 1) * (10 + _pad(indent)),
}


def _guard_filter(name: str, f, budget: _Budget):
    """A built-in filter that is sized before it runs (where _FILTER_SIZES predicts it) and paid for after.
    Filters are called directly by compiled code, not through _Sandbox.call."""
    skip = 1 if getattr(f, "jinja_pass_arg", None) else 0  # the environment or context comes first
    predict = _FILTER_SIZES.get(name)

    @functools.wraps(f)
    def guarded(*args, **kwargs):
        head, args = args[:skip], list(args[skip:])
        if args and isinstance(args[0], Iterator):
            args[0] = list(args[0])  # a generator is listed once so that it can be sized
        if predict:
            _fits(predict(*args, **kwargs), f"the {name} filter")
        budget.spend(sum(map(_size, args)))
        return budget.checked(f(*head, *args, **kwargs))

    return guarded


def _depths(ast) -> tuple[int, int]:
    """(deepest nesting of for-loops, deepest nesting of nodes), walked without recursion: a deeply nested
    template must not overflow the stack here."""
    loops = deepest = 0
    todo = [(ast, 0, 1)]
    while todo:
        node, d, n = todo.pop()
        d += isinstance(node, nodes.For)
        loops, deepest = max(loops, d), max(deepest, n)
        todo.extend((c, d, n + 1) for c in node.iter_child_nodes())
    return loops, deepest


def loop_depth(ast) -> int:
    return _depths(ast)[0]


def _helper(name: str, *args):
    """A call of one of the sandbox's helpers (environment globals named RESERVED + name)."""
    return nodes.Call(nodes.Name(RESERVED + name, "load"), list(args), [], None, None, lineno=args[0].lineno)


class _Guard(NodeTransformer):
    """Rewrites a parsed variant: each for-loop's iterable spends a step per item, and `~` and literal lists,
    tuples and dicts are sized (Jinja builds them in compiled code, out of the sandbox's reach)."""

    def visit_For(self, node):
        node = self.generic_visit(node)
        text = sum(len(t.data) for n in node.body for t in n.find_all(nodes.TemplateData))  # output per item
        node.iter = _helper("iter", node.iter, nodes.Const(text))
        return node

    def visit_Concat(self, node):
        return _helper("concat", *self.generic_visit(node).nodes)

    def visit_List(self, node):
        return _helper("checked", self.generic_visit(node))

    visit_Dict = visit_List

    def visit_Tuple(self, node):
        return self.visit_List(node) if node.ctx == "load" else self.generic_visit(node)  # not a for/set target


def _parse(env: ImmutableSandboxedEnvironment, text: str):
    """A variant's syntax tree; nesting deeper than MAX_NESTING is refused (the parser and compiler recurse)."""
    try:
        ast = env.parse(text)
    except RecursionError:
        ast = None
    if ast is None or _depths(ast)[1] > MAX_NESTING:
        raise SecurityError(f"expressions and blocks nested more than {MAX_NESTING} deep")
    return ast


def _compile(env: ImmutableSandboxedEnvironment, text: str):
    """One variant, parsed, vetted and rewritten (so that its loops and concatenations spend the budget)."""
    ast = _parse(env, text)
    if loop_depth(ast) > MAX_LOOP_DEPTH:
        raise SecurityError(f"loops nested more than {MAX_LOOP_DEPTH} deep")
    if any(name.name.startswith(RESERVED) for name in ast.find_all(nodes.Name)):
        raise SecurityError(f"names starting with '{RESERVED}' are the sandbox's own")
    ast = _Guard().visit(ast)
    ast.set_environment(env)  # on the helper calls too
    return env.from_string(ast)


def environment() -> ImmutableSandboxedEnvironment:
    """A fresh sandbox per rendering: the range(), step and work budgets are per rendering."""
    budget = _Budget()
    env = _Sandbox(budget, undefined=StrictUndefined, autoescape=False, trim_blocks=True, lstrip_blocks=True,
                   finalize=budget.checked)  # every {{ }} output, in macros and set blocks too, is paid for
    env.globals = {"range": _budgeted_range(), "dict": dict, "namespace": env.globals["namespace"],
                   RESERVED + "iter": budget.iterate, RESERVED + "concat": budget.concat,
                   RESERVED + "checked": budget.checked}
    env.filters["num"] = fmt
    env.filters["signed"] = lambda x: fmt(x, True)
    env.filters["cap"] = lambda t: str(t)[:1].upper() + str(t)[1:]
    env.filters = {name: _guard_filter(name, f, budget) for name, f in env.filters.items()}
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
        """Every variant of every sentence, rendered in one sandbox (one budget); raises :class:`TemplateError`
        with file and line."""
        env = environment()
        return [[self._render(env, text, f"{self.path}:{self.lines[s][v]}", context) for v, text in enumerate(variants)]
                for s, variants in enumerate(self.spec.sentences)]

    @staticmethod
    def _render(env: ImmutableSandboxedEnvironment, text: str, where: str, context: dict) -> str:
        try:
            size, chunks = 0, []
            for chunk in _compile(env, text).generate(context):  # stream, so a runaway loop stops at the cap
                size += len(chunk)
                if size > MAX_OUTPUT:
                    raise SecurityError(f"output longer than {MAX_OUTPUT} characters")
                chunks.append(chunk)
            return " ".join("".join(chunks).split())
        except SecurityError as exc:
            raise TemplateError(f"{where}: refused by the sandbox ({exc}).") from None
        except UndefinedError as exc:
            raise TemplateError(f"{where}: {exc}; see `xairl prompts check` for the variables.") from None
        except RecursionError:  # parsing deep nesting, or a macro calling itself
            raise TemplateError(f"{where}: refused by the sandbox (nesting or recursion deeper than Python's stack "
                                "allows; templates may not recurse).") from None
        except TemplateSyntaxError as exc:
            raise TemplateError(f"{where}: syntax error: {exc.message}.") from None
        except Exception as exc:  # a filter or test raising on odd data
            raise TemplateError(f"{where}: cannot render ({type(exc).__name__}: {exc}).") from None


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


def _read(path: Path) -> str:
    """The file's text; a file that cannot be read or is not UTF-8 text is no template to list problems of."""
    try:
        return path.read_bytes().decode("utf-8")
    except OSError as exc:
        raise TemplateError(f"{path}: cannot read it ({exc}).") from None
    except UnicodeDecodeError as exc:
        raise TemplateError(f"{path}: not UTF-8 text (byte {exc.object[exc.start]:#04x} at offset {exc.start}); a "
                            "template is a YAML text file.") from None


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
    return Template(spec, path, lines or [[0] * len(s) for s in spec.sentences])


def parse(path: Path) -> Template:
    """Read and validate a template file; raises :class:`TemplateError` naming the file and line."""
    return _parse_text(path, _read(path))


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
                ast = _parse(env, text)
            except TemplateSyntaxError as exc:
                problems.append(f"{path}:{base + (exc.lineno or 1) - 1}: syntax error: {exc.message}")
                continue
            except SecurityError as exc:  # too deep to analyse: an error, not a problem to list
                raise TemplateError(f"{path}:{base}: refused by the sandbox ({exc}).") from None
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
    if not problems and sample is not None:
        try:
            tpl.render_variants(sample(tpl.spec.kind))
        except TemplateError as exc:
            problems.append(str(exc))
    return problems
