"""Robustness matrix of ``rwadist diagnose`` on modes-on data (issue 14, item 5).

Every cell is E-wheel data from the virtual stand with the extended physics (radial translation,
rocking with gyroscopic forward/backward whirl, axial mode ON: real wheels have modes), random
phases and noise per run, diagnosed on one or both of two paths (below).  Per cell and path:

* clean data (the stand resonance of the cell included when it has one): the effects diagnose adds
  beyond the wheel's own modes (and beyond a ``fixed_resonance`` of role test_stand at the stand's
  frequency when the cell has one) -- must be 0;
* each effect family the registry lists (:func:`rwadist.diagnose.effects.family_classes`) that
  :mod:`rwadist.inject` can inject, injected alone (its parameters below; the wheel-load kinds -- missing
  harmonic, amplitude law, sidebands, counter rotation -- are loads on the rotor that reach the load cell
  through the suspension modes and the stand's fixture, as the wheel's own lines): found or missed (found =
  an effect of that kind on the injected line, :func:`_matches`; one on another line is an addition), the
  fitted parameter against the injected one, and any other effect added beside it (for an injected lever
  arm, its offset itself -- a ``cross_coupling`` within 10 mm of r_z -- is expected beside it);
* a crash of diagnose is a row of the table ("DIAGNOSE CRASHED": a miss, or an addition on clean data);
* the modes: each of radial translation, rocking and axial either found within 2 % of the truth
  (the thesis numbers of tests/independent_wheel.py), listed in ``unconstrained``, or outside 2 % with
  the extended fit's misfit note for that mode in ``analytical.fit.notes`` ("misfit noted") -- a mode
  outside 2 % with neither is a SILENT failure (the acceptance: no such cell).

Two paths per row (``--paths``), because a user meets diagnose twice:

* ``none``: ``rwadist diagnose DATA`` with no model, what a user types first.  Its job is to name the wheel's own
  ``suspension_modes`` and fit them from the data, then anything foreign to the wheel.  The extended fit behind
  ``suspension_modes`` fits every line the data show with its own co/counter split, so an effect that is a
  wheel load of the model's own form (the counter-rotating part of a line, lines at 0.94/1.06 × the speed)
  lands in that fitted base: the model is right but the effect is not named ("in base fit, not named", with its
  parameter read from the base).  Clean data must get nothing beyond the modes here too.
* ``model``: ``rwadist diagnose DATA --model M``, M the extended model (``rwadist fit --extended --mass
  --radius``) fitted on a separate CLEAN run of the same cell: the same stand settings, other phases and noise
  (seed + REFERENCE_SEED_OFFSET).  This is the workflow that asks "what does this run hold that my wheel's model
  does not" (fit on the acceptance run, diagnose the next) and the path on which the issue measured the missed
  classes.  CLASS DETECTION IS COUNTED ON THIS PATH: an injected effect must be NAMED as what the new run adds
  to the reference model.  Clean data on this path must get nothing (a ``test_stand`` at the stand frequency
  is tolerated as on path none: ``fit --extended`` has no stand resonance, so diagnose may name it).  The modes
  column checks the reference model's modes.  Mass and radius are the preset's (a user knows the wheel's); no
  starting values from the preset (``--preset`` would start the fit at the truth).

"Signature above the noise" (:func:`signature`, the three classes added last: counter_rotation,
speed_sidebands, lever_arm_noise): computed per cell from the injection's truth alone (its parameters, the
wheel's modes through which :mod:`rwadist.inject` sends the load, the sensor noise std the stand records, the
record length: a line is judged at the resolution the data hold, a Hann window over the whole record), never
from a detector: a counter-rotating line at least 10 dB over the noise in its bin in >= 3 speeds; both speed sidebands 10 dB over the noise plus the carrier's (and the other
sideband's) Hann-window leakage into their bin in >= 3 speeds; the corrected torque floor raised >= 1 dB by the
force noise (and the r × F line over the torque noise).  The summary counts found / eligible per class and
path (the acceptance: >= 90 % on path model), and prints the cells missed where eligible.

The matrix is NOT a full factorial (3^5·2 = 486 cells × 8 classes).  It is one factor at a time
around a nominal cell (300-3000 rpm, 60 speeds, 8192 samples, 3840 Hz, noise 1 % of the top-speed
fundamental, no stand resonance): each other level of each factor alone (11 cells), plus two corners
(all factors at their cheapest/lowest level; all at their highest with the stand resonance): 14
cells; then two factors beside the stand resonance (:data:`COMBINED`: 100-6000 rpm + stand, 2048 samples + stand),
16 in all.  Interactions other than these are not covered.

Factors: speed range 300-2400 / 300-3000 / 100-6000 rpm; 20 / 60 / 120 speeds; 2048 / 8192 / 32768
samples; 1000 / 3840 / 10000 Hz; noise 0.1 / 1 / 5 %; a test-stand resonance (180 Hz, ζ 0.03, peak
gain 5, all six channels: the issue's case) in the band or not.

Parameters compared with the truth: q against 0.3 (counter_rotation), h_lower/h_upper against 0.94/1.06 and
C/C_carrier against 0.2 each (speed_sidebands), κ against 1 (lever_arm_noise, with r_z).

Run (long: a few minutes per cell on one free core; give it a budget)::

    python benchmarks/diagnose_matrix.py                           # every cell, every class
    python benchmarks/diagnose_matrix.py --cells 0,1 --classes clean,cross_coupling
    python benchmarks/diagnose_matrix.py --classes clean,counter_rotation,speed_sidebands,lever_arm_noise --paths model
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


#: two factors together off the one-factor grid, each with the stand resonance: the corners combine all five, these
#: the two that failed alone beside it (a wide speed range: the modes not named; a short record: the stand missed)
COMBINED = ({"rpm": (100.0, 6000.0), "stand": True}, {"samples": 2048, "stand": True})


def combined_cells() -> list:
    """The cells of :data:`COMBINED` (after :func:`cells`: indices and seeds continue its numbering)."""
    first = len(cells())
    out = []
    for i, over in enumerate(COMBINED):
        name = "+".join(f"{k}={_fmt(k, v)}" for k, v in over.items() if k != "stand") + "+stand"
        out.append(dict(NOMINAL, **over, name=name, seed=2000 + first + i))
    return out


def _fmt(factor, v):
    if factor == "rpm":
        return f"{v[0]:g}-{v[1]:g}"
    if factor == "noise":
        return f"{100 * v:g}%"
    return f"{v:g}" if not isinstance(v, bool) else ("yes" if v else "no")


def registry_kinds() -> list:
    """Every effect family the diagnose registry lists, in its order."""
    from rwadist.diagnose.effects import family_classes

    return [getattr(c, "kind", c.__name__) for c in family_classes()]


def injection(kind: str):
    """(spec string, None) of a family, or (None, why not)."""
    from rwadist.inject import kinds

    if kind in NOT_INJECTED:
        return None, NOT_INJECTED[kind]
    if kind in SPECS:
        return SPECS[kind], None
    if kind in kinds():
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


def _is_offset(e, truth: dict) -> bool:
    """The load-cell offset itself (``cross_coupling``, r_z within 10 mm) of an injected lever arm: the transfer
    of its noise (``lever_arm_noise``) is only defined once the offset is found, so it is expected beside it."""
    return e["kind"] == "cross_coupling" and abs(e["r_m"][2] - truth["r_z"]) < 0.01


#: a diagnosed line is the injected one when its harmonic number is within this of the injection's
H_MATCH = 0.02


def _matches(e, kind: str, truth: dict) -> bool:
    """Whether diagnosed effect ``e`` is the injected one: same kind and, where the injection names them, the same
    line (direction, h within H_MATCH: a missing harmonic at h 5.5 or a law on h = 4.42 is not the injected h = 0.5
    or h = 2, it is an effect added beside it), the fixed resonance at its own frequency, the floor on an
    injected channel, the sidebands at their own f_mod."""
    if e["kind"] != kind:
        return False
    if kind == "fixed_resonance":
        return abs(e["f_Hz"] / truth["f_hz"] - 1) < 0.05
    if kind in ("missing_harmonic", "amplitude_law", "sidebands") and "h" in e:
        same = e.get("direction", truth["direction"]) == truth["direction"] and abs(e["h"] - truth["h"]) < H_MATCH
        if kind == "sidebands" and truth.get("f_mod_hz") is not None:
            same = same and abs(e["f_mod_Hz"] / truth["f_mod_hz"] - 1) < 0.05
        return same
    if kind == "broadband_floor":
        return bool(set(e.get("channel") or ()) & set(truth["channels"]))
    return True


def parameter(kind: str, e: dict, truth: dict) -> str:
    """The diagnosed parameter against the injected one, with its error."""
    def rel(got, want, name):
        return f"{name} {got:.4g} (truth {want:g}, {100 * (got / want - 1):+.1f} %)"

    if kind == "missing_harmonic":
        from rwadist.presets import preset

        # the injected load: fraction·C₁ of the direction's fundamental (rwadist.inject)
        c_true = truth["fraction"] * preset("ithaco-e").fundamental_C(truth["direction"])
        return rel(e["h"], truth["h"], "h") + ", " + rel(e["C"], c_true, "C")
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
        return rel(e["f_mod_Hz"], truth["f_mod_hz"], "f_mod") + ", " + rel(e["depth"], truth["depth"], "m")
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


def _mode_frequencies(model) -> tuple:
    """(f0 Hz per mode, unconstrained modes, fit notes) of a model file's analytical section."""
    from rwadist import extended as ext

    an = dict(getattr(model, "analytical", None) or {})
    p = ext.params_from_model(model, "matrix")
    f0 = {"radial_translation": float(p.omega_r / (2 * np.pi)), "rocking": float(p.omega_rock / (2 * np.pi)),
          "axial": float(np.sqrt(p.k_z / p.mass) / (2 * np.pi))}
    return f0, set(an.get("unconstrained") or []), " ".join((an.get("fit") or {}).get("notes") or [])


def modes_check(d, model=None) -> tuple:
    """(text, silent): each mode found within 2 % of the truth, declared unconstrained, or SILENT (wrong and
    not declared); silent is True when any mode is the last.  ``model``: the extended model diagnose was given
    (path "model": its modes are checked), else the ``suspension_modes`` diagnose named from the data."""
    import independent_wheel as iw

    if model is not None:
        f0, unc, notes = _mode_frequencies(model)
    else:
        sm = [e for e in d.model.effects if e["kind"] == "suspension_modes"]
        if not sm:
            return "no suspension_modes", False
        e = sm[0]
        f0 = {m: e[f"{m}_Hz"] for m in MODES}
        unc = set(e.get("unconstrained") or [])
        notes = " ".join(((getattr(d.model, "analytical", None) or {}).get("fit") or {}).get("notes") or [])
    parts, silent = [], False
    for m in MODES:
        f = f0[m]
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


# ------------------------------------------------------------------ signature above the noise (injection truth)
#: a component stands above the noise in a run when its power in its own Welch bin is at least this many times
#: the noise's (and, for a line beside a stronger one, that line's window leakage) in the same bin: 10 dB
SIGNATURE_RATIO = 10.0
#: runs a line-type signature must stand above the noise in: a speed law (C·Ω², a phase, an offset per
#: revolution) is told from a fixed line or a fluke only over several speeds
SIGNATURE_RUNS = 3
#: lowest bin a line is measured in: below, the Hann window's DC lobe (±2 bins) and the mean overlap it
SIGNATURE_MIN_BIN = 4
#: torque-floor rise (dB) above which the lever-arm noise transfer counts as above the noise: a floor is itself
#: noise; 1 dB (26 % in power) is several times the scatter of a floor level averaged over a band of bins
SIGNATURE_FLOOR_DB = 1.0


def _hann_leakage(n: int, delta_bins) -> np.ndarray:
    """|Σ w e^{−2πiΔk/N}|² / (Σ w)² of the periodic Hann window of ``n`` samples at offsets Δ (bins): the share of a
    line's bin power that a bin Δ away holds (1 at Δ = 0)."""
    from scipy import signal

    w = signal.get_window("hann", n)
    d = np.atleast_1d(np.asarray(delta_bins, float))
    k = np.arange(n)
    out = np.abs(np.exp(-2j * np.pi * np.outer(d.ravel(), k) / n) @ w) ** 2 / np.sum(w) ** 2
    return out.reshape(d.shape)


def _line_to_noise(amp, sigma, n):
    """Power of a sinusoid of amplitude ``amp`` in its own bin over that of white noise of std ``sigma``, Hann
    window of ``n`` samples (a Welch segment or the whole record): A²(Σw)²/(4σ²Σw²) = A²n/(6σ²)."""
    return np.abs(amp) ** 2 * n / (6.0 * sigma**2)


def _modal_amplitudes(direction, h, C, sense, omegas):
    """(f Hz (n,), amplitude (n, 6)) of the wheel load C·Ω² e^{±ihφ} through the E wheel's suspension modes at
    speeds ``omegas`` (rad/s), as :mod:`rwadist.inject` adds it (:func:`rwadist.extended.steady_lines`)."""
    from rwadist import extended as ext
    from rwadist.presets import preset

    f, A = ext.steady_lines(preset("ithaco-e").extended, [ext.Line(direction, float(h), float(C), sense)], omegas)
    return f[:, 0], A[:, 0, :]


def signature(cell: dict, kind: str, test) -> dict:
    """How far the injected component of ``kind`` stands above the noise in ``test`` (the cell's data), from the
    generator's truth alone (the injected parameters, the wheel's modes, the sensor noise std the stand records in
    ``meta["noise_std"]``, the record length), never from the detector.  A line is measured at the resolution the
    data themselves hold: a Hann window over the whole record (fs/n bins; the time series are the data, a Welch
    segment is an analysis choice).  Returns {"text", "eligible"} (eligible None: no measure for this class).

    * counter_rotation: per run, the counter-rotating part's line in Fx and Fy (its amplitude through the modes)
      over the noise in its bin; eligible when >= SIGNATURE_RATIO in SIGNATURE_RUNS runs in band (the x/y phase
      then separates it from the co part at the same frequency).
    * speed_sidebands: per run and side, the sideband's power in its nearest bin over the noise plus the Hann
      leakage of the carrier and of the other sideband into that bin (the window's exact transform); eligible
      when both sides stand >= SIGNATURE_RATIO in SIGNATURE_RUNS runs.
    * lever_arm_noise: the rise of the corrected Tx, Ty floor, 10·log10(1 + r_z²σ_F²/σ_T²) (σ_F² the stand's
      and the injected force-sensor variances), eligible when >= SIGNATURE_FLOOR_DB, and the r × F line itself
      above the torque noise (the offset must be found first)."""
    from rwadist.inject import parse
    from rwadist.presets import preset

    if kind not in ("counter_rotation", "speed_sidebands", "lever_arm_noise"):
        return {"text": "", "eligible": None}
    wheel = preset("ithaco-e")
    truth = parse(SPECS[kind])
    omegas = np.array([abs(r.speed) for r in test.runs])
    fs = float(np.median([r.sample_rate for r in test.runs]))
    n_rec = int(np.median([r.n_samples for r in test.runs]))          # the whole record
    df = fs / n_rec
    f_hi = min(float(test.meta.get("f_lim_hz") or np.inf), 0.5 * fs) - SIGNATURE_MIN_BIN * df
    noise = test.meta["noise_std"]
    if kind == "counter_rotation":
        f, A = _modal_amplitudes("radial_force", truth["h"], wheel.extended.U_s * np.sqrt(truth["fraction"]),
                                 "counter", omegas)
        s = np.minimum(_line_to_noise(A[:, 0], noise["Fx"], n_rec), _line_to_noise(A[:, 1], noise["Fy"], n_rec))
        s = np.where((f >= SIGNATURE_MIN_BIN * df) & (f <= f_hi), s, 0.0)
        n_ok = int(np.sum(s >= SIGNATURE_RATIO))
        return {"text": f"counter line/noise {_db(np.max(s))} dB max, {n_ok}/{s.size} runs >= {_db(SIGNATURE_RATIO)} dB",
                "eligible": n_ok >= SIGNATURE_RUNS}
    if kind == "speed_sidebands":
        dl, C_sb = truth["per_rev"], 0.5 * truth["depth"] * wheel.extended.U_s
        fc, Ac = _modal_amplitudes("radial_force", 1.0, wheel.extended.U_s, "co", omegas)
        sides = [_modal_amplitudes("radial_force", 1.0 + s * dl, C_sb, "co", omegas) for s in (-1.0, 1.0)]
        ratio = []
        for j, (f, A) in enumerate(sides):
            fo, Ao = sides[1 - j]
            k = np.rint(f / df)
            leak = (np.abs(Ac[:, 0]) ** 2 * _hann_leakage(n_rec, k - fc / df)
                    + np.abs(Ao[:, 0]) ** 2 * _hann_leakage(n_rec, k - fo / df))
            sig = np.abs(A[:, 0]) ** 2 * _hann_leakage(n_rec, k - f / df)
            # powers in units of a bin-centred line's bin power: the noise's is 6σ²/n (see _line_to_noise)
            r = sig / (leak + 6.0 * noise["Fx"] ** 2 / n_rec)
            ratio.append(np.where((f >= SIGNATURE_MIN_BIN * df) & (f <= f_hi), r, 0.0))
        both = np.minimum(*ratio)
        n_ok = int(np.sum(both >= SIGNATURE_RATIO))
        return {"text": f"sideband/(noise+carrier leakage) {_db(np.max(both))} dB max, {n_ok}/{both.size} runs "
                        f">= {_db(SIGNATURE_RATIO)} dB", "eligible": n_ok >= SIGNATURE_RUNS}
    # lever_arm_noise
    w_max = float(omegas.max())
    sf2 = noise["Fx"] ** 2 + (truth["force_noise"] * wheel.fundamental_C("radial_force") * w_max**2) ** 2
    rho = truth["r_z"] ** 2 * sf2 / noise["Tx"] ** 2
    rise = 10 * np.log10(1 + rho)
    f, A = _modal_amplitudes("radial_force", 1.0, wheel.extended.U_s, "co", omegas)
    line = _line_to_noise(truth["r_z"] * A[:, 0], noise["Tx"], n_rec)
    n_line = int(np.sum((line >= SIGNATURE_RATIO) & (f >= SIGNATURE_MIN_BIN * df) & (f <= f_hi)))
    return {"text": f"Tx/Ty floor rise {rise:.2f} dB; r x F line above torque noise in {n_line}/{line.size} runs",
            "eligible": bool(rise >= SIGNATURE_FLOOR_DB and n_line >= SIGNATURE_RUNS)}


def _db(x) -> str:
    return f"{10 * np.log10(max(float(x), 1e-30)):.0f}"


#: seed offset of a cell's reference run (path "model"): the clean acceptance run the model is fitted on, other
#: phases and noise than the diagnosed run of the same cell
REFERENCE_SEED_OFFSET = 500
PATHS = ("model", "none")
_REFERENCE: dict = {}


def reference_model(cell: dict):
    """The extended model a user fits on the cell's clean acceptance run (``rwadist fit --extended --mass M
    --radius R`` on the same stand settings, seed + REFERENCE_SEED_OFFSET), memoised per cell."""
    from rwadist import api
    from rwadist.presets import preset

    if cell["name"] not in _REFERENCE:
        wheel = preset("ithaco-e")
        ref = generate(dict(cell, seed=cell["seed"] + REFERENCE_SEED_OFFSET), None)
        _REFERENCE[cell["name"]] = api.fit_extended(ref, mass=wheel.mass_kg, radius=wheel.radius_m)[1]
    return _REFERENCE[cell["name"]]


def _in_base(kind: str, d, truth: dict) -> str:
    """On path "none": the injected content the fitted base already carries without naming it (the extended fit of
    ``suspension_modes`` takes every line and sense the data show), as text with its parameter, else ""."""
    if kind == "missing_harmonic":
        hit = [x for x in d.model.empirical.get(truth["direction"], []) if abs(x.h - truth["h"]) < 0.01]
        return f"h {hit[0].h:.3f}" if hit else ""
    if kind == "counter_rotation" and d.state_after.ext is not None:
        from rwadist.effects.counter_rotation_diagnose import _sense_group

        g = _sense_group(d.state_after, truth["direction"], truth["h"])
        if g is not None and g[2] > 0:
            q = g[2] ** 2 / (g[1] ** 2 + g[2] ** 2)
            return f"q {q:.4g} (truth {truth['fraction']:g}, {100 * (q / truth['fraction'] - 1):+.1f} %)"
        return ""
    if kind == "speed_sidebands":
        hs = [x.h for x in d.model.empirical.get("radial_force", [])]
        pair = [min(hs, key=lambda h: abs(h - (1 + s * truth["per_rev"])), default=np.nan) for s in (-1, 1)]
        if all(abs(h - (1 + s * truth["per_rev"])) < 0.01 for h, s in zip(pair, (-1, 1))):
            return f"h {pair[0]:.4f}/{pair[1]:.4f}"
    return ""


def evaluate(cell: dict, kind: str, path: str = "none"):
    """Diagnose one row: ``kind`` = "clean" or a registry family, ``path`` = "none" (``rwadist diagnose DATA``:
    no model) or "model" (``--model`` the extended model fitted on the cell's clean reference run,
    :func:`reference_model`).  Returns a dict (with ``skipped`` when the family cannot be injected)."""
    from rwadist import api
    from rwadist.data import DataError
    from rwadist.inject import parse

    spec, why = (None, None) if kind == "clean" else injection(kind)
    if kind != "clean" and spec is None:
        return {"cell": cell["name"], "kind": kind, "path": path, "skipped": why}
    try:
        test = generate(cell, spec)
    except DataError as exc:                             # an injection the generator refuses: said, not run
        return {"cell": cell["name"], "kind": kind, "path": path, "skipped": str(exc)}
    model = reference_model(cell) if path == "model" else None
    sig = signature(cell, kind, test) if kind != "clean" else {"text": "", "eligible": None}
    t0 = time.perf_counter()
    try:
        d = api.diagnose(test, model)
    except Exception as exc:                             # a crash of diagnose is a row of the table (a miss, and a
        return {"cell": cell["name"], "kind": kind, "path": path, "crashed": f"{type(exc).__name__}: {exc}",
                "found": False if kind != "clean" else None, "eligible": sig["eligible"], "extra": ["CRASH"],
                "silent": False, "modes": "-", "in_base": ""}         # failure on clean data), not its end
    elapsed = time.perf_counter() - t0
    truth = parse(spec) if spec else {}
    effects = list(d.model.effects)
    expected = [e for e in effects if (e["kind"] == "suspension_modes" and path == "none")
                or (cell["stand"] and _is_stand(e)) or (kind == "lever_arm_noise" and _is_offset(e, truth))]
    hit = [e for e in effects if kind != "clean" and _matches(e, kind, truth) and e not in expected]
    extra = [e for e in effects if e not in expected and e not in hit]
    modes, silent = modes_check(d, model)
    stand_found = any(_is_stand(e) for e in effects) if cell["stand"] else None
    in_base = _in_base(kind, d, truth) if (kind != "clean" and not hit and path == "none") else ""
    return {"cell": cell["name"], "kind": kind, "path": path, "found": bool(hit) if kind != "clean" else None,
            "in_base": in_base, "signature": sig["text"], "eligible": sig["eligible"],
            "param": parameter(kind, hit[0], truth) if hit else "-", "effect": hit[0] if hit else None,
            "extra": [e["kind"] + (f"({e.get('role')} {e['f_Hz']:.0f} Hz)" if e["kind"] == "fixed_resonance" else "")
                      for e in extra],
            "modes": modes, "silent": silent, "stand_found": stand_found,
            "error": (d.error_before, d.error_after), "seconds": elapsed}


HEADER = ("| cell | class | path | found | parameter (truth, error) | signature above noise (truth) | added beside it | "
          "modes (vs truth) | error before -> after | s |")


def row_text(r: dict) -> str:
    if "skipped" in r:
        return f"| {r['cell']} | {r['kind']} | {r['path']} | not injected: {r['skipped']} | | | | | | |"
    if "crashed" in r:
        return f"| {r['cell']} | {r['kind']} | {r['path']} | DIAGNOSE CRASHED: {r['crashed']} | | | | | | |"
    found = "-" if r["found"] is None else ("FOUND" if r["found"] else
                                            f"in base fit, not named: {r['in_base']}" if r.get("in_base") else "missed")
    elig = "" if r["eligible"] is None else (" ELIGIBLE" if r["eligible"] else " below")
    stand = "" if r["stand_found"] is None else ("stand found" if r["stand_found"] else "stand MISSED")
    return (f"| {r['cell']} | {r['kind']} | {r['path']} | {found} | {r['param']} | {r['signature']}{elig} | "
            f"{len(r['extra'])} {','.join(r['extra'])} | {r['modes']} {stand} | "
            f"{r['error'][0]:.3f} -> {r['error'][1]:.4f} | {r['seconds']:.0f} |")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cells", default="all", help="comma-separated cell indices (see --list), or 'all'")
    ap.add_argument("--classes", default="all", help="comma-separated: 'clean' and registry kinds, or 'all'")
    ap.add_argument("--paths", default="model,none",
                    help="comma-separated: 'model' (diagnose --model, the extended model fitted on the cell's clean "
                         "reference run) and/or 'none' (diagnose with no model)")
    ap.add_argument("--budget", type=float, default=None, help="seconds: start no new row after this")
    ap.add_argument("--list", action="store_true", help="print the cells and exit")
    a = ap.parse_args(argv)
    all_cells = cells() + combined_cells()
    if a.list:
        for i, c in enumerate(all_cells):
            print(i, c)
        return 0
    chosen = all_cells if a.cells == "all" else [all_cells[int(i)] for i in a.cells.split(",")]
    kinds = ["clean"] + registry_kinds() if a.classes == "all" else a.classes.split(",")
    paths = a.paths.split(",")
    bad = [p for p in paths if p not in PATHS]
    if bad:
        ap.error(f"--paths: {bad} not among {list(PATHS)}")
    print(HEADER)
    print("|---" * (HEADER.count("|") - 1) + "|")
    t_start = time.perf_counter()
    rows = []
    # class-major: clean data in every cell first (the 0-added acceptance), then each family over the cells,
    # so a run stopped by its budget still covers whole rows of the acceptance
    for kind in kinds:
        skipped = False
        for cell in chosen:
            for path in paths:
                if a.budget is not None and time.perf_counter() - t_start > a.budget:
                    print(f"\n(budget of {a.budget:g} s reached: the table stops here)")
                    return summary(rows)
                r = evaluate(cell, kind, path)
                rows.append(r)
                print(row_text(r), flush=True)
                skipped = "skipped" in r
                if skipped:
                    break                                # a family that cannot be injected: said once
            if skipped:
                break
    return summary(rows)


def summary(rows) -> int:
    crashed = [r for r in rows if "crashed" in r]
    done = [r for r in rows if "skipped" not in r]
    print()
    if crashed:
        print(f"diagnose CRASHED in {len(crashed)} rows: {[(r['cell'], r['kind'], r['path']) for r in crashed]}")
    for path in dict.fromkeys(r["path"] for r in done):
        clean = [r for r in done if r["kind"] == "clean" and r["path"] == path]
        if clean:
            print(f"[{path}] clean rows: {len(clean)}, effects added to clean data: "
                  f"{sum(len(r['extra']) for r in clean)} (cells with any: {[r['cell'] for r in clean if r['extra']]})")
    inj = [r for r in done if r["kind"] != "clean"]
    for k in dict.fromkeys(r["kind"] for r in inj):
        for path in dict.fromkeys(r["path"] for r in inj if r["kind"] == k):
            rk = [r for r in inj if r["kind"] == k and r["path"] == path]
            base = sum(bool(r.get("in_base")) for r in rk)
            found = sum(r["found"] for r in rk)
            text = f"[{path}] {k}: found in {found}/{len(rk)} cells"
            if any(r["eligible"] is not None for r in rk):
                el = [r for r in rk if r["eligible"]]
                fe = sum(r["found"] for r in el)
                text += (f"; signature above the noise in {len(el)}: found in {fe}/{len(el)}"
                         + (f" = {100 * fe / len(el):.0f} %" if el else "")
                         + f" (missed where eligible: {[r['cell'] for r in el if not r['found']]})")
            text += (f" (+{base} in the fitted base, not named)" if base else "")
            text += f"; other effects added beside it in {sum(bool(r['extra']) for r in rk)}"
            print(text)
    print(f"silent modes (outside 2 % and not declared unconstrained): {sum(r['silent'] for r in done)} rows "
          f"{[(r['cell'], r['kind'], r['path']) for r in done if r['silent']]}")
    print("rows without suspension_modes (path none): "
          f"{[(r['cell'], r['kind']) for r in done if r['modes'] == 'no suspension_modes']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
