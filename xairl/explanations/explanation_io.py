"""The JSON forms of an :class:`xairl.Explanation` (``to_json`` / ``from_json``, and one :class:`StateRecord` per
state for JSON lines) and the checks of its structured fields (the observation, the background quartiles) made when
one is built or read: pydantic at the edge, one line on error."""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping
from dataclasses import MISSING, fields
from functools import lru_cache
from typing import Annotated, Any, Literal, get_type_hints

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, create_model

from xairl.errors import InputError, validation_message
from xairl.policies.observation import Observation
from xairl.policies.windows import check_slot_names


class _Window(BaseModel):
    model_config = ConfigDict(extra="forbid")

    signals: list[str] = Field(min_length=1)
    steps: Annotated[int, Field(ge=2)]
    layout: Literal["sequence", "stacked"] = "sequence"
    step_s: Annotated[float, Field(gt=0, allow_inf_nan=False, strict=True)] | None = None
    frames: bool = False  # a frame stack's regions over its frames (xairl.policies.regions.in_regions)


class _Part(BaseModel):
    model_config = ConfigDict(extra="forbid")

    key: str
    shape: list[Annotated[int, Field(ge=1)]]
    categories: Annotated[int, Field(ge=1)] | None = None
    channels: Literal["channels", "frames"] = "channels"  # an image's channels, or the frames of a stack
    window: _Window | None = None  # a window of observations: its signals are the shape's second axis


class _Observation(BaseModel):
    """``Observation.to_dict()``: what an explanation records of the policy's input."""

    model_config = ConfigDict(extra="forbid")

    kind: Literal["flat", "array", "dict", "tuple", "window"]
    parts: list[_Part] = Field(min_length=1)


def check_observation(observation: Any, feature_names: tuple[str, ...]) -> dict:
    """``observation`` as a plain ``Observation.to_dict()`` of one column per feature name; a one-line
    :class:`InputError` for anything else: not a mapping, parts missing, a shape that is a number, other columns, a
    form its kind never has (a 'flat' image, a one-part 'tuple', a key twice), or names that say other columns (a
    window's 'a[t-3]' where its window holds 'a[t-2]')."""
    try:
        obs = _Observation.model_validate(observation)
    except ValidationError as exc:
        raise InputError(
            f"Explanation.observation is not what Observation.to_dict() writes: "
            f"{validation_message(exc, 'observation', 'unknown field')}"
        ) from None
    _check_form(obs)
    columns = sum(p.categories or math.prod(p.shape) for p in obs.parts)
    if columns != len(feature_names):
        raise InputError(
            f"Explanation.observation describes {columns} input columns but the values have "
            f"{len(feature_names)} features; give the observation of the explained policy (or None)."
        )
    out = obs.model_dump()
    for p in out["parts"]:
        if p["window"] is None:
            del p["window"]
        elif not p["window"]["frames"]:
            del p["window"]["frames"]
    _check_names(json.dumps(out, sort_keys=True), tuple(feature_names))
    return out


def _check_form(obs: _Observation) -> None:
    """The forms Observation's constructors make, and no other: 'flat' one vector, 'array' one array of 2 axes or
    more, 'window' one (steps, signals) part with its window, 'tuple' several inputs, 'dict' each key once."""
    kind, parts = obs.kind, obs.parts
    why = None
    if kind in ("flat", "array", "window") and len(parts) != 1:
        why = f"has {len(parts)} parts; it has one"
    elif kind == "flat" and (len(parts[0].shape) != 1 or parts[0].categories):
        why = f"has shape {parts[0].shape}; a flat observation is one vector, [n]"
    elif kind == "array" and (len(parts[0].shape) < 2 or parts[0].categories):
        why = f"has shape {parts[0].shape}; an array has 2 axes or more (one vector is 'flat')"
    elif kind == "tuple" and len(parts) < 2:
        why = "has one part; a tuple is several inputs (one input is 'flat' or 'array')"
    elif kind in ("dict", "tuple") and len({p.key for p in parts}) != len(parts):
        dup = sorted({p.key for p in parts if [q.key for q in parts].count(p.key) > 1})
        why = f"names key '{dup[0]:.40}' twice"
    elif (kind == "window") != (parts[0].window is not None) or any(p.window for p in parts[1:]):
        why = "is inconsistent: a 'window' (and only a window) has one part with its window"
    elif kind == "window" and parts[0].shape != [parts[0].window.steps, len(parts[0].window.signals)]:
        w = parts[0].window
        why = f"has shape {parts[0].shape} but its window is {w.steps} steps x {len(w.signals)} signals"
    if why:
        raise InputError(f"Explanation.observation of kind '{kind}' {why}; give what Observation.to_dict() writes.")


#: a column's name as an array, a dict or a tuple generates it: 'key[2]', 'key[0,3,4]', 'key=1' (a window's slots:
#: :data:`xairl.policies.windows.SLOT_FORM`; a flat observation's 'obs_2' says no structure)
_GENERATED = re.compile(r"(.+?)(?:\[[\d,]+\]|=\d+)", re.S)


@lru_cache(maxsize=16)
def _check_names(observation: str, names: tuple[str, ...]) -> None:
    """Names that the observation would generate, or names of the caller's own: a name in a generated form of one
    of its parts (or a window's slot form), or any name when all are in a generated form, must be the generated name
    of its column, else the names and the observation describe different inputs (cached: an Explanation is checked
    again at each slice)."""
    obs = Observation.from_dict(json.loads(observation))
    if obs.kind == "window":
        return check_slot_names(obs.parts[0].window, names, "Explanation.feature_names")
    if obs.kind == "flat":
        return None
    keys = {p.key for p in obs.parts}
    formed = [(j, m.group(1)) for j, n in enumerate(names) if (m := _GENERATED.fullmatch(n))]
    if not formed:
        return None
    generated = obs.feature_names()
    whole = len(formed) == len(names)  # every name generated: by an observation, this one or another
    for j, key in formed:
        if names[j] != generated[j] and (whole or key in keys):
            raise InputError(
                f"Explanation.feature_names: column {j} is named '{names[j]:.60}' but the observation "
                f"({obs.kind}, {obs.describe()}) names it '{generated[j]:.60}'; the names and the observation disagree."
            )
    return None


def check_quartiles(quartiles: Any, n_features: int) -> None:
    """Background quartiles are a (3, n_features) array: the 25th, 50th and 75th percentiles of each feature."""
    if not isinstance(quartiles, np.ndarray) or quartiles.shape != (3, n_features):
        shape = getattr(quartiles, "shape", type(quartiles).__name__)
        raise InputError(
            f"Explanation.background_quantiles has shape {shape}, expected (3, {n_features}): the 25th, "
            "50th and 75th percentiles of each feature over the background (or None)."
        )


def to_json(exp) -> str:
    """JSON text: each field under its own name, arrays as nested lists (:func:`from_json` reads it back)."""
    data = {f.name: _plain(getattr(exp, f.name)) for f in fields(exp)}
    try:
        return json.dumps(data, allow_nan=False)
    except (TypeError, ValueError) as exc:  # options or extras a plugin filled with something JSON cannot hold
        raise InputError(
            f"this explanation cannot be written as JSON ({exc}); keep its options and extras to "
            "numbers, text, lists and dicts."
        ) from None


def from_json(cls, text: str | bytes):
    """The explanation :func:`to_json` wrote; :class:`InputError` with a one-line reason on anything else."""

    def refuse(constant):
        raise ValueError(f"{constant} is not a finite number")

    def finite(literal):
        value = float(literal)
        return value if np.isfinite(value) else refuse(literal[:20])

    def once(pairs):  # json keeps the last of a key given twice: which one was meant is unknowable
        out = dict(pairs)
        if len(out) != len(pairs):
            seen = [k for k, _ in pairs]
            raise ValueError(f"key '{next(k for k in seen if seen.count(k) > 1)[:40]}' is given twice")
        return out

    try:
        data = json.loads(text, parse_constant=refuse, parse_float=finite, object_pairs_hook=once)
    except RecursionError:
        raise InputError(
            "the explanation's JSON is nested too deeply; give the JSON that Explanation.to_json() writes."
        ) from None
    except (ValueError, TypeError) as exc:  # JSONDecodeError and UnicodeDecodeError are ValueErrors
        raise InputError(
            f"the explanation is not valid JSON ({' '.join(str(exc).split())[:120]}); give the "
            "JSON that Explanation.to_json() writes."
        ) from None
    try:
        record = dict(_json_form(cls).model_validate(data))
    except ValidationError as exc:
        raise InputError(
            f"the explanation's JSON does not match Explanation.to_json(): "
            f"{validation_message(exc, 'explanation', 'unknown field')}"
        ) from None
    except RecursionError:
        raise InputError("the explanation's JSON is nested too deeply.") from None
    try:
        arrays = {k: _ARRAY_FIELDS[k][1](v) for k, v in record.items() if k in _ARRAY_FIELDS and v is not None}
    except (ValueError, OverflowError):  # ragged lists, numbers beyond float64
        raise InputError(
            "the explanation's arrays have rows of different lengths or numbers beyond float64; "
            "give the JSON that Explanation.to_json() writes."
        ) from None
    return cls(**{**record, **arrays})


def _plain(value):
    """A field's value as JSON-ready Python: arrays as nested lists, mappings as dicts, tuples as lists."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (tuple, list)):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value


def _floats(v) -> np.ndarray:
    return np.asarray(v, dtype=np.float64)


def _array_field(ndim: int, item=float):
    """The JSON type of an array field (nested lists ``ndim`` deep) and how it becomes an array again."""
    kind = item
    for _ in range(ndim):
        kind = list[kind]
    return kind, (_floats if item is float else lambda v: np.asarray(v, dtype=bool))


#: the array fields of :class:`Explanation` (all others are JSON as they are); the schema itself is the dataclass
_ARRAY_FIELDS = {
    "values": _array_field(3),
    "base_values": _array_field(2),
    "outputs": _array_field(2),
    "states": _array_field(2),
    "background_quantiles": _array_field(2),
    "available": _array_field(2, bool),
}
_FORM: list[type[BaseModel]] = []


def _json_form(Explanation) -> type[BaseModel]:
    """A validator of the JSON form, generated from the dataclass's own fields (names, types and defaults) once."""
    if _FORM:
        return _FORM[0]
    hints = get_type_hints(Explanation)
    spec = {}
    for f in fields(Explanation):
        kind = hints[f.name]
        if f.name in _ARRAY_FIELDS:
            kind = (
                _ARRAY_FIELDS[f.name][0]
                if f.name in ("values", "base_values", "outputs")
                else _ARRAY_FIELDS[f.name][0] | None
            )
        default = (
            ...
            if f.default is MISSING and f.default_factory is MISSING
            else Field(default_factory=f.default_factory)
            if f.default_factory is not MISSING
            else f.default
        )
        spec[f.name] = (kind, default)
    _FORM.append(create_model("ExplanationJSON", __config__=ConfigDict(extra="forbid"), **spec))
    return _FORM[0]


class StateRecord(BaseModel):
    """One explained state, as written to ``explanations.jsonl`` and by ``xairl explain --format jsonl``."""

    model_config = ConfigDict(extra="forbid")

    index: int
    dataset: str | None = None
    method: str
    state: dict[str, float] | None
    output: str = "actions"
    chosen: str | None
    runner_up: str | None
    scores: dict[str, float]
    base_values: dict[str, float]
    values: dict[str, dict[str, float]]
    additivity_gap: dict[str, float]


def records(exp, dataset: str | None = None) -> list[StateRecord]:
    """One :class:`StateRecord` per state of ``exp`` (the JSON-lines form); ``dataset`` labels where the states
    came from (e.g. 'simulated', 'real')."""
    gap, chosen, runner = exp.additivity_gap, exp.chosen, exp.runner_up
    acts = exp.action_names
    decides = exp.output == "actions"  # continuous dimensions and values have nothing chosen
    out = []
    for i in range(len(exp.values)):
        out.append(
            StateRecord(
                index=i,
                dataset=dataset,
                method=exp.method,
                state=None if exp.states is None else dict(zip(exp.feature_names, exp.states[i].tolist())),
                output=exp.output,
                chosen=acts[chosen[i]] if decides else None,
                runner_up=acts[runner[i]] if decides else None,
                scores=dict(zip(acts, exp.outputs[i].tolist())),
                base_values=dict(zip(acts, exp.base_values[i].tolist())),
                values={f: dict(zip(acts, exp.values[i, j].tolist())) for j, f in enumerate(exp.feature_names)},
                additivity_gap=dict(zip(acts, gap[i].tolist())),
            )
        )
    return out


def state_rows(key, n: int) -> np.ndarray:
    """The positions of the states ``key`` selects among ``n``: a slice, an int, a bool mask (one per state) or
    whole-number positions, as arrays, lists or tensors; a one-line InputError for anything else or out of range."""
    if isinstance(key, tuple):
        raise InputError(
            "an Explanation is indexed by state only (exp[:n], exp[mask], exp[[i, j]]); for one "
            "output use exp.output_slice(j), for features exp.grouped(...)."
        )
    if isinstance(key, (int, np.integer)) and not isinstance(key, (bool, np.bool_)):
        if not -n <= key < n:
            raise InputError(f"index {key} is out of range: the explanation has {n} state(s).")
        key = [int(key) % n]
    if not isinstance(key, slice):
        idx = np.asarray(key.detach().cpu() if hasattr(key, "detach") else key)
        if idx.size == 0 and idx.ndim == 1:
            idx = idx.astype(int)
        if idx.dtype == bool and idx.shape != (n,):
            raise InputError(f"a state mask has one bool per state: got shape {idx.shape} for {n} state(s).")
        if idx.dtype != bool and (idx.ndim != 1 or idx.dtype.kind not in "iu"):
            raise InputError(
                f"states are selected by a slice, a bool mask or whole-number positions, not "
                f"{type(key).__name__} {str(key)[:40]!r}."
            )
        if idx.dtype != bool and idx.size and not (-n <= idx.min() and idx.max() < n):
            raise InputError(
                f"position {idx.max() if idx.max() >= n else idx.min()} is out of range: the "
                f"explanation has {n} state(s)."
            )
        key = idx
    return np.arange(n)[key]
