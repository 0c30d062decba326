"""Robustness matrix of ``rwadist diagnose`` on modes-on data (issue 14, item 5).

Every cell is E-wheel data from the virtual stand with the extended physics (radial translation,
rocking with gyroscopic forward/backward whirl, axial mode ON: real wheels have modes), random
phases and noise per run, and ``rwadist diagnose DATA`` as a user types it first (no model: the
search must name ``suspension_modes`` and fit them from the data).  Per cell:

* clean data (the stand resonance of the cell included when it has one): the effects diagnose adds
  beyond the wheel's own modes (and beyond a ``fixed_resonance`` of role test_stand at the stand's
  frequency when the cell has one) -- must be 0;
* each effect family the registry lists (:data:`rwadist.diagnose.effects.EFFECT_CLASSES`) that
  :mod:`rwadist.inject` can inject, injected alone (its parameters below): found or missed, the
  fitted parameter against the injected one, and any other effect added beside it;
* the modes: each of radial translation, rocking and axial either found within 2 % of the truth
  (the thesis numbers of tests/independent_wheel.py), listed in ``unconstrained``, or outside 2 % with
  the extended fit's misfit note for that mode in ``analytical.fit.notes`` ("misfit noted") -- a mode
  outside 2 % with neither is a SILENT failure (the acceptance: no such cell).

The matrix is NOT a full factorial (3^5·2 = 486 cells × 8 classes).  It is one factor at a time
around a nominal cell (300-3000 rpm, 60 speeds, 8192 samples, 3840 Hz, noise 1 % of the top-speed
fundamental, no stand resonance): each other level of each factor alone (11 cells), plus two corners
(all factors at their cheapest/lowest level; all at their highest with the stand resonance): 14
cells.  Interactions other than the two corners are not covered.

Factors: speed range 300-2400 / 300-3000 / 100-6000 rpm; 20 / 60 / 120 speeds; 2048 / 8192 / 32768
samples; 1000 / 3840 / 10000 Hz; noise 0.1 / 1 / 5 %; a test-stand resonance (180 Hz, ζ 0.03, peak
gain 5, all six channels: the issue's case) in the band or not.

Run (long: a few minutes per cell on one free core; give it a budget)::

    python benchmarks/diagnose_matrix.py                           # every cell, every class
    python benchmarks/diagnose_matrix.py --cells 0,1 --classes clean,cross_coupling
    python benchmarks/diagnose_matrix.py --budget 1800             # stop starting rows after 30 min

Rows run class by class (clean data in every cell first), so a run cut by its budget covers whole classes.

The CI test ``tests/test_diagnose_matrix.py`` runs a few cheap cells.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

NOMINAL = {"rpm": (300.0, 3000.0), "n_speeds": 60, "samples": 8192, "rate": 3840.0, "noise": 0.01, "stand": False}
LEVELS = {"rpm": [(300.0, 2400.0), (300.0, 3000.0), (100.0, 6000.0)], "n_speeds": [20, 60, 120],
          "samples": [2048, 8192, 32768], "rate": [1000.0, 3840.0, 10000.0], "noise": [0.001, 0.01, 0.05],
          "stand": [False, True]}
#: the fixture resonance of a cell with ``stand``: the issue's 180-Hz stand resonance on every channel
STAND_SPEC = "fixed_resonance:f_hz=180,zeta=0.03,gain=5,role=test_stand"
STAND_HZ = 180.0
#: injection of each effect family (rwadist.inject syntax) and the parameter compared: (spec, [(injected
#: key, diagnosed key, tolerance kind)]); families the registry lists but not here are injected with
#: rwadist.inject's defaults when it knows the kind, else reported as not injectable
SPECS = {
    "missing_harmonic": "missing_harmonic:direction=radial_force,h=0.5,fraction=0.5",
    "amplitude_law": "amplitude_law:direction=radial_force,h=2,exponent=3",
    "broadband_floor": "broadband_floor:channels=Fx+Fy+Fz,level=0.05,exponent=3,fc_hz=60",
    "fixed_resonance": "fixed_resonance:f_hz=150,zeta=0.03,gain=5,role=test_stand",
    "cross_coupling": "cross_coupling:r_x=0,r_y=0,r_z=-0.06",
    "sidebands": "sidebands:direction=radial_force,h=2,depth=0.4,f_mod_hz=7",
    # the case: 30 % counter-rotating content on the radial-force fundamental (the imbalance line; the
    # counter part goes through the suspension modes)
    "counter_rotation": "counter_rotation:direction=radial_force,h=1,fraction=0.3",
    # lines at 0.94 and 1.06 x the wheel speed beside the fundamental, 0.2 U_s each
    "speed_sidebands": "sidebands:direction=radial_force,h=1,depth=0.4,per_rev=0.06",
    # a load-cell reference 60 mm below the wheel, the force sensors noisier than the stand's 1 %
    "lever_arm_noise": "cross_coupling:r_x=0,r_y=0,r_z=-0.06,force_noise=0.078",
}
#: why a registered family is not injected on modes-on data
NOT_INJECTED = {
    "suspension_modes": "the wheel's own modes: the base of every cell (checked in the modes column)",
    "spin_acceleration": "needs a spin-up/run-down sweep, not steady runs",
    "speed_ripple": "rwadist.inject refuses it with --physics extended (it rebuilds the preset's lines hard mounted)",
}
MODES = ("radial_translation", "rocking", "axial")


def cells() -> list:
    """The matrix: the nominal cell, one factor at a time, two corners; dicts with a ``name``."""
    out = [dict(NOMINAL, name="nominal")]
    for factor, levels in LEVELS.items():
        for lv in levels:
            if lv != NOMINAL[factor]:
                out.append(dict(NOMINAL, **{factor: lv}, name=f"{factor}={_fmt(factor, lv)}"))
    out.append({k: v[0] for k, v in LEVELS.items()} | {"name": "corner-low"})
    out.append({k: v[-1] for k, v in LEVELS.items()} | {"name": "corner-high"})
    for i, c in enumerate(out):
        c["seed"] = 2000 + i
    return out


def _fmt(factor, v):
    if factor == "rpm":
        return f"{v[0]:g}-{v[1]:g}"
    if factor == "noise":
        return f"{100 * v:g}%"
    return f"{v:g}" if not isinstance(v, bool) else ("yes" if v else "no")


def registry_kinds() -> list:
    """Every effect family the diagnose registry lists, in its order."""
    from rwadist.diagnose.effects import EFFECT_CLASSES

    return [getattr(c, "kind", c.__name__) for c in EFFECT_CLASSES]


def injection(kind: str):
    """(spec string, None) of a family, or (None, why not)."""
    from rwadist.inject import KINDS

    if kind in NOT_INJECTED:
        return None, NOT_INJECTED[kind]
    if kind in SPECS:
        return SPECS[kind], None
    if kind in KINDS:
        return kind, None                        # a family added since: rwadist.inject's defaults
    return None, "rwadist.inject has no such kind"


def generate(cell: dict, spec: str | None):
    """SteadyTest of one cell with ``spec`` (or nothing) injected, the stand resonance when the cell has one."""
    from rwadist.inject import parse, simulate_with_injections
    from rwadist.presets import preset

    specs = ([parse(STAND_SPEC)] if cell["stand"] else []) + ([parse(spec)] if spec else [])
    speeds = np.linspace(*cell["rpm"], cell["n_speeds"])
    return simulate_with_injections(preset("ithaco-e"), specs, speeds, physics="extended", seed=cell["seed"],
                                    sample_rate=cell["rate"], n_samples=cell["samples"], noise=cell["noise"],
                                    test_stand=True)    # the preset has no fixture modes: only the injected ones


def _is_stand(e) -> bool:
    return e["kind"] == "fixed_resonance" and e.get("role") == "test_stand" and abs(e["f_Hz"] / STAND_HZ - 1) < 0.05


def _matches(e, kind: str, truth: dict) -> bool:
    """Whether diagnosed effect ``e`` is the injected one (the fixed resonance at its own frequency)."""
    if e["kind"] != kind:
        return False
    if kind == "fixed_resonance":
        return abs(e["f_Hz"] / truth["f_hz"] - 1) < 0.05
    return True


def parameter(kind: str, e: dict, truth: dict) -> str:
    """The diagnosed parameter against the injected one, with its error."""
    def rel(got, want, name):
        return f"{name} {got:.4g} (truth {want:g}, {100 * (got / want - 1):+.1f} %)"

    if kind == "missing_harmonic":
        return rel(e["h"], truth["h"], "h")
    if kind == "amplitude_law":
        return f"h {e.get('h', float('nan')):.3g}, " + rel(e["exponent"], truth["exponent"], "p")
    if kind == "broadband_floor":
        return f"{e.get('channel')}: " + rel(e["exponent"], truth["exponent"], "p")
    if kind == "fixed_resonance":
        return rel(e["f_Hz"], truth["f_hz"], "f") + f", ζ {e['zeta']:.3g} (truth {truth['zeta']:g}), {e.get('role')}"
    if kind == "cross_coupling":
        r = e["r_m"]
        return f"r_z {1000 * r[2]:.1f} mm (truth {1000 * truth['r_z']:g} mm), r_x {1000 * r[0]:.1f}, r_y {1000 * r[1]:.1f}"
    if kind == "sidebands":
        return rel(e["f_mod_Hz"], truth["f_mod_hz"], "f_mod") + f", m {e['depth']:.3g} (truth {truth['depth']:g})"
    if kind == "speed_sidebands":
        return (rel(e["h_lower"], 1 - truth["per_rev"], "h_lower") + ", " + rel(e["h_upper"], 1 + truth["per_rev"], "h_upper")
                + f", C/C_carrier {e.get('ratio_lower', float('nan')):.3g}/{e.get('ratio_upper', float('nan')):.3g} "
                  f"(truth {truth['depth'] / 2:g})")
    if kind == "lever_arm_noise":
        return rel(e["noise_transfer"], 1.0, "noise transfer") + f", r_z {1000 * e['r_m'][2]:.1f} mm"
    if kind == "counter_rotation":
        return rel(e["counter_fraction"], truth["fraction"], "q") + f" ({e.get('direction')} h={e.get('h')})"
    keys = [k for k in e if k not in ("kind", "evidence", "channel")]
    return ", ".join(f"{k}={e[k]}" for k in keys[:3])


def modes_check(d) -> tuple:
    """(text, silent): each mode found within 2 % of the truth, declared unconstrained, or SILENT (wrong and
    not declared); silent is True when any mode is the last."""
    import independent_wheel as iw

    sm = [e for e in d.model.effects if e["kind"] == "suspension_modes"]
    if not sm:
        return "no suspension_modes", False
    e = sm[0]
    unc = set(e.get("unconstrained") or [])
    notes = " ".join(((getattr(d.model, "analytical", None) or {}).get("fit") or {}).get("notes") or [])
    parts, silent = [], False
    for m in MODES:
        f = e[f"{m}_Hz"]
        err = 100 * (f / iw.TRUTH_HZ[m] - 1)
        # the extended fit's own warning in the model file: the linear model misses the data near the mode
        warned = f"{'axial_translation' if m == 'axial' else m}: the linear model misses" in notes
        if m in unc:
            parts.append(f"{m[:4]} declared")
        elif abs(err) <= 2.0:
            parts.append(f"{m[:4]} {err:+.1f}%")
        elif warned:
            parts.append(f"{m[:4]} {err:+.1f}% (misfit noted)")
        else:
            parts.append(f"{m[:4]} {err:+.1f}% SILENT")
            silent = True
    return ", ".join(parts), silent


def evaluate(cell: dict, kind: str):
    """Diagnose one row: ``kind`` = "clean" or a registry family.  Returns a dict (or None when the
    family cannot be injected, with ``why``)."""
    from rwadist import api
    from rwadist.data import DataError
    from rwadist.inject import parse

    spec, why = (None, None) if kind == "clean" else injection(kind)
    if kind != "clean" and spec is None:
        return {"cell": cell["name"], "kind": kind, "skipped": why}
    try:
        test = generate(cell, spec)
    except DataError as exc:                             # an injection the generator refuses: said, not run
        return {"cell": cell["name"], "kind": kind, "skipped": str(exc)}
    t0 = time.perf_counter()
    d = api.diagnose(test)
    elapsed = time.perf_counter() - t0
    truth = parse(spec) if spec else {}
    effects = list(d.model.effects)
    expected = [e for e in effects if e["kind"] == "suspension_modes" or (cell["stand"] and _is_stand(e))]
    hit = [e for e in effects if kind != "clean" and _matches(e, kind, truth) and e not in expected]
    extra = [e for e in effects if e not in expected and e not in hit]
    modes, silent = modes_check(d)
    stand_found = any(_is_stand(e) for e in effects) if cell["stand"] else None
    # a missing harmonic the wheel's fitted base already carries (the extended fit of suspension_modes takes
    # every line the data show): in the output model, but not named as an effect
    in_base = (kind == "missing_harmonic" and not hit
               and any(abs(x.h - truth["h"]) < 0.01 for x in d.model.empirical.get(truth["direction"], [])))
    return {"cell": cell["name"], "kind": kind, "found": bool(hit) if kind != "clean" else None, "in_base": in_base,
            "param": parameter(kind, hit[0], truth) if hit else "-", "effect": hit[0] if hit else None,
            "extra": [e["kind"] + (f"({e.get('role')} {e['f_Hz']:.0f} Hz)" if e["kind"] == "fixed_resonance" else "")
                      for e in extra],
            "modes": modes, "silent": silent, "stand_found": stand_found,
            "error": (d.error_before, d.error_after), "seconds": elapsed}


def row_text(r: dict) -> str:
    if "skipped" in r:
        return f"| {r['cell']} | {r['kind']} | not injected: {r['skipped']} | | | | | |"
    found = "-" if r["found"] is None else ("FOUND" if r["found"] else
                                            "in base fit, not named" if r.get("in_base") else "missed")
    stand = "" if r["stand_found"] is None else ("stand found" if r["stand_found"] else "stand MISSED")
    return (f"| {r['cell']} | {r['kind']} | {found} | {r['param']} | {len(r['extra'])} {','.join(r['extra'])} | "
            f"{r['modes']} {stand} | {r['error'][0]:.3f} -> {r['error'][1]:.4f} | {r['seconds']:.0f} |")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cells", default="all", help="comma-separated cell indices (see --list), or 'all'")
    ap.add_argument("--classes", default="all", help="comma-separated: 'clean' and registry kinds, or 'all'")
    ap.add_argument("--budget", type=float, default=None, help="seconds: start no new row after this")
    ap.add_argument("--list", action="store_true", help="print the cells and exit")
    a = ap.parse_args(argv)
    all_cells = cells()
    if a.list:
        for i, c in enumerate(all_cells):
            print(i, c)
        return 0
    chosen = all_cells if a.cells == "all" else [all_cells[int(i)] for i in a.cells.split(",")]
    kinds = ["clean"] + registry_kinds() if a.classes == "all" else a.classes.split(",")
    print("| cell | class | found | parameter (truth, error) | added beside it | modes (vs truth) | "
          "error before -> after | s |")
    print("|---|---|---|---|---|---|---|---|")
    t_start = time.perf_counter()
    rows = []
    # class-major: clean data in every cell first (the 0-added acceptance), then each family over the cells,
    # so a run stopped by its budget still covers whole rows of the acceptance
    for kind in kinds:
        for cell in chosen:
            if a.budget is not None and time.perf_counter() - t_start > a.budget:
                print(f"\n(budget of {a.budget:g} s reached: the table stops here)")
                return summary(rows)
            r = evaluate(cell, kind)
            rows.append(r)
            print(row_text(r), flush=True)
            if "skipped" in r:
                break                                    # a family that cannot be injected: said once
    return summary(rows)


def summary(rows) -> int:
    done = [r for r in rows if "skipped" not in r]
    clean = [r for r in done if r["kind"] == "clean"]
    inj = [r for r in done if r["kind"] != "clean"]
    print(f"\nclean rows: {len(clean)}, effects added to clean data: {sum(len(r['extra']) for r in clean)} "
          f"(cells with any: {[r['cell'] for r in clean if r['extra']]})")
    for k in dict.fromkeys(r["kind"] for r in inj):
        rk = [r for r in inj if r["kind"] == k]
        base = sum(bool(r.get("in_base")) for r in rk)
        print(f"{k}: found in {sum(r['found'] for r in rk)}/{len(rk)} cells"
              + (f" (+{base} in the fitted base, not named)" if base else "") + "; "
              f"other effects added beside it in {sum(bool(r['extra']) for r in rk)}")
    print(f"silent modes (outside 2 % and not declared unconstrained): {sum(r['silent'] for r in done)} rows "
          f"{[(r['cell'], r['kind']) for r in done if r['silent']]}")
    print(f"rows without suspension_modes: {[(r['cell'], r['kind']) for r in done if r['modes'] == 'no suspension_modes']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
