"""The example notebook shows its figures inline AND saves them (issue 17 item 4): executed as a user
would run it (a Jupyter kernel, nbclient), every figure it makes appears as an image output and as
a PNG file in its figures folder."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

NOTEBOOK = Path(__file__).resolve().parents[1] / "examples" / "coupling_study.ipynb"


def test_notebook_figures_inline_and_saved(tmp_path):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    nb = nbformat.read(NOTEBOOK, as_version=4)
    code = "\n".join(c.source for c in nb.cells if c.cell_type == "code")
    n_made = len(re.findall(r"plt\.(?:subplots|figure)\(", code))      # figures the notebook makes
    n_saved = len(re.findall(r"\.savefig\(", code))
    assert "matplotlib.use(" not in code                                 # no forced non-inline backend
    nbclient.NotebookClient(nb, timeout=300, kernel_name="python3",
                            resources={"metadata": {"path": str(tmp_path)}}).execute()
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])]
    assert not [o for o in outputs if o.output_type == "error"]
    images = [o for o in outputs if o.output_type in ("display_data", "execute_result")
              and "image/png" in o.get("data", {})]
    saved = sorted((tmp_path / "coupling_study_figures").glob("*.png"))
    assert n_made >= 2 and len(images) == n_made
    assert len(saved) == n_saved == n_made
    assert all(p.stat().st_size > 10_000 for p in saved)                 # a drawn figure, not an empty canvas
