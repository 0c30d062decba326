"""The data contract lives in the repository (issue 15): docs/formats.md exists, the README links it and points
nowhere outside the repository, and the document covers every extension, unit and meta.json key the readers
accept."""
from __future__ import annotations

import re
from pathlib import Path

from rwadist.formats.channels import UNITS
from rwadist.formats.registry import READ_EXTENSIONS

ROOT = Path(__file__).resolve().parents[1]


def test_readme_links_the_formats_doc_and_nothing_outside():
    readme = (ROOT / "README.md").read_text()
    assert "docs/formats.md" in readme
    assert "CONVENTIONS.md" not in readme and "../shared" not in readme
    for link in re.findall(r"\]\(([^)#]+)", readme):
        if not link.startswith("http"):
            assert (ROOT / link).exists(), link


def test_formats_doc_covers_what_the_readers_accept():
    doc = (ROOT / "docs" / "formats.md").read_text()
    for ext in READ_EXTENSIONS:
        assert f"`{ext}`" in doc, ext
    for unit in ("N", "kN", "lbf", "N·m", "in·lbf", "ft·lbf"):
        assert f"`{unit}`" in doc and unit.lower() in UNITS, unit
    for key in ("sample_rate_hz", "channel_map", "calibration", "tach", "pulses_per_rev", "wf_increment",
                "wf_start_offset", "unit_string", "model.schema.json", "wheels.json"):
        assert key in doc, key
