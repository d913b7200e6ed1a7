"""The documentation: the MkDocs site (with the API reference from the docstrings) builds without a warning, the
README stays short, and every relative link in the Markdown files points to a file that exists."""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
README_MAX_LINES = 150

# [text](target) outside code; a target is relative when it has no scheme and is not a bare anchor
_LINK = re.compile(r"(?<!!)\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
_SCHEME = re.compile(r"^[a-zA-Z][a-zA-Z0-9+.-]*:")
_FENCE = re.compile(r"^(```|~~~).*?^\1", re.DOTALL | re.MULTILINE)
_CODE = re.compile(r"`[^`\n]*`")


def _markdown_files() -> list[Path]:
    return [ROOT / "README.md", ROOT / "CONTRIBUTING.md", *sorted(DOCS.rglob("*.md"))]


def _relative_links(path: Path) -> list[str]:
    text = _CODE.sub("", _FENCE.sub("", path.read_text(encoding="utf-8")))
    return [t for t in _LINK.findall(text) if not _SCHEME.match(t) and not t.startswith("#")]


def test_readme_is_short():
    lines = (ROOT / "README.md").read_text(encoding="utf-8").splitlines()
    assert len(lines) <= README_MAX_LINES, f"README.md has {len(lines)} lines; at most {README_MAX_LINES}"


@pytest.mark.parametrize("path", _markdown_files(), ids=lambda p: str(p.relative_to(ROOT)))
def test_relative_links_point_to_files(path):
    assert path.is_file(), f"{path.relative_to(ROOT)} is missing"
    broken = [t for t in _relative_links(path) if not (path.parent / t.split("#", 1)[0]).exists()]
    assert not broken, f"{path.relative_to(ROOT)}: links to missing files: {broken}"


def test_site_builds_without_warnings(tmp_path):
    # no skip when MkDocs is missing: the docs extra (pip install -e '.[docs]') is part of the test set-up
    env = {**os.environ, "NO_COLOR": "1"}
    proc = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
    )
    output = proc.stdout + proc.stderr
    assert proc.returncode == 0, output[-4000:]
    assert "WARNING" not in output, output[-4000:]
    assert (tmp_path / "site" / "index.html").is_file()
    assert (tmp_path / "site" / "api" / "policies" / "index.html").is_file()


def _python_blocks(path: Path) -> list[str]:
    """The ```python blocks of a Markdown file, as written."""
    return re.findall(r"^```python\n(.*?)^```", path.read_text(encoding="utf-8"), re.DOTALL | re.MULTILINE)


def test_the_readmes_python_snippet_runs_as_written():
    """It once called undefined names (q_net, states, bg) and counterfactual() without its background."""
    blocks = _python_blocks(ROOT / "README.md")
    assert len(blocks) == 1 and "xairl.counterfactual(" in blocks[0]
    res = subprocess.run(
        [sys.executable, "-c", blocks[0]],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=300,
        env={**os.environ, "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"},
    )
    assert res.returncode == 0, res.stderr[-2000:]
    printed = res.stdout.splitlines()  # the margins, the narrative and the counterfactual: each names an action
    assert len(printed) >= 3 and any(a in printed[-1] for a in ("forward", "turn", "recharge")), res.stdout
