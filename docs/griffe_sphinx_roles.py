"""A griffe extension for the API reference: Sphinx cross-reference roles in the docstrings (``:class:`xairl.Policy```,
``:meth:`grouped```) are shown as inline code, since MkDocs does not read Sphinx roles."""

from __future__ import annotations

import re

import griffe

_ROLE = re.compile(r":(?:py:)?(?:class|meth|func|attr|mod|obj|data|exc|const):`~?([^`]+)`")


class SphinxRoles(griffe.Extension):
    def on_object(self, *, obj: griffe.Object, **kwargs) -> None:
        if obj.docstring is not None:
            obj.docstring.value = _ROLE.sub(r"``\1``", obj.docstring.value)
