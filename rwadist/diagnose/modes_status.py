"""Why a diagnosis that was to fit the wheel's suspension modes from the data ends without them.

``rwadist diagnose DATA`` with no model (base ``auto``) fits the wheel's own suspension modes when the data show
them (:class:`rwadist.effects.suspension_modes_diagnose.SuspensionModes`).  When it ends on the empirical base the
model holds every line as C·Ω² hard mounted, and a reader must know whether that is because the lines show no
modal amplification (a modes-off test: right) or because they do and no mode could be located or none passed
(trial25: a suspension whose elastic centre is off the rotor's centre of mass couples translation and rocking;
the lines rose near all three modes, no mode was named, and nothing said so).
"""
from __future__ import annotations

import numpy as np

#: the memo key of the modes' empirical fit of every run (:func:`rwadist.diagnose.whole_fit.whole_data_fit`)
WHOLE_DATA_FIT = ("suspension_modes.whole_data_fit",)
#: the memo key of the amplification peaks read from that fit (:func:`rwadist.extended_fit.amplification_peaks`)
AMPLIFICATION_PEAKS = ("modes_status.amplification_peaks",)
#: the memo key, on the context of the data as given, of the context the search read (:func:`rwadist.diagnose.describe.
#: _described`)
SEARCH_CONTEXT = ("modes_status.search_context",)
#: the amplification peaks' directions, in the order they are said
_DIRECTIONS = ("radial_force", "radial_torque", "axial_force")
#: a line of the model within this fraction of a left-out harmonic's h is that harmonic, put back
LEFT_OUT_MATCH = 0.005


def modes_status(diag) -> dict | None:
    """The record of the wheel's suspension modes not fitted, for summary.json, report.md and the console, or None
    when the search was not to fit them (a model given, or the test records the modes off) or fitted them.

    Returns
    -------
    dict or None
        ``status``: "no_amplification" (the lines show none: the empirical base is the right one),
        "not_located" (amplified lines, no mode located on them: no hypothesis) or "rejected" (a hypothesis
        made and not taken); ``left_out``: [{"direction", "h"}] the harmonics the data show that the model lacks,
        their lines modally amplified at nearly every speed (:attr:`Context.left_out`); ``peaks_Hz``: {direction:
        {"median_Hz", "lowest_Hz", "highest_Hz", "lines"}} the amplification peaks (a line's frequency at the speed of its largest rise over C·Ω², away from the speed
        range's ends); ``tried``: [{"iteration", "heldout_gain_fraction",
        "t", "modes_Hz"}] the hypotheses not taken; ``text``: one sentence.
    """
    # the context the search read (the data with fixed lines or a channel's copy taken out: :func:`rwadist.diagnose.
    # describe.start`), not the data as given that the diagnosis's figures read: a pickup line is no mode's rise
    ctx = diag.ctx._memo.get(SEARCH_CONTEXT) or diag.ctx
    if getattr(ctx, "base_switch", False) and diag.state_after.base == "extended":
        return _unread(ctx, diag)
    if not getattr(ctx, "base_switch", False) or diag.state_after.base != "empirical" or ctx.test is None:
        return None
    from ..empirical import fit_empirical
    from ..extended_fit import amplification_peaks

    # the modes' own fit of every run when their search made it, else the empirical fit of the diagnosis's spectra;
    # kept on the context, as every summary of the diagnosis asks again
    peaks = ctx._memo.get(AMPLIFICATION_PEAKS)
    if peaks is None:
        fit = ctx._memo.get(WHOLE_DATA_FIT)
        try:
            peaks = amplification_peaks(fit if fit is not None else fit_empirical(ctx.sp))
        except ValueError:
            peaks = []
        ctx._memo[AMPLIFICATION_PEAKS] = peaks
    # a rise a named resonance explains (a test stand on a modes-off test) is no sign of the wheel's modes
    named = [e.f_r for e in diag.state_after.effects if e.kind == "fixed_resonance"]
    peaks = [p for p in peaks if not p["at_range_edge"] and all(abs(p["f_hz"] / f - 1.0) > 0.1 for f in named)]
    where: dict = {}
    for d in _DIRECTIONS:
        f = [p["f_hz"] for p in peaks if p["direction"] == d]
        if f:
            where[d] = {"median_Hz": float(np.median(f)), "lowest_Hz": float(min(f)), "highest_Hz": float(max(f)),
                        "lines": len(f)}
    # a harmonic the starting fit left out for its modal amplification and nothing put back: the model lacks it
    left = [{"direction": d, "h": h} for d, h in getattr(ctx, "left_out", ())
            if not any(abs(x.h - h) <= LEFT_OUT_MATCH * h for x in diag.state_after.model.harmonics(d))]
    tried = [{"iteration": h.iteration, "heldout_gain_fraction": h.gain_fraction, "t": h.t,
              "modes_Hz": {m: float(h.effect.f0_Hz[m]) for m in ("radial_translation", "rocking", "axial")
                           if m not in h.effect.unconstrained}}
             for h in diag.hypotheses if h.effect.kind == "suspension_modes" and not h.passed]
    if tried:
        status = "rejected"
    elif where or left:
        status = "not_located"
    else:
        return {"status": "no_amplification", "peaks_Hz": {}, "tried": [], "left_out": [],
                "text": "the lines show no modal amplification: every line is fitted as C·Ω² hard mounted "
                        "(no suspension modes in the model)"}
    rise = "; ".join(f"{d.replace('_', ' ')} near {w['median_Hz']:.4g} Hz ({w['lines']} line peak"
                     f"{'s' if w['lines'] > 1 else ''}{_span(w)})" for d, w in where.items()) \
        or ("in the lines left out of the model" if left else "at the ends of the speed range")
    text = f"NOT FITTED, although the lines rise as through a resonance: {rise}"
    if tried:
        words = []
        for t in tried:
            located = ", ".join(f"{m.replace('_', ' ')} {f:.4g} Hz" for m, f in t["modes_Hz"].items()) or "no mode"
            words.append(f"iteration {t['iteration']}: {located} located, held-out gain "
                         f"{100 * t['heldout_gain_fraction']:.1f} % (t {t['t']:.3g}), not taken")
        text += "; tried, " + "; ".join(words)
    else:
        text += "; no mode of the model (a radial translation, a rocking mode whirling by I_zz/I_rr, an axial " \
                "mode) could be located on them"
    if left:
        names = ", ".join(f"{x['direction'].replace('_', ' ')} h {x['h']:.4g}" for x in left)
        text += (f": every line is fitted as C·Ω² hard mounted where it is not modally amplified, so the model holds no "
                 f"modes, and {len(left)} harmonic{'s' if len(left) > 1 else ''} amplified at nearly every speed "
                 f"{'are' if len(left) > 1 else 'is'} left out of it ({names}: C·Ω² does not describe "
                 f"{'them' if len(left) > 1 else 'it'}; the model lacks {'them' if len(left) > 1 else 'it'})")
    else:
        text += ": every line is fitted as C·Ω² hard mounted, so the model holds no modes"
    text += ("; a suspension the model does not describe (translation and rocking coupled, an x/y split) or a stand "
             "resonance moving with speed could do this; a tap test of the wheel on its mount, or the lines read at "
             "more speeds, would tell")
    return {"status": status, "peaks_Hz": where, "tried": tried, "left_out": left, "text": text}


#: The load-cell channels each mode is read on
MODE_CHANNELS = {"radial_translation": ("Fx", "Fy"), "rocking": ("Tx", "Ty"), "axial": ("Fz",)}


def _unread(ctx, diag) -> dict | None:
    """The record of the fitted suspension modes that no recorded channel reads (status "unread"), or None: a test of
    the forces alone reads no rocking, and the model holds that mode and I_zz/I_rr at the fit's starting values (the
    new-user trial of session 54, forces only: "rocking at rest not located (the fit ended at 3964 Hz)" was all it
    said)."""
    modes = next((e for e in diag.state_after.effects if getattr(e, "kind", "") == "suspension_modes"), None)
    if modes is None:
        return None
    unread = [m for m, chans in MODE_CHANNELS.items() if m in modes.unconstrained and not set(chans) & set(ctx.channels)]
    if not unread:
        return None
    words = "; ".join(f"{m.replace('_', ' ')}: no {' or '.join(MODE_CHANNELS[m])} recorded, which read it"
                      for m in unread)
    held = " and I_zz/I_rr (read from its whirls)" if "rocking" in unread else ""
    return {"status": "unread", "peaks_Hz": {}, "tried": [], "left_out": [], "unread": unread,
            "text": f"{words}: the model holds {'it' if len(unread) == 1 else 'them'}{held} at the fit's starting "
                    "values, not fitted; a test recording those channels would locate "
                    f"{'it' if len(unread) == 1 else 'them'}"}


def _span(w: dict) -> str:
    """", 45.2-110.7 Hz" when a direction's peaks spread more than 5 % about their median (a whirling mode)."""
    if w["highest_Hz"] - w["lowest_Hz"] <= 0.05 * w["median_Hz"]:
        return ""
    return f", {w['lowest_Hz']:.4g}-{w['highest_Hz']:.4g} Hz"
