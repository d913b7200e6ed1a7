"""The options convention shared by attributors, narrators, reports and plugins' own settings.

Every configurable piece declares a pydantic model derived from :class:`Options` (unknown keys are an error) and
validates user input with :func:`parse_options`, so a typo in ``-o key=value`` is one line naming the key and the
keys that exist.
"""

from __future__ import annotations

from typing import TypeVar

from pydantic import BaseModel, ConfigDict, ValidationError

from xairl.errors import InputError, validation_message

T = TypeVar("T", bound=BaseModel)


class Options(BaseModel):
    """Base of every options model: unknown keys are an error."""

    model_config = ConfigDict(extra="forbid")


def parse_options(model: type[T], options: dict | T | None, what: str) -> T:
    """``options`` validated against ``model``; raises :class:`InputError` naming the bad keys and the known ones.

    :param what: how the message names the owner, e.g. ``"deep_shap options"``.
    """
    if isinstance(options, model):
        return options
    try:
        return model.model_validate(dict(options or {}))
    except ValidationError as exc:
        known = ", ".join(model.model_fields) or "none"
        raise InputError(f"{validation_message(exc, what)[:-1]}; options: {known}.") from None
    except (TypeError, ValueError) as exc:  # not a mapping at all
        raise InputError(f"invalid {what}: expected key=value options, got {type(options).__name__} ({exc}).") from None
