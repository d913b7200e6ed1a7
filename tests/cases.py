"""The verifier's case corpora (benchmarks/data/verify_cases/*.yaml, issue 54): loaded once, and given to
``pytest.mark.parametrize`` as one item per case with a readable id."""

import functools
import pathlib

import pytest
import yaml

DATA = pathlib.Path(__file__).parents[1] / "benchmarks" / "data" / "verify_cases"


@functools.cache
def load(name: str) -> dict:
    """The whole of ``<name>.yaml``: a mapping of section names to their cases (and any other data, e.g. the
    explanations of second_review.yaml)."""
    return yaml.safe_load((DATA / f"{name}.yaml").read_text(encoding="utf-8"))


def _id(i: int, case: dict) -> str:
    """'007 uav-0 contradicted: The serving RSRQ (-22.5 dB) was worth +12.0 ...': its place in the file, what it is
    read against, the expected verdict and the start of its text."""
    where = [str(case[k]) for k in ("case", "dataset", "index", "explanation") if k in case]
    if "status" in case:
        expected = case["status"]
    elif "accurate" in case:
        expected = "accurate" if case["accurate"] else "inaccurate"
    else:
        expected = f"{case['value']!r}"
    text = case["text"] if len(case["text"]) <= 48 else case["text"][:45] + "..."
    return " ".join([f"{i:03d}", *where, expected]) + ": " + text


def params(name: str, section: str, fields: tuple[str, ...]) -> list:
    """The cases of ``section`` in ``<name>.yaml`` as ``pytest.param``, the values of ``fields`` in that order. A case
    with a ``miss`` (why the reader does not meet it yet: an accurate text contradicted, a false one verified) is a
    strict xfail: it keeps the right verdict in view, and fails the day the reader meets it until the mark goes."""
    return [
        pytest.param(
            *(case[f] for f in fields),
            id=_id(i, case),
            marks=[pytest.mark.xfail(strict=True, reason=case["miss"])] if case.get("miss") else [],
        )
        for i, case in enumerate(load(name)[section])
    ]


def explanation(name: str) -> dict:
    """second_review.yaml's explanation ``name``: the keyword arguments of tests.narrative_corpus.one_output."""
    return load("second_review")["explanations"][name]
