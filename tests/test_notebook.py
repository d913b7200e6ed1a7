"""The example notebook runs top to bottom in a real Jupyter kernel (nbclient), and what a notebook displays is
useful: an Explanation and a Narrative render as HTML, figures as images."""

from pathlib import Path

import pytest

NOTEBOOK = Path(__file__).resolve().parents[1] / "examples" / "quickstart.ipynb"


@pytest.mark.slow
def test_quickstart_notebook_runs_and_shows_html_and_figures():
    import nbformat
    from nbclient import NotebookClient

    nb = nbformat.read(NOTEBOOK, as_version=4)
    NotebookClient(
        nb, timeout=240, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOK.parent)}}
    ).execute()
    outputs = [o for cell in nb.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    html = [o["data"]["text/html"] for o in outputs if "text/html" in o.get("data", {})]
    assert any("xairl-explanation" in h for h in html) and any("class=card" in h for h in html)
    assert sum("image/png" in o.get("data", {}) for o in outputs) >= 3
