"""Virtual test stand: synthetic hard-mounted load-cell data from a wheel description.

A :class:`WheelDescription` holds the *truth* -- empirical harmonics (h, C) per
direction, SI (``C`` in kg·m for forces, kg·m² for torques, amplitude C·Ω² with
Ω in rad/s) -- plus the structural modes that amplify them.
:func:`simulate_steady` and :func:`simulate_sweep` turn it into the load-cell
records a hard-mounted test would give (:class:`rwadist.data.SteadyTest`,
:class:`rwadist.data.Sweep`); the CLI writes them with
:func:`rwadist.data.write_steady` / :func:`rwadist.data.write_sweep`.

Signal model (thesis Eq. 3.1, one line per harmonic i of direction d)::

    A_i = C_i Ω²,   ψ(t) = ∫ Ω dt (signed rotation angle, rad)
    radial:  Fx = Re[A_i·G̃_x·e^{j(h_i ψ + α_i)}],  Fy = Im[A_i·G̃_y·e^{j(h_i ψ + α_i)}]   (Tx, Ty alike)
    axial:   Fz = Re[A_i·G̃_z·e^{j(h_i ψ + α_i)}]                                    (Tz: axial_torque)

For positive spin this is Fx = A cos φ, Fy = A sin φ with φ = h|Ω|t + α: the
force vector turns counter-clockwise about +z.  For negative spin ψ decreases,
so Fx = A cos φ', Fy = -A sin φ' with φ' = h|Ω|t - α (the wheel turns about
-z); the random phase α is uniform, so ±α is the same distribution.  Writing it
through the signed angle keeps a sweep through zero speed continuous.  G̃_ch is
the modal gain (product over the modes acting on the channel) of the line at
its positive frequency h|Ω|/2π, conjugated when Ω < 0 (the line then sits at
negative frequency in this complex notation, where a real filter's response is
the conjugate).

Modal amplification is a simple resonance per mode (not rotor dynamics; a
later issue replaces it)::

    H(r) = (1 - r² + 2j·g·ζ·r) / (1 - r² + 2j·ζ·r),   r = f / f_mode(Ω)

with ζ the damping ratio and g the peak gain.  H → 1 for r ≪ 1 and r ≫ 1 and
|H(1)| = g: it is the transfer of a *lightly participating* mode -- the line
is measured at its true value C·Ω² away from every mode (that is what the
empirical model describes) and is amplified by g where it crosses the mode.
A plain single-degree-of-freedom transmissibility would instead roll off
above the mode and change C·Ω² everywhere, which the thesis data do not show.

The rocking mode of a spinning disc splits into forward (+) and backward (-)
whirl (thesis §2.3, §4.1.1)::

    f_±(Ω) = sqrt((a·Ω_hz/2)² + f0²) ± a·Ω_hz/2,   a = I_zz/I_rr,  Ω_hz = |Ω|/2π

A harmonic h meets it where h·Ω_hz = f_±, i.e. Ω_hz = f0 / sqrt(h (h ∓ a)):
with a = 2, f0 = 54.9 Hz this is 1902 rpm for h = 1 backward and h = 3
forward, 1165 rpm for h = 2 backward and h = 4 forward (thesis Table 3.6:
1900–2000, 1800–2000, 800–1300 and 1150–1400 rpm).

Lines at or above the Nyquist frequency are not recorded (an ideal
anti-aliasing filter, as a real acquisition has: the B wheel test filtered at
480 Hz for 1 kHz sampling).

Extended physics (``physics="extended"``, issue 3).  The wheel's own modes come from
:mod:`rwadist.extended` (rigid rotor on a flexible suspension: radial translation,
gyroscopic rocking with forward/backward whirl, axial translation) instead of the
simple resonances above.  The lines are :func:`extended_lines` of the wheel: the
static and dynamic imbalances ``U_s``, ``U_d`` of ``WheelDescription.extended``
replace the radial force/torque harmonics at h ≈ 1 (within
:data:`IMBALANCE_H_TOL`), every other harmonic keeps its C with the rotation sense
``WheelDescription.senses[(direction, h)]`` (default 'co').  Steady runs are the
closed form :func:`rwadist.extended.steady_lines` at each run speed with, per run,
a uniform random phase for each non-imbalance line and *one* random phase β
shared by the two imbalances: static at β, dynamic at β + ``imbalance_phase``
(a fixed property of the rotor), so the 1× torque/force ratio is the same in
every run.  Sweeps are :func:`rwadist.extended_time.simulate_time` (exact modal
integration, phases h·∫Ω dt, tangential imbalance force U·Ω̇, closed-form steady
state at the first sample) with one set of phases drawn per sweep.  Fixture
resonances (``test_stand_modes``, fixed frequency) act in both physics; with
extended physics they are applied as the real LTI filter H(f) they describe
(steady: × H(f_line); sweep: H(f) on the FFT of the record, circular -- away from
the record ends it matches the steady lines to ~1e-4 of the peak, the residue sitting
near Nyquist where a complex H cannot be applied to sampled data exactly).
The ``modes`` switch belongs to the simple physics (the extended model's modes are
its suspension).  Noise and the anti-aliasing rule are the same in both physics.

Randomness: one :class:`numpy.random.SeedSequence` per call spawns two
generators, one for the phases (per run, per direction, per harmonic) and one
for the sensor noise, so switching noise or modes on and off leaves the
phases unchanged -- a run with and without modes differs by the modal gain
only.
"""
from __future__ import annotations

import numpy as np

from . import extended as ext
from .data import Run, SteadyTest, Sweep
from .dft import unit_phasors
from .errors import ParameterError
from .extended_time import simulate_time
from .units import CHANNELS, DIRECTION_CHANNELS, rad_s_to_rpm, rpm_to_rad_s
from .wheel_description import Mode, WheelDescription  # noqa: F401  (the stand's inputs, defined apart: light)

#: Channel group -> direction whose fundamental sets the noise level of the group.
NOISE_REFERENCE = {"Fx": "radial_force", "Fy": "radial_force", "Fz": "radial_force",
                   "Tx": "radial_torque", "Ty": "radial_torque", "Tz": "radial_torque"}
#: Samples per block when synthesising a sweep (bounds memory of long records).
_SWEEP_BLOCK = 1 << 17
#: Physics of the virtual stand: simple resonances (issue 2) or the extended rotor model (issue 3).
PHYSICS = ("simple", "extended")
#: Radial harmonics with |h − 1| at most this are the imbalances the extended model replaces
#: (the thesis's B wheel lists its fundamental at h = 0.99).
IMBALANCE_H_TOL = ext.IMBALANCE_H_TOL


# --------------------------------------------------------------------------- synthesis

def _channel_modes(wheel: WheelDescription, modes: bool, test_stand: bool) -> dict:
    active = wheel.all_modes(modes, test_stand)
    return {ch: [m for m in active if ch in m.channels] for ch in CHANNELS}


def _noise_std(wheel: WheelDescription, omega_max: float, noise: float) -> dict:
    """Per-channel sensor noise std: noise × C_1·Ω_max² of the group's reference direction."""
    return {ch: float(noise * wheel.fundamental_C(NOISE_REFERENCE[ch]) * omega_max**2) for ch in CHANNELS}


def _add_noise(signals: dict, noise_std: dict, rng) -> None:
    """White sensor noise, std ``noise_std[ch]`` per channel, drawn in channel order (in place)."""
    for ch in CHANNELS:
        if noise_std[ch] > 0:
            signals[ch] += rng.normal(0.0, noise_std[ch], len(signals[ch]))


def _line_gain(ch_modes: list, f_line, omega):
    """Product of the gains of ``ch_modes`` for lines at f_line (Hz) at speed omega (rad/s); None if no mode."""
    g = None
    for m in ch_modes:
        gm = m.gain(f_line, omega)
        g = gm if g is None else g * gm
    return g


def _meta(wheel, sample_rate, seed, noise, modes, test_stand, noise_std, nyquist_dropped, extra) -> dict:
    meta = {
        "sample_rate_hz": float(sample_rate),
        "wheel": wheel.wheel_json(),
        "generator": "rwadist.teststand",
        "seed": int(seed) if isinstance(seed, (int, np.integer)) else repr(seed),
        "noise_relative": float(noise),
        "noise_std": noise_std,
        "modes": bool(modes),
        "test_stand": bool(test_stand),
        "active_modes": [m.to_json() for m in wheel.all_modes(modes, test_stand)],
        "truth": wheel.truth_json(),
        "truth_units": {"C": "SI per (rad/s)^2: kg*m (forces), kg*m^2 (torques)",
                        "note": "amplitude = C * omega^2 away from modes, frequency = h * |omega| / 2pi"},
        "anti_aliasing": "lines at or above Nyquist are not recorded (ideal anti-aliasing filter)",
        "lines_above_nyquist": nyquist_dropped,
        "notes": f"synthetic hard-mounted load-cell data of {wheel.name}",
    }
    meta.update(extra)
    return meta


def simulate_steady(wheel: WheelDescription, speeds_rpm, sample_rate: float = 3840.0, n_samples: int = 8192,
                    noise: float = 0.01, modes: bool = True, test_stand: bool = True, seed=0,
                    physics: str = "simple") -> SteadyTest:
    """Steady-speed runs of ``wheel`` hard-mounted on the virtual stand.

    speeds_rpm : wheel speeds, rpm (signed; negative spins about -z), one run each, in the order given.
    sample_rate : Hz.  n_samples : samples per run.
    noise : white Gaussian sensor noise std relative to the group's fundamental at the top speed,
        std = noise · C_1 · Ω_max² (Ω_max = max |speed|, rad/s; forces use the radial-force
        fundamental, torques the radial-torque one); recorded in ``meta["noise_std"]``.
    modes / test_stand : apply the wheel modes / the fixture resonances.
    seed : seed of the numpy Generator (phases and noise).
    physics : "simple" (lines × simple resonances, the default) or "extended" (closed-form response of
        :mod:`rwadist.extended` with ``wheel.extended``; see the module docstring).
    Returns a :class:`SteadyTest` with all six channels (N, N·m), runs named ``run_0000.csv``, ….
    """
    _check_physics(wheel, physics, modes)
    speeds = np.atleast_1d(np.asarray(speeds_rpm, dtype=float))
    if speeds.ndim != 1 or speeds.size == 0 or not np.all(np.isfinite(speeds)):
        raise ParameterError(f"speeds_rpm must be a non-empty 1-D list of finite speeds, got {speeds_rpm!r}")
    if not sample_rate > 0:
        raise ParameterError(f"sample_rate must be > 0 Hz, got {sample_rate!r}")
    n_samples = int(n_samples)
    if n_samples < 2:
        raise ParameterError(f"n_samples must be >= 2, got {n_samples!r}")
    omegas = rpm_to_rad_s(speeds)
    omega_max = float(np.abs(omegas).max())
    noise_std = _noise_std(wheel, omega_max, noise)
    ch_modes = _channel_modes(wheel, modes, test_stand)
    phase_rng, noise_rng = (np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(2))
    nyquist = 0.5 * sample_rate
    t = np.arange(n_samples) / sample_rate
    if physics == "extended":
        return _steady_extended(wheel, speeds, omegas, t, sample_rate, noise, test_stand, seed, noise_std,
                                phase_rng, noise_rng)
    hc = {d: wheel.h_and_C(d) for d in DIRECTION_CHANNELS}
    dropped: list[dict] = []   # lines above the Nyquist frequency left out, per run
    runs = []
    for k, omega in enumerate(omegas):
        signals = {ch: np.zeros(n_samples) for ch in CHANNELS}
        for d, chans in DIRECTION_CHANNELS.items():
            h, C = hc[d]
            if h.size == 0:
                continue
            alpha = phase_rng.uniform(0.0, 2.0 * np.pi, size=h.size)  # drawn even if lines are dropped
            f_line = h * abs(omega) / (2.0 * np.pi)
            keep = f_line < nyquist
            if not keep.all():
                dropped.extend({"speed_rpm": float(speeds[k]), "direction": d, "h": float(x)} for x in h[~keep])
            if not keep.any() or omega == 0.0:
                continue
            amp = (C * omega**2)[keep]
            # exp(j(h ψ + α)), ψ = Ω t: (n_lines × n_samples) complex, e^{jhΩt} as a product of two small tables of
            # exponentials (rwadist.dft.unit_phasors: the same numbers to rounding, 5x faster than one exp per sample)
            carrier = unit_phasors(-h[keep] * omega / (2.0 * np.pi), 1.0 / sample_rate, t.size) \
                * np.exp(1j * alpha[keep])[:, None]
            for i, ch in enumerate(chans):
                g = _line_gain(ch_modes[ch], f_line[keep], omega)
                c = amp if g is None else amp * (g if omega > 0 else np.conj(g))
                z = c @ carrier
                # radial: x = Re, y = Im (vector turning with the wheel); axial: Re
                signals[ch] += z.imag if i == 1 else z.real
        _add_noise(signals, noise_std, noise_rng)
        runs.append(Run(speed=float(omega), sample_rate=float(sample_rate), signals=signals, t0=0.0,
                        name=f"run_{k:04d}.csv"))
    meta = _meta(wheel, sample_rate, seed, noise, modes, test_stand, noise_std, dropped,
                 {"kind": "steady", "n_samples": n_samples, "physics": "simple"})
    return SteadyTest(runs=runs, meta=meta)


# --------------------------------------------------------------------------- extended physics

def _check_physics(wheel: WheelDescription, physics: str, modes: bool):
    if physics not in PHYSICS:
        raise ParameterError(f"physics must be one of {PHYSICS}, got {physics!r}")
    if physics == "extended":
        if wheel.extended is None:
            raise ParameterError(f"wheel {wheel.name!r} has no extended parameters (WheelDescription.extended); "
                             "physics='extended' needs them")
        if not modes:
            raise ParameterError("modes=False applies to physics='simple' only: with physics='extended' the wheel's "
                             "modes are its suspension (ExtendedParams)")


def _fixture_modes(wheel: WheelDescription, test_stand: bool) -> list:
    """Active fixture resonances (fixed frequency: they are real LTI filters)."""
    out = list(wheel.test_stand_modes) if test_stand else []
    for m in out:
        if m.whirl != 0:
            raise ParameterError(f"test-stand mode {m.name!r} has whirl {m.whirl}; fixture resonances must be "
                             "fixed-frequency (whirl 0)")
    return out


def _fixture_gain(fixture: list, f_hz) -> np.ndarray:
    """(…, 6) complex gain of the fixture resonances at f_hz (Hz, >= 0) on each channel."""
    f = np.asarray(f_hz, dtype=float)
    g = np.ones(f.shape + (len(CHANNELS),), dtype=complex)
    for m in fixture:
        r = m.response(f / m.f0_hz)
        for i, ch in enumerate(CHANNELS):
            if ch in m.channels:
                g[..., i] *= r
    return g


def _extended_phases(wheel: WheelDescription, lines: list, rng) -> np.ndarray:
    """Per-line phases: β (static imbalance), β + imbalance_phase (dynamic), uniform for the others.
    Draw order: β first, then one per non-imbalance line in line order."""
    beta = rng.uniform(0.0, 2.0 * np.pi)
    n_other = sum(1 for ln in lines if not ln.imbalance)
    others = iter(rng.uniform(0.0, 2.0 * np.pi, size=n_other))
    out = []
    for ln in lines:
        if not ln.imbalance:
            out.append(next(others))
        elif ln.direction == "radial_force":
            out.append(beta)
        else:
            out.append(beta + wheel.imbalance_phase)
    return np.array(out, dtype=float)


def _with_phases(lines: list, phases) -> list:
    return [ext.Line(ln.direction, ln.h, ln.C, ln.sense, float(p), ln.angle, ln.imbalance)
            for ln, p in zip(lines, phases)]


def _extended_meta(wheel: WheelDescription, lines: list) -> dict:
    if wheel.extended is None:
        raise ValueError(f"{wheel.name}: the extended physics' meta of a wheel without an extended model")
    return {"physics": "extended",
            "extended": ext.params_to_dict(wheel.extended),
            "imbalance_phase_rad": float(wheel.imbalance_phase),
            "lines": [{"direction": ln.direction, "h": ln.h, "C": ln.C, "sense": ln.sense,
                       "imbalance": ln.imbalance} for ln in lines],
            "extended_note": "wheel modes from rwadist.extended (ExtendedParams); imbalances U_s, U_d replace the "
                             "radial h~1 harmonics; static imbalance at a random phase per run, dynamic at "
                             "that phase + imbalance_phase_rad"}


def _steady_extended(wheel, speeds, omegas, t, sample_rate, noise, test_stand, seed, noise_std, phase_rng,
                     noise_rng) -> SteadyTest:
    base = wheel.extended_lines()
    fixture = _fixture_modes(wheel, test_stand)
    nyquist = 0.5 * sample_rate
    n_samples = t.size
    dropped: list[dict] = []   # lines above the Nyquist frequency left out, per run
    runs = []
    for k, omega in enumerate(omegas):
        lines = _with_phases(base, _extended_phases(wheel, base, phase_rng))
        f, A = ext.steady_lines(wheel.extended, lines, [omega])
        f, A = f[0], A[0]                                    # (n_lines,), (n_lines, 6)
        keep = f < nyquist
        dropped.extend({"speed_rpm": float(speeds[k]), "direction": ln.direction, "h": ln.h}
                       for ln, kp in zip(lines, keep) if not kp)
        if fixture:
            A = A * _fixture_gain(fixture, f)
        A = A[keep]
        z = A.T @ unit_phasors(-f[keep], 1.0 / sample_rate, t.size)   # (6, n_samples): Σ A e^{2πj f t}
        signals = {ch: z[i].real.copy() for i, ch in enumerate(CHANNELS)}
        _add_noise(signals, noise_std, noise_rng)
        runs.append(Run(speed=float(omega), sample_rate=float(sample_rate), signals=signals, t0=0.0,
                        name=f"run_{k:04d}.csv"))
    meta = _meta(wheel, sample_rate, seed, noise, True, test_stand, noise_std, dropped,
                 {"kind": "steady", "n_samples": n_samples, **_extended_meta(wheel, base)})
    meta["active_modes"] = [m.to_json() for m in fixture]
    return SteadyTest(runs=runs, meta=meta)


def _sweep_extended(wheel, t, omega, sample_rate, test_stand, phase_rng) -> tuple:
    """(signals dict, dropped lines, base lines) of an extended-physics sweep without noise."""
    p = wheel.extended
    base = wheel.extended_lines()
    lines = _with_phases(base, _extended_phases(wheel, base, phase_rng))
    nyquist = 0.5 * sample_rate
    w_abs = np.abs(omega)
    w_max = float(w_abs.max())
    below = [ln for ln in lines if ln.h * w_max / (2.0 * np.pi) < nyquist]
    above = [ln for ln in lines if ln.h * w_max / (2.0 * np.pi) >= nyquist]
    out = np.zeros((t.size, len(CHANNELS)))
    if below:
        out += simulate_time(p, below, t, omega, start="steady")
    dropped = []
    for ln in above:
        # superposition: a line reaching Nyquist runs alone and is not recorded while at or above it
        dropped.append({"direction": ln.direction, "h": ln.h,
                        "above_rpm": float(rad_s_to_rpm(2.0 * np.pi * nyquist / ln.h))})
        x = simulate_time(p, [ln], t, omega, start="steady")
        x[ln.h * w_abs / (2.0 * np.pi) >= nyquist] = 0.0
        out += x
    fixture = _fixture_modes(wheel, test_stand)
    if fixture:
        # the fixture resonances are real LTI filters: exact H(f) on the record's spectrum (circular).
        # An odd FFT length (one zero appended when needed) has no Nyquist bin, where a complex H
        # cannot be applied to a real signal.
        m = t.size + (1 - t.size % 2)
        f = np.fft.rfftfreq(m, 1.0 / sample_rate)
        X = np.fft.rfft(out, n=m, axis=0) * _fixture_gain(fixture, f)
        out = np.fft.irfft(X, n=m, axis=0)[: t.size]
    return {ch: out[:, i].copy() for i, ch in enumerate(CHANNELS)}, dropped, base


def speed_profile(t, rpm_start: float, rpm_end: float, duration: float, profile="linear"):
    """Wheel speed Ω(t) in rad/s of a sweep.

    "linear": constant acceleration rpm_start -> rpm_end over ``duration`` (s).
    "exp": Ω = Ω_end + (Ω_start - Ω_end)·exp(-t/τ), τ = duration/5 -- full motor voltage with the
        torque falling with back-EMF, saturating like the thesis E-wheel spin-up (with rpm_start = 0
        this is Ω_end·(1 - exp(-t/τ)); it reaches 99.3 % of Ω_end at t = duration).
    callable: profile(t) -> rpm, any custom profile.
    """
    t = np.asarray(t, dtype=float)
    w0, w1 = float(rpm_to_rad_s(rpm_start)), float(rpm_to_rad_s(rpm_end))
    if callable(profile):
        return rpm_to_rad_s(np.broadcast_to(np.asarray(profile(t), dtype=float), t.shape))
    if profile == "linear":
        return w0 + (w1 - w0) * (t / duration)
    if profile == "exp":
        tau = duration / 5.0
        return w1 + (w0 - w1) * np.exp(-t / tau)
    raise ParameterError(f"unknown sweep profile {profile!r}; expected 'linear', 'exp' or a callable t -> rpm")


def _cumtrapz(y: np.ndarray, dt: float) -> np.ndarray:
    """Cumulative trapezoid integral of uniformly sampled y, starting at 0."""
    out = np.empty_like(y)
    out[0] = 0.0
    np.cumsum(0.5 * dt * (y[1:] + y[:-1]), out=out[1:])
    return out


def simulate_sweep(wheel: WheelDescription, rpm_start: float = 0.0, rpm_end: float = 2400.0,
                   duration: float = 390.0, sample_rate: float = 3840.0, noise: float = 0.01, modes: bool = True,
                   test_stand: bool = True, seed=0, profile="linear", tach: bool = True,
                   physics: str = "simple") -> Sweep:
    """A continuous record through a speed change (spin-up or run-down).

    rpm_start, rpm_end : speeds (rpm, signed); duration : s; sample_rate : Hz.
    profile : "linear", "exp" or a callable t (s) -> rpm (see :func:`speed_profile`).
    Each line's phase is h_i·ψ(t) + α_i with ψ = ∫Ω dt (cumulative trapezoid of the speed profile,
    not Ω(t)·t), its amplitude C_i·Ω(t)².  Modal gain is applied *quasi-steadily*: each sample's
    line is multiplied by the gain at its instantaneous frequency h_i|Ω(t)|/2π and speed Ω(t), as if
    the wheel dwelt there -- valid while the line crosses a mode slowly compared with the mode's
    build-up time 1/(ζ·2π·f_mode) (the thesis spin-ups take minutes); transient ringing is not modelled.
    noise : relative sensor noise, std = noise · C_1 · Ω_max², Ω_max the sweep's largest |Ω|.
    tach : store Ω(t) (rad/s) in ``Sweep.tach``; else None.
    Lines are built one harmonic at a time (memory ~ a few arrays of the record length).
    physics : "simple" (above, the default) or "extended": :func:`rwadist.extended_time.simulate_time` of
        ``wheel.extended`` (exact modal integration incl. transients and the tangential imbalance force,
        started in the closed-form steady state at the first sample; one phase per line per sweep,
        imbalances β and β + imbalance_phase); |dΩ/dt| must stay below
        :data:`rwadist.extended.DEFAULT_MAX_ACCEL`.
    """
    _check_physics(wheel, physics, modes)
    if not duration > 0:
        raise ParameterError(f"duration must be > 0 s, got {duration!r}")
    if not sample_rate > 0:
        raise ParameterError(f"sample_rate must be > 0 Hz, got {sample_rate!r}")
    n = int(round(duration * sample_rate))
    if n < 2:
        raise ParameterError(f"duration × sample_rate gives {n} samples; need at least 2")
    dt = 1.0 / sample_rate
    t = np.arange(n) * dt
    omega = speed_profile(t, rpm_start, rpm_end, duration, profile)
    psi = _cumtrapz(omega, dt)                          # signed rotation angle, rad
    omega_max = float(np.abs(omega).max())
    noise_std = _noise_std(wheel, omega_max, noise)
    ch_modes = _channel_modes(wheel, modes, test_stand)
    active = wheel.all_modes(modes, test_stand)
    phase_rng, noise_rng = (np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(2))
    nyquist = 0.5 * sample_rate
    extra = {"kind": "sweep", "profile": profile if isinstance(profile, str) else "custom",
             "rpm_start": float(rpm_start), "rpm_end": float(rpm_end), "duration_s": float(duration)}
    if profile == "exp":
        extra["tau_s"] = duration / 5.0
    if physics == "extended":
        signals, dropped, base = _sweep_extended(wheel, t, omega, sample_rate, test_stand, phase_rng)
        _add_noise(signals, noise_std, noise_rng)
        extra.update(_extended_meta(wheel, base))
        extra["modal_gain"] = ("exact modal integration (rwadist.extended_time.simulate_time, start: steady state); "
                               "fixture resonances as LTI filters (FFT, circular)")
        meta = _meta(wheel, sample_rate, seed, noise, True, test_stand, noise_std, dropped, extra)
        meta["active_modes"] = [m.to_json() for m in _fixture_modes(wheel, test_stand)]
        return Sweep(time=t, signals=signals, sample_rate=float(sample_rate), tach=omega if tach else None,
                     meta=meta)
    lines, dropped = _sweep_lines(wheel, phase_rng, omega_max, nyquist)
    signals = _sweep_simple_signals(omega, psi, lines, active, ch_modes, nyquist)
    _add_noise(signals, noise_std, noise_rng)
    extra["modal_gain"] = "quasi-steady (gain at the instantaneous line frequency and speed)"
    extra["physics"] = "simple"
    meta = _meta(wheel, sample_rate, seed, noise, modes, test_stand, noise_std, dropped, extra)
    return Sweep(time=t, signals=signals, sample_rate=float(sample_rate), tach=omega if tach else None, meta=meta)


def _sweep_lines(wheel: WheelDescription, phase_rng, omega_max: float, nyquist: float) -> tuple[list, list]:
    """The harmonics of a simple-physics sweep, direction by direction: (channels, h, C, phase α rad) each, the
    phases drawn from ``phase_rng`` in that order, and the entries of those whose frequency rises above
    ``nyquist`` (Hz) at the sweep's largest speed ``omega_max`` (rad/s) (meta ``dropped_lines``)."""
    dropped: list[dict] = []
    lines = []                                          # (channels, h, C, alpha) per harmonic
    for d, chans in DIRECTION_CHANNELS.items():
        h_arr, C_arr = wheel.h_and_C(d)
        if h_arr.size == 0:
            continue
        alpha = phase_rng.uniform(0.0, 2.0 * np.pi, size=h_arr.size)
        for h, C, a in zip(h_arr, C_arr, alpha):
            f_top = h * omega_max / (2.0 * np.pi)
            if f_top >= nyquist:
                dropped.append({"direction": d, "h": float(h),
                                "above_rpm": float(rad_s_to_rpm(2.0 * np.pi * nyquist / h))})
            lines.append((chans, float(h), float(C), float(a)))
    return lines, dropped


def _sweep_simple_signals(omega: np.ndarray, psi: np.ndarray, lines: list, active: list, ch_modes: dict,
                          nyquist: float) -> dict:
    """The six channels of a simple-physics sweep (noise-free): every line of :func:`_sweep_lines` at speed
    ``omega`` (rad/s) and rotation angle ``psi`` (rad) per sample, C·Ω² with phase h·ψ + α, left out above
    ``nyquist`` (Hz), through the channels' modes (``ch_modes``, of ``active``) at each sample's frequency
    (quasi-steady)."""
    n = omega.size
    w_abs = np.abs(omega)
    negative = omega < 0
    signals = {ch: np.zeros(n) for ch in CHANNELS}
    # Blocks of samples bound the temporaries (a 390 s record at 3840 Hz is 1.5 M samples);
    # within a block, one harmonic at a time.
    for start in range(0, n, _SWEEP_BLOCK):
        sl = slice(start, min(start + _SWEEP_BLOCK, n))
        w_b, psi_b, neg_b = omega[sl], psi[sl], negative[sl]
        wa_b = w_abs[sl]
        amp_scale = w_b * w_b
        fm_b = {id(m): m.frequency_hz(wa_b) for m in active}
        for chans, h, C, a in lines:
            f_line = (h / (2.0 * np.pi)) * wa_b
            recorded = f_line < nyquist
            if not recorded.any():
                continue
            z0 = (C * amp_scale) * np.exp(1j * (h * psi_b + a))
            if not recorded.all():
                z0[~recorded] = 0.0
            gains = {}                              # the x and y channels of a pair often share their modes
            for i, ch in enumerate(chans):
                z = z0
                if ch_modes[ch]:
                    key = tuple(id(m) for m in ch_modes[ch])
                    if key not in gains:
                        g = np.ones(len(w_b), dtype=complex)
                        for m in ch_modes[ch]:
                            g *= m.response(f_line / fm_b[id(m)])
                        np.conjugate(g, out=g, where=neg_b)
                        gains[key] = g
                    z = z0 * gains[key]
                signals[ch][sl] += z.imag if i == 1 else z.real
    return signals

