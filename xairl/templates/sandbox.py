"""The sandbox templates are rendered in: Jinja2's immutable sandbox (no private attributes, no mutation of data)
with bounds on the whole rendering, so that a template can neither escape nor hang the process nor fill memory.

Every value a template builds is sized, before it is built where the size can be predicted (``*``, ``+``, ``%``,
``~``, str.format, padding methods and filters), after otherwise; loops, macro calls and the work done spend a budget
per rendering, and a clock (:data:`MAX_SECONDS`) bounds the rest. Each bound is refused with jinja2's ``SecurityError``
naming it; :mod:`xairl.templates.prompts` makes that a one-line ``TemplateError`` (file, line). ``tests/hostile_templates/``.
"""

from __future__ import annotations

import functools
import re
import time
from collections.abc import Callable, Iterator, Mapping

from jinja2 import StrictUndefined, nodes
from jinja2.runtime import LoopContext, Macro
from jinja2.sandbox import ImmutableSandboxedEnvironment, SandboxedFormatter, SecurityError
from jinja2.visitor import NodeTransformer
from markupsafe import EscapeFormatter, Markup

MAX_OUTPUT = 4000  # characters per rendered sentence
MAX_RANGE = 1000  # items produced by range() in one rendering: templates loop over a handful of features
MAX_LOOP_DEPTH = 2  # nested for-loops; deeper nesting is how a small template hangs a process
MAX_VALUE = 100_000  # characters of a string, items of a list (counting its items' own): a sentence needs hundreds
MAX_STEPS = 10_000  # loop iterations and macro calls in one rendering: the built-ins take a few dozen
MAX_WORK = 1_000_000  # characters and items built, read by calls or output in one rendering: a few MB, well under 1 s
MAX_INT_BITS = 10_000  # an integer built by * or ** (3,000 digits): larger ones are slow to build and cannot be printed
MAX_NESTING = 64  # depth of a variant's syntax tree: deeper ones would overflow Python's stack while compiling
MAX_SECONDS = 2.0  # CPU seconds of one rendering of a whole template, compiling included: the built-ins take ms
RESERVED = "xairl_"  # names of the sandbox's own helpers, which the rewritten template calls


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
    return sum(int(d) if len(d) <= 12 else 10**12 for d in re.findall(r"\d+", spec))


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
    n = min(s.count(old) if old else len(s) + 1, count if isinstance(count, int) and count >= 0 else len(s) + 1)
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
        self.steps, self.work, self.deadline = MAX_STEPS, MAX_WORK, time.thread_time() + MAX_SECONDS

    def step(self, work: int = 0) -> None:
        self.steps -= 1
        if self.steps < 0:
            raise SecurityError(f"more than {MAX_STEPS} loop iterations and macro calls in one rendering")
        self.spend(work)

    def spend(self, work: int) -> None:
        self.work -= work
        if self.work < 0:
            raise SecurityError(f"more than {MAX_WORK} characters and items built in one rendering")
        if time.thread_time() > self.deadline:  # slow work within the bounds: its CPU time (a busy machine is not)
            raise SecurityError(f"rendering took over {MAX_SECONDS:g} s: loop over fewer items, write fewer sentences")

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
        # each piece as it prints (a tracked value with its markers, xairl.templates.tracking)
        texts = [str(p) for p in pieces]
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
    """Jinja's immutable sandbox with the bounds of the module doc for the whole rendering."""

    intercepted_binops = frozenset(["*", "**", "+", "%"])

    def __init__(self, budget: _Budget, hidden: frozenset[str], **options):
        super().__init__(**options)
        self.budget, self.hidden = budget, hidden

    def is_safe_attribute(self, obj, attr, value) -> bool:  # the caller's bookkeeping is not the template's to print
        return attr not in self.hidden and super().is_safe_attribute(obj, attr, value)

    def call_binop(self, context, operator, left, right):
        _fits(_binop_size(operator, left, right), f"'{operator}'")
        if (bits := _int_bits(operator, left, right)) > MAX_INT_BITS:
            raise SecurityError(f"'{operator}' would build a {bits}-bit integer (limit {MAX_INT_BITS})")
        if operator == "+" and isinstance(left, str) and isinstance(right, str):
            return self.budget.checked(str(left) + str(right))  # each as it prints, as '~' joins them
        return self.budget.checked(super().call_binop(context, operator, left, right))

    def call(__self, __context, __obj, *args, **kwargs):  # noqa: N805 (Jinja's signature: keywords stay free)
        """Every call a template makes, sized (padding methods first) and paid for; macro calls spend steps."""
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
            formatter = (
                _BoundedEscapeFormatter(self, escape=owner.escape)
                if isinstance(owner, Markup)
                else _BoundedFormatter(self)
            )
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
    "batch": lambda value, linecount, fill_with=None: (
        _size(value) + (0 if fill_with is None else _int(linecount) * (1 + _size(fill_with)))
    ),
    "slice": lambda value, slices, fill_with=None: _size(value) + _int(slices) * (1 + _size(fill_with)),
    # adding n lists one by one copies the running total n times
    "sum": lambda iterable, attribute=None, start=0: (
        0 if isinstance(start, (int, float)) else _size(iterable) * len(iterable) + _size(start)
    ),
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


def parse_variant(env: ImmutableSandboxedEnvironment, text: str):
    """A variant's syntax tree; nesting deeper than MAX_NESTING is refused (the parser and compiler recurse)."""
    try:
        ast = env.parse(text)
    except RecursionError:
        ast = None
    if ast is None or _depths(ast)[1] > MAX_NESTING:
        raise SecurityError(f"expressions and blocks nested more than {MAX_NESTING} deep")
    return ast


def compile_variant(env: ImmutableSandboxedEnvironment, text: str):
    """One variant, parsed, vetted and rewritten (so that its loops and concatenations spend the budget)."""
    ast = parse_variant(env, text)
    if loop_depth(ast) > MAX_LOOP_DEPTH:
        raise SecurityError(f"loops nested more than {MAX_LOOP_DEPTH} deep")
    if any(name.name.startswith(RESERVED) for name in ast.find_all(nodes.Name)):
        raise SecurityError(f"names starting with '{RESERVED}' are the sandbox's own")
    ast = _Guard().visit(ast)
    ast.set_environment(env)  # on the helper calls too
    return env.from_string(ast)


def environment(filters: Mapping[str, Callable] | None = None, hidden=()) -> ImmutableSandboxedEnvironment:
    """A fresh sandbox per rendering (the range(), step, work and time budgets are per rendering), with ``filters``
    added to Jinja's built-in ones (every filter is bounded); attributes named in ``hidden`` are refused."""
    budget = _Budget()
    env = _Sandbox(
        budget,
        frozenset(hidden),
        undefined=StrictUndefined,
        autoescape=False,
        trim_blocks=True,
        lstrip_blocks=True,
        finalize=budget.checked,
    )  # every {{ }} output, in macros and set blocks too, is paid for
    env.globals = {
        "range": _budgeted_range(),
        "dict": dict,
        "namespace": env.globals["namespace"],
        RESERVED + "iter": budget.iterate,
        RESERVED + "concat": budget.concat,
        RESERVED + "checked": budget.checked,
    }
    env.filters.update(filters or {})
    env.filters = {name: _guard_filter(name, f, budget) for name, f in env.filters.items()}
    return env


def render(env: ImmutableSandboxedEnvironment, text: str, context: Mapping) -> str:
    """One variant rendered, streamed so that a runaway loop stops at MAX_OUTPUT, spaces collapsed within each line
    and blank lines dropped (a bullet list stays a list); raises jinja2's SecurityError at any bound."""
    size, chunks = 0, []
    for chunk in compile_variant(env, text).generate(context):
        size += len(chunk)
        if size > MAX_OUTPUT:
            raise SecurityError(f"output longer than {MAX_OUTPUT} characters")
        chunks.append(chunk)
    lines = (" ".join(line.split()) for line in "".join(chunks).splitlines())
    return "\n".join(line for line in lines if line)
