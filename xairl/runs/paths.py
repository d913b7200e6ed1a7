"""Where xairl keeps user files: ``$XAIRL_USER_PATH`` (default ``~/.xairl``)."""

from __future__ import annotations

import os
from pathlib import Path


def user_dir() -> Path:
    """The user folder (prompts/, feedback.sqlite, models/); created on first use."""
    path = Path(os.environ.get("XAIRL_USER_PATH") or Path.home() / ".xairl")
    path.mkdir(parents=True, exist_ok=True)
    return path


def model_cache_dir() -> Path:
    """Converted language models: ``$XAIRL_MODEL_CACHE`` or ``<user dir>/models``."""
    path = Path(os.environ.get("XAIRL_MODEL_CACHE") or user_dir() / "models")
    path.mkdir(parents=True, exist_ok=True)
    return path
