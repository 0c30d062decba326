"""Effects injected into the wheel family's data (:mod:`family_wheel`) from the generator's own physics (not
rwadist.inject), each with its truth and its "signature above the noise" computed from that truth alone.

Known effects (a class of ``rwadist/diagnose/effects/`` describes each; :attr:`Effect.expects` names it):

=================== =================================================================================
missing_harmonic    a co-rotating line at h (1.5: a half-order rub) of fraction × the direction's
                    imbalance coefficient, through the modes
amplitude_law       the wheel's line (direction, h) growing as Ω^p (p = 3) instead of Ω², equal at the
                    mid speed
broadband_floor     random rotor forces (radial x, y, axial) of PSD ∝ Ω^p/(1 + (f/fc)⁴), RMS level ×
                    the top-speed static-imbalance force at the top speed, through the suspension
fixed_resonance     a resonance at a fixed frequency, H(r) = (1 − r² + 2jgζr)/(1 − r² + 2jζr) (peak gain g
                    at r = f/f_r = 1), on one direction's channels (role wheel_mode, a housing mode) or on
                    every channel (role test_stand: a fixture, :class:`Fixture`)
cross_coupling      a load-cell reference offset r: T += r × F (the noise-free forces; sensor noise after)
sidebands           a line amplitude-modulated at a fixed f_mod: the carrier and two lines at f ± f_mod of
                    depth/2, coherent with it, each through the modes at its own frequency
speed_ripple        Ω(t) = Ω0 + ΔΩ sin(2π f_r t + φ): every line's load a(Ω(t))·e^{ihψ(t)} (the
                    imbalances' tangential −iΩ̇ term included) expanded in its Fourier series over a
                    ripple period, each component through the modes
counter_rotation    that share of a radial line's power turned counter-rotating
speed_sidebands     the imbalance amplitude-modulated at δ·Ω: lines at (1 ± δ)Ω, depth/2 each, coherent
lever_arm_noise     a load-cell offset and force sensors noisier than the torque ones
=================== =================================================================================

Unknown kinds (no class describes them; :attr:`Effect.expects` is "unexplained" with the signature a
description should give):

=================== =================================================================================
pickup              electrical pickup: lines at 50, 100, 150, 250 Hz, the same on every channel (common
                    mode), at every speed
crosstalk           the Fz channel carries a copy of the Fy channel's content (κ = 0.2)
moving_resonance    an axial resonance (a disc's umbrella mode) whose frequency stiffens with speed,
                    f_r² = f0² + (κΩ/2π)²: no whirl (axial) and not fixed
hump                a broadband hump at a fixed frequency on every channel (a pump or fan on the stand),
                    the same at every speed
drift               the load cell's gain drifting over the test: runs recorded in shuffled speed order,
                    every line × (1 + fraction·(τ − ½)), τ the run's place in recording time
=================== =================================================================================

Signature above the noise (:meth:`Effect.signature`), from the truth alone, never from a detector: a line
part (the effect's own content: its lines, the change it makes to the wheel's lines, or the part of a law
the best C·Ω² does not absorb) is measured at the resolution the data hold, a Hann window over the whole
record: its power in its nearest bin over the white noise's plus the window leakage of every other line of
the run at another frequency (random phases: powers add); it stands above the noise at >= 10 dB, and the
effect is eligible when some part does in >= 3 runs.  A floor (broadband floor, hump, the lever arm's
force noise in the corrected torques) is eligible when it raises the noise floor by >= 1 dB in its band in
>= 3 runs.
"""
from __future__ import annotations

import family_wheel as fw
import numpy as np
from scipy import signal

#: a line part stands above the noise at this power ratio in its own bin (10 dB)
SIGNATURE_RATIO = 10.0
#: ... in at least this many runs (a speed law needs several speeds)
SIGNATURE_RUNS = 3
#: lowest bin measured (the Hann window's DC lobe and the mean below)
SIGNATURE_MIN_BIN = 4
#: a floor counts when it raises the noise by this much in its band (dB)
SIGNATURE_FLOOR_DB = 1.0


def peak_resonance(f_hz, f_r, zeta, gain):
    """H(r) = (1 − r² + 2jgζr)/(1 − r² + 2jζr), r = f/f_r: 1 far from f_r, g at f_r (the fixture and
    housing-mode shape of docs/diagnose.md, written out here)."""
    r = np.asarray(f_hz, dtype=float) / np.asarray(f_r, dtype=float)
    return (1 - r**2 + 2j * gain * zeta * r) / (1 - r**2 + 2j * zeta * r)


def hann_leakage(n: int, delta_bins) -> np.ndarray:
    """|W(δ)|²/|W(0)|² of the periodic Hann window of n samples at offsets δ (bins), closed form:
    W(δ) = ½D(δ) − ¼D(δ − 1) − ¼D(δ + 1), D the Dirichlet sum Σ_k e^{−2πiδk/n}."""
    d = np.asarray(delta_bins, dtype=float)

    def dirichlet(x):
        num = 1 - np.exp(-2j * np.pi * x)
        den = 1 - np.exp(-2j * np.pi * x / n)
        near = np.abs(den) < 1e-12
        return np.where(near, n * np.exp(-1j * np.pi * x * (n - 1) / n), num / np.where(near, 1.0, den))

    W = 0.5 * dirichlet(d) - 0.25 * dirichlet(d - 1) - 0.25 * dirichlet(d + 1)
    return np.abs(W) ** 2 / (n / 2.0) ** 2


def line_ratios(data: fw.Steady, run: int, channels, f_hz, amps) -> np.ndarray:
    """Power of each line part (amplitudes ``amps`` at ``f_hz`` in ``channels`` of run ``run``) in its nearest
    whole-record Hann bin over the white noise's plus the leakage of every line of the run at another
    frequency into that bin (their phases random: powers add).  0 below SIGNATURE_MIN_BIN or above the
    anti-alias limit."""
    n = data.signals.shape[2]
    df = data.sample_rate / n
    comp, A = data.components[run]
    ch, f_p, a_p = (np.atleast_1d(np.asarray(x)) for x in (channels, f_hz, amps))
    k = np.rint(f_p / df)
    f = comp.w / (2 * np.pi)
    other = np.abs(f[None, :] - f_p[:, None]) > 1e-9                             # (parts, comps)
    leak = np.sum(np.where(other, np.abs(A[:, ch].T) ** 2 * hann_leakage(n, k[:, None] - f[None, :] / df), 0.0),
                  axis=1)
    part = a_p**2 * hann_leakage(n, k - f_p / df)
    # the noise's bin power in units of a bin-centred line's: a line of amplitude a has (a n/4)², the noise
    # σ²·Σw² = σ²·3n/8, so the noise is worth a line of amplitude² 6σ²/n
    r = part / (leak + 6.0 * data.noise_std[ch] ** 2 / n)
    return np.where((k >= SIGNATURE_MIN_BIN) & (f_p < fw.ANTI_ALIAS * data.sample_rate), r, 0.0)


def parts_signature(data: fw.Steady, parts) -> dict:
    """Eligibility of line parts: ``parts`` = [(run, channel, f Hz, amplitude)]."""
    best = np.zeros(len(data.speeds))
    arr = np.array(parts, dtype=float).reshape(-1, 4)
    for run in np.unique(arr[:, 0]).astype(int):
        p = arr[arr[:, 0] == run]
        best[run] = line_ratios(data, run, p[:, 1].astype(int), p[:, 2], p[:, 3]).max()
    n_ok = int(np.sum(best >= SIGNATURE_RATIO))
    return {"eligible": n_ok >= SIGNATURE_RUNS,
            "text": f"{_db(best.max())} dB max over noise+leakage, {n_ok}/{best.size} runs >= "
                    f"{_db(SIGNATURE_RATIO)} dB"}


def floor_signature(rise_db) -> dict:
    rise = np.asarray(rise_db, dtype=float)
    n_ok = int(np.sum(rise >= SIGNATURE_FLOOR_DB))
    return {"eligible": n_ok >= SIGNATURE_RUNS,
            "text": f"floor rise {rise.max():.1f} dB max, {n_ok}/{rise.size} runs >= {SIGNATURE_FLOOR_DB:g} dB"}


def _db(x) -> str:
    return f"{10 * np.log10(max(float(x), 1e-30)):.0f}"


def _tagged(data, tag, channels=None):
    """Line parts of every component tagged ``tag``: [(run, channel, f, |A|)]."""
    out = []
    for i, (comp, A) in enumerate(data.components):
        for j, tg in enumerate(comp.tag):
            if tg == tag:
                for ch in (channels if channels is not None else range(6)):
                    if abs(A[j, ch]) > 0:
                        out.append((i, ch, comp.w[j] / (2 * np.pi), abs(A[j, ch])))
    return out


def _changed(data, factor, channels):
    """Line parts of the change a multiplicative path factor made: |A·(1 − 1/factor(f, run))| per channel."""
    out = []
    for i, (comp, A) in enumerate(data.components):
        f = comp.w / (2 * np.pi)
        g = factor(f, data.speeds[i])
        for ch in channels:
            d = np.abs(A[:, ch] * (1 - 1 / g))
            out += [(i, ch, f[j], d[j]) for j in np.flatnonzero(d > 0) if comp.direction[j] in fw.DIRECTIONS]
    return out


class Effect:
    """Base: ``kind``, ``params`` and what diagnose should make of it (``expects``: a registry kind, or
    "unexplained"; ``describe``: the signature a description should give for an unknown kind)."""

    kind = ""
    expects = ""
    describe = ""

    def __init__(self, **params):
        self.params = params

    def truth(self) -> dict:
        return {"kind": self.kind, "expects": self.expects, "describe": self.describe,
                **{k: (list(v) if isinstance(v, tuple) else v) for k, v in self.params.items()}}

    def signature(self, wheel, data) -> dict:
        raise NotImplementedError


def _find_line(lines, direction, h):
    for ln in lines:
        if ln.direction == direction and abs(ln.h - h) < 1e-9:
            return ln
    raise ValueError(f"the wheel has no {direction} line at h = {h:g}")


class MissingHarmonic(Effect):
    kind = expects = "missing_harmonic"

    def __init__(self, direction="radial_force", h=1.5, fraction=0.3):
        super().__init__(direction=direction, h=h, fraction=fraction)

    def lines(self, wheel, lines):
        p = self.params
        C = p["fraction"] * wheel.imbalance(p["direction"] if p["direction"] != "axial_force" else "radial_force")
        return lines + (fw.Line(p["direction"], p["h"], C, 1.0, self.kind),)

    def signature(self, wheel, data):
        return parts_signature(data, _tagged(data, self.kind))


class AmplitudeLaw(Effect):
    kind = expects = "amplitude_law"

    def __init__(self, direction="radial_force", h=2.0, exponent=3.0):
        super().__init__(direction=direction, h=h, exponent=exponent)

    def lines(self, wheel, lines):
        p = self.params
        ln = _find_line(lines, p["direction"], p["h"])
        w_mid = 0.5 * (wheel.min_rpm + wheel.max_rpm) * fw.RPM
        new = fw.Line(ln.direction, ln.h, ln.C, ln.co, self.kind, p["exponent"], w_mid)
        return tuple(new if x is ln else x for x in lines)

    def signature(self, wheel, data):
        """The part of the law that the best C·Ω² (least squares over the runs' free loads) leaves."""
        p = self.params
        om = data.speeds
        a = np.abs(om / (0.5 * (wheel.min_rpm + wheel.max_rpm) * fw.RPM)) ** p["exponent"]
        c_fit = np.sum(a * om**2) / np.sum(om**4)
        left = np.abs(1 - c_fit * om**2 / a)
        parts = [(r, ch, f, amp * left[r]) for r, ch, f, amp in _tagged(data, self.kind)]
        return parts_signature(data, parts)


class BroadbandFloor(Effect):
    kind = expects = "broadband_floor"

    def __init__(self, level=0.05, exponent=3.0, fc_hz=60.0):
        super().__init__(level=level, exponent=exponent, fc_hz=fc_hz)

    def _psd(self, wheel, omega, f_hz, omega_max):
        p = self.params
        rms = p["level"] * wheel.imbalance("radial_force") * omega_max**2
        s0 = rms**2 / (p["fc_hz"] * np.pi / (2 * np.sqrt(2)))        # ∫ df/(1 + (f/fc)⁴) = fc·π/(2√2)
        return s0 * (omega / omega_max) ** p["exponent"] / (1 + (np.asarray(f_hz) / p["fc_hz"]) ** 4)

    def load_floor(self, wheel, omega, f_hz, rng, fs, n):
        S = self._psd(wheel, omega, f_hz, wheel.max_rpm * fw.RPM)
        return {"radial_force": fw.white_spectrum(S, rng, fs, n, 2), "axial_force": fw.white_spectrum(S, rng, fs, n, 1)}

    def signature(self, wheel, data):
        p = self.params
        f = np.linspace(1.0, 2 * p["fc_hz"], 200)
        rises = []
        for om in data.speeds:
            S = self._psd(wheel, om, f, wheel.max_rpm * fw.RPM)
            at_cell = S * np.abs(fw.transfer(wheel, "radial_force", 2 * np.pi * f, om)[:, 0, 0]) ** 2
            noise = 2 * data.noise_std[0] ** 2 / data.sample_rate
            rises.append(10 * np.log10(1 + np.mean(at_cell) / noise))
        return floor_signature(rises)


class FixedResonance(Effect):
    """role "wheel_mode": a housing mode on one direction's channels; :class:`Fixture` is role test_stand."""

    kind = expects = "fixed_resonance"
    role = "wheel_mode"

    def __init__(self, f_hz, zeta=0.03, gain=5.0, direction="radial_force"):
        super().__init__(f_hz=f_hz, zeta=zeta, gain=gain, direction=direction, role=self.role)

    def _channels(self):
        return fw.DIRECTION_CHANNELS[self.params["direction"]]

    def gain(self, f_hz, omega):
        p = self.params
        g = np.ones((len(f_hz), 6), dtype=complex)
        g[:, list(self._channels())] = peak_resonance(f_hz, p["f_hz"], p["zeta"], p["gain"])[:, None]
        return g

    def signature(self, wheel, data):
        p = self.params
        return parts_signature(data, _changed(data, lambda f, om: peak_resonance(f, p["f_hz"], p["zeta"], p["gain"]),
                                              self._channels()))


class Fixture(FixedResonance):
    """A test-stand (fixture) resonance on every channel."""

    kind = "fixture"
    role = "test_stand"

    def __init__(self, f_hz, zeta=0.03, gain=5.0):
        super().__init__(f_hz=f_hz, zeta=zeta, gain=gain, direction="all")

    def _channels(self):
        return tuple(range(6))


class CrossCoupling(Effect):
    kind = expects = "cross_coupling"

    def __init__(self, r=(0.0, 0.0, -0.06)):
        super().__init__(r=tuple(float(x) for x in r))

    def mixing(self):
        """T += r × F: rows of the torques over the forces."""
        rx, ry, rz = self.params["r"]
        M = np.eye(6)
        M[3:, :3] = np.array([[0.0, -rz, ry], [rz, 0.0, -rx], [-ry, rx, 0.0]])
        return M

    def signature(self, wheel, data):
        """The r × F torque lines (the forces' lines moved into the torques) over the torque noise."""
        M = self.mixing()[3:, :3]
        parts = []
        for i, (comp, A) in enumerate(data.components):
            moved = A[:, :3] @ M.T
            f = comp.w / (2 * np.pi)
            parts += [(i, 3 + c, f[j], abs(moved[j, c])) for j in range(len(f)) for c in range(3) if abs(moved[j, c]) > 0]
        return parts_signature(data, parts)


class Sidebands(Effect):
    kind = expects = "sidebands"

    def __init__(self, direction="radial_force", h=1.0, depth=0.4, f_mod_hz=7.0):
        super().__init__(direction=direction, h=h, depth=depth, f_mod_hz=f_mod_hz)

    def _offsets(self, omega):
        return 2 * np.pi * self.params["f_mod_hz"]

    def components(self, comp, omega, run, rng, wheel):
        p = self.params
        phi_m = rng.uniform(0, 2 * np.pi)
        carrier = [j for j in range(len(comp)) if comp.direction[j] == p["direction"]
                   and abs(comp.w[j] - p["h"] * omega) < 1e-9 * omega and comp.tag[j] != self.kind]
        dw = self._offsets(omega)
        for j in carrier:
            for s in (1.0, -1.0):
                if comp.w[j] + s * dw > 0:
                    comp = comp.extend(comp.direction[j], comp.w[j] + s * dw, comp.sense[j],
                                       comp.c[j] * 0.5 * p["depth"] * np.exp(1j * s * phi_m), self.kind)
        return comp

    def signature(self, wheel, data):
        return parts_signature(data, _tagged(data, self.kind))


class SpeedSidebands(Sidebands):
    """The imbalance amplitude-modulated at per_rev × the speed: lines at (1 ± per_rev)·Ω."""

    kind = expects = "speed_sidebands"

    def __init__(self, per_rev=0.06, depth=0.4):
        Effect.__init__(self, direction="radial_force", h=1.0, depth=depth, per_rev=per_rev)

    def _offsets(self, omega):
        return self.params["per_rev"] * omega

    def signature(self, wheel, data):
        """Both sides must stand above the noise and the carrier's leakage in the same run."""
        parts = _tagged(data, self.kind, channels=(0,))
        by_run = {}
        for run, ch, f, a in parts:
            by_run.setdefault(run, []).append(float(line_ratios(data, run, ch, f, a)[0]))
        both = np.array([min(v) if len(v) == 2 else 0.0 for v in by_run.values()] or [0.0])
        n_ok = int(np.sum(both >= SIGNATURE_RATIO))
        return {"eligible": n_ok >= SIGNATURE_RUNS,
                "text": f"both sidebands over noise+carrier leakage {_db(both.max())} dB max, {n_ok} runs"}


class SpeedRipple(Effect):
    kind = expects = "speed_ripple"
    #: Fourier orders kept of each line's rippled load
    ORDERS = 8

    def __init__(self, f_ripple_hz=8.0, delta_omega=3.0):
        super().__init__(f_ripple_hz=f_ripple_hz, delta_omega=delta_omega)

    def _series(self, h, imbalance, omega, phase):
        """Fourier coefficients e_k (n_comp, 2K + 1; k = −K..K) over one ripple period of each load's envelope
        relative to its steady phasor, (Ω(t)/Ω0)²·e^{ih(ψ − Ω0 t)} (U(Ω² − iΩ̇)/Ω0² for an imbalance),
        ψ − Ω0 t = −(ΔΩ/2πf_r)(cos(2πf_r t + φ) − cos φ)."""
        p = self.params
        fr, dw = p["f_ripple_hz"], p["delta_omega"]
        m = 256
        th = 2 * np.pi * np.arange(m) / m + phase
        om = omega + dw * np.sin(th)
        dpsi = -dw / (2 * np.pi * fr) * (np.cos(th) - np.cos(phase))
        amp = np.where(np.asarray(imbalance)[:, None], (om**2 - 1j * dw * 2 * np.pi * fr * np.cos(th)) / omega**2,
                       (om / omega) ** 2)
        env = amp * np.exp(1j * np.asarray(h)[:, None] * dpsi[None, :])
        e = np.fft.fft(env, axis=1) / m
        k = np.arange(-self.ORDERS, self.ORDERS + 1)
        return k, e[:, k % m]

    def components(self, comp, omega, run, rng, wheel):
        phase = rng.uniform(0, 2 * np.pi)
        k, e = self._series(comp.w / omega, [t == "imbalance" for t in comp.tag], omega, phase)
        w = comp.w[:, None] + k[None, :] * 2 * np.pi * self.params["f_ripple_hz"]
        ok = w > 0
        rows, cols = np.nonzero(ok)
        tags = [comp.tag[j] if k[c] == 0 else self.kind for j, c in zip(rows, cols)]
        return fw.Components([comp.direction[j] for j in rows], w[ok], comp.sense[rows], (comp.c[:, None] * e)[ok],
                             tags)

    def signature(self, wheel, data):
        return parts_signature(data, _tagged(data, self.kind))


class SpeedWander(Effect):
    """The rotor's speed wandering within each run: Ω(t) = Ω₀·(1 + σ·g(t)), g an Ornstein-Uhlenbeck process of unit
    RMS and correlation time ``corr_s`` (exact discretisation) less its mean over the run, θ(t) its trapezoidal
    integral.  The lines' amplitudes (the cell's response) are taken at Ω₀, the mean: quasi-static only to first
    order in σ (the steady generator's loads at the run's mean speed, turning at the wandering angle).  ``angles`` keeps each
    run's θ (rad) for the tests.  Not an effect class: diagnose should track it (rwadist.order_tracking)."""

    kind = "speed_wander"
    expects = "order_tracking"

    def __init__(self, rms_rel=0.003, corr_s=1.0):
        super().__init__(rms_rel=rms_rel, corr_s=corr_s)
        self.angles: dict = {}

    def rotor_angle(self, t, omega, run, rng):
        dt = float(t[1] - t[0])
        a = np.exp(-dt / self.params["corr_s"])
        e = rng.standard_normal(t.size) * np.sqrt(1 - a * a)
        e[0] = rng.standard_normal()
        g = signal.lfilter([1.0], [1.0, -a], e)         # g[k] = a·g[k−1] + e[k]: unit variance throughout
        g -= g.mean()                   # the run's mean speed is Ω₀: the lines' amplitudes are the steady ones there
        om = omega * (1 + self.params["rms_rel"] * g)
        theta = np.concatenate([[0.0], np.cumsum(0.5 * (om[1:] + om[:-1]) * dt)])
        self.angles[run] = theta
        return theta


class CounterRotation(Effect):
    kind = expects = "counter_rotation"

    def __init__(self, direction="radial_force", h=1.0, fraction=0.3):
        super().__init__(direction=direction, h=h, fraction=fraction)

    def lines(self, wheel, lines):
        p = self.params
        ln = _find_line(lines, p["direction"], p["h"])
        new = fw.Line(ln.direction, ln.h, ln.C, ln.co * (1 - p["fraction"]), ln.name, ln.exponent, ln.omega_ref)
        return tuple(new if x is ln else x for x in lines)

    def signature(self, wheel, data):
        """The counter-rotating part against the noise alone in both channels of its pair (the x/y phase
        separates it from the co part at the same frequency)."""
        p = self.params
        chans = fw.DIRECTION_CHANNELS[p["direction"]]
        n = data.signals.shape[2]
        per_run = np.zeros(len(data.speeds))
        for i, (comp, A) in enumerate(data.components):
            for j in range(len(comp)):
                if (comp.direction[j] == p["direction"] and comp.sense[j] < 0
                        and abs(comp.w[j] - p["h"] * data.speeds[i]) < 1e-9 * data.speeds[i]
                        and comp.w[j] / (2 * np.pi) >= SIGNATURE_MIN_BIN * data.sample_rate / n):
                    per_run[i] = min(abs(A[j, ch]) ** 2 * n / (6 * data.noise_std[ch] ** 2) for ch in chans)
        n_ok = int(np.sum(per_run >= SIGNATURE_RATIO))
        return {"eligible": n_ok >= SIGNATURE_RUNS,
                "text": f"counter part over noise {_db(per_run.max())} dB max, {n_ok}/{per_run.size} runs"}


class LeverArmNoise(CrossCoupling):
    kind = expects = "lever_arm_noise"

    def __init__(self, r=(0.0, 0.0, -0.06), force_noise=0.078):
        Effect.__init__(self, r=tuple(float(x) for x in r), force_noise=force_noise)

    def _std(self, wheel):
        return self.params["force_noise"] * wheel.imbalance("radial_force") * (wheel.max_rpm * fw.RPM) ** 2

    def cell_signal(self, t, omega, run, rng, wheel, std):
        out = np.zeros((6, t.size))
        out[:3] = self._std(wheel) * rng.standard_normal((3, t.size))
        return out

    def signature(self, wheel, data):
        """The corrected torque floor's rise 10·log10(1 + r²σ_F²/σ_T²) and the r × F lines over the torque noise."""
        rz = abs(self.params["r"][2])
        sf2 = data.noise_std[0] ** 2 + self._std(wheel) ** 2
        rise = 10 * np.log10(1 + rz**2 * sf2 / data.noise_std[3] ** 2)
        lines = CrossCoupling.signature(self, wheel, data)
        ok = bool(rise >= SIGNATURE_FLOOR_DB and lines["eligible"])
        return {"eligible": ok, "text": f"Tx/Ty floor rise {rise:.1f} dB; r x F lines: {lines['text']}"}


# --------------------------------------------------------------------------------------- unknown kinds
def _top_loads(wheel) -> np.ndarray:
    """Per channel (6,) the wheel's imbalance load at its top speed: the radial force's on the forces, the radial
    torque's on the torques (the scale of a line added at the cell)."""
    top = wheel.max_rpm * fw.RPM
    return np.array([wheel.imbalance("radial_force")] * 3 + [wheel.imbalance("radial_torque")] * 3) * top**2


def _cell_lines(kind: str, w: np.ndarray, A: np.ndarray) -> tuple:
    """(Components, A) of lines at angular frequencies ``w`` (rad/s) added at the cell, tagged ``kind``, with the
    complex amplitudes ``A`` (len(w), 6)."""
    n = len(w)
    return fw.Components(["cell"] * n, w, np.ones(n), np.ones(n, complex), [kind] * n), A


class Pickup(Effect):
    kind = "pickup"
    expects = "unexplained"
    describe = "a line at one fixed frequency in every run (a 50 Hz family: electrical pickup)"

    def __init__(self, mains_hz=50.0, orders=(1, 2, 3, 5), level=0.03):
        super().__init__(mains_hz=mains_hz, orders=tuple(orders), level=level)

    def cell_components(self, omega, run, rng, wheel):
        p = self.params
        w = 2 * np.pi * p["mains_hz"] * np.array(p["orders"], dtype=float)
        phase = rng.uniform(0, 2 * np.pi, len(w))                       # common mode: one phase on every channel
        amp = p["level"] / np.array(p["orders"], dtype=float)
        return _cell_lines(self.kind, w, (amp * np.exp(1j * phase))[:, None] * _top_loads(wheel)[None, :])

    def signature(self, wheel, data):
        return parts_signature(data, _tagged(data, self.kind))


class Crosstalk(Effect):
    kind = "crosstalk"
    expects = "unexplained"
    describe = "a channel that carries a copy of another's content (Fz holds Fy's lines)"

    def __init__(self, source="Fy", target="Fz", kappa=0.2):
        super().__init__(source=source, target=target, kappa=kappa)

    def mixing(self):
        M = np.eye(6)
        M[fw.CHANNELS.index(self.params["target"]), fw.CHANNELS.index(self.params["source"])] = self.params["kappa"]
        return M

    def signature(self, wheel, data):
        p = self.params
        s, tgt = fw.CHANNELS.index(p["source"]), fw.CHANNELS.index(p["target"])
        parts = []
        for i, (comp, A) in enumerate(data.components):
            f = comp.w / (2 * np.pi)
            parts += [(i, tgt, f[j], p["kappa"] * abs(A[j, s])) for j in range(len(f)) if abs(A[j, s]) > 0]
        return parts_signature(data, parts)


class MovingResonance(Effect):
    kind = "moving_resonance"
    expects = "unexplained"
    describe = "a resonance whose frequency changes with speed in a way the gyroscopic whirl does not explain"

    def __init__(self, f0_hz, stiffening=1.5, zeta=0.03, gain=5.0, direction="axial_force"):
        super().__init__(f0_hz=f0_hz, stiffening=stiffening, zeta=zeta, gain=gain, direction=direction)

    def f_r(self, omega):
        p = self.params
        return np.sqrt(p["f0_hz"] ** 2 + (p["stiffening"] * omega / (2 * np.pi)) ** 2)

    def _h(self, f_hz, omega):
        p = self.params
        return peak_resonance(f_hz, self.f_r(omega), p["zeta"], p["gain"])

    def gain(self, f_hz, omega):
        g = np.ones((len(f_hz), 6), dtype=complex)
        g[:, list(fw.DIRECTION_CHANNELS[self.params["direction"]])] = self._h(f_hz, omega)[:, None]
        return g

    def signature(self, wheel, data):
        return parts_signature(data, _changed(data, self._h, fw.DIRECTION_CHANNELS[self.params["direction"]]))


class Hump(Effect):
    kind = "hump"
    expects = "unexplained"
    describe = "a broadband hump at a fixed frequency"

    def __init__(self, f_hz, q=8.0, rise_db=10.0):
        super().__init__(f_hz=f_hz, q=q, rise_db=rise_db)

    def _shape(self, f):
        """|H|² of a second-order band-pass of quality q centred at f_hz (1 at the centre)."""
        p = self.params
        r = np.asarray(f, float) / p["f_hz"]
        return 1.0 / (1.0 + p["q"] ** 2 * (r - 1.0 / np.maximum(r, 1e-12)) ** 2)

    def cell_signal(self, t, omega, run, rng, wheel, std):
        n, fs = t.size, 1.0 / (t[1] - t[0])
        f = np.fft.rfftfreq(n, 1 / fs)
        peak = (10 ** (self.params["rise_db"] / 10) - 1) * 2 * std[:, None] ** 2 / fs     # at the centre, per channel
        spec = fw.white_spectrum(np.ones_like(f), rng, fs, n, 6) * np.sqrt(self._shape(f)[:, None] * peak.T)
        return np.fft.irfft(spec.T, n)

    def signature(self, wheel, data):
        p = self.params
        f = np.linspace(p["f_hz"] * (1 - 0.5 / p["q"]), p["f_hz"] * (1 + 0.5 / p["q"]), 50)
        rise = 10 * np.log10(1 + (10 ** (p["rise_db"] / 10) - 1) * np.mean(self._shape(f)))
        ok = p["f_hz"] < fw.ANTI_ALIAS * data.sample_rate
        return floor_signature(np.full(len(data.speeds), rise if ok else 0.0))


class Drift(Effect):
    kind = "drift"
    expects = "unexplained"
    describe = "a run-to-run change (the lines' strength drifting with the order the runs were recorded in)"

    def __init__(self, fraction=0.4, seed=5):
        super().__init__(fraction=fraction, seed=seed)

    def _factor(self, run, n_runs):
        """The gain of run ``run`` (in speed order) of ``n_runs``: its place τ in a shuffled recording order."""
        order = np.random.default_rng(self.params["seed"]).permutation(n_runs)
        tau = order[run] / max(n_runs - 1, 1)
        return 1.0 + self.params["fraction"] * (tau - 0.5)

    def start(self, n_runs):
        self._n_runs = n_runs

    def components(self, comp, omega, run, rng, wheel):
        g = self._factor(run, self._n_runs)
        return fw.Components(comp.direction, comp.w, comp.sense, comp.c * g, comp.tag)

    def signature(self, wheel, data):
        """The run's lines × |g − 1| (the mean gain, 1, is absorbed by the lines' C)."""
        parts = []
        for i, (comp, A) in enumerate(data.components):
            d = abs(self._factor(i, len(data.speeds)) - 1.0) / self._factor(i, len(data.speeds))
            f = comp.w / (2 * np.pi)
            parts += [(i, ch, f[j], d * abs(A[j, ch])) for j in range(len(f)) for ch in range(6) if abs(A[j, ch]) > 0]
        return parts_signature(data, parts)


class WideHump(Hump):
    """A hump wider than an eighth of the band (a running median over an eighth follows it): a low-q band-pass."""
    kind = "wide_hump"
    describe = "a broadband hump wider than an eighth of the band"


class Rattle(Effect):
    kind = "rattle"
    expects = "unexplained"
    describe = "a hump in some runs only, made of impacts (a part rattling in every third run)"

    def __init__(self, f_hz, zeta=0.05, per_second=20.0, rise_db=15.0, every=3):
        super().__init__(f_hz=f_hz, zeta=zeta, per_second=per_second, rise_db=rise_db, every=every)

    def _ringing(self, fs):
        """(b, a) of a decaying sine at f_hz (damping ratio ζ) and the peak of its |H|² (digital, one-sided)."""
        from scipy import signal

        p = self.params
        w = 2 * np.pi * p["f_hz"] / fs
        a = [1.0, -2 * np.exp(-p["zeta"] * w) * np.cos(w), np.exp(-2 * p["zeta"] * w)]
        _, h = signal.freqz([1.0], a, worN=[w])
        return ([1.0], a), float(np.abs(h[0]) ** 2)

    def rattles(self, run: int) -> bool:
        return run % self.params["every"] == 1

    def cell_signal(self, t, omega, run, rng, wheel, std):
        from scipy import signal

        n, fs = t.size, 1.0 / (t[1] - t[0])
        out = np.zeros((6, n))
        if not self.rattles(run):
            return out
        p = self.params
        (b, a), peak = self._ringing(fs)
        rate = p["per_second"] / fs
        # impacts of random strength: the PSD at the ringing frequency (10^(rise/10) - 1) × the noise's, 2σ²/fs
        # one-sided for white noise, is rate·E[x²]·|H|²·2/fs
        for ch in (0, 1, 3, 4):
            x = (rng.random(n) < rate) * rng.standard_normal(n)
            gain = np.sqrt((10 ** (p["rise_db"] / 10) - 1) * std[ch] ** 2 / (rate * peak))
            out[ch] = gain * signal.lfilter(b, a, x)
        return out

    def signature(self, wheel, data):
        ok = self.params["f_hz"] < fw.ANTI_ALIAS * data.sample_rate
        rise = [self.params["rise_db"] if ok and self.rattles(i) else 0.0 for i in range(len(data.speeds))]
        return floor_signature(rise)


class AffineLine(Effect):
    kind = "affine_line"
    expects = "unexplained"
    describe = "a line at f0 + b × the speed on the axial channels (a source at f0 mixed with a rotor line)"

    def __init__(self, f0_hz, slope=0.5, level=0.03):
        super().__init__(f0_hz=f0_hz, slope=slope, level=level)

    def f_hz(self, omega):
        return self.params["f0_hz"] + self.params["slope"] * abs(omega) / (2 * np.pi)

    def cell_components(self, omega, run, rng, wheel):
        axial = np.isin(np.arange(6), [fw.CHANNELS.index("Fz"), fw.CHANNELS.index("Tz")])
        scale = np.where(axial, _top_loads(wheel) * self.params["level"], 0.0)
        w = np.array([2 * np.pi * self.f_hz(omega)])
        return _cell_lines(self.kind, w, np.exp(1j * rng.uniform(0, 2 * np.pi)) * scale[None, :])

    def signature(self, wheel, data):
        return parts_signature(data, _tagged(data, self.kind))


KNOWN = ("missing_harmonic", "amplitude_law", "broadband_floor", "fixed_resonance", "cross_coupling", "sidebands",
         "speed_ripple", "counter_rotation", "speed_sidebands", "lever_arm_noise")
UNKNOWN = ("pickup", "crosstalk", "moving_resonance", "hump", "drift", "wide_hump", "rattle", "affine_line")


def default_effect(kind: str, wheel) -> Effect:
    """The injection of ``kind`` the matrix makes on ``wheel`` (frequencies placed relative to its modes)."""
    lo = wheel.min_rpm * fw.RPM
    modes = sorted(wheel.modes_hz().values())
    if kind == "missing_harmonic":
        return MissingHarmonic()
    if kind == "amplitude_law":
        # the case: a law on a bearing line (its ball-pass-outer line, h 3-5)
        bpfo = next(ln for ln in wheel.lines if ln.direction == "radial_force" and ln.name == "BPFO")
        return AmplitudeLaw(h=bpfo.h)
    if kind == "broadband_floor":
        return BroadbandFloor(fc_hz=float(np.clip(0.6 * modes[0], 30.0, 200.0)))
    if kind == "fixed_resonance":
        # a housing mode between the two highest modes, on the radial forces
        return FixedResonance(f_hz=float(np.sqrt(modes[1] * modes[2])))
    if kind == "cross_coupling":
        return CrossCoupling()
    # a fixed offset 6 record bins off its carrier (resolved on the whole record), at least 5 Hz
    f_off = float(max(6 * wheel.sample_rate / wheel.n_samples, 5.0))
    if kind == "sidebands":
        return Sidebands(h=1.0, f_mod_hz=f_off)
    if kind == "speed_ripple":
        return SpeedRipple(f_ripple_hz=f_off, delta_omega=0.04 * lo)
    if kind == "counter_rotation":
        return CounterRotation()
    if kind == "speed_sidebands":
        return SpeedSidebands()
    if kind == "lever_arm_noise":
        return LeverArmNoise()
    if kind == "pickup":
        return Pickup()
    if kind == "crosstalk":
        return Crosstalk()
    if kind == "moving_resonance":
        return MovingResonance(f0_hz=float(0.5 * wheel.f_axial + 0.5 * modes[-1]), stiffening=1.5)
    if kind == "hump":
        return Hump(f_hz=float(np.sqrt(modes[0] * modes[1])))
    if kind == "drift":
        return Drift()
    top = fw.ANTI_ALIAS * wheel.sample_rate
    if kind == "wide_hump":
        # q 1.5: a half-power width of f/q, over a quarter of the band at 0.45 of the anti-aliased band
        return WideHump(f_hz=0.45 * top, q=1.5, rise_db=10.0)
    if kind == "rattle":
        return Rattle(f_hz=0.7 * top)
    if kind == "affine_line":
        return AffineLine(f0_hz=0.25 * top, slope=0.5)
    raise ValueError(f"unknown effect kind {kind!r}; known: {KNOWN + UNKNOWN}")
