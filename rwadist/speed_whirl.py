"""The gyroscopic whirl as a test of a speed taken from the data (issue 33, item 5).

A sweep without a speed column gets its speed scale from its lines (:mod:`rwadist.speed_scale`): the 1× line is
the line with one rotation sense in the radial pairs and the most integer multiples.  Two such lines can tie (a
ball-pass line with its 2× against the imbalance with its 2×; a cage line with its 2× below them), and the data's
lines alone cannot tell which is the rotor's: every ratio is self-consistent at any scale.  The wheel's rocking
mode can.  Its whirl obeys I_rr·ω² − I_zz·Ω·ω − k_θ = 0: the gyroscopic term scales with the speed, so speeds k
times the wheel's read an inertia ratio I_zz/I_rr k times too small (a line of the data at whirl rate ω = h·Ω is
the same whatever the scale; the term I_zz·Ω·ω only keeps its value with I_zz/k).  And a rotor's ratio is bounded:

* I_zz/I_rr <= 2 for any rigid body symmetric about its spin axis (I_zz = ∫(x² + y²) dm <= I_xx + I_yy = 2·I_rr,
  equality for a thin disc), about its centre of mass; about any other point I_rr is larger and the ratio smaller;
* a reaction wheel is a flywheel, its mass on a rim: I_zz/I_rr > 1 (1.2-2 for the wheels of the thesis and the
  family; 1.8 for trial 11's).

So when diagnose fitted the wheel's suspension modes (``suspension_modes``) on speeds from the data, a ratio
outside [1, 2] widened by :data:`MARGIN` for the fit's error means the wrong line was taken as 1×: the candidate
(of the speed scale's) that brings the ratio into the band is tried, the data diagnosed again with its speeds
(every run's speed × its ratio h, every line's h ÷ h), and kept when the whirl then reads a ratio in the band.
When the modes are not fitted, or no candidate brings the ratio into the band, the diagnosis says so and asks for
a speed (tach) column; never silently.  What was done goes to the test's ``meta["slicing"]["speed_scale"]
["whirl"]``, read by the report (:func:`speed_record`).

Units: dimensionless ratios; speeds rad/s in the runs, rpm in ``meta``.
"""
from __future__ import annotations

import copy
from dataclasses import replace

import numpy as np

from .effects.suspension_modes import RIGID_INERTIA_RATIO

#: a flywheel's polar inertia exceeds its transverse one: the lower end of the physical band of I_zz/I_rr
FLYWHEEL_INERTIA_RATIO = 1.0
#: relative widening of the band [FLYWHEEL_INERTIA_RATIO, RIGID_INERTIA_RATIO] for the fit's error (a candidate
#: scale moves the ratio by the ratio of two lines, 1.5 or more apart for lines with the same count of multiples)
MARGIN = 1.25
#: most candidate scales diagnosed again
MAX_TRIES = 2
#: relative distance within which a ratio given to :func:`rescaled` is the candidate's line (the speed scale's lines
#: are at least its INTEGER_TOL apart)
SAME_LINE = 1e-3
TACH_ADVICE = "record the wheel's speed (a tach or speed_rpm column) to be sure of it"


def band() -> tuple:
    """(lowest, highest) I_zz/I_rr a wheel's whirl may read before its speed scale is called wrong."""
    return FLYWHEEL_INERTIA_RATIO / MARGIN, RIGID_INERTIA_RATIO * MARGIN


def plausible(ratio: float | None) -> bool:
    """True when the inertia ratio ``ratio`` (I_zz/I_rr, dimensionless) lies in :func:`band`."""
    lo, hi = band()
    return ratio is not None and lo <= ratio <= hi


def _modes(diagnosis) -> dict | None:
    """The ``suspension_modes`` entry a diagnosis fitted (its summary's effect record), or None."""
    return next((e for e in diagnosis.summary()["effects"] if e.get("kind") == "suspension_modes"), None)


def whirl_ratio(diagnosis) -> float | None:
    """I_zz/I_rr of the ``suspension_modes`` a diagnosis fitted from the data, or None when it fitted none or the
    data did not locate the rocking mode (its ratio is then no reading of the whirl)."""
    ratio, located = _ratio_of(_modes(diagnosis))
    return ratio if located else None


def data_scale(test) -> dict | None:
    """The speed scale of a test sliced from a sweep with the speed from the data (``meta["slicing"]
    ["speed_scale"]``, :meth:`rwadist.speed_scale.SpeedScale.to_meta`), or None."""
    slicing = (getattr(test, "meta", None) or {}).get("slicing") or {}
    scale = slicing.get("speed_scale")
    return scale if slicing.get("speed_source") == "data" and isinstance(scale, dict) and scale.get("ratios") else None


def rescaled(test, h: float):
    """``test`` with the line at ratio ``h`` (of the current 1×) as the 1× line: every run's speed × h, the speed
    scale's ratios ÷ h and the slices' speed spreads × h (a copy; ``test`` is left alone)."""
    meta = copy.deepcopy(test.meta)
    if abs(h - 1.0) <= SAME_LINE:
        return type(test)(list(test.runs), meta)
    sl = meta["slicing"]
    sc = sl["speed_scale"]
    # the speed's sign is the 1x line's rotation sense about +z: moving the 1x to a line turning the other way turns
    # every speed round too (trial23's counter-rotating line at 0.39 taken first: the sign kept, the imbalance read
    # counter-rotating)
    sense, shares = _line_sense(sc, h)
    flip = 1.0 if sense is None or sense == sc.get("sense", 1) else -1.0
    sc["sense"] = sc.get("sense", 1) if sense is None else sense
    sc["ratios"] = sorted(round(r / h, 6) for r in sc["ratios"])
    one = sc.setdefault("one_x", {})
    others = [{"h": c["h"] / h, "multiples_found": c.get("multiples_found", [])}
              for c in one.get("candidates", []) if abs(c["h"] / h - 1.0) > SAME_LINE]
    others.append({"h": 1.0 / h, "multiples_found": one.get("multiples_found", [])})
    moved: dict = next((c for c in one.get("candidates", []) if abs(c["h"] / h - 1.0) <= SAME_LINE), {})
    one["candidates"] = others
    one["tied"] = [c for c in others if len(c["multiples_found"]) == len(moved.get("multiples_found", []))]
    one["multiples_found"] = moved.get("multiples_found", [])
    for k, pair in enumerate(("force", "torque")):      # the new 1x line's co shares (:func:`_line_sense`)
        if shares is not None and f"co_share_{pair}" in one and k < len(shares):
            one[f"co_share_{pair}"] = shares[k]
    if "order" in one and one["order"] is not None:
        one["order"] = one["order"] * h
    if "min_speed_rpm" in sl:
        sl["min_speed_rpm"] = sl["min_speed_rpm"] * h
    if "speed_spread_rpm" in sl:
        sl["speed_spread_rpm"] = [v * h for v in sl["speed_spread_rpm"]]
    return type(test)([replace(r, speed=r.speed * h * flip) for r in test.runs], meta)


def _line_sense(scale: dict, h: float) -> tuple:
    """(+1 or −1, the line's co shares) of the speed scale's line at ratio ``h``: its rotation sense about +z, as
    :func:`rwadist.speed_scale.imbalance_line` reads a 1× candidate's (:func:`rwadist.speed_scale.polarized_senses`),
    or (None, shares) when the pairs do not tell (a line turning no one way, or the pairs disagreeing: no speed is
    turned round on that)."""
    from .speed_scale import polarized_senses

    ratios = np.asarray(scale.get("ratios") or [], dtype=float)
    shares = scale.get("co_share") or []
    if ratios.size == 0 or len(shares) != ratios.size:
        return None, None
    i = int(np.argmin(np.abs(ratios - h)))
    if abs(ratios[i] / h - 1.0) > SAME_LINE:
        return None, None
    # the pairs the line was read in (a pair not recorded holds None)
    values = [np.array([float(v)]) for v in shares[i] if v is not None and np.isfinite(v)]
    sense = int(polarized_senses(values, 1)[0])
    return (sense or None), shares[i]


def _ratio_of(entry: dict | None) -> tuple:
    """(I_zz/I_rr, rocking located) of a ``suspension_modes`` record; (None, False) for no record."""
    if entry is None:
        return None, False
    return float(entry["inertia_ratio"]), "rocking" not in (entry.get("unconstrained") or ())


def check(entry: dict) -> bool:
    """``base_check`` of :func:`rwadist.diagnose.diagnose`: False when the suspension modes fitted on a speed scale
    from the data read I_zz/I_rr outside :func:`band` (the wrong line taken as 1×: stop there)."""
    return plausible(_ratio_of(entry)[0])


def settle(test, run) -> tuple:
    """(test, diagnosis) of a test after the whirl's test of a speed scale from the data (module docstring).

    Parameters
    ----------
    test : rwadist.data.SteadyTest
        The test; its ``meta["slicing"]["speed_scale"]`` (that of the test kept) gets the record ``whirl``.
    run : callable
        ``run(test, base_check) -> Diagnosis``: the diagnosis of a test (:func:`rwadist.diagnose.diagnose` with
        that ``base_check``; it raises :class:`rwadist.diagnose.search.BaseRejected` when the check fails).

    Returns
    -------
    tuple
        (test, diagnosis): the given test's, or those of the candidate scale the whirl supports.  A test whose speeds
        are not from the data is diagnosed as it is.
    """
    from .diagnose.search import BaseRejected

    scale = data_scale(test)
    if scale is None:
        return test, run(test, None)
    lo, hi = band()
    rec: dict = {"band": [lo, hi]}
    try:
        diagnosis = run(test, check)
    except BaseRejected as exc:
        rho = _ratio_of(exc.entry)[0]
    else:
        return test, _judged(test, scale, diagnosis, rec)
    # the wrong line taken as 1x: the candidates whose scale puts the ratio in the band, those with the most integer
    # multiples first (the lines' own evidence), then the nearest to the band's middle (a fitted ratio may sit at its
    # bound: trial 11's cage line with its 2x taken as 1x read 3.0 for 4.4, which put the 0.82 line (one multiple)
    # nearer than the imbalance (two))
    one = scale.get("one_x") or {}
    mid = (lo * hi) ** 0.5
    cands = [(c["h"], len(c.get("multiples_found") or ())) for c in one.get("candidates", [])
             if plausible(rho / c["h"])]
    tried = []
    for h in [h for h, _ in sorted(cands, key=lambda c: (-c[1], abs(np.log(rho / c[0] / mid))))][:MAX_TRIES]:
        t2 = rescaled(test, h)
        try:
            d2 = run(t2, check)
        except BaseRejected as exc:
            tried.append(f"h {h:.4g}: I_zz/I_rr {_ratio_of(exc.entry)[0]:.3g}")
            continue
        rho2 = whirl_ratio(d2)
        tried.append(f"h {h:.4g}: I_zz/I_rr {rho2:.3g}" if rho2 is not None else f"h {h:.4g}: rocking not located")
        if plausible(rho2):
            sc2 = t2.meta["slicing"]["speed_scale"]
            sc2["method"] = (f"{scale.get('method', 'speed from the data')}; then the 1x line moved to the line at h "
                             f"{h:.4g} of it by the gyroscopic whirl")
            sc2["whirl"] = dict(rec, status="moved", inertia_ratio=rho2, rocking_located=True,
                                rejected={"inertia_ratio": rho, "h": 1.0 / h},
                                text=(f"with the first line taken as 1x the gyroscopic whirl read I_zz/I_rr {rho:.3g}, "
                                      f"outside {lo:.2g}-{hi:.2g} (no rigid rotor exceeds 2; a flywheel is above 1); "
                                      f"with the line at h {h:.4g} of it as 1x it reads {rho2:.3g}: that line is "
                                      "the 1x line, every speed and ratio rescaled by it (ratios now "
                                      + ", ".join(f"{r:.4g}" for r in sc2.get("ratios", [])) + ")"))
            return t2, d2
    diagnosis = run(test, None)
    located = whirl_ratio(diagnosis) is not None
    # a rocking mode the fit did not locate still carries the whirl it was fitted with: said as such, not as a reading
    # (a new user's run-up: "reads I_zz/I_rr 0.145" beside "rocking at rest not located")
    reads = ("the gyroscopic whirl reads" if located else
             "the rocking mode was not located; the whirl it was fitted with gives")
    scale["whirl"] = dict(rec, status="disagrees", inertia_ratio=rho, rocking_located=located,
                          text=(f"{reads} I_zz/I_rr {rho:.3g}, outside {lo:.2g}-{hi:.2g} (no rigid "
                                "rotor exceeds 2; a flywheel is above 1)"
                                + (f"; candidate scales tried: {'; '.join(tried)}" if tried else
                                   "; no other 1x candidate brings it into the band")),
                          warning="the speed scale from the data is suspect: " + TACH_ADVICE)
    return test, diagnosis


def _judged(test, scale: dict, diagnosis, rec: dict):
    """``diagnosis``, its whirl's verdict on the speed scale (which passed :func:`check`) written to ``scale``."""
    one = scale.get("one_x") or {}
    tied = [c["h"] for c in one.get("tied", [])]
    lo, hi = band()
    rho_any, located = _ratio_of(_modes(diagnosis))
    rho = rho_any if located else None
    rec.update(inertia_ratio=rho_any, rocking_located=located)
    if plausible(rho):
        rec["status"] = "agrees"
        rec["text"] = (f"the gyroscopic whirl reads I_zz/I_rr {rho:.3g}, within {lo:.2g}-{hi:.2g} (a flywheel's "
                       f"1-2, widened by the fit's error): the 1x line stands")
    else:
        rec["status"] = "untested"
        rec["text"] = ("the wheel's rocking mode was not " + ("fitted" if rho_any is None else "located")
                       + ", so its gyroscopic whirl could not test the speed scale")
        if tied:
            rec["warning"] = tie_warning(tied)
    scale["whirl"] = rec
    return diagnosis


def tie_warning(tied: list, advice: str = TACH_ADVICE) -> str:
    """The warning of a speed scale whose 1× line tied with the lines at ratios ``tied`` (of the one taken)."""
    return ("the data cannot tell the 1x line: the line" + ("s" if len(tied) > 1 else "") + " at h "
            + ", ".join(f"{h:.4g}" for h in tied) + " of the one taken " + ("have" if len(tied) > 1 else "has")
            + " as many integer multiples, and every ratio holds at either scale (speeds and ratios off by that "
            "factor); " + advice)


def fit_tie_warning(test) -> str | None:
    """The warning :func:`rwadist.api.fit` gives for a sweep whose speed from the data tied (:func:`tie_warning`; the
    fit has no modes whose whirl could test it, diagnose has), or None."""
    scale = data_scale(test)
    tied = [c["h"] for c in ((scale or {}).get("one_x") or {}).get("tied", [])]
    return tie_warning(tied, "`rwadist diagnose` tests the scale with the wheel's gyroscopic whirl; or "
                       + TACH_ADVICE) if tied else None


def fit_whirl_warning(test, efit) -> str | None:
    """The warning :func:`rwadist.api.fit_extended` gives when a sweep's speed from the data (:func:`data_scale`) has
    the located rocking whirl read an inertia ratio outside :func:`band`: the 1× line taken is likely not the rotor's
    (a new user's ball pass at 4.7 with its 2x had been, and ``fit --extended`` printed I_zz/I_rr 0.286 as a note);
    diagnose takes the candidate that brings the ratio into the band, the fit says so.  None otherwise."""
    scale = data_scale(test)
    if not scale or not efit.identified.get("rocking", False) or plausible(efit.params.inertia_ratio):
        return None
    lo, hi = band()
    one_x = scale.get("one_x") or {}
    others = [f"{c['h']:.4g}" for c in one_x.get("candidates", [])]
    return (f"the rocking whirl reads I_zz/I_rr {efit.params.inertia_ratio:.3g}, outside {lo:.2g}-{hi:.2g} (a "
            "flywheel's 1-2, widened by the fit's error): the speed taken from the data is likely scaled by the wrong "
            "line as 1x" + (f" (other candidates at h {', '.join(others)})" if others else "")
            + "; `rwadist diagnose` tries the candidates against the whirl; or " + TACH_ADVICE)


def warn_whirl_against_scale(test, efit) -> None:
    """Warn (:class:`~rwadist.errors.RwadistWarning`, at the caller of :func:`rwadist.api.fit_extended`) with
    :func:`fit_whirl_warning`'s words, if any."""
    import warnings

    from .errors import RwadistWarning

    if text := fit_whirl_warning(test, efit):
        warnings.warn(RwadistWarning(text), stacklevel=3)


def speed_record(meta, check: dict | None = None) -> dict:
    """How the runs' speeds were obtained, for summary.json and report.md: ``source`` "measured" (a steady test's
    speeds as given), "scaled" (a steady test's speed column multiplied by the scale its imbalance's 1× lines
    give, ``check``: :func:`rwadist.speed_check.check_record`; with ``scale`` and a ``warning``), "tach" (a
    sweep's tach column) or "data" (with the speed scale of :meth:`rwadist.speed_scale.SpeedScale.to_meta`:
    method, ratios, the 1× line's evidence, agreement, the whirl's test, a warning when the speed is suspect).
    A steady test's record holds ``check`` when the 1× lines were measured, and ``runs_off`` with a ``warning``
    when single runs' speeds were taken from their own 1× lines (:func:`rwadist.speed_check.checked`; the method says
    which), ``runs_speed`` with a ``warning`` when runs' mean speeds were taken from their own 1× lines beyond their
    uncertainty or their lines are wider than a steady tone (:func:`rwadist.speed_runs.own_speeds`), ``runs_doubtful`` with a ``warning`` when a run's 1× lines read off beside a line at its given speed (its
    speed kept).  The method says so when every speed was negated (``meta["spin_reversed"]``,
    :mod:`rwadist.channel_polarity`)."""
    slicing = (meta or {}).get("slicing")
    if not isinstance(slicing, dict):
        out: dict = {"source": "measured", "method": "the runs' speeds as given (runs.csv speed_rpm)"}
        if check and check.get("scaled"):
            out = {"source": "scaled", "method": check["text"], "scale": check["scale"],
                   "agreement_rel_rms": check["agreement_rel"],
                   "warning": (f"the speed column reads {1 / check['scale']:.6g} x the rotor speed its imbalance "
                               "lines give: check the tach constant or the speed_rpm column, and the sample "
                               f"rate (a sample rate read {check['scale']:.6g} x the true one puts every frequency, "
                               "the 1x lines' too, at that factor: then the speeds as given were right and every "
                               "frequency in Hz is off)")}
        if check:
            out["check"] = check
        if check and check.get("runs_off"):
            out["runs_off"] = check["runs_off"]
            moved = ", ".join(x["run_name"] for x in check["runs_off"])
            out["method"] = (f"{out['method']}, except {'run' if len(check['runs_off']) == 1 else 'runs'} {moved}: "
                             "taken at the speed of its own 1x lines")
            out["warning"] = " ".join(filter(None, (out.get("warning"), (
                f"{check['text_runs']} (a tach glitch or a speed typed wrong in that run: check its speed_rpm)"))))
        own = (check or {}).get("runs_speed") or {}
        if own.get("runs_moved") or own.get("wander"):
            out["runs_speed"] = own
        if own.get("runs_moved"):
            out["method"] = f"{out['method']}; {own['text']}"
            out["warning"] = " ".join(filter(None, (out.get("warning"), (
                f"the speed column is off each run's rotor speed by {100 * own['rms_rel']:.3g} % RMS (its 1x lines "
                "read to a few ppm): check how speed_rpm was recorded (a set-point, or one tach reading per run)"))))
        if own.get("wander"):
            wander = own["wander"]
            out["warning"] = " ".join(filter(None, (out.get("warning"), f"{wander['text']}; {wander['action']}")))
        if own.get("runs_tracked"):
            out["method"] = f"{out['method']}; {own['wander']['action']}"
        if check and check.get("runs_doubtful"):
            out["runs_doubtful"] = check["runs_doubtful"]
            out["warning"] = " ".join(filter(None, (out.get("warning"), (
                f"{check['text_doubtful']} (check that run's speed_rpm, and what else turns on the test plate)"))))
        if (meta or {}).get("spin_reversed"):    # rwadist.channel_polarity: both pairs' 1x against the column
            out["method"] = f"{out['method']}, each multiplied by -1 (the rotor turns against the column's sign)"
        return out
    if slicing.get("speed_source") != "data":
        return {"source": "tach", "method": "each slice's mean of the sweep's speed (tach) column"}
    sc = slicing.get("speed_scale") or {}
    whirl = sc.get("whirl") or {}
    out = {"source": "data", "method": sc.get("method", "speed from the data"), "ratios": sc.get("ratios", []),
           "one_x": sc.get("one_x", {}), "agreement_rel_rms": sc.get("agreement_rel_rms"), "whirl": whirl}
    if whirl.get("warning"):
        out["warning"] = whirl["warning"]
    return out


def speed_lines(record: dict) -> list:
    """Lines of text (report.md, the console) of :func:`speed_record`'s ``record``."""
    if not record:
        return []
    if record.get("source") == "scaled":
        return [f"speed: {record.get('method')}", f"warning: {record['warning']}"]
    if record.get("source") != "data":
        check = record.get("check") or {}
        return [f"speed: {record.get('method')}"] + ([f"speed check: {check['text']}"] if check.get("text") else []) \
            + ([f"warning: {record['warning']}"] if record.get("warning") else [])
    agree = record.get("agreement_rel_rms")
    out = [str(record.get("method"))
           + (f"; ratios {', '.join(f'{h:.4g}' for h in record.get('ratios', []))}" if record.get("ratios") else "")
           + (f"; the lines agree with the speed to {100 * agree:.3f} % RMS" if agree is not None else "")]
    whirl = record.get("whirl") or {}
    if whirl.get("text"):
        out.append(f"speed check: {whirl['text']}")
    if record.get("warning"):
        out.append(f"warning: {record['warning']}")
    return out
