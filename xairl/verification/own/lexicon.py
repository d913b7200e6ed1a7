"""The words the provenance rules read beside a tracked value (labels, sign words, trend words, the cuts of a
sentence): the ``own:`` section of the one lexicon (xairl/verification/lexicon.yaml), compiled once; and the
quantities each rule applies to."""

from __future__ import annotations

import re
from pathlib import Path

import yaml

NUMERIC = {
    "value",
    "fill",
    "value_change",
    "contribution",
    "share",
    "rank",
    "score",
    "margin",
    "base_value",
    "base_margin",
    "gap",
    "mean_abs",
    "mean",
    "comparison_value",
    "n_states",
    "index",
}
#: the kind of claim a tracked span makes (a checked kind, :data:`xairl.verification.result.CHECKED`, or a name)
KINDS = {
    "action": "action",
    "level": "magnitude",
    "direction": "direction",
    "direction_high": "direction",
    "direction_low": "direction",
    "comparison": "comparison",
    "rank_same_way": "rank",
    "extra": "number",
}
SAID_OF_FEATURE = {
    "direction",
    "value",
    "value_text",
    "fill",
    "value_change",
    "trend",
    "contribution",
    "share",
    "rank",
    "level",
    "mean_abs",
    "mean",
}
NUMBER = re.compile(r"[+-]?\d[\d,]*(?:\.\d+)?(?:e[+-]?\d+)?", re.IGNORECASE)
#: the quantities a trend word may stand before: a signal's change (a trend's own word, tracked, likewise)
TREND_FITS = {"value_change"}
#: the quantities each label group ('score=', 'margin of', 'by') may stand before
LABEL_FITS = {
    "base": {"base_value", "base_margin", "mean", "mean_abs"},
    "score": {"score", "contribution"},  # ('it raised the score by +0.3': a contribution to it)
    "margin": {"margin", "contribution"},
    "change": {"margin", "base_margin", "contribution", "share", "mean", "mean_abs", "comparison_value"},
    "share": {"share"},
    "rank": {"rank"},
}

_WORDS = yaml.safe_load((Path(__file__).parent.parent / "lexicon.yaml").read_text(encoding="utf-8"))["own"]


def _compiled(key: str) -> re.Pattern:
    return re.compile(_WORDS[key], re.IGNORECASE)


#: literal words that cut a sentence into segments (a rule looks only within its segment), and into blocks (a list
#: item, a table's cell)
SEGMENT, BLOCK = _compiled("segment"), _compiled("block")
#: words right before a value that carry its sign ('minus 1.46', 'a drop of 1.46'), and right after it ('below zero')
SIGN_BEFORE, SIGN_AFTER = _compiled("sign_before"), _compiled("sign_after")
#: words that make a background average what it is ('on average'): a base value without one is contradicted
BASE_WORDS = _compiled("base_words")
#: a score named with its action ('turn (score 3.05)', 'turn | score 3.05', '3.99 for B')
SCORE_OF_BEFORE, CELL_SCORE, SCORE_FOR_AFTER = (
    _compiled(k) for k in ("score_of_before", "cell_score", "score_for_after")
)
#: words after a number that make it a contribution ('+0.35 to its margin'); 'to the margin' after a contribution
AS_CONTRIBUTION, VIEW_AFTER = _compiled("as_contribution"), _compiled("view_after")
#: a label right before a number ('score=', 'margin of', 'by') and the group of quantities it names
LABELS = tuple((re.compile(x["before"], re.IGNORECASE), x["group"]) for x in _WORDS["labels"])
#: 'its score was 2.34 higher': a difference, not the score; 'A mattered more than B'
DIFFERENCE, MORE, LESS = _compiled("difference"), _compiled("more"), _compiled("less")
#: a trend word right before a number (its sign in the groups up/down), and a score as the trend's subject
TREND_BEFORE, SCORE_SUBJECT = _compiled("trend_before"), _compiled("score_subject")
#: a role's label right before a score ('runner-up: 2.0', 'won with a score of 3.1'), and what may stand between
#: an action and its own score ('turn (score 3.05)', 'turn: 3.05')
RUNNER_LABEL, CHOSEN_LABEL, SCORE_NEXT = (_compiled(k) for k in ("runner_label", "chosen_label", "score_next"))
#: words right after a number that make it the background's average ('0.3 on average over the background')
BASE_AFTER = _compiled("base_after")
