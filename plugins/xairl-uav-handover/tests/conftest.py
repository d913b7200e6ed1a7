"""The reference plugin's tests run with this plugin selected and no other."""

import pytest

from xairl import plugins


@pytest.fixture(autouse=True)
def only_this_plugin(monkeypatch):
    monkeypatch.setenv(plugins.LOAD_ENV, "uav-handover")
