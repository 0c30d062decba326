"""Robustness of the extended fit over how the data were made (issue 14).

A sample of the cells of ``benchmarks/extended_fit_matrix.py`` (which prints the full table): the
project's stand and an independent real-coordinate generator (tests/independent_wheel.py), speed
ranges, numbers of speeds, record lengths, sample rates, noise levels and planar loads.  In every
cell each mode is either found within 2 % of the truth or declared unconstrained (listed and noted),
never returned silently.  The truth of the independent generator is typed in that file from the
thesis (Table 4.2), not taken from rwadist.
"""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import extended_fit_matrix as matrix  # noqa: E402

CELLS = [
    # the failing case: independent E-like data, 300-3000 rpm, 1 % noise
    {"generator": "independent", "rpm": (300.0, 3000.0), "n_speeds": 60, "samples": 4096, "rate": 3840.0,
     "noise": 0.01, "seed": 7},
    {"generator": "stand", "rpm": (300.0, 3000.0), "n_speeds": 20, "samples": 8192, "rate": 10000.0,
     "noise": 0.01, "seed": 11},
    {"generator": "independent-planar", "rpm": (100.0, 6000.0), "n_speeds": 20, "samples": 2048, "rate": 1000.0,
     "noise": 0.05, "seed": 12},
]


@pytest.mark.parametrize("cell", CELLS, ids=lambda c: f"{c['generator']}-{c['rpm'][1]:.0f}rpm-{c['noise']}")
def test_every_mode_found_within_2_percent_or_declared(cell):
    row = matrix.run_cell(cell)
    print(matrix.format_row(row))
    assert row["ok"], row["problems"]
    # these cells cover every crossing: all three modes must actually be found
    assert all(row[m]["found"] for m in matrix.MODES), matrix.format_row(row)


def test_modes_no_line_reaches_are_located_by_their_rise_or_declared(tmp_path, monkeypatch):
    """300-1000 rpm: the highest line reaches 93 Hz; no line reaches the radial translation (228 Hz), and the axial
    mode (70 Hz) is crossed only by the weak h = 4.33 line near the top.  Below the translation the force lines show
    its rise alone, along which f0 and ζ trade: its damping held, the rise places it (229.6 Hz, +0.8 %), and it is
    declared all the same (a rise alone never locates a mode: with ζ held, a compromise looks pinned) but kept there.
    Every mode is within 2 % or listed in ``unconstrained`` and in the model file; the rocking whirls are crossed and
    found."""
    from rwadist import empirical, extended_fit
    from rwadist import model as model_io
    from rwadist.extended_fit import to_model

    # keep the fits run_cell makes, to write their model file (instead of generating and fitting again)
    made = {}

    def keeping(name, func):
        def run(*args, **kwargs):
            made[name] = func(*args, **kwargs)
            return made[name]
        return run

    monkeypatch.setattr(empirical, "fit_empirical", keeping("fit", empirical.fit_empirical))
    monkeypatch.setattr(extended_fit, "fit_extended", keeping("ef", extended_fit.fit_extended))
    cell = {"generator": "independent", "rpm": (300.0, 1000.0), "n_speeds": 30, "samples": 4096, "rate": 3840.0,
            "noise": 0.01, "seed": 5}
    row = matrix.run_cell(cell)
    print(matrix.format_row(row))
    assert row["ok"], row["problems"]
    assert row["rocking"]["found"] and abs(row["rocking"]["error"]) < 0.02
    fit, ef = made["fit"], made["ef"]
    translation = row["radial_translation"]
    assert not translation["found"] and translation["declared_unconstrained"]
    assert abs(translation["error"]) < 0.02         # kept where its lines' rise puts it, not at a start
    # the model file carries the list
    m = model_io.load(model_io.save(to_model(ef, fit), tmp_path / "m.json"))
    listed = set(m.analytical.get("unconstrained") or [])
    assert {x for x in listed if not x.startswith("zeta_")} == set(ef.unconstrained)


def test_per_unit_fit_without_mass_and_radius():
    """Without mass and radius the fit is per unit mass/inertia and I_zz/I_rr comes from the whirls.
    20 speeds (40 took 24 s of CPU, 20 take 2 s): every mode within 0.08 % of the truth for seeds 1-6 (0.03 %
    with 40 speeds; tolerance 2 %); I_zz/I_rr = 2.0000 with 20, 24 and 40 speeds (tolerance 5 %; 2.0 is also
    the top of the scan's I_zz/I_rr grid)."""
    cell = {"generator": "independent", "rpm": (300.0, 3000.0), "n_speeds": 20, "samples": 4096, "rate": 3840.0,
            "noise": 0.01, "seed": 3}
    row = matrix.run_cell(cell, with_mass=False)
    print(matrix.format_row(row), row["inertia_ratio"])
    assert row["ok"], row["problems"]
    assert row["inertia_ratio"] == pytest.approx(2.0, rel=0.05)
    assert all(row[m]["found"] for m in matrix.MODES)
