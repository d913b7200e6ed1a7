"""A narrator as a plugin: the shortest phrasing of each sentence, at most ``max_sentences`` sentences.

xairl's ``Narrator.narrate`` does the shared work (facts, template, verification, fallback, confidence); this
class only declares its options and implements ``_compose``.
"""

from pydantic import Field

import xairl


class ShortestOptions(xairl.plugin.Options):
    max_sentences: int = Field(2, ge=1, description="sentences kept, in template order")


class ShortestNarrator(xairl.plugin.Narrator):
    """Terse narratives for a dashboard."""

    name = "shortest"
    Options = ShortestOptions

    def _compose(self, variants, context):
        chosen = [min((v for v in options if v), key=len) for options in variants if any(options)]
        return " ".join(chosen[: self.options.max_sentences])
