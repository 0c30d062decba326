"""Diagnose what a wheel model leaves out of measured data, name the effect, add it (issue 7).

:func:`diagnose` starts from a model (the empirical fit of the data, or a given
model file / preset), predicts the expected Welch PSD of every run and channel,
and looks at the residual on the speed × frequency plane.  A library of effect
classes, each a small dataclass, proposes hypotheses from the residual, fits
them on half of the speeds and is ranked on the other half (the overfitting
warning of Wilson & Mah 2003: the data that choose an effect must not also
judge it).  Greedy: the hypothesis explaining the most held-out residual is
added when it passes the statistical rule below, everything is recomputed,
and the search repeats until nothing passes.

Predicted PSD of channel c at speed Ω (unit²/Hz on the spectra's grid)::

    S(f, Ω) = N_c(f) + B_c(f, Ω) + Σ_lines  (a_i(Ω)²/2) · K(f − h_i|Ω|/2π)

* K is the Hann-window line kernel of the Welch estimate, |W(δ)|²/(f_s Σw²),
  evaluated at the exact fractional bin offset δ: a line predicted this way
  has the shape of a measured one (not a single bin, as
  :func:`rwadist.compare.model_psd_on_grid`, which is exact only for the line's
  area), and its area is a²/2 (Parseval).
* a_i(Ω) = C_i Ω² for the model's harmonics, or A_ref (|Ω|/Ω_ref)^p after an
  ``amplitude_law`` effect.  A radial harmonic appears with amplitude a in both
  x and y channels of its direction (the test-stand convention).  This is the
  *empirical base* (``base="empirical"``, the default of :func:`diagnose`).
* *Extended base* (``base="extended"``, or ``"auto"`` with a model that has an
  ``analytical`` section; ``rwadist diagnose --preset/--model`` picks it by
  default): the lines are those of :func:`rwadist.extended.lines_from_model`
  (the imbalances U_s, U_d of the analytical section replace the co-rotating
  radial fundamentals; every other harmonic with its rotation ``sense``), and
  a line's amplitude in channel c is |A_c| of
  :func:`rwadist.extended.steady_lines` at each run speed: modal amplification
  by the suspension (radial translation, rocking with gyroscopic forward and
  backward whirl, axial translation), the sense deciding which whirl a radial
  line meets, the lever arm ``height``.  Lines of one h acting on one channel
  add in power (independent phases: the expected PSD; the fixed imbalance
  phase between U_s and U_d, not in the model file, matters only when
  height ≠ 0).  Every effect composes as on the empirical base: an amplitude
  law replaces the line's free load C·Ω² (:attr:`rwadist.extended.Line.law`);
  a missing harmonic is a wheel disturbance and goes through the modes
  (co-rotating, the model file's default; its C is fitted on the measured
  amplitude divided by the co-rotating modal gain); fixed resonances multiply
  the modal amplitude; sidebands and ripple components take the carrier's
  modal gain (the modes' variation over ±f_mod neglected); coupling as before.
  The modal gain g = a_channel / a_free of each line (:meth:`Context.channel_lines`)
  is divided out wherever a free load is measured (:func:`_measure`).
* N_c(f) is the instrument noise: the median over runs of
  :func:`rwadist.empirical.block_floor` (speed independent by assumption).
* B_c is the wheel's broadband floor (zero until a ``broadband_floor`` effect
  is added).
* a line's amplitude is multiplied by |H(f)| of every ``fixed_resonance``
  acting on the channel; after a ``cross_coupling`` effect the torque data are
  read corrected for the load-cell offset (T − r × F, Welch PSD recomputed).
* a ``sidebands`` effect adds to its carrier two lines at f_i ± f_mod of
  amplitude m·a_i/2; a ``speed_ripple`` replaces every line (sidebands
  included) by lines at f + k·f_ripple of mean squares (a²/2)·|c_k|²
  (:func:`ripple_sideband_powers`); all through the same kernel K, each
  component with the resonance gain at its own frequency.  Components of one
  line are coherent; their Welch cross terms are neglected (they are ≥ 2.5
  bins apart, where the Hann kernels barely overlap, and their relative phase
  turns between Welch segments).

Error metric (``waterfall_unexplained_fraction``): the speed × frequency plane
of each channel is cut into bands of :data:`BAND_BINS` bins over
[f_lo, band limit]; with D the data power and M the model power in a band and
σ the band's noise standard deviation were the model right
(:meth:`Context.band_sigma`),

    E = Σ_{channel, run, band} max(|D − M| − 2σ, 0) / Σ_{channel, run, band} D,

each channel's powers divided by the mean data power of its unit group (forces
or torques), so the two groups weigh alike and a quiet channel weighs little.
It is the fraction of the measured power the model misplaces (too much or
too little, in the wrong band) beyond what the Welch estimate's own noise
explains; without the 2σ allowance a broadband floor's random fluctuation
would count as model error forever.  ``error_before`` is E of the starting
model, ``error_after`` of the final one, both over all runs.  The RMS-vs-speed
error ``rms_relative_error`` (mean over channels and runs of
|σ_model − σ_data|/σ_data with σ the band RMS) is reported next to it.

Acceptance rule of a hypothesis fitted on the fit runs (every other speed)
and judged on the held-out runs (:func:`_judge`): the drop G of misplaced
power on the held-out runs must exceed ``k_sigma`` (default 4) noise standard
errors of that drop (computed from σ and the change of the model, as if the
data were the old model plus Gaussian noise) *and* be at least ``min_gain``
(default 5 %) of the held-out misplaced power (an effect must matter, not
just be detectable: the models' own small imperfections, e.g. kernel
truncation, are not noise and pass any pure significance test).

Effect classes (``kind`` in the model file's ``effects`` list and in
``summary.json``):

``missing_harmonic``  (:class:`MissingHarmonic`) a line at h·|Ω| (any h > 0,
    sub-harmonics below 1 and non-integer ratios included) absent from the
    model.  Signature: a ridge of positive residual along f = h|Ω|/2π.  Fit: h
    refined on the ridge, C by thesis Eq. 3.10.  Added as a real harmonic in
    ``model.empirical`` (it flows into ``rwadist psd``) and recorded as an effect.
``amplitude_law``  (:class:`AmplitudeLaw`) a model harmonic whose amplitude
    goes as Ω^p with p ≠ 2.  Signature: residual along an existing harmonic
    that changes sign with speed.  Fit: log-amplitude vs log-speed least
    squares.  Parameters: direction, h, exponent, amplitude_ref (N or N·m) at
    omega_ref (rad/s).  (The lead's brief called this kind
    ``amplitude_exponent``; the issue's ``amplitude_law`` is used.)
``broadband_floor``  (:class:`BroadbandFloor`) a noise-like floor of one channel
    that grows with speed, S(f, Ω) = S_ref(f)·(|Ω|/Ω_ref)^p.  Signature: the
    off-line floor rising with speed.  Fit: per frequency, N + G·(Ω/Ω_ref)^p by
    linear least squares on the per-run floors, p on a grid.  Parameters:
    channel, exponent, omega_ref_rad_s, f_Hz and psd_ref (unit²/Hz) knots.

``fixed_resonance``  (:class:`FixedResonance`) amplification of the passing
    lines around a frequency f_r that does not move with speed, the simple
    resonance H(r) = (1 − r² + 2j·g·ζ·r)/(1 − r² + 2j·ζ·r), r = f/f_r
    (:meth:`rwadist.teststand.Mode.response`) multiplying every line of its
    channels.  Signature: the lines' measured/predicted power ratio peaking at
    one frequency whatever the harmonic and speed.  Fit: f_r, ζ, g by robust
    nonlinear least squares of ln|H|² on those log ratios (lines that beat with
    a neighbour within 2·LINE_HALF bins left out), re-measured with the
    tentative resonance in place.  Two hypotheses compete on held-out speeds:
    one common to every channel, ``role`` = ``test_stand`` (a fixture
    resonance: to be excluded from the wheel's model), and one per direction,
    ``role`` = ``wheel_mode`` (an unmodelled wheel mode: to be added).
    Parameters: f_Hz, zeta, peak_gain (|H| at f_r), role, directions.
``cross_coupling``  (:class:`CrossCoupling`) a load-cell offset: the torque
    channels carry r × F of the force channels, T_measured = T + r × F (r in m,
    wheel frame).  Signature: torque content at the force lines' frequencies,
    coherent with the forces.  Fit: r by weighted linear least squares on the
    complex line amplitudes of forces and torques at the model's force-line
    frequencies (needs the time series: ``diagnose(..., test=...)``; without
    them the class is not tried).  Parameters: r_m, r_stderr_m.  Applied as a
    calibration of the measurement: the torque data are corrected, so the
    metric after it is that of the corrected data.

``sidebands``  (:class:`Sidebands`) amplitude modulation of one model line at
    a FIXED frequency f_mod (Hz; a cage or electronics frequency):
    a(Ω)(1 + m cos 2πf_mod t)·cos(2πf_i t + φ) is the carrier plus two lines
    at f_i ± f_mod of amplitude m·a/2 each (depth m the same at every speed).
    A modulation at a frequency proportional to speed would put the sidebands
    at harmonics h ± h_m, which ``missing_harmonic`` already takes; only the
    fixed-frequency case is built.  Signature: a pair of residual ridges
    parallel to a model harmonic at a constant offset ±f_mod on the speed ×
    frequency plane (:func:`_offset_scores`, offsets 2.5 bins to 50 Hz).  Fit:
    f_mod from the refined residual peaks on both sides (median), m² by linear
    least squares of the sideband window powers on (a/2)²/2 over every
    speed.  One (h, f_mod, m) explains both sides at all speeds, so it beats
    a missing harmonic, whose straight ridge h|Ω| crosses the offset ridge at
    one speed only.  Parameters: direction, h, f_mod_Hz, depth.
``speed_ripple``  (:class:`SpeedRipple`) a periodic wheel-speed ripple
    Ω(t) = Ω0 + ΔΩ sin 2πf_r t at a fixed f_r (Hz: a speed-loop limit cycle, a
    torque disturbance at a fixed frequency).  The rotation angle is
    ψ = Ω0 t − (ΔΩ/2πf_r) cos 2πf_r t, so the line h is phase modulated with
    index β_h = h·ΔΩ/(2π f_r) (ΔΩ rad/s, f_r Hz) and, its amplitude following
    the instantaneous speed (a ∝ |Ω(t)|^p, p = 2 or the line's amplitude-law
    exponent), amplitude modulated with ε = ΔΩ/|Ω0|: lines at f_i + k f_r of
    power fraction |c_k|² (:func:`ripple_sideband_powers`; J_k(β)² when
    ε = 0, Σ = 1 by Parseval; the amplitude term is kept, it is first order
    in ε like the phase term and makes the sidebands asymmetric, upper ε + β/2,
    lower β/2 − ε for p = 2).  Neglected: the imbalance's tangential force
    ∝ dΩ/dt (relative size ΔΩ·2πf_r/Ω0²) and the resonance gain's variation
    with the instantaneous speed.  ΔΩ is absolute (rad/s), not a fraction:
    a torque ripple T at a fixed frequency gives ΔΩ = T/(I_zz 2πf_r) whatever
    the speed; the fraction law ΔΩ = ε·|Ω| is fitted too (``speed_exponent``
    q = 1 of ΔΩ = ΔΩ_ref (|Ω|/Ω_ref)^q) and the two compete on held-out
    speeds (β_h constant vs growing with speed).  Signature: sideband pairs at
    the same offset ±f_r around every line of every channel, deeper with h
    (β ∝ h) - unlike ``sidebands``, one depth for one line.  Fit: f_r by the
    refined peaks pooled over all lines, ΔΩ_ref by a robust (soft-L1) fit of
    the log first-order sideband powers above 5σ (grid, then a bounded
    minimisation).  Parameters: f_ripple_Hz, delta_omega_rad_s,
    omega_ref_rad_s, speed_exponent, ripple_frac_at_ref.

``counter_rotation``  (:class:`CounterRotation`, extended base only) counter-
    rotating content of a radial harmonic (support anisotropy, planar loads):
    F = a₊e^{+ihφ} + a₋e^{−ihφ} with counter fraction q = |a₋|²/(|a₊|² + |a₋|²),
    the total free power C²Ω⁴ kept.  Hard mounted the senses have the same PSD;
    through the modes the co part meets the forward whirl, the counter part the
    backward one.  Signature: residual power in a radial line where |G₋| ≠ |G₊|,
    chiefly at its backward-whirl crossing (and x/y asymmetry: the co/counter
    cross term, random per run, cancels in x + y only).  Fit: q by weighted
    least squares of the log x + y line power on P_o + P₊ + q(P₋ − P₊);
    with the time series (``test=``) a second estimate from the x/y phase
    (co |X + iY|², counter |X − iY|², each divided by its modal gain),
    reported as ``counter_fraction_phase``.  Recorded in the model as a co
    harmonic C·sqrt(1 − q) and a counter harmonic C·sqrt(q) at the same h (the
    imbalance's co part scales U_s or U_d in ``analytical``), which
    :func:`rwadist.extended.lines_from_model` reads.  Radial-force lines are not
    proposed (the translation mode has no gyroscopic split: no PSD signature).
    Parameters: direction, h, counter_fraction, counter_fraction_stderr,
    counter_fraction_phase.

``spin_acceleration``  (:class:`SpinAcceleration`) the wheel accelerating
    during each run: quasi-steady slices of a spin-up or run-down (``rwadist
    fit/diagnose`` on a sweep CSV) see each line sweep h|α|T/2π Hz in a run of
    length T.  Signature: lines broader than the window's kernel, the more the
    higher h, on every channel.  Prediction: each line spread over that range
    (:meth:`Context.smear_offsets`: points ≤ ½ bin apart, weighted by the Welch
    segments' squared windows and the instantaneous power (Ω(τ)/Ω)⁴).  Fit: |α|
    by a bounded 1-D minimisation of the fit runs' misplaced power (5-8 % low
    on fast sweeps: the smear model is the spectrogram approximation, slightly
    over-broadened, see the code); the noise floor re-estimated with the
    smeared lines masked.  Tried only on runs that
    are slices of one sweep (distinct start times, ``test=`` given); the speed
    track |ΔΩ/Δt0| is the independent estimate ``alpha_track_rad_s2``.  A
    measurement artefact (``role`` = ``measurement``): not a disturbance, so
    ``rwadist psd``, the FMU and coupling ignore it (the FMU takes the wheel's
    acceleration as an input; its tangential imbalance force is in the extended
    model).  Parameters: alpha_rad_s2, alpha_track_rad_s2, role.
"""
from __future__ import annotations

import copy
from dataclasses import dataclass, field, replace

import numpy as np
from scipy import stats

from .empirical import block_floor, fit_empirical
from .model import Harmonic, WheelModel
from .spectra import Spectra, welch_dof
from .units import CHANNEL_DIRECTION, CHANNEL_UNIT, CHANNELS, DIRECTION_CHANNELS, RAD_S_TO_RPM

#: Torque channels, in the order of the components of r × F.
TORQUE_CHANNELS = ("Tx", "Ty", "Tz")

#: Bins per band of the error metric.
BAND_BINS = 8
#: Lowest frequency used, in bins (as the empirical fit's f_min_bins).
F_MIN_BINS = 4
#: Half width (bins) of a line's window when measuring its power.
LINE_HALF = 3
#: Half width (bins) of the line kernel used in predictions.
KERNEL_HALF = 16
#: Exponent grid of the broadband-floor fit (PSD ∝ |Ω|^p).
FLOOR_EXPONENTS = np.arange(0.5, 8.01, 0.25)
METRIC = "waterfall_unexplained_fraction"
#: Line-to-noise power ratio above which a line's log gain gets full weight in a resonance fit.
SNR_KNEE = 10.0
#: Noise standard deviations forgiven per band by the error metric.
NOISE_Z = 2.0


# --------------------------------------------------------------------------- line kernel

def line_kernel(nperseg: int, fs: float, window: str = "hann", half: int = KERNEL_HALF, oversample: int = 64):
    """Tabulated PSD shape of a unit-variance sinusoid in a Welch estimate, 1/Hz.

    Returns (delta, K): K(δ) = |W(δ)|²/(f_s Σw²) at offsets δ (bins) from −half−1
    to half+1 in steps of 1/oversample; Σ_k K(δ+k)·df = 1 over all integer k (Parseval).
    """
    from scipy import signal

    w = signal.get_window(window, nperseg)
    n = np.arange(nperseg)
    delta = np.arange(-(half + 1) * oversample, (half + 1) * oversample + 1) / oversample
    W = np.exp(-2j * np.pi * np.outer(delta, n) / nperseg) @ w
    return delta, np.abs(W) ** 2 / (fs * np.sum(w**2))


# --------------------------------------------------------------------------- state

@dataclass
class State:
    """What the model predicts: harmonics, their amplitude laws, noise and broadband floors.

    model : WheelModel (harmonics in ``empirical``).  laws : (direction, h) -> (amp_ref, omega_ref, p).
    noise : channel -> N_c(f), unit²/Hz.  floors : channel -> (psd_ref(f) unit²/Hz, omega_ref rad/s, p).
    resonances : (f_r Hz, ζ, g, channels) fixed-frequency resonances multiplying the lines of their channels.
    coupling : load-cell offset r (m, 3-vector) of a ``cross_coupling`` effect, or None: the torque data are
        then read corrected, T − r × F (:meth:`Context.data`).
    sidebands : (direction, h, f_mod Hz, depth m) of ``sidebands`` effects: the line h of that direction
        carries two more lines at h|Ω|/2π ± f_mod of amplitude m·a/2.
    ripple : (ΔΩ_ref rad/s, f_ripple Hz, Ω_ref rad/s, q) of a ``speed_ripple`` effect, or None: every line
        is spread over f_i + k·f_ripple with the powers of :func:`ripple_sideband_powers`.
    smear : |dΩ/dt| (rad/s²) of a ``spin_acceleration`` effect, or None: every line of a run is spread
        uniformly over the frequencies its harmonic sweeps during the run (:meth:`Context.smear_offsets`).
    effects : effect objects added so far.
    """

    model: WheelModel
    noise: dict
    laws: dict = field(default_factory=dict)
    floors: dict = field(default_factory=dict)
    effects: list = field(default_factory=list)
    resonances: list = field(default_factory=list)
    coupling: tuple | None = None
    sidebands: list = field(default_factory=list)
    ripple: tuple | None = None
    ext: object = None
    _cache: dict = field(default_factory=dict, repr=False, compare=False)
    smear: float | None = None

    def copy(self) -> "State":
        return State(copy.deepcopy(self.model), self.noise, dict(self.laws), dict(self.floors), list(self.effects),
                     list(self.resonances), self.coupling, list(self.sidebands), self.ripple, self.ext,
                     smear=self.smear)

    @property
    def base(self) -> str:
        """'extended' when the lines go through the rotor's suspension modes (``ext`` set), else 'empirical'."""
        return "empirical" if self.ext is None else "extended"

    def ext_lines(self) -> list:
        """The :class:`rwadist.extended.Line` objects of the extended base: :func:`rwadist.extended.lines_from_model`
        of the model (imbalances from ``ext``, senses from the harmonics) with the state's amplitude laws attached
        (same direction, |Δh| < LAW_H_TOL)."""
        from . import extended as ext

        out = ext.lines_from_model(self.model, self.ext, effects=False)
        if self.laws:
            laws = [(d, h, law) for (d, h), law in self.laws.items()]
            out = [replace(ln, law=next((lw for d, h, lw in laws if d == ln.direction and abs(h - ln.h) < ext.LAW_H_TOL),
                                        None)) for ln in out]
        return out

    def line_components(self, channel: str, h: float):
        """(frequency shift Hz, relative amplitude) of the line h of ``channel``: the carrier (0, 1) and the
        pairs (±f_mod, m/2) of its ``sidebands`` effects."""
        d = CHANNEL_DIRECTION[channel]
        out = [(0.0, 1.0)]
        for dd, hh, f_m, m in self.sidebands:
            if dd == d and abs(hh - h) < 1e-4:
                out += [(f_m, 0.5 * m), (-f_m, 0.5 * m)]
        return out

    def lines(self, channel: str):
        """(h, amplitude function of omega) for every harmonic acting on ``channel``."""
        d = CHANNEL_DIRECTION[channel]
        out = []
        for hm in self.model.harmonics(d):
            law = self.laws.get((d, round(hm.h, 4)))
            out.append((hm.h, hm.C, law))
        return out


class Context:
    """Spectra, kernel, bands and run split shared by every step of a diagnosis.

    test : the SteadyTest the spectra were computed from (same runs, same order), or None; the time
    series are needed by the ``cross_coupling`` effect only (complex line amplitudes, corrected PSDs)."""

    def __init__(self, spectra: Spectra, channels=None, test=None):
        self.sp = spectra
        if test is not None and (len(test.runs) != len(spectra.speed) or not np.allclose(
                [r.speed for r in test.runs], spectra.speed)):
            raise ValueError("diagnose: the test's runs are not those of the spectra (count or speeds differ)")
        self.test = test
        self._memo = {}
        self._corrected = {}
        self.f = spectra.f
        self.df = spectra.df
        self.omega = np.abs(np.asarray(spectra.speed, dtype=float))
        self.runs = np.nonzero(self.omega > 0)[0]
        order = self.runs[np.argsort(self.omega[self.runs], kind="stable")]
        self.fit_runs, self.held_runs = np.sort(order[0::2]), np.sort(order[1::2])
        self.channels = tuple(c for c in (channels or spectra.channels) if c in spectra.psd
                              and c in CHANNEL_DIRECTION)
        self.dof = welch_dof(int(np.min(spectra.n_segments)))
        self.k_lo = F_MIN_BINS
        self.k_hi = int(np.floor(spectra.band_limit / self.df))
        self.n_bands = max((self.k_hi - self.k_lo + 1) // BAND_BINS, 1)
        self.delta, self.kernel = line_kernel(spectra.nperseg, spectra.sample_rate, spectra.window)
        self.osmp = int(round(1 / (self.delta[1] - self.delta[0])))
        self.floor = {c: self._floor(c) for c in self.channels}
        power = {c: float(np.nanmean(self.band_sums(self.sp.psd[c][self.runs]).sum(1))) for c in self.channels}
        # forces are weighed against forces, torques against torques (mean data power of the unit group)
        self._scale = {c: float(np.mean([power[k] for k in self.channels if CHANNEL_UNIT[k] == CHANNEL_UNIT[c]]))
                       for c in self.channels}

    def data(self, state: State, c: str) -> np.ndarray:
        """Measured PSD (n_runs, n_f) of channel ``c`` as the state reads it: a torque channel corrected for
        the state's load-cell offset, T − r × F, its Welch PSD recomputed with the spectra's settings."""
        if state.coupling is None or c not in TORQUE_CHANNELS:
            return self.sp.psd[c]
        key = tuple(float(x) for x in state.coupling)
        if key not in self._corrected:
            from .spectra import compute_spectra

            test = copy.deepcopy(self.test)
            r = np.asarray(key)
            for run in test.runs:
                F = np.column_stack([run.signals[k] for k in ("Fx", "Fy", "Fz")])
                T = np.cross(r[None, :], F)
                for j, k in enumerate(TORQUE_CHANNELS):
                    if k in run.signals:
                        run.signals[k] = run.signals[k] - T[:, j]
            chans = [k for k in TORQUE_CHANNELS if k in self.sp.psd]
            sp = compute_spectra(test, nperseg=self.sp.nperseg, window=self.sp.window, f_lim=self.sp.f_lim,
                                 channels=chans)
            if not np.array_equal(sp.n_segments, self.sp.n_segments):
                raise ValueError("diagnose: the spectra were not computed with 50 % overlap; cannot correct them")
            self._corrected[key] = sp.psd
        return self._corrected[key][c]

    def phasors(self, runs: np.ndarray, f_hz: np.ndarray) -> np.ndarray:
        """Complex amplitudes (len(runs), L, 6) of every channel at frequencies ``f_hz`` (len(runs), L), Hz:
        X = 2·Σ w x e^{−2πj f t}/Σ w over the whole run (Hann window), so x(t) ≈ Re(X e^{2πj f t});
        NaN for a channel the run lacks."""
        from scipy import signal

        out = np.full((runs.size, f_hz.shape[1], len(CHANNELS)), np.nan + 0j)
        for i, r in enumerate(runs):                      # one matrix product per run
            run = self.test.runs[r]
            t = np.arange(run.n_samples) / run.sample_rate
            w = signal.get_window(self.sp.window, run.n_samples)
            have = [j for j, c in enumerate(CHANNELS) if c in run.signals]
            x = np.column_stack([run.signals[CHANNELS[j]] for j in have]) * w[:, None]
            E = np.exp(-2j * np.pi * np.outer(f_hz[i], t))
            out[i][:, have] = 2.0 * (E @ x) / np.sum(w)
        return out

    def _floor(self, c):
        psd = self.sp.psd[c]
        fl = np.full_like(psd, np.nan)
        ok = np.isfinite(psd[:, 0])
        fl[ok] = block_floor(psd[ok], dof=self.dof)
        return fl

    def omega_ref(self) -> float:
        return float(np.median(self.omega[self.runs]))

    # ---- predictions
    def line_psd(self, h: float, amp: np.ndarray, runs: np.ndarray) -> np.ndarray:
        """PSD (len(runs), n_f) of one line h at amplitudes ``amp`` (per run)."""
        return self.psd_at(h * self.omega[runs] / (2 * np.pi), amp**2 / 2.0)

    def psd_at(self, f_hz: np.ndarray, power: np.ndarray) -> np.ndarray:
        """PSD (n_runs, n_f) of lines at frequencies ``f_hz`` (n_runs,) or (n_runs, n) Hz with mean squares
        ``power`` (same shape, unit²) through the line kernel; a line at negative frequency (a lower
        sideband below 0 Hz) folds to |f|."""
        f_hz = np.asarray(f_hz, dtype=float)
        power = np.broadcast_to(np.asarray(power, dtype=float), f_hz.shape)
        if f_hz.ndim == 1:
            f_hz, power = f_hz[:, None], power[:, None]
        n_runs, n_l = f_hz.shape
        out = np.zeros((n_runs, self.f.size))
        pos = (np.abs(f_hz) / self.df).ravel()                           # fractional bin
        k0 = np.rint(pos).astype(int)
        offs = np.arange(-KERNEL_HALF, KERNEL_HALF + 1)
        k = k0[:, None] + offs
        dlt = k - pos[:, None]                                         # bin minus line, bins
        idx = np.clip(np.rint((dlt - self.delta[0]) * self.osmp).astype(int), 0, self.delta.size - 1)
        val = power.ravel()[:, None] * self.kernel[idx]
        ok = (k >= 0) & (k < self.f.size)
        rows = np.broadcast_to(np.repeat(np.arange(n_runs), n_l)[:, None], k.shape)
        np.add.at(out, (rows[ok], k[ok]), val[ok])
        return out

    def ripple_powers(self, state: State, h: float, law, runs: np.ndarray):
        """(k, P) of the state's speed ripple for a line h: sideband orders k (2K+1,) and their power
        fractions P (len(runs), 2K+1) (:func:`ripple_sideband_powers`), or None without a ripple."""
        if state.ripple is None:
            return None
        d_ref, f_r, w_ref, q = state.ripple
        w = self.omega[runs]
        dw = d_ref * (w / w_ref) ** q
        p_amp = 2.0 if law is None else law[2]
        return ripple_sideband_powers(h * dw / (2 * np.pi * f_r), dw / np.maximum(w, 1e-12), p_amp)

    def gain(self, state: State, c: str, f_hz) -> np.ndarray:
        """|H| of the state's fixed resonances acting on channel ``c`` at line frequencies ``f_hz`` (Hz)."""
        g = np.ones_like(np.asarray(f_hz, dtype=float))
        for f_r, zeta, peak, chans in state.resonances:
            if c in chans:
                g = g * np.abs(resonance(f_hz, f_r, zeta, peak))
        return g

    def channel_lines(self, state: State, c: str, runs: np.ndarray) -> list:
        """[(h, law, a, g)] of every line acting on channel ``c``: harmonic number, amplitude law or None, the
        line's amplitude a (unit, one per run of ``runs``, before the fixed resonances) and its modal gain g = a / the
        free load amplitude of the channel's direction at h.

        Empirical base: the state's harmonics, a = C·Ω² (or the law), g = 1.  Extended base (``state.ext`` set):
        the lines of :meth:`State.ext_lines` through :func:`rwadist.extended.steady_lines` (suspension modes,
        gyroscopic whirl, rotation sense, lever arm), lines of one h acting on the channel merged into one entry
        of power Σ|A|²/2 (independent phases: the expected power; a co/counter pair of one h has a cross term
        of zero mean that cancels between x and y).  Cached on the state per set of runs."""
        if state.ext is None:
            return [(h, law, self.amplitude(C, law, runs), np.ones(runs.size)) for h, C, law in state.lines(c)]
        key = ("lines", runs.tobytes())
        if key not in state._cache:
            state._cache[key] = self._ext_lines(state, runs)
        return state._cache[key].get(c, [])

    def _ext_lines(self, state: State, runs: np.ndarray) -> dict:
        from . import extended as ext

        lines = state.ext_lines()
        w = self.omega[runs]
        out = {c: [] for c in self.channels}
        if not lines:
            return out
        _, A = ext.steady_lines(state.ext, lines, w)                  # (S, L, 6)
        P = np.abs(A) ** 2                                             # 2 × mean square
        hs = np.array([ln.h for ln in lines])
        free = np.array([ln.amplitude(w) for ln in lines]).T           # (S, L) load amplitudes
        groups = []
        for j in np.argsort(hs, kind="stable"):
            if groups and abs(hs[j] - hs[groups[-1][0]]) < ext.LAW_H_TOL:
                groups[-1].append(j)
            else:
                groups.append([j])
        for c in self.channels:
            k = CHANNELS.index(c)
            d = CHANNEL_DIRECTION[c]
            for g in groups:
                p = P[:, g, k].sum(1)
                if not np.any(p > 0):
                    continue
                own = [j for j in g if lines[j].direction == d]
                a_free = np.sqrt(np.sum(free[:, own] ** 2, axis=1)) if own else np.zeros(w.size)
                a = np.sqrt(p)
                gain = np.where(a_free > 0, a / np.where(a_free > 0, a_free, 1.0), 1.0)
                j0 = own[0] if own else g[0]
                out[c].append((float(lines[j0].h), lines[j0].law, a, gain))
        return out

    def unit_gain(self, state: State, c: str, direction: str, h: float, sense: str, runs: np.ndarray) -> np.ndarray:
        """|amplitude in channel ``c``| per unit load amplitude of a line (direction, h, sense) through the state's
        suspension modes (:func:`rwadist.extended.steady_lines`), per run; ones on the empirical base."""
        if state.ext is None:
            return np.ones(runs.size)
        from . import extended as ext

        w = self.omega[runs]
        _, A = ext.steady_lines(state.ext, [ext.Line(direction, float(h), 1.0, sense)], w)
        return np.abs(A[:, 0, CHANNELS.index(c)]) / np.maximum(w**2, 1e-300)

    def modal_gain(self, state: State, c: str, h: float, runs: np.ndarray) -> np.ndarray:
        """Modal gain g of the line h of channel ``c`` (:meth:`channel_lines`); for a line the state lacks, that
        of a co-rotating line of the channel's direction (a wheel disturbance goes through the modes)."""
        if state.ext is None:
            return np.ones(runs.size)
        from . import extended as ext

        for hh, _, _, g in self.channel_lines(state, c, runs):
            if abs(hh - h) < ext.LAW_H_TOL:
                return g
        return self.unit_gain(state, c, CHANNEL_DIRECTION[c], h, "co", runs)

    def amplitude(self, C, law, runs):
        w = self.omega[runs]
        if law is None:
            return C * w**2
        a_ref, w_ref, p = law
        return a_ref * (w / w_ref) ** p

    def floor_psd(self, state: State, c: str, runs: np.ndarray) -> np.ndarray:
        out = np.broadcast_to(state.noise[c], (runs.size, self.f.size)).copy()
        if c in state.floors:
            ref, w_ref, p = state.floors[c]
            out += ref[None, :] * (self.omega[runs][:, None] / w_ref) ** p
        return out

    def predict(self, state: State, c: str, runs: np.ndarray, skip=None) -> np.ndarray:
        """Expected PSD of channel ``c`` on ``runs``; ``skip`` = h of a line to leave out (with its
        sidebands).  A line's components (carrier and ``sidebands``, :meth:`State.line_components`) are
        each multiplied by the resonance gain at their own frequency and, under a ``speed_ripple``,
        spread over f + k·f_ripple with the power fractions of :meth:`ripple_powers`."""
        out = self.floor_psd(state, c, runs)
        for h, law, amp, _ in self.channel_lines(state, c, runs):
            if skip is not None and abs(h - skip) < 1e-9:
                continue
            f0 = h * self.omega[runs] / (2 * np.pi)
            rip = self.ripple_powers(state, h, law, runs)
            for shift, rel in state.line_components(c, h):
                f = f0 + shift
                a = amp * rel
                if state.resonances:
                    a = a * self.gain(state, c, f)
                if state.smear is not None:
                    du, wt = self.smear_offsets(state, h, runs)
                    out += self.psd_at(f[:, None] + du, (a**2 / 2.0)[:, None] * wt)
                elif rip is None:
                    out += self.psd_at(f, a**2 / 2.0)
                else:
                    k, P = rip
                    out += self.psd_at(f[:, None] + k[None, :] * state.ripple[1], (a**2 / 2.0)[:, None] * P)
        return out

    def run_durations(self, runs: np.ndarray) -> np.ndarray:
        """Length of each run's record, s: from the time series when known, else from the Welch
        segments (50 % overlap: (n_segments + 1)·nperseg/2 samples)."""
        if self.test is not None:
            return np.array([self.test.runs[r].n_samples / self.test.runs[r].sample_rate for r in runs])
        n = np.asarray(self.sp.n_segments, dtype=float)[runs]
        return (n + 1.0) * self.sp.nperseg / 2.0 / self.sp.sample_rate

    def smear_offsets(self, state: State, h: float, runs: np.ndarray, n_max: int = 48):
        """(offsets Hz, weights) (len(runs), 3M) of a line h smeared by the state's spin acceleration:
        during a run of length T at mean speed Ω the line sweeps f ± h|α|T/(4π); M points spaced at most
        half a bin cover that range, each weighted by the instantaneous power (Ω(τ)/Ω)⁴ (a C·Ω² line) and
        by how much its part of the record weighs in the Welch estimate (:meth:`_welch_weights`), each
        point split in three across a segment's own sweep (see the comment in the code)."""
        alpha = float(state.smear)
        T = self.run_durations(runs)
        width = h * alpha * T / (2 * np.pi)                                  # Hz swept during the run
        m = int(np.clip(np.ceil(2.0 * np.max(width) / self.df) + 1, 1, n_max))
        u = (np.arange(m) + 0.5) / m - 0.5                                     # −½ … ½
        du = width[:, None] * u[None, :]
        w = np.maximum(np.abs(self.omega[runs]), 1e-12)
        amp = (1.0 + alpha * T[:, None] * u[None, :] / w[:, None]) ** 4
        n_samp = np.rint(T * self.sp.sample_rate).astype(int)
        prof = np.array([self._welch_weights(int(n), m) for n in n_samp])
        # within one Welch segment the line still sweeps h|α|L/(2π f_s) Hz and a chirp's windowed spectrum
        # is broader than the average of instantaneous kernels: each point is spread over ±⅓ of that
        # width as well.  Partly double counted (the record-level spread already holds the segments'
        # chirp), so a fitted |α| comes out some 5-8 % low on fast sweeps -- without it the residual
        # skirts of high harmonics invite a spurious broadband floor.
        seg = h * alpha * self.sp.nperseg / self.sp.sample_rate / (2 * np.pi)
        v = np.array([-1.0, 0.0, 1.0]) / 3.0
        du = (du[:, :, None] + seg * v[None, None, :]).reshape(du.shape[0], -1)
        wt = np.repeat(amp * prof, v.size, axis=1) / v.size
        return du, wt

    def _welch_weights(self, n: int, m: int) -> np.ndarray:
        """How much each of m equal parts of an n-sample record weighs in its Welch PSD (sum 1): Σ over
        the segments (50 % overlap) of the squared window falling in the part."""
        key = ("welch_w", n, m)
        if key not in self._memo:
            from scipy import signal

            L = self.sp.nperseg
            w2 = signal.get_window(self.sp.window, L) ** 2
            acc = np.zeros(n)
            for s0 in range(0, n - L + 1, L // 2):
                acc[s0:s0 + L] += w2
            edges = np.rint(np.linspace(0, n, m + 1)).astype(int)
            part = np.add.reduceat(acc, edges[:-1]) if n >= m else np.full(m, acc.sum() / m)
            self._memo[key] = part / part.sum()
        return self._memo[key]

    def band_centres(self) -> np.ndarray:
        return self.f[self.k_lo + BAND_BINS * np.arange(self.n_bands) + BAND_BINS // 2] - 0.5 * self.df

    def offline_bands(self, state: State, c: str, runs: np.ndarray):
        """Mean PSD of the data less the model's lines (their kernel skirts) per band, over the bins away
        from every line (model lines ±LINE_HALF bins and residual peaks above a 1e-4 false-alarm
        threshold ±2 bins): (value unit²/Hz, bins used) per run and band."""
        from scipy import stats

        P = self.predict(state, c, runs)
        D = self.data(state, c)[runs] - (P - self.floor_psd(state, c, runs))     # data less the model's lines
        mask = np.zeros(D.shape, bool)
        offs = np.arange(-LINE_HALF, LINE_HALF + 1)
        rows = np.arange(runs.size)[:, None]
        for h, _, _, _ in self.channel_lines(state, c, runs):
            k = np.clip(np.rint(h * self.omega[runs] / (2 * np.pi) / self.df).astype(int)[:, None] + offs,
                        0, self.f.size - 1)
            mask[rows, k] = True
            if state.smear is not None:     # the whole range a smeared line sweeps, ±LINE_HALF bins
                half = h * state.smear * self.run_durations(runs) / (4 * np.pi) / self.df + LINE_HALF
                kc = h * self.omega[runs] / (2 * np.pi) / self.df
                kk = np.arange(self.f.size)[None, :]
                mask |= (kk >= (kc - half)[:, None]) & (kk <= (kc + half)[:, None])
        if state.sidebands or state.ripple is not None:
            # the model's sideband and ripple lines too, where their power is above a tenth of the noise
            # power in their window
            noise = self.floor_psd(state, c, runs)
            for h, law, amp, _ in self.channel_lines(state, c, runs):
                f0 = h * self.omega[runs] / (2 * np.pi)
                rip = self.ripple_powers(state, h, law, runs) or (np.zeros(1), np.ones((runs.size, 1)))
                for shift, rel in state.line_components(c, h):
                    for j, kk in enumerate(rip[0]):
                        if shift == 0.0 and kk == 0:
                            continue
                        f = np.abs(f0 + shift + kk * (state.ripple[1] if state.ripple else 0.0))
                        k = np.clip(np.rint(f / self.df).astype(int)[:, None] + offs, 0, self.f.size - 1)
                        pw = (amp * rel) ** 2 / 2 * rip[1][:, j]
                        big = pw > 0.1 * noise[rows, k].sum(1) * self.df
                        mask[rows, k] |= big[:, None]
        z = D / np.maximum(self.floor[c][runs], 1e-300) - 1.0     # against the run's own block floor
        thr = stats.chi2.isf(1e-4, self.dof) / self.dof - 1.0
        peak = z > thr
        for j in (-2, -1, 1, 2):
            peak |= np.roll(z > thr, j, axis=1)
        mask |= peak
        lo, n = self.k_lo, self.n_bands * BAND_BINS
        keep = ~mask[:, lo:lo + n].reshape(runs.size, self.n_bands, BAND_BINS)
        vals = D[:, lo:lo + n].reshape(runs.size, self.n_bands, BAND_BINS)
        cnt = keep.sum(-1)
        mean = np.where(cnt > 0, (vals * keep).sum(-1) / np.maximum(cnt, 1), 0.0)
        return mean, cnt.astype(float)

    # ---- metric
    def band_sums(self, x: np.ndarray) -> np.ndarray:
        lo = self.k_lo
        n = self.n_bands * BAND_BINS
        return x[:, lo:lo + n].reshape(x.shape[0], self.n_bands, BAND_BINS).sum(-1) * self.df

    def band_sigma(self, state: State, c: str, runs: np.ndarray, floor=None, lines=None) -> np.ndarray:
        """Noise standard deviation (unit²) of the data power in every band if the model were right.

        A Welch PSD bin of noise N plus a deterministic line L has variance (N² + 2·L·N)·2/ν
        (ν = Welch degrees of freedom; the second term is the line × noise cross term); bins
        are summed as if independent and the result doubled for the Hann correlation of
        neighbouring bins (an approximation, stated)."""
        N = self.floor_psd(state, c, runs) if floor is None else floor
        L = (self.predict(state, c, runs) - N) if lines is None else lines
        var_bin = (N**2 + 2.0 * np.maximum(L, 0.0) * N) * 2.0 / self.dof
        return np.sqrt(2.0 * self.band_sums(var_bin) * self.df)

    def run_errors(self, state: State, runs: np.ndarray, channels=None, detail: bool = False):
        """Per run: (E_num, D_tot) summed over channels and bands, E_num = Σ max(|D − M| − 2σ, 0)
        (the misplaced power beyond two noise standard deviations), each channel divided by the mean
        data power of its unit group so forces and torques weigh alike.  ``detail``: also the per-band
        (channel -> (D − M, σ)) arrays (the residual: an effect may change the model M or, a measurement
        correction, the data D as the state reads them)."""
        err = np.zeros(runs.size)
        tot = np.zeros(runs.size)
        parts = {}
        for c in channels or self.channels:
            Dfull = self.data(state, c)[runs]
            ok = np.isfinite(Dfull[:, 0])
            D = self.band_sums(Dfull)
            N = self.floor_psd(state, c, runs)
            Mfull = self.predict(state, c, runs)
            M = self.band_sums(Mfull)
            sig = self.band_sigma(state, c, runs, N, Mfull - N)
            scale = self.scale(c)
            e = np.maximum(np.abs(D - M) - NOISE_Z * sig, 0.0)
            err[ok] += e[ok].sum(1) / scale
            tot[ok] += D[ok].sum(1) / scale
            parts[c] = ((D - M) / scale, sig / scale)
        return (err, tot, parts) if detail else (err, tot)

    def scale(self, c):
        return self._scale[c]

    def error(self, state: State, runs=None) -> float:
        e, t = self.run_errors(state, self.runs if runs is None else runs)
        return float(e.sum() / t.sum())

    def rms_error(self, state: State) -> float:
        vals = []
        for c in self.channels:
            D = self.band_sums(self.data(state, c)[self.runs]).sum(1)
            M = self.band_sums(self.predict(state, c, self.runs)).sum(1)
            vals.append(np.abs(np.sqrt(M) - np.sqrt(D)) / np.sqrt(D))
        return float(np.nanmean(np.concatenate(vals)))

    def measure_line(self, state: State, c: str, h: float, runs: np.ndarray, skip=None):
        """Amplitude (unit) of a line h in the data of ``runs`` less everything else the state
        predicts (other lines, floors); NaN where the line is out of band or not above noise."""
        R = self.data(state, c)[runs] - self.predict(state, c, runs, skip=skip)
        pos = h * self.omega[runs] / (2 * np.pi) / self.df
        k0 = np.rint(pos).astype(int)
        offs = np.arange(-LINE_HALF, LINE_HALF + 1)
        inband = (k0 - LINE_HALF >= self.k_lo) & (k0 + LINE_HALF <= self.k_hi)
        k = np.clip(k0[:, None] + offs, 0, self.f.size - 1)
        p = np.take_along_axis(R, k, axis=1).sum(1) * self.df
        noise = np.take_along_axis(self.floor_psd(state, c, runs), k, axis=1).sum(1) * self.df
        # 3 standard deviations of the window's noise power: std of a bin mean·sqrt(2/ν), summed
        # over the window's bins with a factor 2 for the Hann correlation of neighbouring bins
        sig = 3.0 * 2.0 * noise * np.sqrt(2.0 / self.dof) / np.sqrt(2 * LINE_HALF + 1)
        amp = np.where(inband & (p > sig), np.sqrt(2 * np.maximum(p, 0)), np.nan)
        return amp


# --------------------------------------------------------------------------- effect classes

@dataclass
class MissingHarmonic:
    """A line at h·|Ω| the model lacks; amplitude C·Ω² (C in SI per (rad/s)²)."""

    direction: str
    h: float
    C: float
    n_points: int = 0
    kind: str = "missing_harmonic"

    @property
    def channels(self):
        return DIRECTION_CHANNELS[self.direction]

    def apply(self, state: State) -> State:
        s = state.copy()
        s.model.empirical[self.direction] = sorted(
            s.model.harmonics(self.direction) + [Harmonic(h=round(self.h, 4), C=self.C, n_points=self.n_points)],
            key=lambda x: x.h)
        s.effects.append(self)
        return s

    def params(self) -> dict:
        return {"direction": self.direction, "h": round(self.h, 4), "C": self.C}

    @staticmethod
    def fit(ctx: Context, state: State, direction: str, h: float, runs) -> "MissingHarmonic | None":
        d, w = _measure(ctx, state, direction, h, runs)
        if d.size < 3:
            return None
        C = float(np.sum(d * w**2) / np.sum(w**4))                      # thesis Eq. 3.10
        return MissingHarmonic(direction, float(h), C, int(d.size))

    @staticmethod
    def candidates(ctx: Context, state: State, runs, max_per_direction: int = 3) -> list:
        out = []
        for d, chans in DIRECTION_CHANNELS.items():
            chans = [c for c in chans if c in ctx.channels]
            if not chans:
                continue
            for h in ridge_peaks(ctx, state, chans, runs, max_per_direction):
                if any(abs(h - x.h) < 0.03 for x in state.model.harmonics(d)):
                    continue
                h = refine_h(ctx, state, chans, runs, h)
                if any(abs(h - x.h) < 0.03 for x in state.model.harmonics(d)) or \
                        any(abs(h - x.h) < 0.005 for x in out if x.direction == d):
                    continue
                e = MissingHarmonic.fit(ctx, state, d, h, runs)
                if e is not None and e.C > 0:
                    out.append(e)
        return out


@dataclass
class AmplitudeLaw:
    """A model harmonic whose amplitude is A_ref·(|Ω|/Ω_ref)^p (A_ref N or N·m, Ω_ref rad/s)."""

    direction: str
    h: float
    exponent: float
    amplitude_ref: float
    omega_ref: float
    exponent_stderr: float = float("nan")
    kind: str = "amplitude_law"

    @property
    def channels(self):
        return DIRECTION_CHANNELS[self.direction]

    def apply(self, state: State) -> State:
        s = state.copy()
        s.laws[(self.direction, round(self.h, 4))] = (self.amplitude_ref, self.omega_ref, self.exponent)
        s.effects.append(self)
        return s

    def params(self) -> dict:
        return {"direction": self.direction, "h": round(self.h, 4), "exponent": self.exponent,
                "exponent_stderr": self.exponent_stderr, "amplitude_ref": self.amplitude_ref,
                "omega_ref_rad_s": self.omega_ref}

    @staticmethod
    def fit(ctx: Context, state: State, direction: str, h: float, runs) -> "AmplitudeLaw | None":
        d, w = _measure(ctx, state, direction, h, runs, skip=h)
        if d.size < 5 or np.ptp(np.log(w)) < 0.3:
            return None
        w_ref = ctx.omega_ref()
        X = np.column_stack([np.ones(w.size), np.log(w / w_ref)])
        coef, res, *_ = np.linalg.lstsq(X, np.log(d), rcond=None)
        r = np.log(d) - X @ coef
        s2 = float(r @ r) / max(d.size - 2, 1)
        cov = s2 * np.linalg.inv(X.T @ X)
        if state.ext is not None and coef[1] < 0:
            return None         # rwadist.extended.Line takes laws of exponent >= 0 only (extended base)
        return AmplitudeLaw(direction, float(h), float(coef[1]), float(np.exp(coef[0])), w_ref,
                            float(np.sqrt(cov[1, 1])))

    @staticmethod
    def candidates(ctx: Context, state: State, runs) -> list:
        out = []
        for d in DIRECTION_CHANNELS:
            if not any(c in ctx.channels for c in DIRECTION_CHANNELS[d]):
                continue
            for hm in state.model.harmonics(d):
                if (d, round(hm.h, 4)) in state.laws:
                    continue
                e = AmplitudeLaw.fit(ctx, state, d, hm.h, runs)
                if e is not None:
                    out.append(e)
        return out


@dataclass
class BroadbandFloor:
    """A broadband floor of one channel: S(f, Ω) = psd_ref(f)·(|Ω|/Ω_ref)^p, unit²/Hz."""

    channel: str
    exponent: float
    omega_ref: float
    f_hz: np.ndarray
    psd_ref: np.ndarray
    noise: np.ndarray
    kind: str = "broadband_floor"
    #: the knots written to the model file (band centres with flat ends over the analysed band): psd_ref is
    #: exactly their linear interpolation (0 outside), so the file reproduces the fitted floor
    knots_f: np.ndarray | None = None
    knots_psd: np.ndarray | None = None

    @property
    def channels(self):
        return (self.channel,)

    def apply(self, state: State) -> State:
        s = state.copy()
        s.noise = dict(s.noise)
        s.noise[self.channel] = self.noise
        s.floors[self.channel] = (self.psd_ref, self.omega_ref, self.exponent)
        s.effects.append(self)
        return s

    def params(self) -> dict:
        kf = self.f_hz[::BAND_BINS] if self.knots_f is None else self.knots_f
        kp = self.psd_ref[::BAND_BINS] if self.knots_psd is None else self.knots_psd
        return {"channel": self.channel, "exponent": self.exponent, "omega_ref_rad_s": self.omega_ref,
                "psd_law": "psd_ref(f) * (|omega|/omega_ref)^exponent, linear between knots, 0 outside",
                "unit": f"{CHANNEL_UNIT[self.channel]}^2/Hz",
                "f_Hz": [float(x) for x in kf],
                "psd_ref": [float(x) for x in kp]}

    @staticmethod
    def fit(ctx: Context, state: State, c: str, runs) -> "BroadbandFloor | None":
        y, wt = ctx.offline_bands(state, c, runs)                       # (n_runs, n_bands) unit²/Hz
        if not np.isfinite(ctx.sp.psd[c][runs, 0]).all() or wt.sum(0).min() < 0:
            return None
        w_ref = ctx.omega_ref()
        x0 = ctx.omega[runs] / w_ref
        level = np.maximum(np.sum(wt * y, 0) / np.maximum(wt.sum(0), 1e-300), 1e-300)
        expected = np.broadcast_to(level, y.shape)
        for _ in range(3):
            # weights: bins used / expected value² (a band mean of chi² bins has variance ∝ mean²/bins),
            # re-estimated from the previous pass (iteratively reweighted least squares)
            # (relative to the largest level, floored at 1e-12 of it: squares of tiny PSDs underflow, and a
            # band 12 decades down carries no information worth an astronomically large weight)
            wts = wt / np.maximum(expected / float(np.max(level)), 1e-12) ** 2
            best = None
            for p in FLOOR_EXPONENTS:
                x = x0[:, None] ** p
                # weighted 2-parameter least squares per band: y = n + g·x
                s0, s1, s2 = wts.sum(0), (wts * x).sum(0), (wts * x * x).sum(0)
                t0, t1 = (wts * y).sum(0), (wts * x * y).sum(0)
                det = s0 * s2 - s1 * s1
                with np.errstate(divide="ignore", invalid="ignore"):
                    g = np.maximum(np.where(det > 0, (s0 * t1 - s1 * t0) / det, 0.0), 0.0)
                n = np.where(s0 > 0, np.maximum((t0 - g * s1) / np.maximum(s0, 1e-300), 0.0), 0.0)
                sse = float(np.sum(wts * (y - n - g * x) ** 2))
                if best is None or sse < best[0]:
                    best = (sse, p, n, g)
            _, p, n, g = best
            expected = np.maximum(n[None, :] + g[None, :] * x0[:, None] ** p, 1e-300)
        _, p, n, g = best
        f = ctx.f
        # knots: the band centres, held flat out to the analysed band's first and last bins (a floor below
        # the first centre -- energy below 1x -- is there in the data too)
        kf = np.concatenate([[f[ctx.k_lo]], ctx.band_centres(), [f[ctx.k_lo + ctx.n_bands * BAND_BINS - 1]]])
        kg, kn = np.concatenate([[g[0]], g, [g[-1]]]), np.concatenate([[n[0]], n, [n[-1]]])
        n0 = np.array(state.noise[c], dtype=float)
        band = (f >= kf[0]) & (f <= kf[-1])
        n0[band] = np.interp(f[band], kf, kn)
        ref = np.interp(f, kf, kg, left=0.0, right=0.0)
        return BroadbandFloor(c, float(p), w_ref, f.copy(), ref, n0, knots_f=kf, knots_psd=kg)

    @staticmethod
    def candidates(ctx: Context, state: State, runs) -> list:
        out = []
        for c in ctx.channels:
            if c in state.floors:
                continue
            e = BroadbandFloor.fit(ctx, state, c, runs)
            if e is not None and e.psd_ref.max() > 0:
                out.append(e)
        return out


def resonance(f_hz, f_r: float, zeta: float, peak_gain: float):
    """Complex gain H(r) = (1 − r² + 2j·g·ζ·r)/(1 − r² + 2j·ζ·r), r = f/f_r, of a simple resonance at f_r (Hz)
    with damping ratio ζ and |H(1)| = g (:meth:`rwadist.teststand.Mode.response`); H → 1 far from f_r."""
    r = np.abs(np.asarray(f_hz, dtype=float)) / f_r
    base = 1.0 - r * r
    two_zr = 2.0 * zeta * r
    return (base + 1j * peak_gain * two_zr) / (base + 1j * two_zr)


def _line_gain_points(ctx, state, chans, runs):
    """(f Hz, y, weight) of every model line of ``chans`` on ``runs`` measured above the noise and at least
    2·LINE_HALF bins from the channel's other lines:
    y = ln(measured power / predicted power) = 2 ln(a_measured/a_predicted), the log power gain a
    further resonance would have to supply at the line's frequency f = h|Ω|/2π.  weight = s²/(s² + s_k²)
    with s the line's power over the noise power in its window and s_k = :data:`SNR_KNEE`: the scatter of
    a log power falls as 1/s for weak lines and is bounded by model error for strong ones."""
    fs, ys, ws = [], [], []
    offs = np.arange(-LINE_HALF, LINE_HALF + 1)
    for c in chans:
        noise = ctx.floor_psd(state, c, runs)
        cl = ctx.channel_lines(state, c, runs)
        hs = np.array([x[0] for x in cl])
        for h, law, amp, _ in cl:
            f = h * ctx.omega[runs] / (2 * np.pi)
            a_pred = amp * ctx.gain(state, c, f)
            a = ctx.measure_line(state, c, h, runs, skip=h)
            # a line within 2·LINE_HALF bins of another beats with it in the Welch estimate: left out
            sep = np.abs(hs[hs != h][:, None] - h) * ctx.omega[runs][None, :] / (2 * np.pi) / ctx.df
            alone = np.all(sep >= 2 * LINE_HALF, axis=0) if sep.size else np.ones(runs.size, bool)
            ok = np.isfinite(a) & (a_pred > 0) & alone
            k = np.clip(np.rint(f / ctx.df).astype(int)[:, None] + offs, 0, ctx.f.size - 1)
            snr = np.where(ok, a, 0.0) ** 2 / 2 / (np.take_along_axis(noise, k, axis=1).sum(1) * ctx.df)
            fs.append(f[ok])
            ys.append(2.0 * np.log(a[ok] / a_pred[ok]))
            ws.append(snr[ok] ** 2 / (snr[ok] ** 2 + SNR_KNEE**2))
    if not fs:
        return np.empty(0), np.empty(0), np.empty(0)
    return np.concatenate(fs), np.concatenate(ys), np.concatenate(ws)


@dataclass
class FixedResonance:
    """A resonance at a fixed frequency f_r (Hz, the same at every speed) multiplying every line of its
    channels by H(f/f_r) (:func:`resonance`; ζ damping ratio, g = |H| at f_r).  ``role``: "test_stand" when
    it acts on every channel alike (a fixture resonance, to be excluded from the wheel's model),
    "wheel_mode" when on one direction's channels only (an unmodelled wheel mode, to be added)."""

    f_r: float
    zeta: float
    peak_gain: float
    channels: tuple
    role: str
    n_points: int = 0
    kind: str = "fixed_resonance"

    def apply(self, state: State) -> State:
        s = state.copy()
        s.resonances.append((self.f_r, self.zeta, self.peak_gain, tuple(self.channels)))
        s.effects.append(self)
        return s

    def params(self) -> dict:
        dirs = sorted({CHANNEL_DIRECTION[c] for c in self.channels})
        return {"f_Hz": self.f_r, "zeta": self.zeta, "peak_gain": self.peak_gain, "role": self.role,
                "directions": dirs, "n_points": self.n_points,
                "gain_law": "H = (1 - r^2 + 2j*peak_gain*zeta*r)/(1 - r^2 + 2j*zeta*r) with r = f/f_Hz"}

    @staticmethod
    def peak(f: np.ndarray, y: np.ndarray, lo: float, hi: float, df: float):
        """Frequency (Hz) and mean log power gain of the strongest excess of ``y`` vs ``f``: the mean of y
        within ±max(2 df, 2 %) of every grid frequency, scored by |mean|·sqrt(count) (4 points at least)."""
        grid = np.arange(lo, hi, df)
        if grid.size == 0 or f.size < 4:
            return None
        half = np.maximum(2.0 * df, 0.02 * grid)
        inside = np.abs(f[None, :] - grid[:, None]) <= half[:, None]
        cnt = inside.sum(1)
        mean = np.where(cnt > 0, (inside * y[None, :]).sum(1) / np.maximum(cnt, 1), 0.0)
        score = np.where(cnt >= 4, np.abs(mean) * np.sqrt(cnt), 0.0)
        i = int(np.argmax(score))
        return (float(grid[i]), float(mean[i])) if score[i] > 0 else None

    @staticmethod
    def fit(ctx: Context, state: State, channels, runs, f0: float | None = None,
            role: str = "wheel_mode", n_iter: int = 3) -> "FixedResonance | None":
        """f_r, ζ, g by robust (soft-L1) nonlinear least squares of ln|H(f)|² against the lines' log power
        gains (:func:`_line_gain_points`), parameters in logs (positive), started at the strongest excess
        (or ``f0``) with ζ ∈ {0.01, 0.03, 0.1}; ``n_iter`` passes, each re-measuring the lines with the
        previous pass's resonance in the state."""
        from scipy.optimize import least_squares

        chans = [c for c in channels if c in ctx.channels]
        f, y, wt = _line_gain_points(ctx, state, chans, runs)
        lo, hi = ctx.k_lo * ctx.df, ctx.k_hi * ctx.df
        pk = FixedResonance.peak(f, y, lo, hi, ctx.df)
        if pk is None or f.size < 6:
            return None
        lb, ub = np.log([lo, 1e-3, 0.02]), np.log([hi, 0.5, 200.0])
        g0 = float(np.clip(np.exp(pk[1] / 2.0), 0.1, 50.0))
        starts = [np.log([pk[0] if f0 is None else f0, z0, max(g0, 1.01) if pk[1] > 0 else min(g0, 0.99)])
                  for z0 in (0.01, 0.03, 0.1)]
        e = None
        for _ in range(n_iter):
            if e is not None:
                # re-measure with the tentative resonance in the state, so that neighbouring lines are
                # subtracted amplified; the total log gain is the residual one plus the tentative ln|H|²
                st = e.apply(state)
                f, y, wt = _line_gain_points(ctx, st, chans, runs)
                y = y + np.log(np.abs(resonance(f, e.f_r, e.zeta, e.peak_gain)) ** 2)
                starts = [np.log([e.f_r, e.zeta, e.peak_gain])]
            if f.size < 6:
                return None

            def res(x):
                return np.sqrt(wt) * (y - np.log(np.abs(resonance(f, np.exp(x[0]), np.exp(x[1]), np.exp(x[2]))) ** 2))
            best = None
            for x0 in starts:
                sol = least_squares(res, np.clip(x0, lb + 1e-9, ub - 1e-9), loss="soft_l1", f_scale=0.5,
                                    bounds=(lb, ub))
                if best is None or sol.cost < best.cost:
                    best = sol
            f_r, zeta, g = (float(v) for v in np.exp(best.x))
            e = FixedResonance(f_r, zeta, g, tuple(channels), role, int(f.size))
        return e

    @staticmethod
    def candidates(ctx: Context, state: State, runs) -> list:
        """One resonance per direction (role wheel_mode) and one common to every channel (role test_stand)."""
        out = []
        dirs = [d for d, ch in DIRECTION_CHANNELS.items()
                if any(c in ctx.channels for c in ch) and state.model.harmonics(d)]
        for d in dirs:
            e = FixedResonance.fit(ctx, state, DIRECTION_CHANNELS[d], runs, role="wheel_mode")
            if e is not None:
                out.append(e)
        if len(dirs) > 1:
            e = FixedResonance.fit(ctx, state, ctx.channels, runs, role="test_stand")
            if e is not None:
                out.append(e)
        return [e for e in out if not any(abs(e.f_r - r[0]) < 0.02 * r[0] and set(e.channels) & set(r[3])
                                          for r in state.resonances)]



@dataclass
class CrossCoupling:
    """Load-cell offset: the measured torque carries r × F of the measured force (r in m, wheel frame),
    T_measured = T + r × F, i.e. Tx += r_y·Fz − r_z·Fy, Ty += r_z·Fx − r_x·Fz, Tz += r_x·Fy − r_y·Fx.
    Added to a state it reads the torque data corrected, T − r × F (a calibration of the measurement,
    not a part of the wheel)."""

    r: np.ndarray
    r_stderr: np.ndarray
    n_points: int = 0
    kind: str = "cross_coupling"

    @property
    def channels(self):
        return TORQUE_CHANNELS

    def apply(self, state: State) -> State:
        s = state.copy()
        s.coupling = tuple(float(x) for x in self.r)
        s.effects.append(self)
        return s

    def params(self) -> dict:
        return {"r_m": [float(x) for x in self.r], "r_stderr_m": [float(x) for x in self.r_stderr],
                "n_points": self.n_points, "law": "T_measured = T + r x F (r in m in the wheel frame)"}

    @staticmethod
    def fit(ctx: Context, state: State, runs) -> "CrossCoupling | None":
        """r by weighted linear least squares on the complex amplitudes (:meth:`Context.phasors`) of the
        forces and torques at every force line of the model (radial and axial force harmonics, in band):
        T_c = T0_c + M_c(F)·r with M(F) = −[F]× (r × F = −F × r), real and imaginary parts stacked.  The
        wheel's own torque T0 is the error term: each equation is weighted by 1/P_c(f), P_c the torque PSD
        the state predicts at the line (its torque lines and noise), so lines shared with the torque
        harmonics weigh little.  Unbiased when T0 and F have independent phases (as the test stand's
        random phases); standard errors from the weighted residual."""
        if ctx.test is None or state.coupling is not None:
            return None
        tq = [c for c in TORQUE_CHANNELS if c in ctx.channels]
        if not tq or not all(c in ctx.channels for c in ("Fx", "Fy", "Fz")):
            return None
        hs = sorted({round(x.h, 4) for d in ("radial_force", "axial_force") for x in state.model.harmonics(d)})
        if not hs:
            return None
        f = np.outer(ctx.omega[runs], hs) / (2 * np.pi)                     # (n_runs, L) Hz
        inb = (f >= ctx.k_lo * ctx.df) & (f <= ctx.k_hi * ctx.df)
        X = ctx.phasors(runs, f)                                             # (n_runs, L, 6)
        Fx, Fy, Fz = X[..., 0], X[..., 1], X[..., 2]
        zero = np.zeros_like(Fx)
        M = {"Tx": (zero, Fz, -Fy), "Ty": (-Fz, zero, Fx), "Tz": (Fy, -Fx, zero)}
        k = np.clip(np.rint(f / ctx.df).astype(int), 0, ctx.f.size - 1)
        rows, rhs = [], []
        for c in tq:
            P = np.take_along_axis(ctx.predict(state, c, runs), k, axis=1)      # unit²/Hz at the lines
            T = X[..., CHANNELS.index(c)]
            ok = inb & np.isfinite(T) & np.isfinite(Fx) & np.isfinite(Fy) & np.isfinite(Fz) & (P > 0)
            wt = 1.0 / np.sqrt(P[ok])
            A = np.column_stack([m[ok] for m in M[c]]) * wt[:, None]
            b = T[ok] * wt
            rows += [A.real, A.imag]
            rhs += [b.real, b.imag]
        A, b = np.vstack(rows), np.concatenate(rhs)
        if b.size < 6:
            return None
        r, *_ = np.linalg.lstsq(A, b, rcond=None)
        res = b - A @ r
        s2 = float(res @ res) / max(b.size - 3, 1)
        cov = s2 * np.linalg.pinv(A.T @ A)
        return CrossCoupling(r, np.sqrt(np.diag(cov)), int(b.size // 2))

    @staticmethod
    def candidates(ctx: Context, state: State, runs) -> list:
        e = CrossCoupling.fit(ctx, state, runs)
        return [] if e is None else [e]


# --------------------------------------------------------------------------- modulation: sidebands, speed ripple

def ripple_sideband_powers(beta, eps, p=2.0, k_max: int | None = None):
    """Power fractions of the lines a periodic speed ripple makes of one harmonic line.

    With Ω(t) = Ω0 + ΔΩ·sin θ, θ = 2π f_r t, the rotation angle is ψ = Ω0 t − (ΔΩ/2πf_r)·cos θ, so the line
    h of amplitude a(Ω) ∝ |Ω|^p becomes a·g(θ)·e^{j2πf_i t} with
    g(θ) = (1 + ε sin θ)^p · exp(−jβ cos θ),  β = h·ΔΩ/(2π f_r) (phase-modulation index, rad),
    ε = ΔΩ/|Ω0|, and g = Σ_k c_k e^{jkθ}: lines at f_i + k·f_r of amplitude |c_k|·a.  Without the amplitude
    term (ε = 0) c_k = J_k(β)e^{-jkπ/2}, |c_k|² = J_k(β)² and Σ_k |c_k|² = 1 (Parseval); with it Σ|c_k|² is the
    mean of (1 + ε sin θ)^{2p} (1 + 3ε² + 3ε⁴/8 for p = 2).  c_k by an FFT over one period of θ: the complex
    coefficients are :func:`rwadist.extended.ripple_coefficients` (which the coupling kit applies per line);
    this returns their squared moduli.  (For ε > 1, a speed reversal within the ripple, the amplitude is
    |1 + ε sin θ|^p, the exact |Ω(t)|^p.)

    beta, eps : broadcastable arrays (shape S); p : amplitude exponent (scalar or broadcastable).
    Returns (k (2K+1,), P (S + (2K+1,))), P = |c_k|².
    """
    from .extended import ripple_coefficients

    k, c = ripple_coefficients(beta, eps, p, k_max)
    return k, np.abs(c) ** 2


def _residual_z(ctx, state, c, runs):
    """Residual (data − model) of channel ``c`` and its value over the model's floor, the latter the
    maximum of each bin and its two neighbours (a line between bins)."""
    R = ctx.data(state, c)[runs] - ctx.predict(state, c, runs)
    z = R / ctx.floor_psd(state, c, runs)
    return R, np.maximum(np.maximum(z, np.roll(z, 1, axis=1)), np.roll(z, -1, axis=1))


def _offset_scores(ctx, state, chans, runs, hs, offsets):
    """Sum and count (len(hs), len(offsets)) of the clipped normalised residual at h|Ω|/2π ± Δ for every
    carrier h of ``hs`` and offset Δ (Hz) of ``offsets``, over ``chans``, ``runs`` and both sides (in band
    only): parallel ridges at a constant frequency offset from a line."""
    tot = np.zeros((len(hs), offsets.size))
    cnt = np.zeros((len(hs), offsets.size))
    rows = np.arange(runs.size)[None, :]
    for c in chans:
        _, z = _residual_z(ctx, state, c, runs)
        z = np.clip(z, -5.0, 20.0)
        for i, h in enumerate(hs):
            f0 = h * ctx.omega[runs] / (2 * np.pi)
            for side in (1.0, -1.0):
                k = np.rint((f0[None, :] + side * offsets[:, None]) / ctx.df).astype(int)
                inb = (k >= ctx.k_lo) & (k <= ctx.k_hi)
                vals = z[rows, np.clip(k, 0, ctx.f.size - 1)]
                tot[i] += np.where(inb, vals, 0.0).sum(1)
                cnt[i] += inb.sum(1)
    return tot, cnt


def _offset_threshold(ctx, n):
    """Pooled-score threshold of a ridge (as :func:`ridge_peaks`): 10 noise standard deviations of a mean
    of ``n`` normalised residual bins, plus 0.5."""
    return 10.0 * np.sqrt(2.0 / ctx.dof) / np.sqrt(max(n, 1)) + 0.5


def _offset_grid(ctx, f_max: float = 50.0):
    """Offsets (Hz) searched for sidebands: from 2.5 bins (clear of the carrier's main lobe) to f_max."""
    return np.arange(2.5 * ctx.df, min(f_max, 0.5 * ctx.k_hi * ctx.df), 0.25 * ctx.df)


def _refine_offset(ctx, state, chans, runs, hs, off, n_iter: int = 2):
    """Constant offset (Hz) of the sideband ridges near ``off`` around the carriers ``hs``: in every (channel,
    run, carrier, side) the residual peak within ±2 bins of f_i ± off, refined by a log-parabola through three
    bins and kept when > 20 × floor; the offset is the median of side·(f_peak − f_i).  Returns (offset, count)."""
    n = 0
    for _ in range(n_iter):
        est = []
        for c in chans:
            R, _ = _residual_z(ctx, state, c, runs)
            z = R / ctx.floor_psd(state, c, runs)
            r = np.arange(runs.size)
            for h in hs:
                f0 = h * ctx.omega[runs] / (2 * np.pi)
                for side in (1.0, -1.0):
                    k0 = np.rint((f0 + side * off) / ctx.df).astype(int)
                    k = np.clip(k0[:, None] + np.arange(-2, 3), 1, ctx.f.size - 2)
                    kp = k[r, np.argmax(z[r[:, None], k], axis=1)]
                    ok = (kp - 1 >= ctx.k_lo) & (kp + 1 <= ctx.k_hi) & (z[r, kp] > 20.0)
                    lo, mid, hi = (np.log(np.maximum(R[r, kp + j], 1e-300)) for j in (-1, 0, 1))
                    den = lo - 2 * mid + hi
                    with np.errstate(divide="ignore", invalid="ignore"):
                        dl = np.clip(np.where(den < 0, 0.5 * (lo - hi) / den, 0.0), -0.5, 0.5)
                    est.append((side * ((kp + dl) * ctx.df - f0))[ok])
        est = np.concatenate(est) if est else np.empty(0)
        n = est.size
        if n < 3:
            return off, n
        off = float(np.median(est))
    return off, n


def _window_power(ctx, state, c, runs, f_hz, R):
    """Residual power (unit²) in ±LINE_HALF bins around ``f_hz`` (len(runs),), the model floor's power there,
    its noise standard deviation (as :meth:`Context.measure_line`) and an in-band mask."""
    k0 = np.rint(np.abs(f_hz) / ctx.df).astype(int)
    offs = np.arange(-LINE_HALF, LINE_HALF + 1)
    inband = (k0 - LINE_HALF >= ctx.k_lo) & (k0 + LINE_HALF <= ctx.k_hi)
    k = np.clip(k0[:, None] + offs, 0, ctx.f.size - 1)
    p = np.take_along_axis(R, k, axis=1).sum(1) * ctx.df
    noise = np.take_along_axis(ctx.floor_psd(state, c, runs), k, axis=1).sum(1) * ctx.df
    sig = 2.0 * noise * np.sqrt(2.0 / ctx.dof) / np.sqrt(2 * LINE_HALF + 1)
    return p, noise, sig, inband


def _clear_of_lines(ctx, state, c, runs, f_hz, own_h):
    """True where frequency ``f_hz`` (len(runs),) lies at least 2·LINE_HALF bins from every line of channel
    ``c`` other than ``own_h`` (and their sidebands): its window measures that line's component alone."""
    ok = np.ones(runs.size, bool)
    for h, _, _ in state.lines(c):
        if abs(h - own_h) < 1e-9:
            continue
        for shift, _ in state.line_components(c, h):
            g = np.abs(h * ctx.omega[runs] / (2 * np.pi) + shift)
            ok &= np.abs(g - np.abs(f_hz)) >= 2 * LINE_HALF * ctx.df
    return ok


@dataclass
class Sidebands:
    """Amplitude modulation of one harmonic line at a FIXED frequency f_mod (Hz, the same at every speed: a
    cage or electronics frequency, a drive's PWM beat): a(Ω)·(1 + m·cos 2πf_mod t)·cos(2πf_i t + φ) is the
    carrier plus two lines at f_i ± f_mod of amplitude m·a/2 (depth m, dimensionless)."""

    direction: str
    h: float
    f_mod: float
    depth: float
    n_points: int = 0
    kind: str = "sidebands"

    @property
    def channels(self):
        return DIRECTION_CHANNELS[self.direction]

    def apply(self, state: State) -> State:
        s = state.copy()
        s.sidebands.append((self.direction, round(self.h, 4), self.f_mod, self.depth))
        s.effects.append(self)
        return s

    def params(self) -> dict:
        return {"direction": self.direction, "h": round(self.h, 4), "f_mod_Hz": self.f_mod, "depth": self.depth,
                "n_points": self.n_points,
                "law": "a(1 + depth*cos(2 pi f_mod t)): lines at h|omega|/2pi +- f_mod_Hz of amplitude depth*a/2"}

    @staticmethod
    def fit(ctx: Context, state: State, direction: str, h: float, runs, f_mod: float) -> "Sidebands | None":
        """f_mod by :func:`_refine_offset` on both sides of the carrier; m² by linear least squares of the
        measured sideband window powers P on their prediction per unit m², q = (a/2)²/2 (a the carrier's model
        amplitude, times the resonance gain at the sideband), over every in-band side clear of other lines."""
        chans = [c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels]
        f_mod, n = _refine_offset(ctx, state, chans, runs, [h], f_mod)
        if n < 3 or f_mod <= 0:
            return None
        P, Q = [], []
        for c in chans:
            R, _ = _residual_z(ctx, state, c, runs)
            a = next((x[2] for x in ctx.channel_lines(state, c, runs) if abs(x[0] - h) < 1e-9), None)
            if a is None:
                return None
            for side in (1.0, -1.0):
                f = h * ctx.omega[runs] / (2 * np.pi) + side * f_mod
                p, _, _, inb = _window_power(ctx, state, c, runs, f, R)
                ok = inb & _clear_of_lines(ctx, state, c, runs, f, h) & (f > 0)
                g = ctx.gain(state, c, f) if state.resonances else 1.0
                P.append(p[ok])
                Q.append(((a * g) ** 2 / 8.0 * np.ones(runs.size))[ok])
        P, Q = np.concatenate(P), np.concatenate(Q)
        if P.size < 3 or not np.sum(Q * Q) > 0:
            return None
        m2 = float(np.sum(P * Q) / np.sum(Q * Q))
        if m2 <= 0:
            return None
        return Sidebands(direction, float(h), float(f_mod), float(np.sqrt(m2)), int(P.size))

    @staticmethod
    def candidates(ctx: Context, state: State, runs, max_per_direction: int = 3) -> list:
        """Per direction, the carriers whose best constant-offset ridge pair (:func:`_offset_scores`) clears
        :func:`_offset_threshold`; at most ``max_per_direction``, strongest first."""
        out = []
        offsets = _offset_grid(ctx)
        if offsets.size < 3:
            return out
        for d, chans in DIRECTION_CHANNELS.items():
            chans = [c for c in chans if c in ctx.channels]
            hs = [x.h for x in state.model.harmonics(d)
                  if not any(dd == d and abs(hh - x.h) < 1e-4 for dd, hh, _, _ in state.sidebands)]
            if not chans or not hs:
                continue
            tot, cnt = _offset_scores(ctx, state, chans, runs, hs, offsets)
            score = np.where(cnt >= 6, tot / np.maximum(cnt, 1), 0.0)
            found = []
            for i, h in enumerate(hs):
                s = score[i]
                j = int(np.argmax(s))
                if 0 < j < s.size - 1 and s[j] > _offset_threshold(ctx, cnt[i, j]):
                    found.append((s[j], h, float(offsets[j])))
            for _, h, f_m in sorted(found, reverse=True)[:max_per_direction]:
                e = Sidebands.fit(ctx, state, d, h, runs, f_m)
                if e is not None:
                    out.append(e)
        return out


@dataclass
class SpeedRipple:
    """A periodic wheel-speed ripple at a fixed frequency f_ripple (Hz): Ω(t) = Ω0 + ΔΩ·sin(2π f_ripple t),
    with ΔΩ(|Ω0|) = ΔΩ_ref·(|Ω0|/Ω_ref)^q (rad/s; q = 0 a ripple of fixed size, q = 1 a fixed fraction of the
    speed).  Every line is phase modulated (β_h = h·ΔΩ/2πf_ripple) and amplitude modulated (a ∝ |Ω(t)|^p):
    lines at f_i + k·f_ripple with the power fractions of :func:`ripple_sideband_powers`."""

    delta_omega: float
    f_ripple: float
    omega_ref: float
    exponent: float = 0.0
    n_points: int = 0
    kind: str = "speed_ripple"

    @property
    def channels(self):
        return CHANNELS

    def apply(self, state: State) -> State:
        s = state.copy()
        s.ripple = (self.delta_omega, self.f_ripple, self.omega_ref, self.exponent)
        s.effects.append(self)
        return s

    def params(self) -> dict:
        return {"f_ripple_Hz": self.f_ripple, "delta_omega_rad_s": self.delta_omega,
                "omega_ref_rad_s": self.omega_ref, "speed_exponent": self.exponent,
                "ripple_frac_at_ref": self.delta_omega / self.omega_ref, "n_points": self.n_points,
                "law": "omega(t) = omega0 + dw*sin(2 pi f_ripple t), dw = delta_omega_rad_s*(|omega0|/omega_ref)"
                       "^speed_exponent; line h: phase index h*dw/(2 pi f_ripple), amplitude ~ |omega(t)|^p"}

    @staticmethod
    def _points(ctx, state, runs, f_r):
        """Measured first-order ripple sidebands of every model line: (P window power, σ noise std, h, Ω,
        a carrier amplitude × gain, p amplitude exponent, side) over channels, lines and both sides, in band
        and clear of other lines."""
        cols = {k: [] for k in ("P", "sig", "h", "w", "a", "p", "side")}
        for c in ctx.channels:
            if not np.isfinite(ctx.sp.psd[c][runs, 0]).all():
                continue
            R, _ = _residual_z(ctx, state, c, runs)
            for h, law, a, _ in ctx.channel_lines(state, c, runs):
                f0 = h * ctx.omega[runs] / (2 * np.pi)
                for side in (1.0, -1.0):
                    f = f0 + side * f_r
                    p, _, sig, inb = _window_power(ctx, state, c, runs, f, R)
                    ok = inb & (f > 0) & _clear_of_lines(ctx, state, c, runs, f, h)
                    g = ctx.gain(state, c, f0) if state.resonances else np.ones(runs.size)
                    for k, v in (("P", p), ("sig", sig), ("h", np.full(runs.size, h)), ("w", ctx.omega[runs]),
                                 ("a", a * g), ("p", np.full(runs.size, 2.0 if law is None else law[2])),
                                 ("side", np.full(runs.size, side))):
                        cols[k].append(np.asarray(v, float)[ok])
        return {k: np.concatenate(v) if v else np.empty(0) for k, v in cols.items()}

    @staticmethod
    def fit(ctx: Context, state: State, runs, f_r: float, exponent: float = 0.0) -> "SpeedRipple | None":
        """f_ripple by :func:`_refine_offset` over every line of every channel; ΔΩ_ref by a robust (soft-L1)
        fit of ln P to ln(|c_{±1}|²·a²/2) over the first-order sidebands standing 5σ above the noise (a log-
        spaced grid, then a bounded scalar minimisation), with ΔΩ < ½·min|Ω| of the runs."""
        from scipy.optimize import minimize_scalar

        hs = sorted({x[0] for c in ctx.channels for x in state.lines(c)})
        if not hs:
            return None
        f_r, n = _refine_offset(ctx, state, ctx.channels, runs, hs, f_r)
        if n < 3 or f_r <= 0:
            return None
        pt = SpeedRipple._points(ctx, state, runs, f_r)
        det = pt["P"] > 5.0 * pt["sig"]
        if det.sum() < 5:
            return None
        pt = {k: v[det] for k, v in pt.items()}
        w_ref = ctx.omega_ref()
        y = np.log(pt["P"])
        ki = np.where(pt["side"] > 0, 1, -1)

        def cost(x):
            dw = np.exp(x) * (pt["w"] / w_ref) ** exponent
            k, P = ripple_sideband_powers(pt["h"] * dw / (2 * np.pi * f_r), dw / pt["w"], pt["p"], k_max=4)
            pred = P[np.arange(ki.size), ki + 4] * pt["a"] ** 2 / 2
            r = (y - np.log(np.maximum(pred, 1e-300))) / 0.5
            return float(np.sum(2.0 * (np.sqrt(1.0 + r * r) - 1.0)))        # soft-L1

        top = np.log(0.5 * float(np.min(ctx.omega[runs] * (w_ref / ctx.omega[runs]) ** exponent)))
        grid = np.linspace(top - 12.0, top, 97)
        vals = [cost(x) for x in grid]
        i = int(np.argmin(vals))
        lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
        sol = minimize_scalar(cost, bounds=(lo, hi), method="bounded", options={"xatol": 1e-4})
        x = float(sol.x) if sol.fun <= vals[i] else float(grid[i])
        return SpeedRipple(float(np.exp(x)), float(f_r), w_ref, float(exponent), int(y.size))

    @staticmethod
    def candidates(ctx: Context, state: State, runs) -> list:
        """The strongest constant offset of residual ridges around every line of every channel pooled
        (:func:`_offset_scores`), fitted with q = 0 and q = 1 (two hypotheses judged on held-out speeds)."""
        if state.ripple is not None:
            return []
        offsets = _offset_grid(ctx)
        tot = np.zeros(offsets.size)
        cnt = np.zeros(offsets.size)
        for c in ctx.channels:
            hs = [x[0] for x in state.lines(c)]
            if not hs:
                continue
            t, n = _offset_scores(ctx, state, [c], runs, hs, offsets)
            tot += t.sum(0)
            cnt += n.sum(0)
        score = np.where(cnt >= 6, tot / np.maximum(cnt, 1), 0.0)
        if score.size < 3:
            return []
        j = int(np.argmax(score))
        if not (0 < j < score.size - 1 and score[j] > _offset_threshold(ctx, cnt[j])):
            return []
        out = []
        for q in (0.0, 1.0):
            e = SpeedRipple.fit(ctx, state, runs, float(offsets[j]), q)
            if e is not None:
                out.append(e)
        return out

# --------------------------------------------------------------------------- counter rotation (extended base)

def _sense_group(state: State, direction: str, h: float):
    """The state's extended lines of (direction, h) (|Δh| < LAW_H_TOL) when they are all co- or counter-rotating and
    carry no amplitude law: (h of the group, C_co, C_counter, imbalance?) with C the root-sum-square of the lines'
    C (kg·m or kg·m², per (rad/s)²; an imbalance's C is U_s or U_d of the analytical section); else None."""
    from . import extended as ext

    if state.ext is None:
        return None
    g = [ln for ln in state.ext_lines() if ln.direction == direction and abs(ln.h - h) < ext.LAW_H_TOL]
    if not g or any(ln.sense == "planar" or ln.law is not None for ln in g):
        return None
    c_co = float(np.sqrt(sum(ln.C**2 for ln in g if ln.sense == "co")))
    c_ct = float(np.sqrt(sum(ln.C**2 for ln in g if ln.sense == "counter")))
    if c_co**2 + c_ct**2 <= 0:
        return None
    return float(g[0].h), c_co, c_ct, any(ln.imbalance for ln in g)


@dataclass
class CounterRotation:
    """Counter-rotating content of a radial harmonic (extended base only).

    The radial load of harmonic h is F = a₊e^{+iσθ} + a₋e^{−iσθ} (θ = h·φ, φ the rotor angle, complex x + iy
    coordinates): a co-rotating part a₊ and a counter-rotating part a₋ (a planar, anisotropic load is
    |a₊| = |a₋|).  ``counter_fraction`` q = |a₋|²/(|a₊|² + |a₋|²), the total free power |a₊|² + |a₋|² = C²Ω⁴
    kept: the harmonic becomes a co line of C·sqrt(1 − q) and a counter line of C·sqrt(q) (for the
    imbalance h = 1 the co part is U_s or U_d of the analytical section, scaled by sqrt(1 − q)).
    Hard mounted the two parts have the same PSD; through the rotor's modes the co part meets the forward
    whirl and the counter part the backward one (:mod:`rwadist.extended`), so q is seen where
    |G₊| ≠ |G₋|, above all at the backward-whirl crossing.  The radial translation has no gyroscopic split
    (|G₊| = |G₋|): q of a radial-force line is not seen in PSDs and the class does not propose it.
    ``counter_fraction_phase``: a second, independent estimate from the x/y phase of the time series
    (:meth:`fit`), NaN without them."""

    direction: str
    h: float
    counter_fraction: float
    counter_fraction_stderr: float = float("nan")
    counter_fraction_phase: float = float("nan")
    n_points: int = 0
    kind: str = "counter_rotation"

    @property
    def channels(self):
        return DIRECTION_CHANNELS[self.direction]

    def split(self, state: State):
        """(C_co, C_counter) of the harmonic after this effect, from the state's group total."""
        g = _sense_group(state, self.direction, self.h)
        if g is None:
            raise ValueError(f"counter_rotation: no co/counter line {self.direction} h = {self.h} in the state")
        c_tot = float(np.hypot(g[1], g[2]))
        q = float(np.clip(self.counter_fraction, 0.0, 1.0))
        return c_tot * np.sqrt(1.0 - q), c_tot * np.sqrt(q)

    def apply(self, state: State) -> State:
        from . import extended as ext

        h0, c_co0, c_ct0, imb = _sense_group(state, self.direction, self.h)
        c_co, c_ct = self.split(state)
        s = state.copy()
        d = self.direction
        old = s.model.harmonics(d)
        at_h = [x for x in old if abs(x.h - h0) < ext.LAW_H_TOL]
        keep = [x for x in old if abs(x.h - h0) >= ext.LAW_H_TOL]
        h_key = at_h[0].h if at_h else h0
        new = []
        if imb:
            # the co part is the imbalance of the analytical section; the model's co harmonic (its empirical
            # coefficient, read by the hard-mounted consumers) is scaled alike
            name = "U_s" if d == "radial_force" else "U_d"
            s.ext = replace(s.ext, **{name: c_co})
            s.model.analytical = dict(s.model.analytical or {}, **ext.params_to_dict(s.ext))
            scale = c_co / c_co0 if c_co0 > 0 else 0.0
            new += [replace(x, C=x.C * scale) for x in at_h if x.sense != "counter"]
        elif c_co > 0:
            new.append(Harmonic(h=h_key, C=c_co, sense="co"))
        if c_ct > 0:
            new.append(Harmonic(h=h_key, C=c_ct, sense="counter"))
        s.model.empirical[d] = sorted(keep + new, key=lambda x: (x.h, x.sense == "counter"))
        s.effects.append(self)
        return s

    def params(self) -> dict:
        return {"direction": self.direction, "h": round(self.h, 4), "counter_fraction": self.counter_fraction,
                "counter_fraction_stderr": self.counter_fraction_stderr,
                "counter_fraction_phase": self.counter_fraction_phase, "n_points": self.n_points,
                "law": "radial load C*omega^2*(sqrt(1-q) e^{+i h phi} + sqrt(q) e^{-i h phi}), q = counter_fraction "
                       "= |a-|^2/(|a+|^2+|a-|^2); model: a co harmonic C*sqrt(1-q) and a counter one C*sqrt(q)"}

    @staticmethod
    def _points(ctx, state, direction, h, runs):
        """Per run: measured power of the line h summed over the direction's x and y channels (cross term of
        the co/counter pair cancels), and its prediction P_o + P₊ + q·(P₋ − P₊) at counter fraction q;
        returns (Pm, P_o, P₊, P₋, weight, ok) arrays."""
        g = _sense_group(state, direction, h)
        h0, c_co, c_ct, _ = g
        c_tot = float(np.hypot(c_co, c_ct))
        q0 = c_ct**2 / c_tot**2
        chans = [c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels]
        w = ctx.omega[runs]
        f = h0 * w / (2 * np.pi)
        a2 = (c_tot * w**2) ** 2 / 2.0                      # free mean square of the harmonic
        Pm, Po, Pp, Pn, Nn = (np.zeros(runs.size) for _ in range(5))
        ok = np.ones(runs.size, bool)
        offs = np.arange(-LINE_HALF, LINE_HALF + 1)
        k = np.clip(np.rint(f / ctx.df).astype(int)[:, None] + offs, 0, ctx.f.size - 1)
        for c in chans:
            a = ctx.measure_line(state, c, h0, runs, skip=h0)
            ok &= np.isfinite(a)
            Hc2 = ctx.gain(state, c, f) ** 2
            gp = ctx.unit_gain(state, c, direction, h0, "co", runs) ** 2
            gn = ctx.unit_gain(state, c, direction, h0, "counter", runs) ** 2
            grp = next((x[2] for x in ctx.channel_lines(state, c, runs) if abs(x[0] - h0) < 1e-3), np.zeros(runs.size))
            other = np.maximum(grp**2 / 2.0 - a2 * ((1 - q0) * gp + q0 * gn), 0.0)
            Pm += np.where(np.isfinite(a), a, 0.0) ** 2 / 2.0
            Po += other * Hc2
            Pp += a2 * gp * Hc2
            Pn += a2 * gn * Hc2
            Nn += np.take_along_axis(ctx.floor_psd(state, c, runs), k, axis=1).sum(1) * ctx.df
        snr = Pm / np.maximum(Nn, 1e-300)
        return Pm, Po, Pp, Pn, snr**2 / (snr**2 + SNR_KNEE**2), ok & (Pm > 0)

    @staticmethod
    def phase_fraction(ctx, state, direction, h, runs) -> float:
        """Counter fraction from the x/y phase of the time series (NaN without them): per run the complex
        amplitudes X, Y of the direction's x and y channels at h|Ω|/2π (:meth:`Context.phasors`) split into the
        co-rotating |X + iY|²/4 and counter-rotating |X − iY|²/4 mean squares (swapped for Ω < 0), each divided
        by its modal power gain |G±|² (and the fixed resonances) to the free load; q = Σ counter / Σ both."""
        chans = DIRECTION_CHANNELS[direction]
        if ctx.test is None or not all(c in ctx.channels for c in chans):
            return float("nan")
        h0 = _sense_group(state, direction, h)[0]
        f = h0 * ctx.omega[runs] / (2 * np.pi)
        inb = (f >= ctx.k_lo * ctx.df) & (f <= ctx.k_hi * ctx.df)
        X = ctx.phasors(runs, f[:, None])[:, 0, :]
        x, y = X[:, CHANNELS.index(chans[0])], X[:, CHANNELS.index(chans[1])]
        co, ct = np.abs(x + 1j * y) ** 2 / 4.0, np.abs(x - 1j * y) ** 2 / 4.0
        neg = np.asarray(ctx.sp.speed, float)[runs] < 0
        co, ct = np.where(neg, ct, co), np.where(neg, co, ct)
        Hc2 = ctx.gain(state, chans[0], f) ** 2
        co = co / (ctx.unit_gain(state, chans[0], direction, h0, "co", runs) ** 2 * Hc2)
        ct = ct / (ctx.unit_gain(state, chans[0], direction, h0, "counter", runs) ** 2 * Hc2)
        ok = inb & np.isfinite(co) & np.isfinite(ct)
        tot = float(np.sum(co[ok] + ct[ok]))
        return float(np.sum(ct[ok]) / tot) if tot > 0 else float("nan")

    @staticmethod
    def fit(ctx: Context, state: State, direction: str, h: float, runs) -> "CounterRotation | None":
        """q by weighted least squares of ln(measured x + y line power) on ln(P_o + P₊ + q(P₋ − P₊)) over the
        runs where the line stands above the noise (:meth:`_points`; weights s²/(s² + SNR_KNEE²), s the line's
        power over the noise in its window), q in [0, 1] (grid, then a bounded scalar minimisation); its
        standard error from the curvature and the residual scatter.  None when the data cannot tell the senses
        apart (max |ln P₋/P₊| < 0.1 over the runs) or fewer than 3 runs measure the line."""
        from scipy.optimize import minimize_scalar

        if _sense_group(state, direction, h) is None:
            return None
        Pm, Po, Pp, Pn, wt, ok = CounterRotation._points(ctx, state, direction, h, runs)
        if ok.sum() < 3:
            return None
        Pm, Po, Pp, Pn, wt = (v[ok] for v in (Pm, Po, Pp, Pn, wt))
        if np.max(np.abs(np.log(np.maximum(Pn, 1e-300) / np.maximum(Pp, 1e-300)))) < 0.1:
            return None
        y = np.log(Pm)

        def cost(q):
            return float(np.sum(wt * (y - np.log(np.maximum(Po + Pp + q * (Pn - Pp), 1e-300))) ** 2))

        grid = np.linspace(0.0, 1.0, 201)
        vals = [cost(q) for q in grid]
        i = int(np.argmin(vals))
        sol = minimize_scalar(cost, bounds=(grid[max(i - 1, 0)], grid[min(i + 1, 200)]), method="bounded",
                              options={"xatol": 1e-6})
        q = float(sol.x) if sol.fun <= vals[i] else float(grid[i])
        P = Po + Pp + q * (Pn - Pp)
        J = (Pn - Pp) / P
        info = float(np.sum(wt * J**2))
        s2 = cost(q) / max(y.size - 1, 1)
        se = float(np.sqrt(s2 / info)) if info > 0 else float("inf")
        return CounterRotation(direction, float(h), q, se, CounterRotation.phase_fraction(ctx, state, direction, h, runs),
                               int(y.size))

    @staticmethod
    def candidates(ctx: Context, state: State, runs) -> list:
        """Every co/counter radial harmonic of the extended base not yet split, whose fitted q departs from the
        state's own (0 for a co line, 1 for a counter line) by more than 0.01 and 2 standard errors."""
        if state.ext is None:
            return []
        done = {(e.direction, round(e.h, 3)) for e in state.effects if isinstance(e, CounterRotation)}
        out = []
        for d in ("radial_force", "radial_torque"):
            if not any(c in ctx.channels for c in DIRECTION_CHANNELS[d]):
                continue
            hs = sorted({round(ln.h, 4) for ln in state.ext_lines() if ln.direction == d})
            for h in hs:
                g = _sense_group(state, d, h)
                if g is None or (d, round(h, 3)) in done:
                    continue
                q0 = g[2] ** 2 / (g[1] ** 2 + g[2] ** 2)
                e = CounterRotation.fit(ctx, state, d, h, runs)
                if e is not None and abs(e.counter_fraction - q0) > max(0.01, 2 * e.counter_fraction_stderr):
                    out.append(e)
        return out


@dataclass
class SpinAcceleration:
    """Lines smeared by the wheel's acceleration during each run of a sweep (a measurement artefact of
    slicing a spin-up or run-down into quasi-steady runs): the line of harmonic h sweeps h|α|T/2π Hz
    during a run of length T.  ``alpha`` (rad/s², |dΩ/dt|) is fitted to the residual; ``alpha_track``
    is the independent estimate from the runs' speeds and start times (NaN for steady runs)."""

    alpha: float
    alpha_track: float = float("nan")
    noise: dict | None = None        # instrument noise re-estimated with the smeared lines masked
    kind: str = "spin_acceleration"

    @property
    def channels(self):
        return CHANNELS

    def apply(self, state: State) -> State:
        s = state.copy()
        s.smear = self.alpha
        if self.noise is not None:
            s.noise = self.noise
        s.effects.append(self)
        return s

    def params(self) -> dict:
        return {"alpha_rad_s2": self.alpha, "alpha_track_rad_s2": self.alpha_track, "role": "measurement"}

    @staticmethod
    def track(ctx: Context, runs) -> float:
        """Median |dΩ/dt| (rad/s²) from the runs' speeds against their start times (runs of one sweep,
        ``Run.t0`` distinct), or NaN."""
        if ctx.test is None or len(runs) < 3:
            return float("nan")
        t0 = np.array([ctx.test.runs[r].t0 for r in runs], dtype=float)
        w = ctx.omega[runs]
        order = np.argsort(t0)
        dt = np.diff(t0[order])
        if not np.all(np.isfinite(t0)) or np.any(dt <= 0):
            return float("nan")
        return float(np.median(np.abs(np.diff(w[order]) / dt)))

    @staticmethod
    def fit(ctx: Context, state: State, runs) -> "SpinAcceleration | None":
        from scipy import optimize

        if state.smear is not None or len(runs) < 3:
            return None
        track = SpinAcceleration.track(ctx, np.asarray(runs))
        if not np.isfinite(track):      # not slices of one sweep (steady runs, or no time series given)
            return None
        T = float(np.median(ctx.run_durations(runs)))
        h_max = max((h for c in ctx.channels for h, *_ in ctx.channel_lines(state, c, runs)), default=0.0)
        if h_max <= 0 or T <= 0:
            return None
        # search up to the acceleration that smears the highest line over 16 bins
        a_max = max(2 * np.pi * 16 * ctx.df / (h_max * T), 3.0 * track)

        def cost(a):
            trial = state.copy()
            trial.smear = float(a)
            return float(ctx.run_errors(trial, runs)[0].sum())

        res = optimize.minimize_scalar(cost, bounds=(0.0, a_max), method="bounded",
                                       options={"xatol": 1e-3 * a_max})
        if not (res.x > 1e-3 * a_max and res.fun < cost(0.0)):
            return None
        trial = state.copy()
        trial.smear = float(res.x)
        return SpinAcceleration(float(res.x), track, noise_estimate(ctx, trial))

    @staticmethod
    def candidates(ctx: Context, state: State, runs) -> list:
        e = SpinAcceleration.fit(ctx, state, runs)
        return [] if e is None else [e]


EFFECT_CLASSES = (MissingHarmonic, AmplitudeLaw, BroadbandFloor, FixedResonance, CrossCoupling, Sidebands,
                  SpeedRipple, CounterRotation, SpinAcceleration)


def _measure(ctx, state, direction, h, runs, skip=None):
    """Line amplitudes of (direction, h) pooled over the direction's channels: (amplitude, omega)."""
    ds, ws = [], []
    for c in DIRECTION_CHANNELS[direction]:
        if c not in ctx.channels:
            continue
        a = ctx.measure_line(state, c, h, runs, skip=skip)
        a = a / ctx.gain(state, c, h * ctx.omega[runs] / (2 * np.pi))     # the line before any resonance
        if state.ext is not None:
            a = a / ctx.modal_gain(state, c, h, runs)                      # ... and before the wheel's modes
        ok = np.isfinite(a)
        ds.append(a[ok])
        ws.append(ctx.omega[runs][ok])
    return np.concatenate(ds) if ds else np.empty(0), np.concatenate(ws) if ws else np.empty(0)


def _ridge_score(ctx, state, chans, runs, h_grid):
    """Mean normalised residual along f = h|Ω|/2π for every h of ``h_grid`` (pairs in band only)."""
    score = np.zeros(h_grid.size)
    count = np.zeros(h_grid.size)
    for c in chans:
        R = ctx.data(state, c)[runs] - ctx.predict(state, c, runs)
        z = R / ctx.floor_psd(state, c, runs)
        zmax = np.maximum(np.maximum(z, np.roll(z, 1, axis=1)), np.roll(z, -1, axis=1))
        k = np.rint(np.outer(h_grid, ctx.omega[runs]) / (2 * np.pi) / ctx.df).astype(int)   # (n_h, n_runs)
        inb = (k >= ctx.k_lo) & (k <= ctx.k_hi)
        vals = zmax[np.arange(runs.size)[None, :], np.clip(k, 0, ctx.f.size - 1)]
        vals = np.clip(vals, -5.0, 20.0)          # a presence-like score: strong lines count alike
        score += np.where(inb, vals, 0).sum(1)
        count += inb.sum(1)
    return np.where(count >= 6, score / np.maximum(count, 1), 0.0)


def ridge_peaks(ctx, state, chans, runs, n_max: int, h_min: float = 0.1):
    """Harmonic numbers of the strongest residual ridges (local maxima of the ridge score above
    10 noise standard deviations of a pooled residual)."""
    top = ctx.k_hi * ctx.df * 2 * np.pi / max(ctx.omega[runs].min(), 1e-9)
    h_grid = np.arange(h_min, min(top, 40.0), 0.005)
    if h_grid.size < 3:
        return []
    s = _ridge_score(ctx, state, chans, runs, h_grid)
    # a noise bin of the pooled mean has std ~ sqrt(2/dof)/sqrt(n_pairs); demand a clear ridge
    thr = 10.0 * np.sqrt(2.0 / ctx.dof) / np.sqrt(max(runs.size * len(chans), 1)) + 0.5
    peaks = np.nonzero((s[1:-1] > s[:-2]) & (s[1:-1] >= s[2:]) & (s[1:-1] > thr))[0] + 1
    peaks = peaks[np.argsort(-s[peaks])][:n_max]
    return [float(h_grid[i]) for i in peaks]


def refine_h(ctx, state, chans, runs, h, n_iter: int = 3):
    """Harmonic number of the ridge near ``h``: in every (run, channel) the residual peak within
    ±2 bins of h|Ω|/2π, its frequency refined by a log-parabola through three bins (accurate to a few
    hundredths of a bin for a Hann window), and h = least squares of f_peak = h·|Ω|/2π over the peaks
    standing clear of the noise (residual > 20 × floor)."""
    for _ in range(n_iter):
        fs_, ws_ = [], []
        for c in chans:
            R = ctx.data(state, c)[runs] - ctx.predict(state, c, runs)
            z = R / ctx.floor_psd(state, c, runs)
            k0 = np.rint(h * ctx.omega[runs] / (2 * np.pi) / ctx.df).astype(int)
            offs = np.arange(-2, 3)
            k = np.clip(k0[:, None] + offs, 1, ctx.f.size - 2)
            rows = np.arange(runs.size)[:, None]
            # the peak of the residual itself (z = R / floor can peak beside it where the floor dips), kept
            # only where it is a local maximum standing clear of the noise
            kp = k[np.arange(runs.size), np.argmax(R[rows, k], axis=1)]
            r = np.arange(runs.size)
            ok = (kp - 1 >= ctx.k_lo) & (kp + 1 <= ctx.k_hi) & (z[r, kp] > 20.0)
            ok &= (R[r, kp] >= R[r, kp - 1]) & (R[r, kp] >= R[r, np.minimum(kp + 1, ctx.f.size - 1)])
            lo, mid, hi = (np.log(np.maximum(R[r, kp + j], 1e-300)) for j in (-1, 0, 1))
            den = lo - 2 * mid + hi
            with np.errstate(divide="ignore", invalid="ignore"):
                dl = np.clip(np.where(den < 0, 0.5 * (lo - hi) / den, 0.0), -0.5, 0.5)
            fs_.append(((kp + dl) * ctx.df)[ok])
            ws_.append((ctx.omega[runs] / (2 * np.pi))[ok])
        f_pk, w_hz = np.concatenate(fs_), np.concatenate(ws_)
        if f_pk.size < 3:
            return h
        h = float(np.sum(f_pk * w_hz) / np.sum(w_hz**2))
    return h


# --------------------------------------------------------------------------- greedy search

@dataclass
class Hypothesis:
    """A fitted effect judged on held-out speeds."""

    effect: object
    gain: float           # held-out improvement / held-out data power
    gain_fraction: float  # improvement / held-out unexplained power
    t: float              # improvement in standard errors
    passed: bool
    iteration: int


@dataclass
class Diagnosis:
    model: WheelModel
    state_before: State
    state_after: State
    error_before: float
    error_after: float
    rms_error_before: float
    rms_error_after: float
    hypotheses: list
    iterations: int
    ctx: Context

    @property
    def effects(self) -> list:
        return self.state_after.effects

    def summary(self) -> dict:
        chosen = [h for h in self.hypotheses if h.passed]
        return {
            "metric": METRIC,
            "base": self.state_before.base,
            "metric_definition": "sum over channels, runs and %d-bin bands of |data - model| power / sum of "
                                 "data power (each channel divided by the mean power of its unit group)" % BAND_BINS,
            "error_before": self.error_before, "error_after": self.error_after,
            "rms_relative_error_before": self.rms_error_before, "rms_relative_error_after": self.rms_error_after,
            "iterations": self.iterations,
            "effects": [effect_entry(h) for h in chosen],
            "hypotheses": [effect_entry(h) for h in self.hypotheses],
        }


def effect_entry(hyp: Hypothesis) -> dict:
    e = hyp.effect
    d = {"kind": e.kind, **e.params(), "channel": list(e.channels),
         "evidence": {"heldout_gain": hyp.gain, "heldout_gain_fraction": hyp.gain_fraction,
                      "t": hyp.t, "passed": hyp.passed, "iteration": hyp.iteration}}
    return d


def _judge(ctx, state, effect, k_sigma, min_gain, iteration):
    """Held-out evidence of ``effect`` (fitted on the fit runs) added to ``state``.

    gain = Σ over held-out runs of the drop in misplaced power; its noise standard error is
    sqrt(Σ_bands min(|Δ|, σ)²·P_b), Δ = the change of the residual D − M (of the model M, or of the data
    D as read for a measurement correction such as ``cross_coupling``): if the data were M_0 plus
    Gaussian noise of std σ, a band's term max(|D − M| − zσ, 0) changes by at most |Δ| (and by about σ
    when the change is larger), and changes at all only with probability P_b = 2·Q(z − |Δ|/σ).  Passes
    when gain > k_sigma·SE and gain ≥ min_gain × the held-out misplaced power."""
    runs = ctx.held_runs
    chans = [c for c in effect.channels if c in ctx.channels]
    e0, _, p0 = ctx.run_errors(state, runs, chans, detail=True)
    e1, _, p1 = ctx.run_errors(effect.apply(state), runs, chans, detail=True)
    e0_all, all_tot = ctx.run_errors(state, runs)
    var = 0.0
    for c in chans:
        dm, sig = np.abs(p1[c][0] - p0[c][0]), p0[c][1]       # |Δ(D − M)|
        r = dm / np.maximum(sig, 1e-300)
        # a band's term changes only when the noise reaches past the forgiven NOISE_Z·σ less |ΔM|
        p_change = np.minimum(2.0 * stats.norm.sf(np.maximum(NOISE_Z - r, 0.0)), 1.0)
        var += float(np.sum(np.minimum(dm, sig) ** 2 * p_change))
    se = np.sqrt(var)
    d = e0 - e1
    gain = float(d.sum())
    t = gain / se if se > 0 else (np.inf if gain > 0 else 0.0)
    frac = gain / max(float(e0_all.sum()), 1e-300)
    passed = bool(t > k_sigma and frac >= min_gain)
    return Hypothesis(effect, gain / max(float(all_tot.sum()), 1e-300), frac, float(t), passed, iteration)


def _refit(ctx, state, effect):
    """The chosen effect refitted on every run."""
    runs = ctx.runs
    if isinstance(effect, MissingHarmonic):
        return MissingHarmonic.fit(ctx, state, effect.direction, effect.h, runs) or effect
    if isinstance(effect, AmplitudeLaw):
        return AmplitudeLaw.fit(ctx, state, effect.direction, effect.h, runs) or effect
    if isinstance(effect, BroadbandFloor):
        return BroadbandFloor.fit(ctx, state, effect.channel, runs) or effect
    if isinstance(effect, FixedResonance):
        return FixedResonance.fit(ctx, state, effect.channels, runs, effect.f_r, effect.role) or effect
    if isinstance(effect, CrossCoupling):
        return CrossCoupling.fit(ctx, state, runs) or effect
    if isinstance(effect, Sidebands):
        return Sidebands.fit(ctx, state, effect.direction, effect.h, runs, effect.f_mod) or effect
    if isinstance(effect, SpeedRipple):
        return SpeedRipple.fit(ctx, state, runs, effect.f_ripple, effect.exponent) or effect
    if isinstance(effect, CounterRotation):
        return CounterRotation.fit(ctx, state, effect.direction, effect.h, runs) or effect
    if isinstance(effect, SpinAcceleration):
        return SpinAcceleration.fit(ctx, state, runs) or effect
    return effect


def initial_state(ctx: Context, model: WheelModel, ext_params=None) -> State:
    """The model with a speed-independent instrument noise per channel: the off-line band means
    (:meth:`Context.offline_bands`) averaged over every run, interpolated between the centres of the
    bands with a positive mean (the median block floor of the data outside them).  ``ext_params``:
    the :class:`rwadist.extended.ExtendedParams` of the extended base, or None (empirical base)."""
    rough = {c: np.nanmedian(ctx.floor[c][ctx.runs], axis=0) for c in ctx.channels}
    state = State(copy.deepcopy(model), rough, ext=ext_params)
    return State(state.model, noise_estimate(ctx, state), ext=ext_params)


def noise_estimate(ctx: Context, state: State) -> dict:
    """Instrument noise per channel (unit²/Hz on the grid) as :func:`initial_state` estimates it, the
    model's lines (as ``state`` predicts them, smear included) masked out; ``state.noise`` is the
    fallback outside the bands."""
    noise = {}
    fc = ctx.band_centres()
    for c in ctx.channels:
        ok = ctx.runs[np.isfinite(ctx.sp.psd[c][ctx.runs, 0])]
        y, cnt = ctx.offline_bands(state, c, ok)
        mean = np.sum(y * cnt, 0) / np.maximum(cnt.sum(0), 1)
        # a band whose mean is not positive (the model's line skirts exceed the data there: coherent lines
        # closer than the kernel beat in the Welch estimate) says nothing about the noise: interpolated over
        good = (cnt.sum(0) > 0) & (mean > 0)
        n = np.array(state.noise[c], dtype=float)
        band = (ctx.f >= fc[0]) & (ctx.f <= fc[-1])
        if good.sum() >= 2:
            n[band] = np.interp(ctx.f[band], fc[good], mean[good])
        noise[c] = n
    return noise


BASES = ("empirical", "extended", "auto")


def resolve_base(model: WheelModel | None, base: str = "empirical") -> str:
    """'empirical' or 'extended' for a ``base`` request: 'auto' is 'extended' when the model has an
    ``analytical`` section, else 'empirical'; 'extended' without one is a ValueError."""
    if base not in BASES:
        raise ValueError(f"diagnose: base must be one of {BASES}, got {base!r}")
    has = model is not None and bool(getattr(model, "analytical", None))
    if base == "auto":
        return "extended" if has else "empirical"
    if base == "extended" and not has:
        raise ValueError("diagnose: base 'extended' needs a model with an analytical section "
                         "(rwadist.extended.params_to_dict), e.g. preset('ithaco-e').to_model()")
    return base


def diagnose(spectra: Spectra, model: WheelModel | None = None, k_sigma: float = 4.0, min_gain: float = 0.05,
             max_iterations: int = 8, channels=None, test=None, base: str = "empirical") -> Diagnosis:
    """Greedy effect search on ``spectra`` starting from ``model`` (default: the empirical fit).

    k_sigma, min_gain : acceptance rule (module docstring).  test : the SteadyTest ``spectra`` were
    computed from (50 % overlap), needed for ``cross_coupling`` (phases); without it that class is not tried.
    base : 'empirical' (default; lines C·Ω², hard mounted), 'extended' (lines through the suspension modes of
    the model's ``analytical`` section, :func:`rwadist.extended.steady_lines`) or 'auto' (extended when the
    model has an analytical section); see :func:`resolve_base`.
    Returns a :class:`Diagnosis` whose ``model`` carries the added harmonics in ``empirical`` and every
    effect in ``effects``.
    """
    if model is None:
        model = fit_empirical(spectra).model
    base = resolve_base(model, base)
    ext_params = None
    if base == "extended":
        from .extended import params_from_model

        ext_params = params_from_model(model, getattr(model, "name", "<model>"))
    ctx = Context(spectra, channels, test)
    state0 = initial_state(ctx, model, ext_params)
    state = state0
    hyps = []
    it = 0
    for it in range(1, max_iterations + 1):
        cands = []
        for cls in EFFECT_CLASSES:
            cands += cls.candidates(ctx, state, ctx.fit_runs)
        judged = [_judge(ctx, state, e, k_sigma, min_gain, it) for e in cands]
        judged.sort(key=lambda h: -h.gain)
        passing = [h for h in judged if h.passed]
        for h in judged:
            h.passed = False
        if not passing:
            hyps += judged[:5]
            break
        best = passing[0]
        best.passed = True
        hyps += judged[:5]
        state = _refit(ctx, state, best.effect).apply(state)
        best.effect = state.effects[-1]
    else:
        it = max_iterations
    out = copy.deepcopy(state.model)
    out.effects = list(model.effects) + [effect_entry(h) for h in hyps if h.passed]
    out.provenance = dict(out.provenance, diagnose={"metric": METRIC, "base": base})
    return Diagnosis(out, state0, state, ctx.error(state0), ctx.error(state), ctx.rms_error(state0),
                     ctx.rms_error(state), hyps, it, ctx)


# --------------------------------------------------------------------------- report (I/O at the edge)

def _clean(x):
    """JSON-safe: numpy scalars to Python, NaN/inf to None."""
    if isinstance(x, dict):
        return {k: _clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_clean(v) for v in x]
    if isinstance(x, (np.floating, float)):
        return float(x) if np.isfinite(x) else None
    if isinstance(x, np.integer):
        return int(x)
    return x


def rms_vs_speed(diag: Diagnosis) -> dict:
    """Columns: speed_rpm, then per channel data RMS and model RMS before and after (band [f_lo, top])."""
    ctx = diag.ctx
    runs = ctx.runs
    cols = {"speed_rpm": np.asarray(ctx.sp.speed, float)[runs] * RAD_S_TO_RPM}
    for c in ctx.channels:
        u = CHANNEL_UNIT[c]
        cols[f"data_{c}_rms_{u}"] = np.sqrt(ctx.band_sums(ctx.sp.psd[c][runs]).sum(1))
        for tag, st in (("before", diag.state_before), ("after", diag.state_after)):
            cols[f"model_{tag}_{c}_rms_{u}"] = np.sqrt(ctx.band_sums(ctx.predict(st, c, runs)).sum(1))
    return cols


def _fmt(v, spec: str) -> str:
    """A parameter for the report: floats with ``spec``, short lists space-separated (no commas: CSV)."""
    if isinstance(v, (list, tuple)):
        return "[" + " ".join(_fmt(x, spec) for x in v) + "]"
    return format(v, spec) if isinstance(v, float) else str(v)


def _write_csv(path, cols: dict):
    names = list(cols)
    arr = np.column_stack([np.asarray(cols[k], dtype=float) for k in names])
    np.savetxt(path, arr, delimiter=",", header=",".join(names), comments="", fmt="%.8g")


def _waterfall_figure(diag: Diagnosis):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    ctx = diag.ctx
    runs = ctx.runs[np.argsort(ctx.omega[ctx.runs])]
    chans = ctx.channels
    fig = Figure(figsize=(3.2 * len(chans), 6.4))
    FigureCanvasAgg(fig)
    fc = ctx.band_centres()
    rpm = ctx.omega[runs] * RAD_S_TO_RPM
    for j, c in enumerate(chans):
        for i, (tag, st) in enumerate((("before", diag.state_before), ("after", diag.state_after))):
            D = ctx.band_sums(ctx.data(st, c)[runs])
            ax = fig.add_subplot(2, len(chans), i * len(chans) + j + 1)
            M = ctx.band_sums(ctx.predict(st, c, runs))
            with np.errstate(divide="ignore", invalid="ignore"):
                r = 10 * np.log10(np.maximum(D, 1e-300) / np.maximum(M, 1e-300))
            im = ax.pcolormesh(fc, rpm, r, cmap="RdBu_r", vmin=-10, vmax=10, shading="nearest")
            ax.set_title(f"{c} {tag}", fontsize=9)
            if j == 0:
                ax.set_ylabel("speed, rpm")
            if i == 1:
                ax.set_xlabel("f, Hz")
    fig.colorbar(im, ax=fig.axes, label="data / model, dB (band power)")
    return fig


def _rms_figure(diag: Diagnosis, cols: dict):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    ctx = diag.ctx
    fig = Figure(figsize=(12, 6))
    FigureCanvasAgg(fig)
    order = np.argsort(cols["speed_rpm"])
    for j, c in enumerate(ctx.channels):
        ax = fig.add_subplot(2, 3, j + 1)
        u = CHANNEL_UNIT[c]
        for key, style, lab in ((f"data_{c}_rms_{u}", "k.", "data"), (f"model_before_{c}_rms_{u}", "C0-", "before"),
                                (f"model_after_{c}_rms_{u}", "C3--", "after")):
            ax.plot(cols["speed_rpm"][order], cols[key][order], style, label=lab, ms=3)
        ax.set_title(f"{c} RMS, {u}", fontsize=9)
        ax.set_xlabel("speed, rpm")
        if j == 0:
            ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def write_report(diag: Diagnosis, out_dir) -> list:
    """summary.json, model.json (the improved model), rms_vs_speed.csv/.png, residual_waterfall.png,
    hypotheses.csv and report.md into ``out_dir``; returns the paths."""
    import json
    from pathlib import Path

    from .model import save

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    files = []
    summary = _clean(diag.summary())
    p = out / "summary.json"
    p.write_text(json.dumps(summary, indent=2) + "\n")
    files.append(p)
    model = copy.deepcopy(diag.model)
    model.effects = _clean(model.effects)
    files.append(save(model, out / "model.json"))
    cols = rms_vs_speed(diag)
    p = out / "rms_vs_speed.csv"
    _write_csv(p, cols)
    files.append(p)
    p = out / "rms_vs_speed.png"
    _rms_figure(diag, cols).savefig(p, dpi=100)
    files.append(p)
    p = out / "residual_waterfall.png"
    _waterfall_figure(diag).savefig(p, dpi=100)
    files.append(p)
    p = out / "hypotheses.csv"
    lines = ["iteration,kind,channels,parameters,heldout_gain,heldout_gain_fraction,t,passed"]
    for h in diag.hypotheses:
        e = h.effect
        par = ";".join(f"{k}={_fmt(v, '.6g')}" for k, v in e.params().items()
                       if not (isinstance(v, list) and len(v) > 4)).replace(",", " ")     # one CSV field
        lines.append(f"{h.iteration},{e.kind},{' '.join(e.channels)},{par},{h.gain:.6g},{h.gain_fraction:.6g},"
                     f"{h.t:.4g},{h.passed}")
    p.write_text("\n".join(lines) + "\n")
    files.append(p)
    md = ["# rwadist diagnose", "",
          f"Metric: `{METRIC}` — {summary['metric_definition']}; a band's misplaced power is counted beyond "
          f"{NOISE_Z:g} noise standard deviations.", "",
          f"- base: {diag.state_before.base} (lines "
          + ("through the suspension modes of the model's analytical section)" if diag.state_before.ext is not None
             else "C·Ω², hard mounted)"),
          f"- error before: {diag.error_before:.4g}", f"- error after: {diag.error_after:.4g}",
          f"- RMS-vs-speed relative error before / after: {diag.rms_error_before:.4g} / {diag.rms_error_after:.4g}",
          f"- iterations: {diag.iterations}", "", "## Effects added", ""]
    chosen = [h for h in diag.hypotheses if h.passed]
    if not chosen:
        md.append("None: nothing left in the residual passed the held-out test.")
    for h in chosen:
        par = ", ".join(f"{k} = {_fmt(v, '.5g')}"
                        for k, v in h.effect.params().items() if not (isinstance(v, list) and len(v) > 4))
        md.append(f"- **{h.effect.kind}** ({par}): held-out gain {h.gain_fraction:.1%} of the unexplained "
                  f"power, {h.t:.1f} noise standard errors")
    md += ["", "## Hypotheses (best five per iteration)", "", "see `hypotheses.csv`", "",
           "![residual](residual_waterfall.png)", "", "![rms](rms_vs_speed.png)", ""]
    p = out / "report.md"
    p.write_text("\n".join(md))
    files.append(p)
    return files
