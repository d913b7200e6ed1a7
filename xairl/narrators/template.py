"""The deterministic narrator: the first phrasing of every sentence. Always available, instant."""
from __future__ import annotations

from .base import Narrator


class TemplateNarrator(Narrator):
    name = "template"

    def __init__(self, **options):
        if options:
            from ..errors import InputError

            raise InputError(f"the template narrator takes no options (got {', '.join(options)}).")

    def compose(self, variants: list[list[str]], context: dict) -> str:
        return " ".join(s[0] for s in variants if s[0])
