"""A family of reaction wheels on a load cell, generated WITHOUT rwadist's physics (test and benchmark helper).

tests/independent_wheel.py does this for the thesis's E wheel; this module does it for any wheel of a family
(mass 2-15 kg, I_zz/I_rr 1.2-2.2, suspension modes 50-600 Hz, bearing-like line sets, speeds to 3000, 6000
and 10000 rpm, sample rates 2-10 kHz), in steady runs and in sweeps, so that what rwadist fits is checked on
wheels its own stand never made.  Only numpy; nothing is imported from rwadist.

Physics (small motion, linear, real coordinates).  A rigid rotor (mass M, polar and transverse inertia
I_zz, I_rr about its centre) on a suspension symmetric about that centre, inside a rigid housing bolted to
the load cell:

* radial translation  M ẍ + c_r ẋ + k_r x = F_x  (and y);
* rocking (θx, θy: small rotations of the spin axis about x and y; the spin axis is (θy, −θx, 1), so the
  transverse angular momentum is H_x = I_rr θ̇x + I_zz Ω θy, H_y = I_rr θ̇y − I_zz Ω θx, and dH/dt = T):
  I_rr θ̈x + I_zz Ω θ̇y + c_θ θ̇x + k_θ θx = T_x,
  I_rr θ̈y − I_zz Ω θ̇x + c_θ θ̇y + k_θ θy = T_y
  (dH/dt also holds I_zz Ω̇ (θy, −θx) while the wheel accelerates; the motor's torque I_zz Ω̇ acts about the
  rotor's own axis, whose transverse part is that same vector, so the two cancel);
* axial translation  M z̈ + c_z ż + k_z z = F_z.

The load cell reads the suspension's reaction on the housing, (k + c d/dt) of each coordinate, with its
reference at the rotor centre (a load-cell offset is an effect: :mod:`family_effects`); Tz carries no line
(the motor's reaction torque I_zz Ω̇ is the wheel's intended output, not a disturbance).

Loads.  A :class:`Line` (direction, h, C, co) is a free load of amplitude C·Ω² (or an amplitude law
C·Ω_ref²·(Ω/Ω_ref)^p) whose power is split co : 1 − co between a co-rotating part F_x + iF_y ∝ e^{+ihφ}
and a counter-rotating part ∝ e^{−ihφ} (φ = ∫Ω dt the rotor angle), each with its own random phase per
run; an axial line has no sense.  The static and dynamic imbalances are the lines named ``imbalance`` at
h = 1, co-rotating, U·(Ω² − iΩ̇)e^{iφ} (the −iΩ̇ part is the tangential force of the imbalance mass on an
accelerating rotor), with one phase per run between them fixed by the wheel's geometry.

Steady runs: every line component is solved by harmonic balance at its own frequency, the 2x2 complex
system Z(w)·X = F of x and y written out in real coordinates (:func:`transfer`).  Sweeps: the state
equations are integrated in time (:func:`sweep`), each component's forcing exactly over each sample interval
(an exponential input), in modal coordinates; the rocking system's gyroscopic terms are frozen over short
blocks (its eigenvalues follow Ω to first order inside a block).  A steady speed gives the harmonic balance
to 1e-9 (tests/test_family_wheel.py).

Noise: white, per channel, a fraction of the top-speed imbalance load of its group (forces U_s·Ω_max²,
torques U_d·Ω_max²).  Lines at or above 0.45 × the sample rate are not recorded (an ideal anti-alias filter).

Units SI (kg, m, s, N, N·m, rad/s); rpm only in arguments named ``*_rpm``; Hz for frequencies named ``f*``.
"""
from __future__ import annotations

import json
import os
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np

CHANNELS = ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")
COLUMNS = ("Fx_N", "Fy_N", "Fz_N", "Tx_Nm", "Ty_Nm", "Tz_Nm")
DIRECTIONS = ("radial_force", "radial_torque", "axial_force")
#: channels (indices into CHANNELS) of each load direction
DIRECTION_CHANNELS = {"radial_force": (0, 1), "radial_torque": (3, 4), "axial_force": (2,)}
RPM = 2.0 * np.pi / 60.0
#: lines at or above this fraction of the sample rate are not recorded (an ideal anti-alias filter)
ANTI_ALIAS = 0.45


@dataclass(frozen=True)
class Line:
    """One disturbance line of the wheel (a free load on the rotor).

    direction : "radial_force", "radial_torque" or "axial_force".  h : frequency / wheel speed.
    C : kg·m (forces) or kg·m² (torques); amplitude C·Ω² (exponent 2), else C·Ω_ref²·(|Ω|/Ω_ref)^exponent.
    co : co-rotating share of a radial line's power (1: co-rotating, 0: counter-rotating, 0.5: planar).
    name : what the line is ("imbalance", "cage", "BPFO", "2xBPFO", ...).
    """

    direction: str
    h: float
    C: float
    co: float = 1.0
    name: str = ""
    exponent: float = 2.0
    omega_ref: float = 1.0

    def amplitude(self, omega):
        """Free-load amplitude (N or N·m) at wheel speed(s) ``omega`` (rad/s)."""
        w = np.abs(np.asarray(omega, dtype=float))
        return self.C * self.omega_ref**2 * (w / self.omega_ref) ** self.exponent


@dataclass(frozen=True)
class Wheel:
    """A wheel and the test it is run in.

    mass kg, I_zz and I_rr kg·m²; f_* the suspension modes at rest (Hz: radial translation, rocking
    sqrt(k_θ/I_rr)/2π, axial) and zeta_* their damping ratios; lines (:class:`Line`, the imbalances named
    "imbalance"); imbalance_phase: the dynamic imbalance's phase ahead of the static one's, rad.  The test:
    min_rpm..max_rpm, sample_rate Hz, n_samples per steady run, n_speeds.
    """

    name: str
    mass: float
    I_zz: float
    I_rr: float
    f_trans: float
    f_rock: float
    f_axial: float
    zeta_trans: float
    zeta_rock: float
    zeta_axial: float
    lines: tuple
    min_rpm: float
    max_rpm: float
    sample_rate: float
    n_samples: int = 8192
    n_speeds: int = 24
    imbalance_phase: float = 0.6
    bearing: dict = field(default_factory=dict)

    @property
    def inertia_ratio(self) -> float:
        return self.I_zz / self.I_rr

    def subsystem(self, direction: str) -> tuple:
        """(inertia, damping, stiffness) of the direction's coordinates (SI)."""
        m, f, z = {"radial_force": (self.mass, self.f_trans, self.zeta_trans),
                   "radial_torque": (self.I_rr, self.f_rock, self.zeta_rock),
                   "axial_force": (self.mass, self.f_axial, self.zeta_axial)}[direction]
        k = m * (2 * np.pi * f) ** 2
        return m, 2 * z * np.sqrt(k * m), k

    def modes_hz(self) -> dict:
        """The suspension modes at rest (Hz), named as rwadist's ``suspension_modes`` reports them."""
        return {"radial_translation": self.f_trans, "rocking": self.f_rock, "axial": self.f_axial}

    def imbalance(self, direction: str) -> float:
        """C of the direction's imbalance line (kg·m or kg·m²); without one, its largest line's (0 if none)."""
        own = [ln.C for ln in self.lines if ln.direction == direction]
        named = [ln.C for ln in self.lines if ln.direction == direction and ln.name == "imbalance"]
        return float(named[0] if named else max(own, default=0.0))

    def truth(self) -> dict:
        """Everything the wheel is, as JSON-ready values."""
        d = asdict(self)
        d["lines"] = [asdict(ln) for ln in self.lines]
        d["inertia_ratio"] = self.inertia_ratio
        d["modes_hz"] = self.modes_hz()
        return d


# ----------------------------------------------------------------------------------------- the family
def bearing_ratios(n_balls: int, ball_over_pitch: float, contact_deg: float) -> dict:
    """Kinematic frequencies of a bearing with a stationary outer race, per shaft revolution: cage (FTF),
    ball pass outer (BPFO) and inner (BPFI), ball spin (BSF).  g = (d/D)·cos α."""
    g = ball_over_pitch * np.cos(np.radians(contact_deg))
    cage = 0.5 * (1.0 - g)
    return {"cage": cage, "BPFO": n_balls * cage, "BPFI": n_balls * (1.0 - cage),
            "BSF": 0.5 / ball_over_pitch * (1.0 - g * g)}


#: (mass kg, I_zz/I_rr, rotor radius m, modes Hz (translation, rocking, axial), max rpm, sample rate Hz,
#:  balls, d/D, contact deg, integer harmonics beyond 1x in the radial directions): eight wheels spanning the
#:  family's ranges.  #0 is the issue's new wheel (4.2 kg, ratio 1.56, 310/95/140 Hz, 600-6000 rpm, 5 kHz;
#:  8 balls, cage 0.385, BPFO 3.08, BPFI 4.92, no 2x or 3x radial lines: bearing lines near the integers
#:  are its strongest), #4 E-like
FAMILY_TABLE = (
    (4.2, 1.56, 0.12, (310.0, 95.0, 140.0), 6000.0, 5000.0, 8, 0.23, 0.0, False),
    (2.0, 1.20, 0.07, (520.0, 180.0, 260.0), 10000.0, 10000.0, 9, 0.26, 0.0, True),
    (15.0, 2.20, 0.22, (90.0, 50.0, 62.0), 3000.0, 2000.0, 11, 0.18, 20.0, False),
    (7.0, 1.80, 0.15, (230.0, 70.0, 120.0), 6000.0, 4000.0, 10, 0.20, 10.0, True),
    (10.6, 2.00, 0.1965, (227.7, 54.9, 70.0), 3000.0, 3840.0, 11, 0.16, 0.0, True),
    (3.0, 1.40, 0.09, (600.0, 250.0, 400.0), 10000.0, 8000.0, 9, 0.28, 25.0, False),
    (12.0, 1.65, 0.18, (150.0, 110.0, 85.0), 3000.0, 2500.0, 10, 0.21, 15.0, True),
    (5.5, 2.10, 0.13, (400.0, 130.0, 200.0), 10000.0, 6000.0, 9, 0.24, 5.0, False),
)


def make_wheel(index: int, mass, ratio, radius, modes, max_rpm, rate, balls, d_over_D, contact, integers=True,
               seed: int = 0) -> Wheel:
    """One wheel of the family: inertias from the rotor's size, imbalances from a balance grade, and a line
    set of integer harmonics (``integers``: 2x and 3x in the radial directions) and bearing lines (cage,
    BPFO, BPFI, 2×BSF and multiples) with random strengths and rotation senses, no two lines of a direction
    within 0.1 in h."""
    rng = np.random.default_rng([index, seed, 33])
    I_zz = 0.5 * mass * radius**2 * rng.uniform(1.0, 1.4)          # a rim-weighted rotor: above a disc's ½MR²
    I_rr = I_zz / ratio
    U_s = mass * rng.uniform(0.3e-6, 1.0e-6)                          # eccentricity 0.3-1 µm
    U_d = U_s * rng.uniform(0.25, 0.6)                                # kg·m² (kg·m × m)
    b = bearing_ratios(balls, d_over_D, contact)
    sense = lambda: float(rng.choice([1.0, 1.0, 0.0, 0.5, 0.8]))      # noqa: E731
    cand = {
        "radial_force": [("imbalance", 1.0, U_s, 1.0), ("2x", 2.0, 0.2, sense()), ("3x", 3.0, 0.1, sense()),
                         ("cage", b["cage"], 0.06, 0.0), ("BPFO", b["BPFO"], 0.25, sense()),
                         ("BPFI", b["BPFI"], 0.12, sense()), ("2xBSF", 2 * b["BSF"], 0.08, sense()),
                         ("2xBPFO", 2 * b["BPFO"], 0.08, sense())],
        "radial_torque": [("imbalance", 1.0, U_d, 1.0), ("2x", 2.0, 0.25, sense()),
                          ("BPFO", b["BPFO"], 0.2, sense()), ("BPFI", b["BPFI"], 0.1, sense())],
        "axial_force": [("1x", 1.0, 0.6, 1.0), ("2x", 2.0, 0.3, 1.0), ("BPFO", b["BPFO"], 0.3, 1.0),
                        ("3x", 3.0, 0.1, 1.0), ("2xBPFO", 2 * b["BPFO"], 0.1, 1.0)],
    }
    lines = []
    for d, items in cand.items():
        ref = U_d if d == "radial_torque" else U_s
        kept = []
        for name, h, c, co in items:
            if not integers and d != "axial_force" and name in ("2x", "3x"):
                continue
            C = c if name == "imbalance" else ref * c * rng.uniform(0.6, 1.5)
            if all(abs(h - k.h) >= 0.1 for k in kept):
                kept.append(Line(d, float(h), float(C), float(co), name))
        lines += kept
    f_t, f_r, f_a = modes
    return Wheel(name=f"family-{index}", mass=mass, I_zz=I_zz, I_rr=I_rr, f_trans=f_t, f_rock=f_r, f_axial=f_a,
                 zeta_trans=float(rng.uniform(0.005, 0.03)), zeta_rock=float(rng.uniform(0.005, 0.03)),
                 zeta_axial=float(rng.uniform(0.01, 0.05)), lines=tuple(lines), min_rpm=max_rpm / 10.0,
                 max_rpm=max_rpm, sample_rate=rate, imbalance_phase=float(rng.uniform(0, 2 * np.pi)),
                 bearing={"balls": balls, "d_over_D": d_over_D, "contact_deg": contact, **b})


def family(seed: int = 0) -> list:
    """The eight wheels of :data:`FAMILY_TABLE` (deterministic for a seed)."""
    return [make_wheel(i, *row, seed=seed) for i, row in enumerate(FAMILY_TABLE)]


def trial_wheel_a() -> Wheel:
    """Session 68's new-user trial wheel A (6 kg, I_zz/I_rr 1.6, translation 180 Hz, rocking 110 Hz, axial 260 Hz,
    300-6000 rpm at 4 kHz; a cage 0.41 and ball-pass 3.62 / 5.38 line set): its torque lines sparse (one imbalance
    20-40× the bearing lines), so the rocking whirl's course is read mostly on the imbalance line."""
    L = Line
    lines = [L("radial_force", 1.0, 5e-6, 1.0, "imbalance"), L("radial_force", 2.0, 4e-7), L("radial_force", 0.41, 2e-7),
             L("radial_force", 3.62, 3e-7), L("radial_force", 5.38, 2e-7), L("radial_force", 7.24, 1e-7),
             L("radial_torque", 1.0, 2e-6, 1.0, "imbalance"), L("radial_torque", 0.41, 5e-8),
             L("radial_torque", 3.62, 1e-7), L("radial_torque", 5.38, 6e-8), L("axial_force", 1.0, 3e-7),
             L("axial_force", 2.0, 2e-7), L("axial_force", 3.62, 4e-7), L("axial_force", 7.24, 2e-7)]
    return Wheel(name="trial-A", mass=6.0, I_zz=0.048, I_rr=0.03, f_trans=180.0, f_rock=110.0, f_axial=260.0,
                 zeta_trans=0.02, zeta_rock=0.02, zeta_axial=0.025, lines=tuple(lines), min_rpm=300.0,
                 max_rpm=6000.0, sample_rate=4000.0, n_speeds=24)


# ------------------------------------------------------------------------------ harmonic balance (steady)
def transfer(wheel: Wheel, direction: str, w, omega) -> np.ndarray:
    """Reaction over load of a direction at forcing frequencies ``w`` (rad/s, >= 0) and wheel speed
    ``omega`` (rad/s): (..., 2, 2) complex for the radial directions (x, y), (..., 1, 1) axial.

    Z·X = F with Z = [[k − m w² + iwc, iwg], [−iwg, k − m w² + iwc]] (g = I_zz·Ω for rocking, 0 for
    translation), the reaction (k + iwc)·X, so the transfer is (k + iwc)·Z⁻¹."""
    m, c, k = wheel.subsystem(direction)
    w = np.asarray(w, dtype=float)
    d = k - m * w**2 + 1j * w * c
    react = k + 1j * w * c
    if direction == "axial_force":
        return (react / d)[..., None, None]
    g = wheel.I_zz * np.asarray(omega, dtype=float) if direction == "radial_torque" else 0.0
    off = 1j * w * g
    det = d * d + off * off
    inv = np.stack([np.stack([d, -off], -1), np.stack([off, d], -1)], -2) / det[..., None, None]
    return react[..., None, None] * inv


def load_vector(direction: str, sense) -> np.ndarray:
    """Phasor pattern of a unit load component: co-rotating (sense +1) F_x = cos, F_y = sin -> (1, −i);
    counter-rotating (sense −1) F_x = cos, F_y = −sin -> (1, +i); axial (1,).  Shape (..., 2) or (..., 1)."""
    s = np.asarray(sense, dtype=float)
    if direction == "axial_force":
        return np.ones(s.shape + (1,), dtype=complex)
    return np.stack([np.ones_like(s, dtype=complex), -1j * s], -1)


@dataclass
class Components:
    """Line components of one run: direction (str per row), w rad/s (> 0), sense (+1/−1), c (complex load
    phasor, N or N·m: the load is Re(c·pattern·e^{iwt})), tag (the line's name or the effect that made it)."""

    direction: list
    w: np.ndarray
    sense: np.ndarray
    c: np.ndarray
    tag: list

    @staticmethod
    def empty():
        return Components([], np.zeros(0), np.zeros(0), np.zeros(0, complex), [])

    def __len__(self):
        return len(self.direction)

    def extend(self, direction, w, sense, c, tag):
        n = np.size(w)
        return Components(self.direction + [direction] * n if isinstance(direction, str) else self.direction + list(direction),
                          np.concatenate([self.w, np.atleast_1d(w).astype(float)]),
                          np.concatenate([self.sense, np.broadcast_to(np.asarray(sense, float), (n,))]),
                          np.concatenate([self.c, np.atleast_1d(c).astype(complex)]),
                          self.tag + ([tag] * n if isinstance(tag, str) else list(tag)))

    def select(self, mask):
        idx = np.flatnonzero(mask)
        return Components([self.direction[i] for i in idx], self.w[idx], self.sense[idx], self.c[idx],
                          [self.tag[i] for i in idx])


def line_components(lines, omega: float, rng, imbalance_phase: float = 0.0) -> Components:
    """The components of ``lines`` at steady speed ``omega`` (rad/s > 0) with random phases from ``rng``:
    a radial line's co part sqrt(co)·a and counter part sqrt(1 − co)·a (independent phases), an axial line
    a; the two imbalances share one phase (the dynamic one ``imbalance_phase`` ahead)."""
    out = Components.empty()
    beta = rng.uniform(0, 2 * np.pi)
    for ln in lines:
        a = float(ln.amplitude(omega))
        ph_co, ph_ct = rng.uniform(0, 2 * np.pi, 2)
        if ln.name == "imbalance":
            ph_co = beta + (imbalance_phase if ln.direction == "radial_torque" else 0.0)
        w = ln.h * omega
        if ln.direction == "axial_force":
            out = out.extend(ln.direction, w, 1.0, a * np.exp(1j * ph_co), ln.name)
            continue
        for s, share, ph in ((1.0, ln.co, ph_co), (-1.0, 1.0 - ln.co, ph_ct)):
            if share > 0:
                out = out.extend(ln.direction, w, s, np.sqrt(share) * a * np.exp(1j * ph), ln.name)
    return out


def cell_amplitudes(wheel: Wheel, comp: Components, omega: float) -> np.ndarray:
    """Complex amplitudes (n, 6) of every component at the load cell (channel = Re(A·e^{iwt}))."""
    A = np.zeros((len(comp), 6), dtype=complex)
    for d in DIRECTIONS:
        rows = np.array([i for i, x in enumerate(comp.direction) if x == d], dtype=int)
        if rows.size == 0:
            continue
        T = transfer(wheel, d, comp.w[rows], omega)
        f = load_vector(d, comp.sense[rows]) * comp.c[rows, None]
        A[np.ix_(rows, DIRECTION_CHANNELS[d])] = np.einsum("nij,nj->ni", T, f)
    return A


def whirl_hz(wheel: Wheel, omega) -> tuple:
    """(forward, backward) rocking whirl frequencies (Hz) at speed ``omega`` (rad/s), undamped closed form
    ν = ±aΩ/2 + sqrt((aΩ/2)² + ω0²), a = I_zz/I_rr, ω0 = 2π f_rock."""
    half = 0.5 * wheel.inertia_ratio * np.abs(np.asarray(omega, dtype=float))
    root = np.sqrt(half**2 + (2 * np.pi * wheel.f_rock) ** 2)
    return (root + half) / (2 * np.pi), (root - half) / (2 * np.pi)


def noise_std(wheel: Wheel, noise: float, omega_max: float) -> np.ndarray:
    """White-noise std per channel (6,): ``noise`` × the top-speed imbalance load of its group."""
    f = noise * wheel.imbalance("radial_force") * omega_max**2
    t = noise * wheel.imbalance("radial_torque") * omega_max**2
    return np.array([f, f, f, t, t, t])


def synthesize(f_hz: np.ndarray, A: np.ndarray, t: np.ndarray, block: int = 64) -> np.ndarray:
    """Σ Re(A·e^{2πift}) per channel: (6, len(t)) from component frequencies (n,) and amplitudes (n, 6), t
    uniform from t[0].  e^{2πif(t0 + jB + k)dt} = e^{2πif(t0 + jB)dt}·e^{2πifk dt}: one complex product per
    sample instead of an exponential."""
    n = t.size
    if len(f_hz) == 0:
        return np.zeros((A.shape[1], n))
    dt = (t[-1] - t[0]) / max(n - 1, 1)
    n_blk = -(-n // block)
    w = 2j * np.pi * np.asarray(f_hz, dtype=float)
    coarse = np.exp(np.outer(w, t[0] + np.arange(n_blk) * block * dt))          # (n_comp, n_blk)
    fine = np.exp(np.outer(w, np.arange(block) * dt))                         # (n_comp, block)
    E = (coarse[:, :, None] * fine[:, None, :]).reshape(len(f_hz), -1)[:, :n]
    return np.real(A.T @ E)


# ------------------------------------------------------------------------------------------ steady runs
@dataclass
class Steady:
    """Steady runs: speeds rad/s (n_runs,), sample_rate Hz, signals (n_runs, 6, n_samples), noise_std (6,)
    (the white sensor noise), per run its line components and their amplitudes at the cell
    (:class:`Components`, A (n, 6) complex: channel = Re(A·e^{2πift}), f = w/2π), truth."""

    speeds: np.ndarray
    sample_rate: float
    signals: np.ndarray
    noise_std: np.ndarray
    components: list
    truth: dict


def steady(wheel: Wheel, speeds_rpm=None, sample_rate=None, n_samples=None, noise: float = 0.01, seed: int = 0,
           effects=()) -> Steady:
    """Steady runs of ``wheel`` (default: its own test, ``n_speeds`` speeds min_rpm..max_rpm) with ``effects``
    (objects of :mod:`family_effects`; each may provide the hooks below, called in this order):

    * ``start(n_runs)``: told the number of runs first;
    * ``lines(wheel, lines) -> lines``: the wheel's line set changed (a law, a counter part, a new line);
    * ``components(comp, omega, run, rng, wheel) -> comp``: the run's load components changed;
    * ``gain(f_hz, omega) -> (n, 6)``: a multiplicative path gain at the cell (a fixture, a wheel mode);
    * ``mixing() -> (6, 6)``: a linear map of the cell's channels (a load-cell offset, crosstalk);
    * ``load_floor(wheel, omega, f_hz, rng) -> {direction: (n_f, k) complex}``: random loads on the rotor;
    * ``cell_components(omega, run, rng, wheel) -> Components, A (k, 6)``: lines added at the cell (pickup);
    * ``cell_signal(t, omega, run, rng, wheel, std) -> (6, n)``: added at the cell (a hump, sensor noise);
    * ``rotor_angle(t, omega, run, rng) -> (n,)``: the rotor's angle θ(t) rad when the speed moves within the run
      (a wander): every line of the rotor then turns at (w/Ω)·θ(t), its amplitude the steady one at ``omega``
      (not with ``cell_components``).
    """
    speeds_rpm = np.linspace(wheel.min_rpm, wheel.max_rpm, wheel.n_speeds) if speeds_rpm is None else speeds_rpm
    fs = float(sample_rate or wheel.sample_rate)
    n = int(n_samples or wheel.n_samples)
    omegas = np.asarray(speeds_rpm, dtype=float) * RPM
    rng = np.random.default_rng([seed, 7])
    lines = tuple(wheel.lines)
    for e in effects:
        lines = e.lines(wheel, lines) if hasattr(e, "lines") else lines
    std = noise_std(wheel, noise, float(omegas.max()))
    t = np.arange(n) / fs
    f_bins = np.fft.rfftfreq(n, 1 / fs)
    mix = np.eye(6)
    for e in effects:
        mix = e.mixing() @ mix if hasattr(e, "mixing") else mix
        if hasattr(e, "start"):
            e.start(len(omegas))
    signals = np.zeros((len(omegas), 6, n))
    comps = []
    for i, om in enumerate(omegas):
        comp = line_components(lines, om, rng, wheel.imbalance_phase)
        for e in effects:
            comp = e.components(comp, om, i, rng, wheel) if hasattr(e, "components") else comp
        comp = comp.select(comp.w / (2 * np.pi) < ANTI_ALIAS * fs)
        f = comp.w / (2 * np.pi)
        A = cell_amplitudes(wheel, comp, om) * _gains(effects, f, om)
        A = A @ mix.T
        for e in effects:
            if hasattr(e, "cell_components"):
                extra, A_extra = e.cell_components(om, i, rng, wheel)
                comp = comp.extend(extra.direction, extra.w, extra.sense, extra.c, extra.tag)
                A = np.vstack([A, A_extra])
        keep = comp.w / (2 * np.pi) < ANTI_ALIAS * fs
        comp, A = comp.select(keep), A[keep]
        f = comp.w / (2 * np.pi)
        angle = [e.rotor_angle(t, om, i, rng) for e in effects if hasattr(e, "rotor_angle")]
        if angle:                       # a wandering speed: each line at its order of the rotor's angle
            signals[i] = np.real(A.T @ np.exp(1j * np.outer(comp.w / om, angle[0])))
        else:
            signals[i] = synthesize(f, A, t)
        spec = _floor_spectrum(wheel, effects, om, f_bins, rng, fs, n)
        if spec is not None:
            spec = (spec * _gains(effects, f_bins, om)) @ mix.T
            signals[i] += np.fft.irfft(spec.T, n)
        for e in effects:
            if hasattr(e, "cell_signal"):
                signals[i] += e.cell_signal(t, om, i, rng, wheel, std)
        signals[i] += std[:, None] * rng.standard_normal((6, n))
        comps.append((comp, A))
    truth = {"wheel": wheel.truth(), "speeds_rad_s": omegas.tolist(), "sample_rate_hz": fs, "n_samples": n,
             "noise": noise, "noise_std": std.tolist(), "seed": seed,
             "effects": [e.truth() for e in effects if hasattr(e, "truth")]}
    return Steady(omegas, fs, signals, std, comps, truth)


def _gains(effects, f_hz, omega) -> np.ndarray:
    g = np.ones((len(f_hz), 6), dtype=complex)
    for e in effects:
        if hasattr(e, "gain"):
            g = g * e.gain(f_hz, omega)
    return g


def _floor_spectrum(wheel, effects, omega, f_bins, rng, fs, n):
    """rfft spectrum (n_f, 6) at the cell of every effect's random rotor loads (through the suspension), or None."""
    spec = None
    w = 2 * np.pi * f_bins
    for e in effects:
        if not hasattr(e, "load_floor"):
            continue
        spec = np.zeros((len(f_bins), 6), dtype=complex) if spec is None else spec
        for d, loads in e.load_floor(wheel, omega, f_bins, rng, fs, n).items():
            T = transfer(wheel, d, w, omega)
            spec[:, DIRECTION_CHANNELS[d]] += np.einsum("nij,nj->ni", T, loads)
    return spec


def white_spectrum(psd_one_sided, rng, fs: float, n: int, k: int = 1) -> np.ndarray:
    """rfft coefficients (n_f, k) of k independent stationary Gaussian noises of one-sided PSD
    ``psd_one_sided`` (unit²/Hz at np.fft.rfftfreq(n, 1/fs)); irfft of them has that PSD (E|X|² = n·S·fs/2)."""
    s = np.sqrt(np.maximum(np.asarray(psd_one_sided, float), 0.0) * fs * n / 2.0)[:, None]
    z = (rng.standard_normal((len(s), k)) + 1j * rng.standard_normal((len(s), k))) / np.sqrt(2.0)
    out = s * z
    out[0] = 0.0
    if n % 2 == 0:
        out[-1] = 0.0
    return out


# ------------------------------------------------------------------------------------------------ sweeps
def speed_profile(t, rpm_start: float, rpm_end: float, duration: float, profile: str = "linear") -> tuple:
    """(Ω rad/s, φ rad, dΩ/dt rad/s²) at times ``t`` (s; constant speed rpm_start before 0 and rpm_end after
    ``duration``).  "linear": constant acceleration; "exp": Ω_end + (Ω_start − Ω_end)·e^{−t/τ}, τ =
    duration/4 (a motor at full voltage against its back-EMF), reaching the end speed within 2 % at t =
    duration and held there."""
    t = np.asarray(t, dtype=float)
    w0, w1 = rpm_start * RPM, rpm_end * RPM
    tc = np.clip(t, 0.0, duration)
    if profile == "linear":
        a = (w1 - w0) / duration
        om = w0 + a * tc
        phi = w0 * tc + 0.5 * a * tc**2
        acc = np.where((t > 0) & (t < duration), a, 0.0)
    elif profile == "exp":
        tau = duration / 4.0
        e = np.exp(-tc / tau)
        om = w1 + (w0 - w1) * e
        phi = w1 * tc + (w0 - w1) * tau * (1.0 - e)
        acc = np.where((t > 0) & (t < duration), -(w0 - w1) / tau * e, 0.0)
    else:
        raise ValueError(f"profile {profile!r}: 'linear' or 'exp'")
    om_end = om[-1] if om.size else w1
    phi = phi + np.where(t < 0, w0 * t, 0.0) + np.where(t > duration, om_end * (t - duration), 0.0)
    return om, phi, acc


def _state_space(wheel: Wheel, direction: str, omega: float) -> tuple:
    """(A, dA/dΩ, B, C) of a direction's state x = (q, q̇): ẋ = A x + B u, reaction y = C x."""
    m, c, k = wheel.subsystem(direction)
    n = 1 if direction == "axial_force" else 2
    eye, zero = np.eye(n), np.zeros((n, n))
    J = np.array([[0.0, 1.0], [-1.0, 0.0]]) if n == 2 else zero
    gyro = wheel.I_zz if direction == "radial_torque" else 0.0
    A = np.block([[zero, eye], [-k * eye / m, -(c * eye + gyro * omega * J) / m]])
    dA = np.block([[zero, zero], [zero, -gyro * J / m]])
    B = np.vstack([zero, eye / m])
    C = np.hstack([k * eye, c * eye])
    return A, dA, B, C


#: rocking blocks: the gyroscopic terms frozen over at most this relative change of speed (the eigenvalues
#: follow Ω to first order inside a block; the eigenvectors are re-taken at each block)
BLOCK_SPEED_CHANGE = 1e-3
#: blocks end before the slowest mode's decay e^{-x} over them passes this x (the recurrence's dynamic range)
BLOCK_DECAY = 20.0


def _block_starts(om: np.ndarray, dt: float, decay: float, gyro: bool) -> np.ndarray:
    """Start indices of the integration blocks over the n = len(om) − 1 intervals: a new block each
    BLOCK_SPEED_CHANGE of travel in ln|Ω| (rocking only), and none longer than the decay limit."""
    n = om.size - 1
    starts = np.array([0])
    if gyro:
        lw = np.log(np.abs(om[:-1]))
        travel = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(lw)))])
        key = np.floor(travel / BLOCK_SPEED_CHANGE)
        starts = np.flatnonzero(np.diff(key, prepend=-1.0))
    max_len = max(int(BLOCK_DECAY / (decay * dt)), 1)
    bounds = np.append(starts, n)
    out = [np.arange(a, b, max_len) for a, b in zip(bounds[:-1], bounds[1:])]
    return np.concatenate(out)


def _integrate(wheel, direction, comps, om, dt, x0, chunk: int = 16384):
    """Reaction (n_samples, n_out) of one direction to load components comps = [(pattern (n_in,), u (n+1,)
    complex amplitude at the samples, θ (n+1,) phase at the samples)], the load Re(pattern·u·e^{iθ}), exactly
    integrated over each interval for an input u·e^{iθ} whose phase grows linearly across it; initial state
    x0 (complex).  Modal coordinates per block (A is affine in Ω: one batched eigendecomposition); inside a
    block q_{n+1} = e^{λ_n dt} q_n + g_n with λ_n first order in the interval's speed, solved by cumulative
    products and sums."""
    n = om.size - 1
    gyro = direction == "radial_torque"
    A0, dA, B, C = _state_space(wheel, direction, 0.0)
    decay = float(np.max(-np.linalg.eigvals(_state_space(wheel, direction, float(om[0]))[0]).real))
    starts = _block_starts(om, dt, decay, gyro)
    stops = np.append(starts[1:], n)
    mids = (starts + stops) // 2
    lam, V = np.linalg.eig(A0[None] + om[mids][:, None, None] * dA[None])            # (blocks, s), (blocks, s, s)
    Vi = np.linalg.inv(V)
    slope = np.einsum("bij,jk,bki->bi", Vi, dA, V) if gyro else np.zeros(lam.shape)
    patterns = np.array([p for p, _, _ in comps])                                     # (c, n_in)
    beta = np.einsum("bij,jk,ck->bic", Vi, B, patterns)                               # (blocks, s, c)
    block_of = np.repeat(np.arange(starts.size), stops - starts)
    w_int = 0.5 * (om[:-1] + om[1:])
    L = lam[block_of] + slope[block_of] * (w_int - om[mids][block_of])[:, None]      # (n, s)
    g = np.zeros(L.shape, dtype=complex)
    for a in range(0, n, chunk):
        sl = slice(a, min(a + chunk, n))
        dth = np.array([th[sl.start + 1:sl.stop + 1] - th[sl] for _, _, th in comps])            # (c, m)
        u_mid = np.array([0.5 * (u[sl] + u[sl.start + 1:sl.stop + 1]) * np.exp(1j * th[sl]) for _, u, th in comps])
        Ld = L[sl] * dt                                                                           # (m, s)
        z = 1j * dth.T[:, None, :] - Ld[:, :, None]                                               # (m, s, c)
        phi1 = np.where(np.abs(z) < 1e-8, 1.0 + 0.5 * z, np.expm1(z) / np.where(z == 0, 1.0, z))
        g[sl] = np.exp(Ld) * dt * np.einsum("msc,cm,msc->ms", beta[block_of[sl]], u_mid, phi1)
    out = np.zeros((n, C.shape[0]))
    x = x0.astype(complex)
    for b, (a, e) in enumerate(zip(starts, stops)):
        logp = np.concatenate([np.zeros((1, lam.shape[1])), np.cumsum(L[a:e] * dt, axis=0)])     # log P_0..P_len
        P = np.exp(logp)
        q = P * (Vi[b] @ x + np.concatenate([np.zeros((1, lam.shape[1])), np.cumsum(g[a:e] / P[1:], axis=0)]))
        xs = q @ V[b].T                                                                           # (len + 1, states)
        out[a:e] = np.real(xs[:-1] @ C.T)
        x = xs[-1]
    return out


def _steady_state(wheel, direction, comps, omega, dt):
    """Complex state at sample 0 of the direction's steady response to ``comps`` at constant speed ``omega``:
    (iw − A)⁻¹·B·pattern·u·e^{iθ} per component, w its phase rate."""
    A, _, B, _ = _state_space(wheel, direction, omega)
    x = np.zeros(A.shape[0], dtype=complex)
    for pattern, u, th in comps:
        w = (th[1] - th[0]) / dt
        x += np.linalg.solve(1j * w * np.eye(A.shape[0]) - A, B @ pattern) * u[0] * np.exp(1j * th[0])
    return x


@dataclass
class SweepData:
    """A sweep: time s (n,), signals (6, n), speed Ω rad/s (n,), sample_rate Hz, truth."""

    time: np.ndarray
    signals: np.ndarray
    speed: np.ndarray
    sample_rate: float
    truth: dict


def sweep(wheel: Wheel, rpm_start: float, rpm_end: float, duration: float, sample_rate=None, noise: float = 0.01,
          seed: int = 0, profile: str = "linear", effects=(), preroll: float = 1.0) -> SweepData:
    """A run-up (rpm_start < rpm_end) or run-down of ``duration`` s, integrated in time (module docstring).
    ``effects``: only their ``lines``, ``gain`` (applied to the recorded channels in the frequency domain: a
    fixed resonance is linear time-invariant) and ``mixing`` hooks act on a sweep.  The record starts after
    ``preroll`` s at rpm_start (the wheel's and the fixture's responses settled) and ends at ``duration``."""
    fs = float(sample_rate or wheel.sample_rate)
    dt = 1.0 / fs
    n_pre = int(round(preroll * fs))
    n_rec = int(round(duration * fs))
    t = (np.arange(n_pre + n_rec + 1) - n_pre) * dt
    om, phi, acc = speed_profile(t, rpm_start, rpm_end, duration, profile)
    rng = np.random.default_rng([seed, 11])
    lines = tuple(wheel.lines)
    for e in effects:
        lines = e.lines(wheel, lines) if hasattr(e, "lines") else lines
    beta = rng.uniform(0, 2 * np.pi)
    total = np.zeros((6, t.size - 1))
    nyq_w = ANTI_ALIAS * 2 * np.pi * fs
    for d in DIRECTIONS:
        comps = []
        for ln in (x for x in lines if x.direction == d):
            a = ln.amplitude(om).astype(complex)
            if ln.name == "imbalance":
                a = a - 1j * ln.C * acc * (ln.exponent == 2.0)           # U·(Ω² − iΩ̇)
            # an ideal anti-alias filter: the line fades out over the last 2 % below the cut
            a = a * np.clip((nyq_w - ln.h * om) / (0.02 * nyq_w), 0.0, 1.0)
            ph = rng.uniform(0, 2 * np.pi, 2)
            if ln.name == "imbalance":
                ph[0] = beta + (wheel.imbalance_phase if d == "radial_torque" else 0.0)
            th = ln.h * phi
            if d == "axial_force":
                comps.append((load_vector(d, 1.0), a * np.exp(1j * ph[0]), th))
                continue
            # a counter part: F_x + iF_y ∝ e^{−ihφ}, i.e. pattern (1, +i) on the conjugate phasor
            if ln.co > 0:
                comps.append((load_vector(d, 1.0), np.sqrt(ln.co) * a * np.exp(1j * ph[0]), th))
            if ln.co < 1:
                comps.append((load_vector(d, -1.0), np.sqrt(1 - ln.co) * np.conj(a) * np.exp(-1j * ph[1]), th))
        if not comps:
            continue
        x0 = _steady_state(wheel, d, comps, float(om[0]), dt)
        total[list(DIRECTION_CHANNELS[d])] += _integrate(wheel, d, comps, om, dt, x0).T
    total = _sweep_filters(total, effects, fs, om[:-1])
    std = noise_std(wheel, noise, float(np.max(om)))
    rec = total[:, n_pre:] + std[:, None] * rng.standard_normal((6, n_rec))
    truth = {"wheel": wheel.truth(), "rpm_start": rpm_start, "rpm_end": rpm_end, "duration_s": duration,
             "profile": profile, "sample_rate_hz": fs, "noise": noise, "noise_std": std.tolist(), "seed": seed,
             "effects": [e.truth() for e in effects if hasattr(e, "truth")]}
    return SweepData(t[n_pre:-1] - t[n_pre], rec, om[n_pre:-1], fs, truth)


def _sweep_filters(x: np.ndarray, effects, fs: float, om) -> np.ndarray:
    """The effects' gains (time-invariant: evaluated at the mean speed) applied to the channels (6, n) in the
    frequency domain, zero-padded (a linear, causal response), then their mixing."""
    gains = [e for e in effects if hasattr(e, "gain")]
    if gains:
        n = x.shape[1]
        nfft = 1 << int(np.ceil(np.log2(2 * n)))
        f = np.fft.rfftfreq(nfft, 1 / fs)
        X = np.fft.rfft(x, nfft, axis=1) * _gains(gains, f, float(np.mean(om))).T
        x = np.fft.irfft(X, nfft, axis=1)[:, :n]
    for e in effects:
        if hasattr(e, "mixing"):
            x = e.mixing() @ x
    return x


# ------------------------------------------------------------------------------ the interchange format
def _write_csv(path: Path, columns: dict, fmt: str = "%.10g") -> None:
    names = list(columns)
    data = np.column_stack([np.asarray(columns[c], dtype=float) for c in names])
    tmp = path.with_name(path.name + ".tmp")
    # the bytes of np.savetxt(fh, data, delimiter=",", fmt=fmt), formatted by one % of the whole table (1.6x faster)
    row = ",".join([fmt] * data.shape[1]) + "\n"
    with open(tmp, "w") as fh:
        fh.write(",".join(names) + "\n")
        fh.write((row * data.shape[0]) % tuple(data.ravel().tolist()))
    os.replace(tmp, path)


def write_steady(data: Steady, directory, wheel_name: str = "") -> Path:
    """The runs as a steady-test directory of docs/formats.md (runs.csv, run_NNNN.csv, meta.json); the truth
    is not written there (see :func:`write_truth`)."""
    d = Path(directory)
    d.mkdir(parents=True, exist_ok=True)
    n = data.signals.shape[2]
    t = np.arange(n) / data.sample_rate
    rows = []
    for i, om in enumerate(data.speeds):
        name = f"run_{i:04d}.csv"
        _write_csv(d / name, {"time_s": t, **{c: data.signals[i, j] for j, c in enumerate(COLUMNS)}})
        rows.append(f"{name},{om / RPM:.10g}")
    (d / "runs.csv").write_text("file,speed_rpm\n" + "\n".join(rows) + "\n")
    (d / "meta.json").write_text(json.dumps({"sample_rate_hz": data.sample_rate,
                                             "wheel": {"name": wheel_name or "family wheel"}}, indent=1))
    return d


def write_sweep(data: SweepData, path, tach: bool = True) -> Path:
    """The sweep as one interchange CSV (time_s, channels, and speed_rpm when ``tach``) and its sidecar
    NAME.meta.json."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    cols = {"time_s": data.time, **{c: data.signals[j] for j, c in enumerate(COLUMNS)}}
    if tach:
        cols["speed_rpm"] = data.speed / RPM
    _write_csv(p, cols)
    p.with_suffix(".meta.json").write_text(json.dumps({"sample_rate_hz": data.sample_rate}, indent=1))
    return p


def write_truth(truth: dict, path) -> Path:
    """The generator's truth as JSON (kept apart from the data rwadist reads)."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(json.dumps(truth, indent=1, default=float))
    return p


def with_lines(wheel: Wheel, lines) -> Wheel:
    return replace(wheel, lines=tuple(lines))
