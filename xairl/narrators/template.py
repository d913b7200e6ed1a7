"""The deterministic narrator: the first phrasing of every sentence. Always available, instant; no options."""

from __future__ import annotations

from xairl.narrators.base import Narrator, first_phrasings


class TemplateNarrator(Narrator):
    """The template author's first phrasing of every sentence."""

    name = "template"

    def _compose(self, variants: list[list[str]], context: dict) -> str:
        return first_phrasings(variants)
