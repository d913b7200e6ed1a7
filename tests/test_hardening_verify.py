"""Issue 51, item 1: the verifier's patterns read hostile text (long digit runs, runs of spaces and punctuation,
repeated names) in work linear in its length. `speed 999...9 ! battery raised it.` took 4x the time per 2 more
digits in `directions._JOIN`; other patterns were cubic in a run of spaces.

Work is counted, not timed: :mod:`tests.regex_steps` replays Python's backtracking over a pattern and counts its
steps, the same on any machine and under any load. The times are in ``benchmarks/bench_verify_fuzz.py``.
"""

import importlib
import pkgutil
import re

import numpy as np
import pytest

import xairl
from tests.regex_steps import StepCounter, TooManySteps, steps
from xairl.narrators.verify import binding, comparisons, decision, directions, names, sums, verify

BUDGET = 100_000  # steps: the linear patterns take a few thousand on these texts, the old _JOIN billions


def _steps(pattern: re.Pattern, text: str) -> int:
    try:
        return steps(pattern, text, "match", BUDGET)
    except TooManySteps:
        pytest.fail(
            f"{pattern.pattern[:60]!r}... backtracks past {BUDGET} steps on {text[:40]!r}... ({len(text)} characters)"
        )


#: each pattern that backtracked more than linearly, with the text family that showed it (the run doubles)
HOSTILE = {
    "directions._JOIN digits": (directions._JOIN, lambda k: " " + "9" * k + " ! "),
    "directions._JOIN numbers and list words": (directions._JOIN, lambda k: " " + "9 and " * k + "!"),
    "directions._JOIN commas": (directions._JOIN, lambda k: ", " * k + "!"),
    "directions._HEADER digits": (directions._HEADER, lambda k: "9" * k + "!"),
    "directions._HEADER apostrophes": (directions._HEADER, lambda k: "a'" * k + "!"),
    "directions._SIGNED_OBJECT spaces": (directions._SIGNED_OBJECT, lambda k: " " * k + "!"),
    "names._ASSIGNED spaces": (names._ASSIGNED, lambda k: " " * k + "!"),
    "binding._OUTPUT_AFTER spaces": (binding._OUTPUT_AFTER, lambda k: " " * k + "!"),
    "binding._FROM_NAME spaces": (binding._FROM_NAME, lambda k: " " * k + "!"),
    "binding._FROM_NAME a number's spaces": (binding._FROM_NAME, lambda k: " from 9" + " " * k + "!"),
    "binding._SCORE_GAP spaces": (binding._SCORE_GAP, lambda k: " " * k + "!"),
    "binding._FROM_TO spaces": (binding._FROM_TO, lambda k: "from 9 to" + " " * (3 * k) + "!"),  # (past its 40)
    "comparisons._FACTOR_AFTER spaces": (comparisons._FACTOR_AFTER, lambda k: " " * k + "!"),
    "sums._TOTAL_AFTER spaces": (sums._TOTAL_AFTER, lambda k: " " * k + "!"),
    "decision._COMPARE_AFTER spaces": (decision._COMPARE_AFTER, lambda k: " " * k + "!"),
    "decision._RUNNER_BEFORE spaces": (decision._RUNNER_BEFORE, lambda k: "against" + " " * k + "!"),
}


@pytest.mark.parametrize("case", HOSTILE, ids=list(HOSTILE))
def test_twice_the_run_takes_about_twice_the_steps(case):
    """Linear: doubling the hostile run at most 2.5x the steps (quadratic is 4x; the old _JOIN ran past the budget
    at 40 digits, _HEADER took 12x per doubling, _ASSIGNED and the patterns with '\\s*X?\\s*' 4x to 7x)."""
    pattern, make = HOSTILE[case]
    short, long = _steps(pattern, make(20)), _steps(pattern, make(40))
    assert long <= 2.5 * short, f"{short} steps for a run of 20, {long} for 40"


def _module_patterns():
    package = importlib.import_module("xairl.narrators.verify")
    found = {}
    for info in pkgutil.iter_modules(package.__path__):
        module = importlib.import_module(f"xairl.narrators.verify.{info.name}")
        for name, value in vars(module).items():
            if isinstance(value, re.Pattern) and value.pattern not in found:
                found[value.pattern] = (f"{info.name}.{name}", value)
    return sorted(found.values(), key=lambda x: x[0])


PATTERNS = _module_patterns()
RUNS = ["9", " ", ",", ".", "9 ", "9,", ", ", "( ", "'", "\0", "a ", "\0 ", "-"]


def test_every_pattern_of_the_verifier_is_swept():
    assert len(PATTERNS) >= 150 and "directions._JOIN" in {name for name, _ in PATTERNS}


@pytest.mark.slow
@pytest.mark.parametrize("name, pattern", PATTERNS, ids=[name for name, _ in PATTERNS])
def test_no_pattern_backtracks_past_the_budget_on_a_hostile_run(name, pattern):
    """Every module-level pattern of the verifier, at the start of a run of 24 digits, spaces, commas, points,
    brackets, apostrophes, masked names ('\\0') or words (its own first words before them, so that an anchored
    pattern gets past its opening), ending in a character none of them wants: within the budget."""
    words = sorted(set(re.findall(r"[a-z]{2,}", re.sub(r"\\[a-zA-Z]", " ", pattern.pattern))))[:2]
    for lead in [""] + [w + " " for w in words]:
        for run in RUNS + [w + " " for w in words]:
            counter = StepCounter(pattern, BUDGET)
            try:
                counter.match(lead + run * 24 + "!")
            except TooManySteps:
                pytest.fail(f"{name} backtracks past {BUDGET} steps on {lead!r} + {run!r} * 24 + '!'")


def _explanation(names_, values):
    v = np.asarray(values, dtype=float).reshape(1, -1, 1)
    return xairl.Explanation(
        values=v,
        base_values=np.zeros((1, 1)),
        outputs=v.sum(axis=1),
        states=np.ones((1, len(names_))),
        feature_names=tuple(names_),
        action_names=("out",),
        method="given",
        output="value",
    )


@pytest.mark.parametrize("digits", [12, 30, 400, 5000])
def test_the_issues_sentence_is_read(digits):
    """`speed 99...9 ! battery raised it.`: the '!' ends the list, so 'raised' is said of battery alone (which
    lowered it: contradicted), whatever the digits."""
    exp = _explanation(["speed", "battery", "load"], [0.4, -0.2, 0.05])
    result = verify(f"speed {'9' * digits} ! battery raised it.", exp, 0)
    directions_said = [c for c in result.claims if c.kind == "direction"]
    assert [c.status for c in directions_said] == ["contradicted"]
    assert "battery" in directions_said[0].detail and "speed" not in directions_said[0].detail


@pytest.mark.parametrize(
    "text, statuses",
    [
        ("speed 22 and battery raised it.", ["verified", "contradicted"]),  # a list, with a value between the names
        ("speed (0.4), 3 km and battery lowered it.", ["contradicted", "verified"]),
        ("speed 999999999999999999999999 and load raised it.", ["verified", "verified"]),
    ],
)
def test_a_list_with_numbers_between_its_names_is_still_one_subject(text, statuses):
    exp = _explanation(["speed", "battery", "load"], [0.4, -0.2, 0.05])
    result = verify(text, exp, 0)
    assert [c.status for c in result.claims if c.kind == "direction"] == statuses, result.claims


def test_sentence_ends_are_found_in_linear_work(monkeypatch):
    """2,000 tabs and 2,000 '! ': each '!' was a candidate end whose test for a list item's number ('1.') read the
    whole text before it again (quadratic); the cheap tests come first now, and the number is read in place."""
    verifier = importlib.import_module("xairl.narrators.verify")  # (the package: its name is also the function's)
    read = []

    class Counted:
        def fullmatch(self, text, start, end):
            read.append(end - start)
            return verifier._ITEM_NUMBER_PATTERN.fullmatch(text, start, end)

    monkeypatch.setattr(verifier, "_ITEM_NUMBER_PATTERN", verifier._ITEM_NUMBER, raising=False)
    monkeypatch.setattr(verifier, "_ITEM_NUMBER", Counted())
    text = "\t" * 2000 + " x" + " !" * 2000 + " " + "Speed raised it. 1. Load lowered it. e.g. " * 3
    spans = verifier.sentences(text)
    assert sum(read) <= 4 * len(text), f"{sum(read)} characters read for a text of {len(text)}"
    assert [text[a:b].strip() for a, b in spans][-3:] == ["e.g. Speed raised it.", "1. Load lowered it.", "e.g."]
