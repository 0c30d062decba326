"""Known effects injected into virtual-stand data, so a user can try ``rwadist diagnose`` on a known case.

``rwadist simulate-test OUT --preset ithaco-e --inject KIND:PARAM=VALUE,...`` (``--inject`` may be
repeated).  Every injection is recorded in ``meta.json`` under ``injected`` (kind and parameters in
SI), which is the truth to compare the diagnosis with.  The injections are those the project's
diagnose tests make (tests/test_diagnose*.py), exposed:

============== ===================================================================================
kind           parameters (default)
============== ===================================================================================
missing_harmonic  direction (radial_force), h (0.5), fraction (0.5): a line h·|Ω| of amplitude
                  fraction·C1·Ω² (C1 the direction's fundamental coefficient), co-rotating
                  (x cos, y sin), random phase per run
amplitude_law  direction (radial_force), h (2.0), exponent (3.0), fraction (1.0): the line (d, h) of the
               wheel replaced by A(Ω) = fraction·C_h·Ω_mid²·(Ω/Ω_mid)^exponent (Ω_mid the median speed)
broadband_floor  channels (Fx+Fy+Fz), level (0.05), exponent (3.0), fc_hz (60): Gaussian noise
                 low-passed at fc (2nd-order Butterworth), RMS level·C1·Ω_max²·(Ω/Ω_max)^(exponent/2)
                 (its PSD grows as Ω^exponent)
fixed_resonance  f_hz (150), zeta (0.03), gain (5.0), channels (all six), role (test_stand | wheel_mode):
                 a fixed-frequency resonance H(f/f_r) on the lines of those channels (the stand's
                 fixture resonance / a wheel mode; wheel_mode needs --physics simple)
cross_coupling r_x, r_y, r_z (0, 0, -0.06 m), force_noise (0): load-cell offset, torques += r × F of the
               noise-free forces (the sensors' noise comes after the geometry: correcting T − r × F
               then moves the force noise into the torques); force_noise: extra white sensor noise on
               Fx, Fy, Fz of std force_noise·C1·Ω_max² (C1 the radial-force fundamental), after the offset
sidebands      direction (radial_force), h (2.0), depth (0.4), f_mod_hz (7.0) or per_rev (fraction of the
               wheel speed: speed-proportional sidebands at (h ± per_rev)·Ω): the line (d, h) amplitude
               modulated C·Ω²·(1 + depth·cos(2π f_mod t + φ)); random carrier and modulation phases; with
               --physics extended a wheel load: the carrier (the line's own sense) and two lines (depth/2)·C·Ω²
               at f_c ± f_mod (or (h ± per_rev)·Ω) through the modes, each at its own frequency; on h = 1
               the imbalance U (simulated through the modes) is the carrier and only the two sides are added
speed_ripple   f_ripple_hz (8.0), delta_omega (3.0 rad/s): Ω(t) = Ω0 + ΔΩ sin(2π f t + φ) on every line
               (amplitude C·Ω(t)², phase h·∫Ω dt); --physics simple
counter_rotation  direction (radial_force), h (1.0), fraction (0.3): that share of the line's power
                  turned against the spin (x cos, y −sin), the rest left co-rotating; with --physics
                  extended it is a wheel load: the counter part goes through the suspension modes
                  (:func:`rwadist.extended.steady_lines`) and, on h = 1, the imbalance U_s or U_d keeps
                  the co part (scaled by sqrt(1 − fraction))
============== ===================================================================================

Where each kind acts.  With --physics extended the wheel-load kinds (missing_harmonic, amplitude_law,
sidebands, counter_rotation) are loads on the rotor: like every line of the simulation they reach the load
cell through the suspension modes (:func:`rwadist.extended.steady_lines` at the run's speed, each component at
its own whirl rate, the line's rotation sense from the preset: a line the wheel has keeps its sense,
a missing harmonic is co-rotating) and then through the stand's fixture resonances (those the simulation
applied); see :func:`_wheel_loads`.  The kinds that are not wheel loads stay where they physically act:
fixed_resonance of role test_stand is a fixture filter applied by the simulation to everything it passes;
cross_coupling is the load cell's own geometry, applied last, on the total force the cell measures (the
simulation's and every noise-free content added here); broadband_floor stays a per-channel floor at the
load cell (its channels are given, not its load direction).  With --physics simple every added line
reaches the load cell as it is (the simple physics' resonances are not applied to it).
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from scipy import signal

from .data import DataError
from .units import CHANNELS, DIRECTION_CHANNELS

_DIRS = ("radial_force", "radial_torque", "axial_force")
_ROLES = ("test_stand", "wheel_mode")

#: kind -> {param: default}; a default of None means "optional, no default"
KINDS = {
    "missing_harmonic": {"direction": "radial_force", "h": 0.5, "fraction": 0.5},
    "amplitude_law": {"direction": "radial_force", "h": 2.0, "exponent": 3.0, "fraction": 1.0},
    "broadband_floor": {"channels": "Fx+Fy+Fz", "level": 0.05, "exponent": 3.0, "fc_hz": 60.0},
    "fixed_resonance": {"f_hz": 150.0, "zeta": 0.03, "gain": 5.0, "channels": "Fx+Fy+Fz+Tx+Ty+Tz",
                        "role": "test_stand"},
    "cross_coupling": {"r_x": 0.0, "r_y": 0.0, "r_z": -0.06, "force_noise": 0.0},
    "sidebands": {"direction": "radial_force", "h": 2.0, "depth": 0.4, "f_mod_hz": None, "per_rev": None},
    "speed_ripple": {"f_ripple_hz": 8.0, "delta_omega": 3.0},
    "counter_rotation": {"direction": "radial_force", "h": 1.0, "fraction": 0.3},
}
_TEXT = {"direction", "channels", "role"}
_POSITIVE = {"h", "fc_hz", "f_hz", "zeta", "gain", "f_mod_hz", "per_rev", "f_ripple_hz"}


def _bad(spec, field, why):
    return DataError("--inject", field, f"{spec!r}: {why}")


def parse(spec: str) -> dict:
    """``KIND:PARAM=VALUE,...`` -> {"kind": KIND, params with defaults filled}; DataError on anything wrong."""
    kind, _, rest = spec.partition(":")
    kind = kind.strip()
    if kind not in KINDS:
        raise _bad(spec, "kind", f"unknown kind {kind!r}; known: {', '.join(KINDS)}")
    out = {"kind": kind}
    given = {}
    for item in filter(None, (x.strip() for x in rest.split(","))):
        key, eq, value = item.partition("=")
        key = key.strip()
        if not eq:
            raise _bad(spec, key, f"{item!r} is not PARAM=VALUE")
        if key not in KINDS[kind]:
            raise _bad(spec, key, f"unknown parameter {key!r} of {kind}; known: {', '.join(KINDS[kind])}")
        if key in _TEXT:
            given[key] = value.strip()
            continue
        try:
            v = float(value)
        except ValueError:
            raise _bad(spec, key, f"{key}={value!r} is not a number") from None
        if not math.isfinite(v) or (key in _POSITIVE and v <= 0) or v < 0 and key not in ("r_x", "r_y", "r_z"):
            raise _bad(spec, key, f"{key}={value!r} must be a finite number"
                       + (" > 0" if key in _POSITIVE else " >= 0" if not key.startswith("r_") else ""))
        given[key] = v
    for key, default in KINDS[kind].items():
        out[key] = given.get(key, default)
    if "direction" in out and out["direction"] not in _DIRS:
        raise _bad(spec, "direction", f"{out['direction']!r}; expected one of {', '.join(_DIRS)}")
    if "channels" in out:
        chans = tuple(c.strip() for c in out["channels"].split("+") if c.strip())
        bad = [c for c in chans if c not in CHANNELS]
        if bad or not chans:
            raise _bad(spec, "channels", f"{out['channels']!r}; give channels joined by '+', from {'+'.join(CHANNELS)}")
        out["channels"] = chans
    if kind == "fixed_resonance" and out["role"] not in _ROLES:
        raise _bad(spec, "role", f"{out['role']!r}; expected one of {', '.join(_ROLES)}")
    if kind in ("counter_rotation",) and not 0 < out["fraction"] <= 1:
        raise _bad(spec, "fraction", f"fraction={out['fraction']!r} must be in (0, 1]")
    if kind == "counter_rotation" and out["direction"] == "axial_force":
        raise _bad(spec, "direction", "an axial line has no rotation sense")
    if kind == "sidebands" and (out["f_mod_hz"] is None) == (out["per_rev"] is None):
        raise _bad(spec, "f_mod_hz/per_rev", "give exactly one of f_mod_hz (fixed) or per_rev (speed-proportional)")
    return out


def _harmonic(wheel, spec, direction, h):
    for hh, C in wheel.harmonics.get(direction, []):
        if abs(hh - h) <= 1e-6:
            return hh, C
    known = ", ".join(f"{hh:g}" for hh, _ in wheel.harmonics.get(direction, []))
    raise DataError("--inject", "h", f"{spec['kind']}: the wheel has no {direction} line at h = {h:g} "
                    f"(it has h = {known})")


def _without(wheel, direction, h):
    return replace(wheel, harmonics={d: [(hh, C) for hh, C in v if not (d == direction and abs(hh - h) <= 1e-6)]
                                     for d, v in wheel.harmonics.items()})


def _is_imbalance(direction, h):
    return direction != "axial_force" and abs(h - 1.0) <= 0.011


def prepare_wheel(wheel, specs: list, physics: str):
    """The wheel to simulate: lines an injection replaces are taken out (or scaled), resonances added."""
    from .teststand import Mode

    for s in specs:
        k = s["kind"]
        if k in ("speed_ripple",) and physics != "simple":
            raise DataError("--inject", k, "needs --physics simple (the ripple is applied to the preset's lines)")
        if k == "fixed_resonance":
            mode = Mode(f"injected_{s['role']}", s["f_hz"], s["zeta"], s["gain"], s["channels"])
            if s["role"] == "test_stand":
                wheel = replace(wheel, test_stand_modes=list(wheel.test_stand_modes) + [mode])
            elif physics != "simple":
                raise DataError("--inject", "role", "fixed_resonance role=wheel_mode needs --physics simple "
                                "(with extended physics the wheel's modes are its suspension)")
            else:
                wheel = replace(wheel, modes=list(wheel.modes) + [mode])
        elif k in ("amplitude_law", "sidebands", "counter_rotation"):
            h, C = _harmonic(wheel, s, s["direction"], s["h"])
            s["C"] = C
            if k == "sidebands" and physics != "simple" and _is_imbalance(s["direction"], h):
                # the imbalance stays in the simulation (through the modes); only its two sidebands are added
                s["C"] = getattr(wheel.extended, "U_s" if s["direction"] == "radial_force" else "U_d")
                s["sidebands_only"] = True
                continue
            if physics != "simple" and _is_imbalance(s["direction"], h) and k != "counter_rotation":
                raise DataError("--inject", "h", f"{k}: with --physics extended the radial h = 1 lines are the "
                                "rotor's imbalances; pick another h or --physics simple")
            if k == "counter_rotation" and physics != "simple" and _is_imbalance(s["direction"], h):
                name = "U_s" if s["direction"] == "radial_force" else "U_d"
                s["C"] = getattr(wheel.extended, name)
                wheel = replace(wheel, extended=replace(wheel.extended, **{name: s["C"] * math.sqrt(1 - s["fraction"])}))
            elif k == "counter_rotation":
                wheel = replace(wheel, harmonics={d: [(hh, c * math.sqrt(1 - s["fraction"]) if d == s["direction"]
                                                       and hh == h else c) for hh, c in v]
                                                  for d, v in wheel.harmonics.items()})
            else:
                wheel = _without(wheel, s["direction"], h)
    return wheel


def _add_line(run, direction, amp, phase, sense=1.0):
    """amp, phase: (n_samples,) arrays; co-rotating x = a cos, y = a sin (sense −1: y = −a sin)."""
    chans = DIRECTION_CHANNELS[direction]
    run.signals[chans[0]] = run.signals[chans[0]] + amp * np.cos(phase)
    if len(chans) > 1:
        run.signals[chans[1]] = run.signals[chans[1]] + sense * amp * np.sin(phase)


def _sense(wheel, direction, h):
    """The rotation sense the preset gives the line (direction, h) ('co' when it has none; axial: 'co')."""
    return next((v for (d, hh), v in wheel.senses.items() if d == direction and abs(hh - h) <= 1e-6), "co")


def _wheel_loads(wheel, spec, w_mid, rng) -> list:
    """The wheel loads (:class:`rwadist.extended.Line`, random phases from ``rng``) one run of ``spec`` adds with
    extended physics; they reach the load cell through the suspension modes (:func:`_add_wheel_loads`).

    missing_harmonic: a co-rotating line fraction·C1·Ω² at h (the model file's default sense).  amplitude_law: the
    line taken out of the wheel (:func:`prepare_wheel`) with its own sense and the law A(Ω) =
    fraction·C·Ω_mid²·(Ω/Ω_mid)^exponent.  counter_rotation: the counter part C·sqrt(fraction)·Ω² (the co part stays
    in the simulation).  sidebands: the modulated line a(1 + depth·cos(ψ_m)) is the carrier a (with the line's
    own sense; on h = 1 the imbalance is the carrier and stays in the simulation) and two lines of amplitude
    depth·a/2 at a fixed offset ±f_mod (:attr:`rwadist.extended.Line.f_offset`) or at h ± per_rev, phases
    φ_c ± φ_m: each meets the modes at its own whirl rate."""
    from . import extended as ext

    k, d, h = spec["kind"], spec["direction"], spec["h"]
    if k == "missing_harmonic":
        return [ext.Line(d, float(h), float(spec["fraction"] * wheel.fundamental_C(d)), "co", rng.uniform(0, 2 * np.pi))]
    if k == "counter_rotation":
        return [ext.Line(d, float(h), float(spec["C"] * math.sqrt(spec["fraction"])), "counter",
                         rng.uniform(0, 2 * np.pi))]
    sense = "co" if spec.get("sidebands_only") else _sense(wheel, d, h)
    if k == "amplitude_law":
        law = (spec["fraction"] * spec["C"] * w_mid**2, w_mid, spec["exponent"])
        return [ext.Line(d, float(h), float(spec["C"]), sense, rng.uniform(0, 2 * np.pi), law=law)]
    # sidebands
    ph_c, ph_m = rng.uniform(0, 2 * np.pi, 2)
    side_C = 0.5 * spec["depth"] * spec["C"]
    out = [] if spec.get("sidebands_only") else [ext.Line(d, float(h), float(spec["C"]), sense, ph_c)]
    for side in (1.0, -1.0):
        if spec["per_rev"] is not None:
            out.append(ext.Line(d, float(h + side * spec["per_rev"]), float(side_C), sense, ph_c + side * ph_m))
        else:
            out.append(ext.Line(d, float(h), float(side_C), sense, ph_c + side * ph_m, f_offset=side * spec["f_mod_hz"]))
    return out


def _add_wheel_loads(run, params, lines, fixture=()):
    """Add wheel loads ``lines`` (:class:`rwadist.extended.Line`) to ``run`` through the suspension modes of
    ``params`` (:func:`rwadist.extended.steady_lines` at the run's signed speed) and the stand's ``fixture``
    resonances (as the simulation applies them to its own lines): every channel each line reaches; a line at
    or above Nyquist is not recorded (as the simulation drops it)."""
    from . import extended as ext
    from .teststand import _fixture_gain

    f, A = ext.steady_lines(params, lines, [run.speed])
    f, A = f[0], A[0]                                           # (n_lines,), (n_lines, 6)
    if fixture:
        A = A * _fixture_gain(list(fixture), f)
    t = np.arange(run.n_samples) / run.sample_rate
    for j in np.flatnonzero(f < 0.5 * run.sample_rate):
        z = np.exp(2j * np.pi * f[j] * t)
        for i, c in enumerate(CHANNELS):
            if c in run.signals and A[j, i] != 0:
                run.signals[c] = run.signals[c] + (A[j, i] * z).real


def apply(test, wheel, specs: list, seed: int = 0, clean=None, physics: str = "simple", fixture=()):
    """Add the post-simulation parts of ``specs`` to ``test`` (in place) and record them in its meta.

    wheel : the preset as given (before :func:`prepare_wheel`).  clean : noise-free simulation of the
    prepared wheel with the same seed (needed by speed_ripple and cross_coupling; without it
    cross_coupling takes the noisy forces).  physics : that of the simulation ("extended": every wheel
    load -- missing_harmonic, amplitude_law, sidebands, counter_rotation -- goes through the suspension
    modes, :func:`_add_wheel_loads`).  fixture : the stand's active fixture resonances
    (:class:`rwadist.teststand.Mode`, those the simulation applied): with extended physics a wheel load
    added here passes through them as the simulated lines do."""
    rng = np.random.default_rng(np.random.SeedSequence([int(seed), 14]))
    extended = physics != "simple"
    speeds = np.array([abs(r.speed) for r in test.runs])
    w_max, w_mid = float(speeds.max()), float(np.median(speeds))
    record = [{key: (list(v) if isinstance(v, tuple) else v) for key, v in s.items()} for s in specs]
    # the load-cell offset acts on the total force the cell measures: applied last, on the forces of the
    # simulation plus every noise-free content added here before it (the sensors' noise stays out of r × F)
    ordered = [s for s in specs if s["kind"] != "cross_coupling"] + [s for s in specs if s["kind"] == "cross_coupling"]
    forces_before = [{c: r.signals[c].copy() for c in ("Fx", "Fy", "Fz")} for r in test.runs]
    for s in ordered:
        k = s["kind"]
        for run_i, r in enumerate(test.runs):
            t = np.arange(r.n_samples) / r.sample_rate
            w = abs(r.speed)
            if extended and k in ("missing_harmonic", "amplitude_law", "counter_rotation", "sidebands"):
                _add_wheel_loads(r, wheel.extended, _wheel_loads(wheel, s, w_mid, rng), fixture)
            elif k in ("missing_harmonic", "amplitude_law", "counter_rotation"):
                if k == "missing_harmonic":
                    a = s["fraction"] * wheel.fundamental_C(s["direction"]) * w**2
                elif k == "amplitude_law":
                    a = s["fraction"] * s["C"] * w_mid**2 * (w / w_mid) ** s["exponent"]
                else:
                    a = s["C"] * math.sqrt(s["fraction"]) * w**2
                _add_line(r, s["direction"], a, s["h"] * w * t + rng.uniform(0, 2 * np.pi),
                          -1.0 if k == "counter_rotation" else 1.0)
            elif k == "sidebands":
                f_mod = s["f_mod_hz"] if s["f_mod_hz"] is not None else s["per_rev"] * w / (2 * np.pi)
                env = 1.0 + s["depth"] * np.cos(2 * np.pi * f_mod * t + rng.uniform(0, 2 * np.pi))
                _add_line(r, s["direction"], s["C"] * w**2 * env, s["h"] * w * t + rng.uniform(0, 2 * np.pi))
            elif k == "broadband_floor":
                b, a_ = signal.butter(2, s["fc_hz"], fs=r.sample_rate)
                for c in s["channels"]:
                    c1 = wheel.fundamental_C("radial_force" if c.startswith("F") else "radial_torque")
                    x = signal.lfilter(b, a_, rng.normal(size=r.n_samples + 1024))[1024:]
                    x /= np.sqrt(np.mean(x**2))
                    r.signals[c] = r.signals[c] + s["level"] * c1 * w_max**2 * (w / w_max) ** (s["exponent"] / 2) * x
            elif k == "cross_coupling":
                if clean is None:
                    F = np.column_stack([r.signals[c] for c in ("Fx", "Fy", "Fz")])
                else:
                    F = np.column_stack([clean.runs[run_i].signals[c] + r.signals[c] - forces_before[run_i][c]
                                         for c in ("Fx", "Fy", "Fz")])
                T = np.cross(np.array([s["r_x"], s["r_y"], s["r_z"]])[None, :], F)
                for j, c in enumerate(("Tx", "Ty", "Tz")):
                    r.signals[c] = r.signals[c] + T[:, j]
                if s["force_noise"] > 0:
                    std = s["force_noise"] * wheel.fundamental_C("radial_force") * w_max**2
                    for c in ("Fx", "Fy", "Fz"):
                        r.signals[c] = r.signals[c] + rng.normal(0.0, std, r.n_samples)
            elif k == "speed_ripple":
                c_run = clean.runs[run_i]
                for ch in r.signals:
                    r.signals[ch] = r.signals[ch] - c_run.signals[ch]          # the noise alone
                ph = rng.uniform(0, 2 * np.pi)
                th = 2 * np.pi * s["f_ripple_hz"] * t + ph
                omega = w + s["delta_omega"] * np.sin(th)
                psi = w * t - s["delta_omega"] / (2 * np.pi * s["f_ripple_hz"]) * (np.cos(th) - np.cos(ph))
                for d in DIRECTION_CHANNELS:
                    for h, C in wheel.harmonics.get(d, []):
                        if h * (w + s["delta_omega"]) / (2 * np.pi) >= 0.5 * r.sample_rate:
                            continue
                        sense = -1.0 if wheel.senses.get((d, h)) == "counter" else 1.0
                        _add_line(r, d, C * omega**2, h * psi + rng.uniform(0, 2 * np.pi), sense)
    test.meta["injected"] = record
    return test


def simulate_with_injections(wheel, specs: list, speeds_rpm, physics: str = "simple", seed: int = 0, **kwargs):
    """:func:`rwadist.teststand.simulate_steady` of ``wheel`` with ``specs`` (parsed) injected."""
    from .teststand import _fixture_modes, simulate_steady

    specs = [dict(s) for s in specs]
    if any(s["kind"] == "speed_ripple" for s in specs) and kwargs.get("modes", True) and physics == "simple":
        raise DataError("--inject", "speed_ripple", "needs --no-modes (the rippled lines are rebuilt without the "
                        "wheel's resonances)")
    prepared = prepare_wheel(wheel, specs, physics)
    test = simulate_steady(prepared, speeds_rpm, physics=physics, seed=seed, **kwargs)
    clean = None
    if any(s["kind"] in ("speed_ripple", "cross_coupling") for s in specs):
        clean = simulate_steady(prepared, speeds_rpm, physics=physics, seed=seed, **{**kwargs, "noise": 0.0})
    fixture = _fixture_modes(prepared, kwargs.get("test_stand", True)) if physics != "simple" else ()
    return apply(test, wheel, specs, seed=seed, clean=clean, physics=physics, fixture=fixture)
