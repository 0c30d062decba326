"""Detector of the open world (issue 33, item 3) on the final model's residual: a suspension mode of the model whose
frequency moves over the runs (a ``moving_resonance`` of the wheel's own mode, not a resonance beside it).

The model holds each suspension mode at one frequency f_m (ζ_m): a radial or axial line reaches the load cell
through H(f; f_m) = (1 + 2jζr)/(1 − r² + 2jζr), r = f/f_m.  When the suspension itself changes over the test -- a
bearing preload or a mount warming as the runs go on, a bearing's stiffness changing with speed -- the lines pass
through H(f; f(Ω)) instead, and their measured-over-predicted power ratios follow |H(f; f(Ω))|²/|H(f; f_m)|²: a rise
where the mode now is and a dip where the model holds it, the pair moving with the speed.  A resonance lifting
the lines (:func:`.describe_structure.moving_resonance`) fits the rise alone and its track goes astray: the session-54
new-user trial (its own generator: a 9 kg wheel whose 140 Hz radial translation fell 6 % from the first run to the
last, recorded in speed order) had "63.3 -> 131.6 Hz, slope +1.20 Hz per Hz of spin, a rotor mode stiffening"
beside a fixed 148 Hz resonance, its own lifted lines at 141-152 Hz.

Fitted here on the same ratios (each line's offset taken out, as there): f(Ω) = f0 + b·(f_spin − mid) over a grid of
f0 (±15 % of f_m in 0.5 % steps), b (±1.5 Hz per Hz of spin in 0.02 steps) and the moved mode's ζ (the model's or
:data:`ZETAS`), against the best fixed f0 and ζ (b = 0: one frequency other than the model's).  Described when the slope pays as a moving resonance's
does (F statistic :data:`~.describe_structure.MOVING_F` or more, at most :data:`~.describe_structure.MOVING_RATIO`
of the fixed misfit and :data:`~.describe_structure.MOVING_NULL_RATIO` of the offsets-only misfit) and the mode moves
over the speeds by more than its half-power half-width ζf (the F statistic has told it from a fixed mode already:
family wheel 4's translation moving −5 %, 11.4 Hz at ζ 0.029, F 1588).
"""
from __future__ import annotations

import numpy as np

from ..units import DIRECTION_CHANNELS
from .describe_structure import MOVING_F, MOVING_NULL_RATIO, MOVING_RATIO, LineRatios, _offsets_only
from .line_offsets import line_indicator
from .unexplained import Unexplained

#: The mode of the suspension each direction's lines pass (the rocking's whirl moves with speed by itself: not here)
MODE_OF = {"radial_force": "radial_translation", "axial_force": "axial"}
#: Grids: f0 as a factor of the model's mode, the slope (Hz per Hz of spin)
F0_FACTORS = np.exp(np.arange(-0.15, 0.15 + 1e-9, 0.005))
SLOPES = np.round(np.arange(-1.5, 1.5 + 1e-9, 0.02), 2)
#: ... and the moving mode's damping ratio (beside the model's own)
ZETAS = (0.005, 0.01, 0.02, 0.04, 0.08)
#: A mode read on this many points at least, of two lines or more, one of them this far (dB) from the model at least
#: (a rise or a dip: the moved mode's lines read both; a moving resonance's gate is a 2 dB rise, and family wheels 0
#: and 3 with the translation moving +6 % and +5 % rise 1.9 dB at most; their clean cells read 0.06-0.27 dB)
MIN_POINTS = 8
MIN_DB = 1.0
#: ... within this log distance of the model's mode (±20 %: the grids' ±15 % and the lines' reach beyond it)
NEAR_MODE = 0.2


def _gain_db(f: np.ndarray, f_r: "np.ndarray | float", zeta: float) -> np.ndarray:
    """10·log10|H|² (dB) of the suspension's transmissibility H = (1 + 2jζr)/(1 − r² + 2jζr), r = f/f_r (any shapes
    that broadcast): 10·log10((1 + (2ζr)²)/((1 − r²)² + (2ζr)²)) in real arithmetic."""
    r2 = (f / f_r) ** 2
    x = 4 * zeta**2 * r2
    return 10 * np.log10((1 + x) / ((1 - r2) ** 2 + x))


def _grid_sse(r: LineRatios, q: np.ndarray, f0s: np.ndarray, slopes: np.ndarray, zetas, onehot, count) -> tuple:
    """(sse, f0, slope, ζ) of the best track f0 + slope·(spin − mid) over the grids (every combination at once), each
    line's offset out: Σ res² − Σ_lines (Σ res)²/n per curve."""
    mid = 0.5 * (r.spin.min() + r.spin.max())
    fr = f0s[None, :, None] + slopes[:, None, None] * (r.spin - mid)[None, None, :]          # (S, F, N)
    valid = np.all(fr > 0, axis=2)
    fr = np.where(fr > 0, fr, 1.0)
    best = (np.inf, np.nan, np.nan, np.nan)
    for z in zetas:
        res = (q - _gain_db(r.f, fr, z)).reshape(-1, q.size)
        sse = (res * res).sum(1) - (((res @ onehot.T) ** 2) / count).sum(1)
        sse = np.where(valid.ravel(), sse, np.inf)
        i = int(np.argmin(sse))
        if sse[i] < best[0]:
            best = (float(sse[i]), float(f0s[i % f0s.size]), float(slopes[i // f0s.size]), float(z))
    return best


def _drift_fit(r: LineRatios, f_m: float, zeta: float) -> tuple:
    """((sse, f0, slope, ζ) of the best moving mode, (sse, f0, ζ) of the best fixed one) of the ratios ``r`` read as
    the model's mode at ``f_m`` Hz (ζ ``zeta``) replaced by one on the track f0 + slope·(spin − mid), its own ζ from
    :data:`ZETAS` or the model's (a mode the fit did not locate has no damping to trust: family wheel 3's translation
    moving +5 % was held at ζ 0.0038, its truth 0.016).  Coarse (f0 in 1 % steps, the slope in 0.1) then fine about
    the best (:data:`F0_FACTORS`' 0.5 % steps over ±1 %, :data:`SLOPES`' 0.02 over ±0.1, ζ × 0.7-1.4)."""
    onehot, count = line_indicator(r.line)
    q = r.q + _gain_db(r.f, f_m, zeta)          # the data over the model with the model's mode put back
    zetas = (zeta,) + ZETAS
    _, f0, b, z = _grid_sse(r, q, f_m * F0_FACTORS[::2], SLOPES[::5], zetas, onehot, count)
    near_f0 = f_m * F0_FACTORS[np.abs(np.log(f_m * F0_FACTORS / f0)) <= 0.0101]
    near_b = SLOPES[np.abs(SLOPES - b) <= 0.1001]
    best = _grid_sse(r, q, near_f0, near_b, (0.7 * z, z, 1.4 * z), onehot, count)
    sse_f, f0_f, _, z_f = _grid_sse(r, q, f_m * F0_FACTORS, np.zeros(1), zetas, onehot, count)
    return best, (sse_f, f0_f, z_f)


def drifting_modes(ctx, state, ratios: list, shares) -> list:
    """``moving_resonance`` records of the model's suspension modes whose frequency the lines read moving with the
    speed (module docstring); ``ratios``: the :class:`LineRatios` of each direction (steady, resolved lines),
    ``shares(chans, track, zeta)`` -> (share of the misplaced power, level dB) of the track's cells."""
    modes = next((e for e in state.effects if getattr(e, "kind", "") == "suspension_modes"), None)
    if modes is None:
        return []
    out = []
    for r in ratios:
        name = MODE_OF.get(r.direction)
        if name is None or r.q.size < MIN_POINTS or np.unique(r.line).size < 2:
            continue
        f_m, zeta = float(modes.f0_Hz[name]), float(modes.zeta[name])
        if not np.any((np.abs(r.q) >= MIN_DB) & (np.abs(np.log(r.f / f_m)) <= NEAR_MODE)):
            continue                    # a moved mode changes the lines near it: none is off the model there
        (sse_m, f0, b, zeta_m), (sse_f, _, _) = _drift_fit(r, f_m, zeta)
        sse0 = _offsets_only(r)
        dof = max(r.q.size - np.unique(r.line).size - 3, 1)
        f_stat = (sse_f - sse_m) / max(sse_m / dof, 1e-300)
        span = r.spin.max() - r.spin.min()
        if not (f_stat >= MOVING_F and sse_m <= MOVING_RATIO * sse_f and sse_m <= MOVING_NULL_RATIO * sse0
                and abs(b) * span > zeta_m * f0):
            continue
        mid = 0.5 * (r.spin.min() + r.spin.max())
        f_low, f_high = f0 + b * (r.spin.min() - mid), f0 + b * (r.spin.max() - mid)
        chans = tuple(c for c in DIRECTION_CHANNELS[r.direction] if c in ctx.channels)
        share, level = shares(chans, lambda spin: f0 + b * (spin - mid), zeta_m)
        label = name.replace("_", " ")
        out.append(Unexplained(
            signature="moving_resonance", channels=chans, speed_rpm=(float(r.spin.min() * 60), float(r.spin.max() * 60)),
            f_Hz=(float(min(f_low, f_high)), float(max(f_low, f_high))), level_dB=level, share=share,
            n_runs=int(np.unique(r.run).size),
            parameters={"direction": r.direction, "mode": name, "model_mode_Hz": f_m, "zeta": zeta_m,
                        "f_at_lowest_speed_Hz": float(f_low), "f_at_highest_speed_Hz": float(f_high),
                        "slope_Hz_per_Hz_of_spin": float(b), "f_statistic": float(f_stat),
                        "fixed_mode_misfit_ratio": float(sse_m / max(sse_f, 1e-300)),
                        "whirl": f"no gyroscopic whirl moves the {label} mode"},
            causes=(f"the wheel's own {label} mode moving over the runs: from {f_low:.4g} Hz at the lowest speed to "
                    f"{f_high:.4g} Hz at the highest ({b:+.2f} Hz per Hz of spin), where the model holds one frequency, "
                    f"{f_m:.4g} Hz: the lines read a rise where the mode is and a dip where the model has it.  The "
                    "suspension's stiffness changes over the test: a bearing preload or the mount warming as the "
                    "runs go on (a drift with time), or a bearing's stiffness changing with speed",),
            would_tell="the runs in the order they were recorded (a drift with time follows it, not the speed); a low "
                       "speed repeated after the top ones; a tap test of the wheel on its mount before and after"))
    return out


def same_track(u: Unexplained, drift: Unexplained) -> bool:
    """Whether the ``moving_resonance`` record ``u`` is read on the same direction's lines as the drifting mode
    ``drift`` and reaches within 20 % of the model's mode: the rise of that mode's lines, fitted as a resonance of its
    own."""
    p, d = u.parameters, drift.parameters
    lo, hi = 0.8 * d["model_mode_Hz"], 1.2 * d["model_mode_Hz"]
    return p.get("direction") == d["direction"] and u.f_Hz[0] <= hi and u.f_Hz[1] >= lo
