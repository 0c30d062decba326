"""What the empirical fit warns of once it has its model (:func:`rwadist.fit`): a speed scale the lines contradict,
a sweep's 1x line tied with another, a radial channel recorded in another unit than its partner, an empty model.

Each function returns the warning's words ('' or None when there is nothing to say); :func:`rwadist.fit` raises them
as :class:`rwadist.RwadistWarning`.
"""
from __future__ import annotations

import numpy as np

from .units import DIRECTION_CHANNELS, RADIAL_PAIRS, unit_words

#: A line is read on a channel of a radial pair when its power stands this many times over the channel's median
#: PSD near it (both channels of the pair must read it)
UNIT_LINE_SNR = 10.0
#: Half-width of a line's power sum, bins (the Hann window's main lobe)
LINE_BINS = 2
#: Bins either side of a line whose median PSD is its channel's floor there
FLOOR_BINS = 20
#: Readings (harmonic × run) a pair needs before its ratio is judged
UNIT_MIN_READINGS = 4


def pair_amplitude_ratios(spectra, model) -> dict:
    """Per radial pair ((a, b) of :data:`rwadist.units.RADIAL_PAIRS` both present), the median over the model's
    harmonics of the direction (radial force for Fx/Fy, radial torque for Tx/Ty) and the spinning runs of the
    amplitude ratio of ``a`` over ``b`` on the line (the square root of their power ratio; a rotating load gives x and
    y the same power), over the readings where both channels' lines stand :data:`UNIT_LINE_SNR` over their floor.
    Pairs with fewer than :data:`UNIT_MIN_READINGS` readings are left out.  ``spectra``: :class:`rwadist.spectra.Spectra`;
    ``model``: the fitted :class:`rwadist.model.WheelModel`."""
    f, df = np.asarray(spectra.f, dtype=float), float(spectra.df)
    top = f[-1] if spectra.f_lim is None else min(float(spectra.f_lim), f[-1])
    spin = np.abs(np.asarray(spectra.speed, dtype=float)) / (2 * np.pi)        # Hz, (n_runs,)
    out = {}
    for a, b in RADIAL_PAIRS:
        if a not in spectra.psd or b not in spectra.psd:
            continue
        hs = [float(hm.h) for hm in model.empirical.get("radial_force" if a[0] == "F" else "radial_torque", [])]
        if not hs:
            continue
        line_f = np.outer(hs, spin)                                             # (n_h, n_runs)
        ok = np.isfinite(line_f) & (line_f > (FLOOR_BINS + 1) * df) & (line_f < top - (FLOOR_BINS + 1) * df)
        k = np.rint(np.where(ok, line_f, 0.0) / df).astype(int)
        run = np.broadcast_to(np.arange(spin.size), k.shape)
        power, floor = {}, {}
        for c in (a, b):
            psd = np.asarray(spectra.psd[c], dtype=float)
            near = np.clip(k[..., None] + np.arange(-FLOOR_BINS, FLOOR_BINS + 1), 0, f.size - 1)
            rows = psd[run[..., None], near]                                    # (n_h, n_runs, 2·FLOOR_BINS + 1)
            power[c] = rows[..., FLOOR_BINS - LINE_BINS:FLOOR_BINS + LINE_BINS + 1].sum(axis=-1)
            floor[c] = np.median(rows, axis=-1) * (2 * LINE_BINS + 1)
        read = ok & (power[a] > UNIT_LINE_SNR * floor[a]) & (power[b] > UNIT_LINE_SNR * floor[b])
        if int(read.sum()) >= UNIT_MIN_READINGS:
            out[(a, b)] = float(np.exp(np.median(0.5 * np.log(power[a][read] / power[b][read]))))
    return out


def unit_mixup_warning(spectra, model) -> str:
    """'' or the words for a radial pair whose channels read the lines in a ratio that is a unit factor
    (:data:`rwadist.units.UNIT_FACTORS` within :data:`rwadist.units.UNIT_TOLERANCE`): one channel recorded or
    declared in another unit, which biases the pair's fitted coefficients (the fit takes the pair as one
    rotating load)."""
    said = []
    for (a, b), ratio in pair_amplitude_ratios(spectra, model).items():
        hi, lo, r = (a, b, ratio) if ratio >= 1 else (b, a, 1 / ratio)
        words = unit_words(r, a)
        if words:
            direction = "radial force" if a[0] == "F" else "radial torque"
            said.append(f"{hi} reads the {direction} lines {r:.4g} times {lo} (a rotating load gives both the same "
                        f"power){words} The fitted {direction} coefficients take the pair as one load and are off "
                        "until the unit is put right")
    return "; ".join(said)


def empty_model_advice(test, settings, presence: float) -> str:
    """The words of an empty empirical fit: the cause the test shows (too few spinning runs for a harmonic's
    ``min_points`` measurements), else where to look (the presence threshold, the band, the speed column's unit)."""
    spinning = sum(1 for r in test.runs if np.isfinite(r.speed) and r.speed != 0)
    if spinning < settings.min_points:
        return (f"the model is empty: a harmonic needs {settings.min_points} measurements and the test has "
                f"{spinning} spinning run(s); give at least {settings.min_points} runs over the speed range")
    from .speed_check import misread_unit

    unit = misread_unit(test)
    if unit is not None:
        return (f"the model is empty: the speeds look like {unit['unit']}, not rpm: the imbalance's radial-force line "
                f"sits at the column's value read in {unit['unit']} in {unit['runs']} of {unit['spinning']} spinning "
                f"runs; give the speeds in rpm (multiply them by {unit['factor']:.6g})")
    return (f"no harmonic passed the presence threshold ({presence:g} of the runs): the model is empty; check that "
            "the lines lie in the band read (`f_lim`) and that the speeds are in rpm, give more runs over the speed "
            "range, or lower `presence`")


__all__ = ["pair_amplitude_ratios", "unit_mixup_warning", "empty_model_advice"]


def sense_unread_warning(spectra, model) -> str:
    """'' or the words for the radial directions whose lines the model holds while no run has both channels of their
    pair (:meth:`rwadist.spectra.Spectra.available`): their rotation senses cannot be read from the x/y phase, and
    every consumer takes them co-rotating (session 62's trial without Fy: the imbalance and every force line had been
    made counter-rotating; a reviewer's Fx and Fy recorded in alternate runs, never together: no sense, no word)."""
    said = []
    for d, pair in DIRECTION_CHANNELS.items():
        if d not in ("radial_force", "radial_torque") or not model.harmonics(d):
            continue
        lost = [c for c in pair if c not in spectra.channels or not spectra.available(c).any()]
        what = " and ".join(lost) + " in no run" if lost else " and ".join(pair) + " in no run together"
        if lost or not (spectra.available(pair[0]) & spectra.available(pair[1])).any():
            said.append(f"{what}: the {d.replace('_', ' ')} lines' rotation senses cannot be "
                        "read from the x/y phase (each is taken co-rotating: a counter-rotating line's whirl, coupling "
                        "and FMU x/y phase are then wrong); record both channels of the pair in the same runs to read "
                        "them")
    return "; ".join(said)


def unresolved_warning(fit, test=None) -> str:
    """'' or the words for the harmonics an empirical fit (:class:`rwadist.empirical.EmpiricalFit`) of ``test`` detected
    in enough runs but did not measure, no measurement being resolved from a line beside them (their power windows of
    ±``line_half_width`` bins overlap at every speed): the model lacks them, with no other word (trial nuV's 2.5-kg
    wheel: a run-up's line smeared over its slices, read as two candidates 0.4 % apart, neither measured; family wheel
    1's 30-s run-up: axial h 6.65 and 6.69, the wheel's 6.66).  On a sweep's slices (``test.meta["slicing"]``) such
    a pair is often one line the speed smears across the slice; on steady runs longer segments resolve a pair.
    Its own category (:class:`rwadist.errors.UnresolvedLinesWarning`): ``rwadist fit --extended`` measures those lines
    and silences it."""
    lost = sorted({(b.direction, round(b.h, 3)) for b in fit.bins
                   if not b.kept and b.reason.startswith("no measurement resolved")})
    if not lost:
        return ""
    names = [f"{d} h={h:.4g}" for d, h in lost]
    sliced = "slicing" in (getattr(test, "meta", None) or {})
    return (f"{len(lost)} harmonic(s) the data show were not measured apart from a line beside them "
            f"({', '.join(names[:6])}{' and more' if names[6:] else ''}): "
            "the empirical model lacks them; the extended fit (--extended) and rwadist diagnose measure such lines "
            "together on each run's whole record" + (" (a line the speed smears across a slice as one line)" if sliced
                                                     else ", and longer segments (--nperseg) resolve them on the PSDs"))


def model_warnings(spectra, fit, test) -> list:
    """The warnings (:class:`rwadist.RwadistWarning`) of :func:`unit_mixup_warning`, :func:`sense_unread_warning` and
    :func:`unresolved_warning` (an :class:`rwadist.errors.UnresolvedLinesWarning`) on the empirical fit ``fit`` of
    ``test`` (its ``spectra``), those with something to say."""
    from .errors import RwadistWarning, UnresolvedLinesWarning

    texts = [(unit_mixup_warning(spectra, fit.model), RwadistWarning),
             (sense_unread_warning(spectra, fit.model), RwadistWarning),
             (unresolved_warning(fit, test), UnresolvedLinesWarning)]
    return [kind(text) for text, kind in texts if text]
