"""The example notebook shows its figures inline AND saves them (issue 17 item 4): executed as a user
would run it (a Jupyter kernel, nbclient), every figure it makes appears as an image output and as
a PNG file in its figures folder.  The notebook is executed once per test run (conftest.py
``executed_notebook``; test_coupling.py checks the same run for errors)."""
from __future__ import annotations

import re


def test_notebook_figures_inline_and_saved(executed_notebook):
    nb, run_dir = executed_notebook
    code = "\n".join(c.source for c in nb.cells if c.cell_type == "code")
    n_made = len(re.findall(r"plt\.(?:subplots|figure)\(", code))      # figures the notebook makes
    n_saved = len(re.findall(r"\.savefig\(", code))
    assert "matplotlib.use(" not in code                                 # no forced non-inline backend
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])]
    assert not [o for o in outputs if o.output_type == "error"]
    images = [o for o in outputs if o.output_type in ("display_data", "execute_result")
              and "image/png" in o.get("data", {})]
    saved = sorted((run_dir / "coupling_study_figures").glob("*.png"))
    assert n_made >= 2 and len(images) == n_made
    assert len(saved) == n_saved == n_made
    assert all(p.stat().st_size > 10_000 for p in saved)                 # a drawn figure, not an empty canvas
