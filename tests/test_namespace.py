"""The public namespace (issue 51, item 19; item 11): ``xairl`` holds what a user calls, ``xairl.plugin`` what a
plugin author builds on, ``xairl.facts`` the narration facts; one name per thing; keyword-only options."""

import inspect
import subprocess
import sys

import pytest

import xairl
import xairl.facts
import xairl.plugin

NAMESPACES = {"xairl": xairl, "xairl.plugin": xairl.plugin, "xairl.facts": xairl.facts}


def _public(module):
    return {name: getattr(module, name) for name in module.__all__}


@pytest.mark.parametrize("namespace", sorted(NAMESPACES))
def test_every_public_name_resolves_and_is_the_things_own_name(namespace):
    for name, value in _public(NAMESPACES[namespace]).items():
        if inspect.ismodule(value):
            assert value.__name__ == f"xairl.{name}", name
        elif inspect.isfunction(value) or inspect.isclass(value):
            assert value.__name__ == name, f"{namespace}.{name} is {value.__module__}.{value.__name__}"


def test_no_thing_has_two_public_names():
    seen = {}
    for namespace, module in NAMESPACES.items():
        for name, value in _public(module).items():
            if inspect.isfunction(value) or inspect.isclass(value):
                assert id(value) not in seen, f"{namespace}.{name} is also {seen[id(value)]}"
                seen[id(value)] = f"{namespace}.{name}"


def test_the_top_level_is_what_a_user_calls():
    top = set(xairl.__all__)
    assert {"explain", "narrate", "verify", "Policy", "Explanation", "plots"} <= top
    assert not top & set(xairl.plugin.__all__), "plugin-author names belong to xairl.plugin only"
    assert not top & set(xairl.facts.__all__), "the fact types belong to xairl.facts only"
    assert "TorchPolicy" not in top and len(top) < 30


@pytest.mark.slow
def test_plots_are_reachable_after_a_bare_import():
    """`import xairl; xairl.plots.beeswarm(exp)` as the README says (an AttributeError before)."""
    code = "import xairl; assert callable(xairl.plots.beeswarm); assert callable(xairl.plugin.hookimpl)"
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr[-800:]


def test_importing_the_plugin_namespace_stays_light():
    code = "import sys, xairl.plugin; xairl.plugin.hookimpl; assert 'torch' not in sys.modules, 'torch loaded'"
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr[-800:]


def test_narrate_takes_its_options_by_keyword_only():
    params = list(inspect.signature(xairl.narrate).parameters.values())
    assert [p.name for p in params[:2]] == ["explanation", "index"]
    keyword = (inspect.Parameter.KEYWORD_ONLY, inspect.Parameter.VAR_KEYWORD)  # (the NarrationOptions' fields)
    assert all(p.kind in keyword for p in params[2:]), params
    policy = xairl.get_policy("toy")
    exp = xairl.explain(policy, policy.background(2, seed=0), background=policy.background(20, seed=1))
    with pytest.raises(TypeError):
        xairl.narrate(exp, 0, "template")
    assert xairl.narrate(exp, 0, narrator="template", robustness=False).text


def test_an_old_name_says_its_successor():
    """Issue 64: an old script's ``xairl.TorchPolicy`` (was a bare AttributeError) runs on as ``xairl.Policy``, with a
    warning that names the new name, in both forms a script writes it."""
    with pytest.warns(FutureWarning, match=r"xairl\.TorchPolicy was renamed xairl\.Policy"):
        assert xairl.TorchPolicy is xairl.Policy
    with pytest.warns(FutureWarning, match=r"renamed xairl\.Policy"):
        from xairl import TorchPolicy
    assert TorchPolicy is xairl.Policy and "TorchPolicy" not in dir(xairl)
