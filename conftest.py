"""Fixtures for every test folder (core and plugins)."""

import os
from pathlib import Path

import pytest

from xairl.registry import plugins


@pytest.fixture(autouse=True)
def user_path(tmp_path, monkeypatch):
    """Every test gets its own empty user folder (prompts, feedback store, model cache)."""
    path = tmp_path / "xairl-user"
    path.mkdir()
    monkeypatch.setenv("XAIRL_USER_PATH", str(path))
    return path


@pytest.fixture(autouse=True)
def fresh_plugins():
    """Each test starts from a fresh plugin manager and empty registries."""
    plugins.reset()
    yield
    plugins.reset()


@pytest.fixture(autouse=True, scope="session")
def model_cache(tmp_path_factory):
    """One converted copy of the local language model per test session (the conversion takes ~15 s), or the one
    `make test`'s set-up made ($XAIRL_TEST_MODEL_CACHE)."""
    given = os.environ.get("XAIRL_TEST_MODEL_CACHE")
    path = Path(given) if given else tmp_path_factory.mktemp("models")
    old = os.environ.get("XAIRL_MODEL_CACHE")
    os.environ["XAIRL_MODEL_CACHE"] = str(path)
    yield path
    if old is None:
        os.environ.pop("XAIRL_MODEL_CACHE", None)
    else:
        os.environ["XAIRL_MODEL_CACHE"] = old
