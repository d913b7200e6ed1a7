"""``xairl verify --explanation FILE``: the explanation a text is checked against, read from either form xairl writes:
the JSON of ``Explanation.to_json()`` (every state), or the JSON lines of ``xairl explain --out`` /
``--format jsonl`` (one :class:`xairl.plugin.StateRecord` a line, ``--index`` choosing the line)."""

from __future__ import annotations

import json

import numpy as np

from xairl.errors import InputError
from xairl.explanations.explanation import Explanation

#: the keys that tell a record line from an explanation's JSON written on one line
_RECORD_KEYS = frozenset({"index", "scores", "base_values", "values", "additivity_gap"})


def read_explanation(path: str, index: int | None) -> tuple[Explanation, int]:
    """(explanation, state to check) from ``path``; ``index`` None: state 0 of an explanation, or the file's one
    record (a file of several records needs ``--index``). One-line InputError on anything else."""
    try:
        with open(path, "rb") as fh:
            raw = fh.read()
    except OSError as exc:
        raise InputError(
            f"cannot read --explanation {path}: {exc.strerror}; give the JSON that Explanation.to_json() writes, "
            "or the explanations.jsonl that xairl explain --out writes."
        ) from None
    lines = [line for line in raw.splitlines() if line.strip()]
    if lines and _is_record(lines[0]):
        return _from_records(path, lines, index), 0
    if lines and _is_narrative(lines[0]):
        raise InputError(
            f"--explanation {path} holds narratives (xairl explain --narrate's lines), not explanations; give the "
            "explanations.jsonl that xairl explain --out writes, or explain again without --narrate."
        )
    try:
        exp = Explanation.from_json(raw)
    except InputError as exc:
        raise InputError(f"--explanation {path}: {exc}") from None
    index = 0 if index is None else index
    try:
        exp.check_index(index)
    except InputError as exc:
        raise InputError(f"--index {index}: {exc}") from None
    return exp, index


def _is_record(line: bytes) -> bool:
    try:
        first = json.loads(line)
    except (ValueError, RecursionError):
        return False
    return isinstance(first, dict) and _RECORD_KEYS <= first.keys() and isinstance(first["values"], dict)


def _is_narrative(line: bytes) -> bool:
    try:
        first = json.loads(line)
    except (ValueError, RecursionError):
        return False
    return isinstance(first, dict) and {"text", "verified"} <= first.keys()


def _from_records(path: str, lines: list[bytes], index: int | None) -> Explanation:
    """Record ``index`` (its line among the file's records, from 0) as an explanation of one state."""
    from pydantic import ValidationError

    from xairl.explanations.explanation_io import StateRecord

    n = len(lines)
    if index is None and n > 1:
        raise InputError(
            f"--explanation {path} holds {n} records (one state each); choose one with --index 0..{n - 1}."
        )
    index = 0 if index is None else index
    if index >= n:
        raise InputError(f"--index {index}: {path} holds {n} record(s); give --index 0..{n - 1}.")
    try:
        data = json.loads(lines[index], parse_constant=_not_finite)
        data.pop("counterfactual", None)  # --format jsonl --counterfactual adds it: not part of the explanation
        rec = StateRecord.model_validate(data)
        return _explanation(rec)
    except (ValueError, TypeError, AttributeError, RecursionError, ValidationError) as exc:
        why = " ".join(str(exc).split())[:120]
        raise InputError(
            f"--explanation {path}: record {index} is not one that xairl explain writes ({why})."
        ) from None


def _not_finite(constant: str):
    raise ValueError(f"{constant} is not a finite number")


def _explanation(rec) -> Explanation:
    """One state's explanation from its record; the actions are the scores' keys, the features the values' keys."""
    actions, features = list(rec.scores), list(rec.values)

    def row(d: dict, what: str) -> list[float]:
        if list(d) != actions:
            raise ValueError(f"{what} names actions {list(d)}, the scores {actions}")
        return [d[a] for a in actions]

    if rec.state is not None and list(rec.state) != features:
        raise ValueError(f"the state names {list(rec.state)}, the values {features}")
    outputs = np.array([row(rec.scores, "scores")])
    available = None
    decides = rec.output == "actions" and rec.chosen in actions and rec.runner_up in actions
    if decides and actions[int(np.argmax(outputs[0]))] != rec.chosen:  # a masked action scored higher
        floor = outputs[0, actions.index(rec.runner_up)]
        available = np.array([[a in (rec.chosen, rec.runner_up) or s < floor for a, s in zip(actions, outputs[0])]])
    return Explanation(
        values=np.array([[row(rec.values[f], f"the values of {f}") for f in features]]),
        base_values=np.array([row(rec.base_values, "base_values")]),
        outputs=outputs,
        states=None if rec.state is None else np.array([[rec.state[f] for f in features]]),
        feature_names=tuple(features),
        action_names=tuple(actions),
        method=rec.method,
        output=rec.output,
        available=available,
    )
