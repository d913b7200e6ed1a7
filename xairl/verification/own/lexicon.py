"""The words the provenance rules read (:mod:`xairl.verification.own`): labels, role words, sign words, rank
and comparison words, the cuts of a sentence. Data, one place."""

from __future__ import annotations

import re

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
#: the kind of claim a tracked span makes (a checked kind, :data:`xairl.verification.prose.checks.CHECKED`, or a name)
KINDS = {
    "action": "action",
    "level": "magnitude",
    "direction": "direction",
    "direction_high": "direction",
    "direction_low": "direction",
    "comparison": "number",
    "extra": "number",
}
SAID_OF_FEATURE = {
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
#: literal words that cut a sentence into segments (a rule looks only within its segment)
SEGMENT = re.compile(r"[;:()\[\]\n]|\s\|(?=\s)|,|\s[—–-]\s|\b(?:but|while|whereas|although|though|yet|despite)\b", re.I)
BLOCK = re.compile(r"[;:\n]|\s\|(?=\s)")  # (a table's cell, not 'mean |contribution|')
SIGNED_CONTEXT = re.compile(
    r"\b(?:side|push\w*|pull\w*|weigh\w*|reasons?|help\w*|hurt\w*|held|back|for|against|toward\w*|favou?r\w*)\b",
    re.IGNORECASE,
)
#: words right before a value that carry its sign ('minus 1.46', 'a drop of 1.46'), and right after it ('1.46 below
#: zero')
SIGN_BEFORE = re.compile(
    r"\b(?:minus|negative|a drop of|a fall of|a deficit of|fell(?: by)?|dropped(?: by)?|down(?: by)?|"
    r"decreased(?: by)?|short by)\W*$",
    re.IGNORECASE,
)
SIGN_AFTER = re.compile(r"^\W*(?:(?:below|under|less than) (?:zero|0)|in the red|negative|short)\b", re.IGNORECASE)
CHOSEN_BEFORE = re.compile(
    r"\b(?:chose|chosen|choose|chooses|picked|picks|selected|selects|took|takes|preferred|prefers|went with|"
    r"decided on|decision(?: was)?|winner(?: was| is)?|won with|(?<!next )best(?: action)?(?: was| is)?|"
    r"executing|executes|executed|why|action\s*[=:]|chosen\s*[=:]|decision\s*[=:])\W*$",
    re.IGNORECASE,
)
RUNNER_BEFORE = re.compile(
    r"\b(?:runner[-_ ]?up(?: was| is)?|second(?: was| is| best| choice| place)?|rather than|instead of|beat|beats|"
    r"next best(?: was| is)?|alternative(?: was| is)?|why not|preferred to|preferred over|"
    r"(?:lead|margin|edge|advantage|ahead) over|over)\W*$",
    re.IGNORECASE,
)
CHOSEN_AFTER = re.compile(
    r"^\W*(?:won|wins|was chosen|is chosen|was picked|was selected|was preferred|is preferred|beat|beats|"
    r"came first)\b",
    re.I,
)
RUNNER_AFTER = re.compile(r"^\W*(?:came second|was second|lost|was the runner[- ]up|trailed)\b", re.I)
#: words that make a background average what it is ('on average', 'the background's'); a base value printed in
#: a sentence without one is the average written as if it were the decision's own number
BASE_WORDS = re.compile(
    r"\b(?:average|averages|expected|expectation|baseline|base|background|typical|usual|mean|prior|start\w*|"
    r"reference)\b",
    re.IGNORECASE,
)
#: a score named with its action: 'turn (score 3.05)', 'turn won with a score of 3.05', 'score=... for turn'
SCORE_OF_BEFORE = re.compile(r"^\W*(?:\w+\W+){0,8}$")
#: an action's cell, then its score's ('turn | score 3.05', '| turn | score: 3.05')
CELL_SCORE = re.compile(r"\s*\|\s*(?:score|q[- ]?value|value)?\s*[=:]?\s*", re.IGNORECASE)
#: words after a number that make it a contribution ('+0.35 to its margin', '+0.82 (for forward)')
AS_CONTRIBUTION = re.compile(
    r"\s*(?:\(\s*)?(?:to (?:the |its )?(?:margin|score)|(?:for|against|toward|towards|in favou?r of)\s*$)", re.I
)
SCORE_FOR_AFTER = re.compile(r"^\s*(?:for|of|by)\s*$", re.IGNORECASE)
SIDE_OF = re.compile(r"^['’]s\s+(?:side|favou?r|camp)\b", re.IGNORECASE)
#: a label right before a number (key=value, 'score of', '(margin '); quantity group it names
LABELS = (
    (re.compile(r"\b(?:average|expected|baseline|base(?: value)?|background)\b[\w\s']{0,12}\W*$", re.I), "base"),
    (re.compile(r"\b(?:q[- ]?value|score|logit|prediction|estimate)s?\b(?:\s+(?:of|was|is|at))?\W*$", re.I), "score"),
    (
        re.compile(
            r"\b(?:came out at|came out as|ended (?:up )?at|came to|(?:was )?set to|landed at|reached)\W*$", re.I
        ),
        "score",
    ),
    (re.compile(r"\b(?:margin|gap|lead)\b(?:\s+(?:of|was|is))?\W*$", re.I), "margin"),
    (re.compile(r"\b(?:share)\b(?:\s+(?:of|was|is))?\W*$", re.I), "share"),
    (
        re.compile(
            r"\b(?:by|added|adds|adding|subtracted|took|cut|cutting|contributed|contributing|gave|worth)"
            r"(?:\s+(?:about|around|roughly|some|nearly|almost|just))?\W*$",
            re.I,
        ),
        "change",
    ),
    (re.compile(r"\b(?:rank(?:ed)?)\b(?:\s+(?:of|was|is))?\W*$", re.I), "rank"),
)
LABEL_FITS = {
    "base": {"base_value", "base_margin", "mean", "mean_abs"},
    "score": {"score", "contribution"},  # ('it raised the score by +0.3': a contribution to it)
    "margin": {"margin", "contribution"},
    "change": {"margin", "base_margin", "contribution", "share", "mean", "mean_abs", "comparison_value"},
    "share": {"share"},
    "rank": {"rank"},
}
DIFFERENCE = re.compile(
    r"\W*(?:points?\s+)?(?:higher|lower|more|less|above|below|ahead|behind|greater|smaller|better|worse)\b", re.I
)
VIEW_AFTER = re.compile(
    r"^\W*(?:\w+\W+){0,2}?(?:to|on|of|for)\s+(?:the\s+|its\s+)?(?:(margin|gap|lead)|(score))\b", re.I
)
SUPERLATIVE = re.compile(
    r"\b(?:most|biggest|largest|strongest|greatest|main|top|primary|chief|leading|foremost|first|1st|"
    r"number one|mattered most)\b",
    re.IGNORECASE,
)
ORDINAL = {
    2: re.compile(r"\b(?:second|2nd|runner[- ]up feature)\b", re.I),
    3: re.compile(r"\b(?:third|3rd)\b", re.I),
}
NOT_RANK = re.compile(r"\b(?:at most|most of|almost|mostly)\b", re.I)
MORE = re.compile(
    r"\b(?:more than|outweighed|outweighs|bigger than|larger than|stronger than|exceeded|ahead of)\b", re.I
)
LESS = re.compile(r"\b(?:less than|smaller than|weaker than|behind)\b", re.I)
EXTRA_DIRECTIONS = re.compile(r"\b(?:(?P<neg>despite|in spite of)|(?P<for>for))\b", re.IGNORECASE)
#: words that say a side ('favoured B', 'toward B', 'against B'): about the options, so they need to name one
SIDE = re.compile(
    r"favou?r\w*|in favou?r of|toward|towards|against|for|supports?|supported|supporting|help\w*|argu\w* (?:for|against)",
    re.IGNORECASE,
)
#: the side named in words: the chosen action ('favoured it', 'toward the decision')
CHOSEN_SIDE = re.compile(r"\s+(?:it|this|the (?:chosen )?(?:action|decision|choice)|its choice)\b", re.IGNORECASE)
LEVEL = re.compile(
    r"\b(?:low|high|typical|normal|moderate|average)\b(?!\s+(?:value|values|of|score|margin|when))", re.I
)
NEGATED = re.compile(r"(?:\b(?:not|never|no longer|neither|nor)|n't)\b\W*(?:\w+\W+){0,2}$", re.IGNORECASE)
#: a trend word right before a number: the number is a signal's change over its window (:mod:`xairl.policies.windows`), and
#: an 'up' or 'down' word says its sign ('changed', 'moved' say none)
TREND_BEFORE = re.compile(
    r"\b(?:(?P<up>rose|risen|rising|climbed|climbing|increased|increasing|grew|growing|gained|jumped|went up)|"
    r"(?P<down>fell|fallen|falling|dropped|dropping|decreased|decreasing|declined|declining|sank|dipped|went down)|"
    r"changed|moved)(?:\s+by)?(?:\s+(?:about|around|roughly|some|nearly|almost|just))?\W*$",
    re.IGNORECASE,
)
#: what may stand between a direction word and a change it is said of ('went down by about 2 dB')
CHANGE_NEXT = re.compile(r"\W*(?:by\W*)?(?:(?:about|around|roughly|some|nearly|almost|just)\W*)?", re.IGNORECASE)
#: a score as the subject of a trend word ('the margin grew by 8.8'): the number is no signal's change
SCORE_SUBJECT = re.compile(r"\b(?:margin|score|lead|q[- ]?values?|gap|estimate|probability|logit)s?\b", re.I)
#: the quantities a trend word may stand before: a signal's change (a trend's own word, tracked, likewise)
TREND_FITS = {"value_change"}
