import subprocess
import sys
import textwrap
from dataclasses import replace

import pytest

import xairl
from xairl.errors import PluginError, UnknownNameError
from xairl.registry import plugins


class DuplicateAttributor:
    @xairl.plugin.hookimpl
    def register_attributors(self, register):
        register("deep_shap", "xairl.attributors.exact:Exact")


def test_duplicate_name_is_an_error_naming_both_plugins():
    pm = plugins.get_plugin_manager()
    pm.register(DuplicateAttributor(), name="dup-plugin")
    plugins.reset(pm)
    with pytest.raises(
        PluginError, match="'deep_shap' is registered by both '(xairl|dup-plugin)' and '(xairl|dup-plugin)'"
    ):
        plugins.registry("attributor")


def test_unknown_names_list_the_known_ones():
    with pytest.raises(UnknownNameError, match="unknown policy 'nope'; known: toy"):
        plugins.get_policy("nope")


def test_entry_point_plugin_is_discovered(tmp_path, monkeypatch):
    """A real distribution on sys.path with an entry point in group 'xairl' (no mock of importlib.metadata)."""
    (tmp_path / "fake_xairl_plugin.py").write_text(
        textwrap.dedent("""
        import xairl

        @xairl.plugin.hookimpl
        def register_policies(register):
            register("fake-policy", "xairl.toy:toy_policy", "borrowed toy")

        @xairl.plugin.hookimpl
        def register_commands(register):
            def configure(parser):
                parser.add_argument("--word", default="hi")
                parser.set_defaults(run=lambda args: print("fake says", args.word) or 0)
            register("fake", configure, "a command from a plugin")
    """)
    )
    dist = tmp_path / "fake_xairl_plugin-0.1.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: fake-xairl-plugin\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text("[xairl]\nfake = fake_xairl_plugin\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv(plugins.LOAD_ENV, "fake")
    plugins.reset()
    assert "fake-policy" in plugins.registry("policy").names()
    assert plugins.registry("policy").entry("fake-policy").plugin == "fake"
    assert plugins.get_policy("fake-policy").n_features == 5
    from xairl.cli import main

    assert main(["fake", "--word", "yo"]) == 0
    assert plugins.summary()["fake"] == {"policy": ["fake-policy"], "command": ["fake"]}


def _install(tmp_path, monkeypatch, name: str, code: str) -> None:
    """A real distribution on sys.path whose entry point ``name`` in group 'xairl' is the module ``code``."""
    mod = f"{name.replace('-', '_')}_plugin"
    (tmp_path / f"{mod}.py").write_text(textwrap.dedent(code))
    dist = tmp_path / f"{mod}-0.1.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {mod}\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text(f"[xairl]\n{name} = {mod}\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, mod, raising=False)  # a module of that name imported by an earlier test


GOOD = """
    import xairl

    @xairl.plugin.hookimpl
    def register_policies(register):
        register("good-policy", "xairl.toy:toy_policy", "borrowed toy")
"""


@pytest.mark.parametrize(
    "broken, error",
    [
        ("raise RuntimeError('boom at import')", "fails to load (RuntimeError: boom at import)"),
        (
            "import xairl\n@xairl.plugin.hookimpl\ndef register_policies(register):\n    register('half', 'x:y')\n"
            "    raise KeyError('oops')\n",
            "failed in register_policies (KeyError",
        ),
        (
            "import xairl\n@xairl.plugin.hookimpl\ndef register_everything(register):\n    pass\n",
            "implements an unknown hook",
        ),
    ],
)
def test_a_broken_plugin_is_reported_and_breaks_nothing_else(tmp_path, monkeypatch, capsys, broken, error):
    from xairl.cli import main

    _install(tmp_path, monkeypatch, "good", GOOD)
    _install(tmp_path, monkeypatch, "broken", broken)
    monkeypatch.setenv(plugins.LOAD_ENV, "good,broken")
    plugins.reset()
    assert main(["explain", "--policy", "good-policy", "--n", "1", "--method", "exact"]) == 0
    assert "half" not in plugins.registry("policy").names()  # a hook that failed half-way registers nothing
    capsys.readouterr()
    assert main(["plugins"]) == 0
    out = capsys.readouterr().out
    assert "good\n  policy: good-policy" in out and f"broken\n  LEFT OUT: {error}" in out
    with pytest.raises(UnknownNameError, match=r"left out: broken \(see `xairl plugins`\)"):
        plugins.get_policy("nope")


def test_plugins_are_selected_by_environment(tmp_path, monkeypatch):
    _install(tmp_path, monkeypatch, "good", GOOD)
    monkeypatch.delenv(plugins.LOAD_ENV)
    plugins.reset()
    assert "good-policy" in plugins.registry("policy").names()  # unset: every installed plugin
    monkeypatch.setenv(plugins.LOAD_ENV, "")
    plugins.reset()
    assert plugins.registry("policy").names() == ["toy"]  # empty: the built-ins only
    monkeypatch.setenv(plugins.LOAD_ENV, "good, missing")
    plugins.reset()
    assert "good-policy" in plugins.registry("policy").names()
    assert plugins.failures() == {"missing": f"is named in ${plugins.LOAD_ENV} but not installed"}


def test_import_is_lazy():
    """`import xairl` loads no plugin and no heavy library; the first lookup does."""
    code = (
        "import sys, xairl; heavy = [m for m in ('torch', 'shap', 'transformers', 'captum', 'xairl.registry.builtins') "
        "if m in sys.modules]; print(heavy)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


REPORT = """
    import numpy as np
    from pydantic import Field
    import xairl

    class TinyOptions(xairl.plugin.Options):
        rows: int = Field(1, ge=1, description="rows of the plugin's own table")

    class TinyReport(xairl.plugin.Report):
        name = "tiny"
        Options = TinyOptions

        def build(self, request):
            policy = xairl.get_policy("toy")
            table = xairl.plugin.table_html(["k", "square"], [[k, k * k] for k in range(self.options.rows)])
            return xairl.plugin.ReportContent(title="tiny report", policy=policy, background=policy.background(20),
                                       datasets=[("sampled", policy.background(request.n_states, seed=1)),
                                                 ("again", policy.background(request.n_states, seed=1))],
                                       tables=[("squares", table)],
                                       commentary=lambda exps: [f"read {', '.join(exps)}"])

    @xairl.plugin.hookimpl
    def register_reports(register):
        register("tiny", "tiny_plugin:TinyReport", "a report with one option")
"""


def test_a_plugin_report_declares_its_own_options(tmp_path, monkeypatch, capsys):
    from xairl.cli import main

    _install(tmp_path, monkeypatch, "tiny", REPORT)
    monkeypatch.setenv(plugins.LOAD_ENV, "tiny")
    plugins.reset()
    out = tmp_path / "rep"
    assert main(["report", "--plugin", "tiny", "-o", "rows=3", "--n", "4", "--method", "exact", "--out", str(out)]) == 0
    html = (out / "report.html").read_text()
    assert "tiny report" in html and "<td>2</td><td>4</td>" in html and "<td>3</td><td>9</td>" not in html
    assert len((out / "explanations.jsonl").read_text().splitlines()) == 8
    # two identical datasets: the same ranks, a rank correlation of exactly 1; the commentary saw both
    assert "Spearman rank correlation again vs sampled: 1.00" in html and "<li>read sampled, again</li>" in html
    capsys.readouterr()
    assert main(["report", "--plugin", "tiny", "-o", "colour=red", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "colour: unknown option" in err and "options: rows" in err
    assert main(["report", "--plugin", "nope", "--out", str(out)]) == 2
    assert "unknown report 'nope'; known: tiny" in capsys.readouterr().err


def test_facts_hook_must_return_domain_facts():
    from xairl.toy import toy_policy

    policy = toy_policy()
    exp = xairl.explain(policy, policy.background(1, seed=2), background=policy.background(20), method="exact")
    policy = replace(
        policy,
        facts_hook=lambda state, chosen, runner_up: xairl.facts.DomainFacts(
            {"note": 7}, (xairl.facts.Comparison("the gap was 1.5 m", 1.5, "m"),)
        ),
    )
    assert xairl.verify("The gap was 1.5 m.", exp, 0, policy).ok
    assert not xairl.verify("The gap was 2.5 m.", exp, 0, policy).ok
    policy = replace(policy, facts_hook=lambda state, chosen, runner_up: {"extras": {}, "comparisons": []})
    with pytest.raises(PluginError, match="facts_hook returned dict; it must return xairl.facts.DomainFacts"):
        xairl.narrate(exp, 0, policy=policy)
