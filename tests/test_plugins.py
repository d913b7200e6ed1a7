import subprocess
import sys
import textwrap

import pytest

import xairl
from xairl import plugins
from xairl.errors import PluginError, UnknownNameError


class DuplicateAttributor:
    @xairl.hookimpl
    def register_attributors(self, register):
        register("deep_shap", "xairl.attributors.exact:Exact")


def test_duplicate_name_is_an_error_naming_both_plugins():
    pm = plugins.get_plugin_manager()
    pm.register(DuplicateAttributor(), name="dup-plugin")
    plugins.reset(pm)
    with pytest.raises(PluginError, match="'deep_shap' is registered by both '(xairl|dup-plugin)' and "
                                          "'(xairl|dup-plugin)'"):
        plugins.registry("attributor")


def test_unknown_names_list_the_known_ones():
    with pytest.raises(UnknownNameError, match="unknown policy 'nope'; known: toy"):
        plugins.get_policy("nope")


def test_entry_point_plugin_is_discovered(tmp_path, monkeypatch):
    """A real distribution on sys.path with an entry point in group 'xairl' (no mock of importlib.metadata)."""
    (tmp_path / "fake_xairl_plugin.py").write_text(textwrap.dedent('''
        import xairl

        @xairl.hookimpl
        def register_policies(register):
            register("fake-policy", "xairl.toy:toy_policy", "borrowed toy")

        @xairl.hookimpl
        def register_commands(register):
            def configure(parser):
                parser.add_argument("--word", default="hi")
                parser.set_defaults(run=lambda args: print("fake says", args.word) or 0)
            register("fake", configure, "a command from a plugin")
    '''))
    dist = tmp_path / "fake_xairl_plugin-0.1.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: fake-xairl-plugin\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text("[xairl]\nfake = fake_xairl_plugin\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    plugins.reset()
    assert "fake-policy" in plugins.registry("policy").names()
    assert plugins.registry("policy").entry("fake-policy").plugin == "fake"
    assert plugins.get_policy("fake-policy").n_features == 5
    from xairl.cli import main
    assert main(["fake", "--word", "yo"]) == 0
    assert plugins.summary()["fake"] == {"policy": ["fake-policy"], "command": ["fake"]}


def test_import_is_lazy():
    """`import xairl` loads no plugin and no heavy library; the first lookup does."""
    code = ("import sys, xairl; heavy = [m for m in ('torch', 'shap', 'transformers', 'captum', 'xairl.builtins') "
            "if m in sys.modules]; print(heavy)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"
