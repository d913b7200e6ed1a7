"""Wheels as users install them: xairl's and the reference plugin's wheels are built, installed into a fresh
virtual environment (their dependencies reached from this one's site-packages, since tests run offline) and used
from a folder outside the repository: `xairl --version` and one explanation of each package's policy."""

import os
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest

from xairl.registry import plugins

ROOT = Path(__file__).resolve().parents[1]
PLUGIN = ROOT / "plugins" / "xairl-uav-handover"


def _run(args, cwd):
    env = {k: v for k, v in os.environ.items() if k != plugins.LOAD_ENV}  # as a user has it: every plugin loads
    res = subprocess.run([str(a) for a in args], capture_output=True, text=True, cwd=cwd, timeout=300, env=env)
    assert res.returncode == 0, (args, res.stdout[-1500:], res.stderr[-1500:])
    return res.stdout


@pytest.mark.slow
def test_wheels_install_into_a_fresh_venv_and_run(tmp_path):
    dist = tmp_path / "dist"
    for project in (ROOT, PLUGIN):
        _run([sys.executable, "-m", "build", "--wheel", "--no-isolation", "--outdir", dist, project], cwd=tmp_path)
    core, plugin = sorted(dist.glob("xairl-*.whl")), sorted(dist.glob("xairl_uav_handover-*.whl"))
    assert len(core) == 1 and len(plugin) == 1, sorted(dist.iterdir())
    names = zipfile.ZipFile(core[0]).namelist()
    assert "xairl/prompts/explain_action.yaml" in names and not any(n.startswith("tests/") for n in names)
    assert any(n.endswith("uav-dqn.safetensors") for n in zipfile.ZipFile(plugin[0]).namelist())

    venv = tmp_path / "venv"
    _run([sys.executable, "-m", "venv", venv], cwd=tmp_path)
    py = venv / "bin" / "python"
    site = Path(_run([py, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], cwd=tmp_path).strip())
    # the dependencies (torch, shap, spaCy ...) from this environment, after the fresh one's own packages; its
    # editable xairl is not reachable (a plain path line does not run that folder's .pth files)
    (site / "zz_deps.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    _run([py, "-m", "pip", "install", "--no-deps", "--no-index", "-q", core[0], plugin[0]], cwd=tmp_path)

    where = _run(
        [py, "-c", "import xairl, xairl_uav_handover as u; print(xairl.__file__); print(*u.__path__)"], cwd=tmp_path
    )
    assert all(line.startswith(str(venv)) for line in where.split()), where
    assert _run([venv / "bin" / "xairl", "--version"], cwd=tmp_path).startswith(
        "xairl 0.1.0 (plugins: xairl-uav-handover"
    )
    out = _run([venv / "bin" / "xairl", "explain", "--n", "1", "--narrate", "--no-record"], cwd=tmp_path)
    assert "chose" in out and "verified" in out
    out = _run([venv / "bin" / "xairl", "explain", "--policy", "uav-dqn", "--n", "1", "--top", "3"], cwd=tmp_path)
    assert out.count(": chose ") == 1


# what the repository's root may hold: the source and its configuration, never a run's output (outputs go to out/,
# which .gitignore keeps out of the repository)
_ROOT_ENTRIES = {
    ".ci",
    ".gitignore",
    "CONTRIBUTING.md",
    "Makefile",
    "README.md",
    "benchmarks",
    "conftest.py",
    "docs",
    "examples",
    "mkdocs.yml",
    "plugins",
    "prompts",
    "pyproject.toml",
    "requirements-nlp.txt",
    "tests",
    "xairl",
}


def test_the_root_holds_source_only():
    """Every tracked entry at the root is a known source folder or file (a committed report or figure folder fails)."""
    res = subprocess.run(["git", "ls-files"], capture_output=True, text=True, cwd=ROOT)
    if res.returncode != 0:
        pytest.skip("not a git checkout")
    top = {line.split("/")[0] for line in res.stdout.splitlines()}
    assert top <= _ROOT_ENTRIES, f"not source, or a new root entry to add here: {sorted(top - _ROOT_ENTRIES)}"
    assert "out/" in (ROOT / ".gitignore").read_text().split()
