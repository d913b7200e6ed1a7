"""Fixtures for every test folder (core and plugins)."""
import pytest

from xairl import plugins


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
