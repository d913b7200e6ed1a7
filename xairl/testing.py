"""Test helpers for plugin authors: a corpus that checks the verifier against your templates.

:func:`corpus` renders your templates for real decisions and makes each sentence wrong in one way (a number
changed beyond rounding, a direction flipped, a rank swapped, a feature that is not in the explanation, the wrong
action named as chosen) and right in other ways (another phrasing of the template, coarser rounding, direction
synonyms, clauses reordered). A plugin's tests assert that every wrong case fails ``xairl.verify`` and every right
one passes. ``label_words`` is the plugin's vocabulary of words followed by an identifier, not a quantity
(the UAV plugin passes ``("BS", "candidate")``: "BS 15" is a cell id), so those numbers are not mutated.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from xairl.verification.prose.numbers import NUMBER_RE

FLIPS = {"toward": "against", "against": "toward"}


@dataclass(frozen=True)
class Case:
    """One text for the verifier: ``should_pass`` says whether it is true of decision ``index``."""

    kind: str
    text: str
    index: int
    should_pass: bool


def _numbers(text: str, label_words: tuple[str, ...]) -> list[re.Match]:
    """Numbers that are claims: not inside identifiers and names, not right after a label word ("BS 15")."""
    label = re.compile(rf"\b({'|'.join(map(re.escape, label_words))})\s$") if label_words else None
    return [
        m
        for m in NUMBER_RE.finditer(text)
        if not re.search(r"[A-Za-z_]$", text[: m.start()]) and not (label and label.search(text[: m.start()]))
    ]


def wrong(
    text: str, index: int, action: str, other_actions: list[str], label_words: tuple[str, ...] = ()
) -> list[Case]:
    """Copies of a true ``text`` made wrong in one way each."""
    out = []
    for m in _numbers(text, label_words)[:4]:
        s = m.group(1)
        decimals = len(s.split(".")[1]) if "." in s else 0
        bumped = float(s) * 1.5 + (1.0 if abs(float(s)) < 1 else 0) + 10**-decimals * 7
        new = f"{bumped:+.{decimals}f}" if s[0] == "+" else f"{bumped:.{decimals}f}"
        out.append(Case("wrong number", text[: m.start(1)] + new + text[m.end(1) :], index, False))
    for w, flip in FLIPS.items():
        for m in list(re.finditer(rf"\b{w}\b", text))[:2]:
            out.append(Case("flipped direction", text[: m.start()] + flip + text[m.end() :], index, False))
    if "The most important feature" in text:
        out.append(
            Case(
                "swapped rank",
                text.replace("The most important feature", "The second most important feature", 1),
                index,
                False,
            )
        )
    if "The biggest push" in text:
        out.append(Case("swapped rank", text.replace("The biggest push", "The third biggest push", 1), index, False))
    if "mattered most" in text:
        out.append(
            Case("swapped rank", text.replace("mattered most", "was the third most important factor", 1), index, False)
        )
    out.append(
        Case(
            "unknown feature",
            re.sub(r"^(.*?)(\()", r"\1(battery_temperature 41, ", text, count=1)
            if "(" in text
            else text + " The wind_speed pushed toward it by +0.20.",
            index,
            False,
        )
    )
    for m in re.finditer(rf"\b(chose|picked) {re.escape(action)}\b", text):
        for other in other_actions[:2]:
            out.append(
                Case("wrong action", text[: m.start()] + f"{m.group(1)} {other}" + text[m.end() :], index, False)
            )
        break
    return out


def paraphrases(text: str, variants: list[str], index: int, label_words: tuple[str, ...] = ()) -> list[Case]:
    """Rewordings of a true ``text`` that stay true."""
    out = [Case("other phrasing", v, index, True) for v in variants if v != text]
    coarse = text
    for m in reversed(
        [m for m in _numbers(text, label_words) if "." in m.group(1) and len(m.group(1).split(".")[1]) == 2]
    ):
        s = m.group(1)
        x = float(s)
        if abs(x) >= 0.1 and s[-1] != "5":  # one decimal fewer; a trailing 5 would round ambiguously
            coarse = coarse[: m.start(1)] + (f"{x:+.1f}" if s[0] == "+" else f"{x:.1f}") + coarse[m.end(1) :]
    if coarse != text:
        out.append(Case("coarser rounding", coarse, index, True))
    if " toward " in text:
        out.append(Case("direction synonym", text.replace(" pushed toward ", " pushed in favour of "), index, True))
    if " against " in text:
        out.append(Case("direction synonym", text.replace(" pushed against ", " worked against "), index, True))
    parts = text.rstrip(".").split("; ")
    if len(parts) >= 2 and parts[0].count(".") == 0:
        out.append(Case("clauses reordered", "; ".join(parts[1:] + parts[:1]) + ".", index, True))
    return out


def corpus(
    explanation, policy, templates=("explain_action", "why_not"), indices=range(10), label_words: tuple[str, ...] = ()
) -> list[Case]:
    """Mutations and paraphrases of every sentence of the given templates for the given states.

    :param label_words: words after which a number is an identifier, not a claim (see the module doc).
    States where the chosen action was the only available one (an ``action_mask``) have no runner-up, so the
    ``why_not`` template is skipped there.
    """
    from xairl.facts import decision_facts
    from xairl.templates import prompts

    cases: list[Case] = []
    for name in templates:
        tpl = prompts.load(name)
        for i in indices:
            d = decision_facts(explanation, i, policy)
            if name == "why_not" and d.runner_up == d.action:
                continue
            others = [a for a in explanation.action_names if a != d.action]
            for variants in tpl.render_variants(d.context()):
                if not variants[0]:
                    continue
                cases += wrong(variants[0], i, d.action, others, label_words)
                cases += paraphrases(variants[0], variants, i, label_words)
    return cases
