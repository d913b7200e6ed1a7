"""One test per example of every rule in :mod:`xairl.narrators.verify.rules`: a 'fires' sentence's verification
holds a claim made by that rule, a 'silent' one's holds none. The table and the code name the same rules, and the
docs list them all."""

import pathlib
import re

import pytest

import xairl
from xairl.narrators.verify import binding, rules

VERIFY = pathlib.Path(xairl.__file__).parent / "narrators" / "verify"
_RULE_ID = re.compile(
    r"[\"']((?:names|action|category|number|parse|direction|rank|identifier|region)\.[a-z-]+)"
    r"[\"']"
)
EXAMPLES = [
    pytest.param(r.id, fires, name, text, id=f"{r.id}-{'fires' if fires else 'silent'}-{i}")
    for r in rules.RULES
    for fires, examples in ((True, r.fires), (False, r.silent))
    for i, (name, text) in enumerate(examples)
]


@pytest.mark.parametrize("rule,fires,name,text", EXAMPLES)
def test_rule_example(rule, fires, name, text):
    claims = xairl.verify(text, rules.example(name), 0).claims
    assert (rule in {c.rule for c in claims}) == fires, [(c.rule, c.status, c.text) for c in claims]


def test_every_rule_has_examples_both_ways():
    assert all(r.fires and r.silent for r in rules.RULES), [r.id for r in rules.RULES if not (r.fires and r.silent)]
    assert len(rules.BY_ID) == len(rules.RULES)


def test_the_table_names_every_rule_the_code_makes():
    """A rule id is a quoted 'kind.what' literal in the verifier's modules (or one of binding.GUESSED)."""
    made = set(binding.GUESSED)
    for path in VERIFY.glob("*.py"):
        if path.name != "rules.py":
            made |= {m.group(1) for m in _RULE_ID.finditer(path.read_text())}
    assert made == set(rules.BY_ID), (made - set(rules.BY_ID), set(rules.BY_ID) - made)


def test_the_docs_list_every_rule():
    doc = (pathlib.Path(__file__).parents[1] / "docs" / "verifier.md").read_text()
    assert not [r.id for r in rules.RULES if f"`{r.id}`" not in doc]


def test_every_claim_names_its_rule():
    """No reading makes a claim without an id (the trace would show '-')."""
    for r in rules.RULES:
        for name, text in r.fires + r.silent:
            assert all(c.rule for c in xairl.verify(text, rules.example(name), 0).claims), text
