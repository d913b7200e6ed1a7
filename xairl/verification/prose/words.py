"""The words of feature names and the words people write for them: the ``names:`` section of the one lexicon
(xairl/verification/lexicon.yaml), read once."""

from __future__ import annotations

from pathlib import Path

import yaml

_WORDS = yaml.safe_load((Path(__file__).parent.parent / "lexicon.yaml").read_text(encoding="utf-8"))["names"]

#: stop words; words too generic to name a feature on their own; words of a span of time (generic, never a shared
#: mention); units and statistics in names that never name a feature on their own ('14.7 min' names no hm_pr_min)
STOP, GENERIC, SPAN, UNIT_PARTS = (set(_WORDS[k]) for k in ("stop", "generic", "span", "unit_parts"))
#: abbreviations in feature names and the words people write for them ('dist_to_charger_m': 'the distance')
ABBREVIATIONS: dict[str, str] = dict(_WORDS["abbreviations"])
#: words of feature names and other words for the same thing ('battery_pct': 'the charge'); a word shared by two
#: names names both, ambiguously
SYNONYMS: dict[str, tuple[str, ...]] = {k: tuple(v) for k, v in _WORDS["synonyms"].items()}
#: participles said the other way round ('year built' -> 'the build year'); irregular past forms
BASE_FORM: dict[str, str] = dict(_WORDS["base_form"])
IRREGULAR: dict[str, str] = dict(_WORDS["irregular"])
