"""One line of plain words per diagnosed effect, with its key numbers and units, for the console
(`rwadist diagnose`, `rwadist model show`).  Units at this edge: Hz, rpm, N, N·m, mm; the model file
keeps SI (rad/s, m).  An effect kind this module does not know (a newer file) is still shown, as its
scalar fields.
"""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .units import DIRECTION_C_UNIT, RAD_S_TO_RPM

#: fields never shown on the one line: arrays of knots, evidence, texts of laws
_SKIP = {"kind", "evidence", "psd_ref", "f_Hz_knots", "gain_law", "whirl"}
_AMPLITUDE_UNIT = {"radial_force": "N", "axial_force": "N", "radial_torque": "N·m", "axial_torque": "N·m"}


def _words(name: str) -> str:
    return str(name).replace("_", " ")


def _num(v, spec: str = ".4g") -> str:
    return format(float(v), spec)


def _rpm(omega_rad_s) -> str:
    return f"{abs(float(omega_rad_s)) * RAD_S_TO_RPM:.0f} rpm"


def _pm(e: Mapping, key: str, spec: str = ".2g") -> str:
    v = e.get(key)
    return f" ±{format(float(v), spec)}" if v is not None and np.isfinite(float(v)) else ""


def _directions(v) -> str:
    return ", ".join(_words(d) for d in (v if isinstance(v, (list, tuple)) else [v]))


def _generic(e: Mapping) -> str:
    parts = []
    for k, v in e.items():
        if k in _SKIP or isinstance(v, (list, tuple, np.ndarray, Mapping)):
            continue
        parts.append(f"{_words(k)} {_num(v) if isinstance(v, float) else v}")
    return ", ".join(parts)


def describe_effect(effect: Mapping) -> str:
    """``effect`` (a model file's effect entry or a diagnose summary entry, a mapping with ``kind``) as
    one line: its name in words and its key numbers with units."""
    e = dict(effect)
    kind = str(e.get("kind", "effect"))
    try:
        body = _DESCRIBE[kind](e)
    except (KeyError, TypeError, ValueError):           # an unknown kind, or fields of another version
        body = _generic(e)
    return f"{_words(kind)}: {body}"


def _missing_harmonic(e):
    d = e["direction"]
    return f"{_words(d)}, h {_num(e['h'])}, C {_num(e['C'], '.3e')} {DIRECTION_C_UNIT[d]}"


def _amplitude_law(e):
    d = e["direction"]
    return (f"{_words(d)}, h {_num(e['h'])}, amplitude ∝ |Ω|^{_num(e['exponent'], '.3g')}{_pm(e, 'exponent_stderr')}, "
            f"{_num(e['amplitude_ref'], '.3g')} {_AMPLITUDE_UNIT[d]} at {_rpm(e['omega_ref_rad_s'])}")


def _broadband_floor(e):
    f = np.asarray(e["f_Hz"], dtype=float)
    psd = np.asarray(e["psd_ref"], dtype=float)
    chans = " ".join(e["channel"]) if isinstance(e["channel"], (list, tuple)) else str(e["channel"])
    return (f"{chans}, PSD ∝ |Ω|^{_num(e['exponent'], '.3g')}, {f.min():.0f}–{f.max():.0f} Hz, "
            f"peak {psd.max():.3g} {_psd_unit(e)} at {_rpm(e['omega_ref_rad_s'])}")


def _psd_unit(e) -> str:
    """The floor's PSD unit: its channel's unit squared per Hz (N²/Hz or (N·m)²/Hz)."""
    from .units import CHANNEL_UNIT

    chans = e["channel"] if isinstance(e["channel"], (list, tuple)) else [e["channel"]]
    unit = CHANNEL_UNIT.get(chans[0]) if chans else None
    return {"N": "N²/Hz", "Nm": "(N·m)²/Hz"}.get(unit, f"({unit})²/Hz" if unit else "unit²/Hz")


def _fixed_resonance(e):
    role = "test stand" if e["role"] == "test_stand" else "wheel mode"
    return (f"{role}, {_num(e['f_Hz'], '.2f')} Hz, ζ {_num(e['zeta'], '.3g')}, peak gain {_num(e['peak_gain'], '.3g')}"
            f", on {_directions(e['directions'])}")


def _cross_coupling(e):
    r = np.asarray(e["r_m"], dtype=float) * 1e3
    se = e.get("r_stderr_m")
    err = "" if se is None else " ±(" + ", ".join(f"{x:.1f}" for x in np.asarray(se, dtype=float) * 1e3) + ")"
    # + 0.0: a component that rounds to zero is written 0.0, not -0.0
    return "load-cell reference offset r = (" + ", ".join(f"{float(f'{x:.1f}') + 0.0:.1f}" for x in r) + f"){err} mm"


def _sidebands(e):
    return (f"{_words(e['direction'])}, h {_num(e['h'])}, lines at ±{_num(e['f_mod_Hz'], '.3g')} Hz, "
            f"depth {_num(e['depth'], '.3g')}")


def _speed_ripple(e):
    dw = float(e["delta_omega_rad_s"]) * RAD_S_TO_RPM
    tail = f", ∝ |Ω|^{_num(e['speed_exponent'], '.3g')}" if float(e.get("speed_exponent") or 0.0) else ""
    return (f"{_num(e['f_ripple_Hz'], '.3g')} Hz, amplitude {dw:.3g} rpm at {_rpm(e['omega_ref_rad_s'])}{tail}")


def _counter_rotation(e):
    return (f"{_words(e['direction'])}, h {_num(e['h'])}, counter-rotating fraction q "
            f"{_num(e['counter_fraction'], '.3g')}{_pm(e, 'counter_fraction_stderr')}")


def _spin_acceleration(e):
    return f"α {_num(e['alpha_rad_s2'], '.3g')} rad/s²"


def _suspension_modes(e):
    free = e.get("unconstrained") or ()
    note = f"; not located by the data: {_directions(free)}" if free else ""
    return (f"radial translation {_num(e['radial_translation_Hz'], '.4g')} Hz (ζ {_num(e['zeta_radial_translation'], '.2g')})"
            f", rocking at rest {_num(e['rocking_Hz'], '.4g')} Hz (ζ {_num(e['zeta_rocking'], '.2g')})"
            f", axial {_num(e['axial_Hz'], '.4g')} Hz (ζ {_num(e['zeta_axial'], '.2g')})"
            f", I_zz/I_rr {_num(e['inertia_ratio'], '.3g')}{note}")


def _speed_sidebands(e):
    d = e["direction"]
    return (f"{_words(d)}, lines at h {_num(e['h_lower'])} and {_num(e['h_upper'])} beside h {_num(e['h'])} "
            f"(±{_num(e['per_rev'], '.3g')} per revolution), C/C of the carrier {_num(e['ratio_lower'], '.3g')} and "
            f"{_num(e['ratio_upper'], '.3g')}")


def _lever_arm_noise(e):
    rise = e.get("floor_rise_dB") or {}
    rises = ", ".join(f"{c} +{float(v):.2f} dB" for c, v in rise.items())
    return (f"force-sensor noise moved into the corrected torques by the lever arm, transfer "
            f"{_num(e['noise_transfer'], '.3g')}{_pm(e, 'noise_transfer_stderr')} (1 = the lever arm alone)"
            + (f", noise floor {rises}" if rises else "") + " (measurement, not a wheel load)")


_DESCRIBE = {"missing_harmonic": _missing_harmonic, "amplitude_law": _amplitude_law,
             "broadband_floor": _broadband_floor, "fixed_resonance": _fixed_resonance,
             "cross_coupling": _cross_coupling, "sidebands": _sidebands, "speed_ripple": _speed_ripple,
             "counter_rotation": _counter_rotation, "spin_acceleration": _spin_acceleration,
             "suspension_modes": _suspension_modes, "speed_sidebands": _speed_sidebands,
             "lever_arm_noise": _lever_arm_noise}


def diagnose_lines(effects) -> list:
    """Console lines of the effects a diagnosis added (its summary's ``effects``), with the held-out
    gain each brought."""
    out = []
    for e in effects:
        gain = (e.get("evidence") or {}).get("heldout_gain_fraction")
        tail = f" (held-out gain {100 * float(gain):.1f} %)" if gain is not None else ""
        out.append(f"  + {describe_effect(e)}{tail}")
    return out


def model_table(model) -> list:
    """Lines of `rwadist model show` (table format): the harmonics, then one line per effect."""
    from .model import DIRECTIONS

    rows = [(d, h) for d in DIRECTIONS for h in model.harmonics(d)]
    out = [f"model {model.name!r}  (C in SI per (rad/s)²: kg·m for forces, kg·m² for torques)",
           f"{'direction':<14} {'h':>7} {'C':>12} {'stderr':>10} {'points':>6}  excluded rpm"]
    for d, h in rows:
        se = "" if h.C_stderr is None else f"{h.C_stderr:.2e}"
        ex = " ".join(f"{lo:.0f}-{hi:.0f}" for lo, hi in h.excluded_rpm)
        out.append(f"{d:<14} {h.h:7.3f} {h.C:12.4e} {se:>10} {h.n_points:6d}  {ex}")
    effects = list(model.effects or [])
    out.append(f"effects ({len(effects)}):" if effects else "effects: none")
    out += [f"  {i + 1}. {describe_effect(e)}" for i, e in enumerate(effects)]
    return out
