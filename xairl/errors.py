"""Exception types a user can cause. Each message is one line that says what is wrong and what to do."""

import re

#: two periods that end a sentence ('... could not parse it..'), not an ellipsis nor a range ('rows 0..99')
_DOUBLED = re.compile(r"(?<![.\d])\.\.(?=\s|\)|$)")


class XairlError(Exception):
    """Base class of every error xairl raises on purpose; the CLI prints it as one line and exits with status 2."""

    def __init__(self, *args):
        if args and isinstance(args[0], str):  # a message built around another that ends in '.': one period
            args = (_DOUBLED.sub(".", args[0]), *args[1:])
        super().__init__(*args)


class InputError(XairlError, ValueError):
    """States, background or files that cannot be explained as given (shape, NaN, non-numeric cells, ...)."""


class UnknownNameError(XairlError, LookupError):
    """A policy, attributor, narrator or command name that no plugin registered."""

    def __str__(self) -> str:  # LookupError would quote the message like a dict key
        return str(self.args[0]) if self.args else ""


class PluginError(XairlError):
    """A plugin that registers something twice or fails to load."""


class UnsupportedModelError(XairlError):
    """A network that an attributor cannot explain correctly (it says which layer and what to use instead)."""


class CheckpointError(XairlError):
    """A checkpoint that is missing, corrupt or does not match the architecture."""


def one_line(exc: BaseException, limit: int = 300) -> str:
    """``TypeName: message`` of an exception raised in user code, on one line and at most ``limit`` characters."""
    return f"{type(exc).__name__}: {' '.join(str(exc).split())[:limit]}"


def validation_message(exc, what: str, unknown: str = "unknown option") -> str:
    """One line naming each bad field of a pydantic ``ValidationError``: ``invalid {what} (field: reason; ...).``

    Plugins use it to turn a settings model's error into an :class:`InputError` message.

    :param unknown: what a field the model does not have is called ("unknown option", "unknown field").
    """
    parts = []
    for err in exc.errors():
        loc = ".".join(str(p)[:40] for p in err["loc"]) or "value"
        msg = unknown if err["type"] == "extra_forbidden" else err["msg"]
        parts.append(f"{loc}: {msg}")
    return " ".join(f"invalid {what} ({'; '.join(parts[:6])}{'; ...' if len(parts) > 6 else ''}).".split())
