"""The layers as documented in docs/architecture.md: the core's modules import only from the layers below theirs
(the import-linter contracts in pyproject.toml), no module of the core is part of an import cycle, the core (``xairl/``)
and its benchmarks import no plugin (they reach plugins through the registry, ``xairl.get_policy``), and the
reference plugin's code and benchmarks reach xairl only through ``import xairl`` (its public names and its public
namespaces as attributes: ``xairl.plugin.hookimpl``, ``xairl.facts.Comparison``), never by importing a module."""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PLUGIN = ROOT / "plugins" / "xairl-uav-handover"


def _imports(path: Path) -> set[str]:
    out = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            out.add(node.module)
    return out


@pytest.mark.parametrize(
    "path",
    sorted([*(ROOT / "xairl").rglob("*.py"), *(ROOT / "benchmarks").glob("*.py")]),
    ids=lambda p: str(p.relative_to(ROOT)),
)
def test_the_core_imports_no_plugin(path):
    assert not {m for m in _imports(path) if m.split(".")[0] == "xairl_uav_handover"}


@pytest.mark.parametrize(
    "path",
    sorted([*(PLUGIN / "xairl_uav_handover").rglob("*.py"), *(PLUGIN / "benchmarks").glob("*.py")]),
    ids=lambda p: str(p.relative_to(ROOT)),
)
def test_the_plugin_uses_public_names_only(path):
    assert not {m for m in _imports(path) if m.startswith("xairl.")}  # xairl.plugin, xairl.facts: as attributes


def test_the_core_keeps_its_layers(capsys):
    from importlinter.cli import lint_imports

    rc = lint_imports(config_filename=str(ROOT / "pyproject.toml"), no_cache=True)
    assert rc == 0, capsys.readouterr().out[-3000:]


def test_no_module_is_in_an_import_cycle(monkeypatch):
    """Neither in the core nor in the reference plugin, nor between them. Imports inside functions count (grimp
    reads them all): a lazy import is still a loop in the design. A failure names each cycle, module by module."""
    import grimp
    from grimp.adaptors.packagefinder import ImportLibPackageFinder

    found = ImportLibPackageFinder.determine_package_directories

    def this_checkout(self, package_name, file_system):  # the plugin is a namespace package: another checkout's
        dirs = found(self, package_name, file_system)  # copy (an editable install) would be read too, either file
        return {d for d in dirs if Path(d).resolve().is_relative_to(ROOT)} or dirs  # winning at random

    monkeypatch.setattr(ImportLibPackageFinder, "determine_package_directories", this_checkout)
    graph = grimp.build_graph("xairl", "xairl_uav_handover", cache_dir=None)
    assert any(m.startswith("xairl_uav_handover.") for m in graph.modules), "the plugin's modules were not read"
    cycles = {  # a imports b, and b leads back to a
        " -> ".join((a, *graph.find_shortest_chain(importer=b, imported=a)))
        for a in sorted(graph.modules)
        for b in sorted(graph.find_modules_directly_imported_by(a))
        if graph.chain_exists(importer=b, imported=a)
    }
    assert not cycles, "import cycles:\n" + "\n".join(sorted(cycles)[:10])


def test_the_architecture_page_names_every_module_and_its_layer():
    """docs/architecture.md's layers table lists each module of xairl/ once, on the layer that pyproject.toml's
    contract gives it: a top-level module or package, or a module of a grouping folder (``runs/stream.py`` is
    ``runs.stream``); a new module that the contract or the page does not name fails here."""
    import re

    import tomllib

    contract = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"][0]
    layer_of = {
        m.strip().removeprefix("xairl."): i for i, line in enumerate(contract["layers"], 1) for m in line.split("|")
    }
    modules = set()
    for p in (ROOT / "xairl").iterdir():
        if p.suffix == ".py" and p.stem != "__init__":
            modules.add(p.stem)
        elif (p / "__init__.py").exists():  # a package that is a layer, or a folder grouping modules of several
            modules |= {p.name} if p.name in layer_of else {f"{p.name}.{m.stem}" for m in p.glob("[!_]*.py")}
    assert modules == set(layer_of), ("modules not in the layers contract, or gone", modules ^ set(layer_of))
    rows = re.findall(r"^\| (\d+) \| (.+?) \|", (ROOT / "docs" / "architecture.md").read_text(), re.M)
    documented = {m: int(n) for n, cell in rows for m in re.findall(r"`([a-z0-9_.]+)`", cell)}
    assert documented == layer_of, {
        m: (documented.get(m), layer_of.get(m))
        for m in modules | set(documented)
        if documented.get(m) != layer_of.get(m)
    }


@pytest.mark.parametrize(
    "path",
    sorted([*(ROOT / "tests").glob("*.py"), *(PLUGIN / "tests").glob("*.py")]),
    ids=lambda p: str(p.relative_to(ROOT)),
)
def test_tests_import_no_benchmark_script(path):
    """A benchmark is a script (it may load a peer library, time, print); what a test shares with it lives in a
    test helper module that the benchmark imports (tests/narrative_corpus.py, tests/resume_fuzz.py, ...)."""
    assert not {m for m in _imports(path) if m.split(".")[0] == "benchmarks"}
