"""Self-contained runtime of the extended wheel model for the FMU (numpy only, no rwadist).

This file and its two siblings (:mod:`rwadist.fmu.runtime_model`, the model file; :mod:`rwadist.fmu.runtime_math`,
closed forms and the native kernel's interface) are copied verbatim into the FMU's ``resources/`` so a host needs
only Python and numpy; next to them goes a verbatim copy of :mod:`rwadist.schema` (``rwadist_model_schema.py``),
the one reader of the model file (a test pins the copies to the sources byte for byte).  This module holds the
stepping model, :class:`WheelRuntime`, and re-exports the siblings' public names.  It re-implements, step by step, the equations of :mod:`rwadist.extended` (rigid rotor
on a flexible suspension; see that module's docstring for the physics and sign conventions)
and is tested against :func:`rwadist.extended_time.simulate_time` to 1e-9 relative
(tests/test_fmu.py).  Everything is SI: rad/s, rad/s², s, N, N·m, kg, m.

One communication step [t_n, t_n + h] with wheel speed Ω_n and acceleration α (rad/s²):

* speed is linear over the step, Ω(τ) = Ω_n + α τ; rotor angle φ += (Ω_n + Ω_{n+1}) h / 2
  (exact for the linear speed, the trapezoid of ``simulate_time``);
* each forcing line is C·coef·amp(τ)·e^{iσh(φ_n + Δφ τ/h)}, amplitude linear over the step from
  C(Ω_n² − iΩ̇_n) to C(Ω_{n+1}² − iΩ̇_{n+1}) (the −iΩ̇ tangential term for imbalance lines only;
  Ω̇_n is the mean of the previous and this step's α -- the central difference of
  ``simulate_time`` -- and Ω̇_{n+1} = α);
* every mode is a linear state integrated exactly against that load over the step: radial and
  axial translation through their two complex eigen-coordinates (fixed poles), rocking through
  the exact 2×2 transition matrix at the step's mean speed (gyroscopic term frozen over a step);
* outputs are the suspension reactions at t_n + h (wheel frame, Fx, Fy, Fz, Tx, Ty, Tz) and
  their spacecraft-frame image F_sc = R F, T_sc = R T + r × F_sc.

The step runs in numpy, or, when the FMU carries its native library (built from
``rwadist/fmu/native/rwadist_fmu_native.c`` by ``rwadist fmu build`` where a C compiler is found), in
that library's ``rwadist_kernel_step`` -- the same equations in C, ~10× faster per step, tested
against this numpy code (:func:`load_kernel`, :data:`KERNEL_PARAMS`).
"""
from __future__ import annotations

import cmath
import importlib.util
import math
import os
import sys

import numpy as np

#: the runtime's sibling modules (``rwadist/fmu/<stem>.py``): the model file and the closed forms / native kernel
#: interface; ``rwadist/fmu/build.py`` ships each in the FMU's resources as :func:`fmu_file_name` (no import cycle:
#: neither imports the other, both are imported here)
SIBLINGS = ("runtime_model", "runtime_math")


def fmu_file_name(stem):
    """File name of sibling ``stem`` in the FMU's resources."""
    return f"rwadist_fmu_{stem}.py"


def _load_sibling(stem):
    """Sibling module ``stem``: its copy next to this file (inside an FMU, loaded under a name unique to
    this runtime, so two FMUs load side by side), else ``rwadist.fmu.<stem>`` (the source tree)."""
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), fmu_file_name(stem))
    if not os.path.isfile(path):
        return importlib.import_module(f"rwadist.fmu.{stem}")
    name = f"{__name__}_{stem}"
    mod = sys.modules.get(name)
    if mod is None:
        spec = importlib.util.spec_from_file_location(name, path)
        if spec is None or spec.loader is None:
            raise ImportError(f"rwadist FMU: cannot load the runtime module {path}")
        mod = importlib.util.module_from_spec(spec)
        sys.modules[name] = mod
        try:
            spec.loader.exec_module(mod)
        except BaseException:
            sys.modules.pop(name, None)
            raise
    return mod


_model = _load_sibling("runtime_model")
_math = _load_sibling("runtime_math")
#: the model-file schema the runtime reads with (the FMU's copy, or rwadist.schema)
_schema = _model._schema
# the split-off modules' public names, importable from here as before the split
SCHEMA_FILE = _model.SCHEMA_FILE
EFFECTS_DIR = _model.EFFECTS_DIR
UNITS_FILE = _model.UNITS_FILE
SCHEMA = _model.SCHEMA
SCHEMA_VERSION = _model.SCHEMA_VERSION
ANALYTICAL_KIND = _model.ANALYTICAL_KIND
DIRECTIONS = _model.DIRECTIONS
CHANNELS = _model.CHANNELS
PARAM_KEYS = _model.PARAM_KEYS
ModelError = _model.ModelError
IMBALANCE_H_TOL = _model.IMBALANCE_H_TOL
LAW_H_TOL = _model.LAW_H_TOL
read_document = _model.read_document
laws_from_doc = _model.laws_from_doc
effects_from_doc = _model.effects_from_doc
load_model = _model.load_model
model_from_doc = _model.model_from_doc
physics_of = _model.physics_of
components = _model.components
PLANAR_Y = _model.PLANAR_Y
rotation_check = _model.rotation_check
expand_lines = _model.expand_lines
fmu_switches = _model.fmu_switches
SWITCH_SLOTS = _model.SWITCH_SLOTS
quad_roots = _math.quad_roots
to_spacecraft = _math.to_spacecraft
frame12 = _math.frame12
load_kernel = _math.load_kernel
KERNEL_PARAMS = _math.KERNEL_PARAMS
KERNEL_COMP = _math.KERNEL_COMP
KERNEL_STRIDE = _math.KERNEL_STRIDE
KERNEL_RES = _math.KERNEL_RES

SMALL_Z = 1e-3

#: floor phasors are recomputed from the time every so many steps (rounding of the rotation stays ~1e-13)
FLOOR_RESYNC = 1000
#: most sinusoids the broadband floors may take (~200 MB with the rotation caches, ~3 ms per step)
FLOOR_MAX_COMPONENTS = 2_000_000
#: seed of the floors' phases when the FMU has none (seed -1): deterministic, still independent per sinusoid
FLOOR_DEFAULT_SEED = 20_251_122
#: a speed ripple needs this many communication steps per ripple period (the rotor's speed is linear over
#: a step: at 20 the sidebands are within ~1 % of their closed form)
RIPPLE_STEPS_PER_PERIOD = 20



def _switched(items, switch_of, key, off):
    """(items kept, the switches of those kept): ``items`` (ripples or floors of :func:`effects_from_doc`) without
    those whose FMU switch (``switch_of[key]``) is in ``off``."""
    items = list(items or [])
    names = list((switch_of or {}).get(key) or [None] * len(items))
    if off and items and switch_of is None:
        raise ModelError(f"effect switches {sorted(off)} off, but the {key} carry no switch_of (effects_from_doc)")
    kept = [(x, n) for x, n in zip(items, names) if n not in off]
    return [x for x, _ in kept], list(dict.fromkeys(n for _, n in kept if n is not None))


class WheelRuntime:
    """The extended wheel model as a stepping state machine.

    params, lines : from :func:`load_model`.  seed : None -> each line's phase 0 (the model
    file's), else phases = numpy default_rng(seed).uniform(0, 2π, len(lines)) over *all* lines
    (as ``simulate_time(seed=...)``), so switching effects off keeps the others' phases.
    imbalance, harmonics, modes : effect switches (modes off: the internal loads reach the
    interface directly).  start_steady : start from the closed-form steady state at the first
    step's speed instead of rest.  max_accel : |dΩ/dt| limit, rad/s².  max_step : largest
    communication step accepted, s.  dcm, position : mounting, wheel → spacecraft DCM (3×3,
    default identity) and interface position, m (default 0), for the spacecraft-frame outputs.
    kernel : ``rwadist_kernel_step`` from :func:`load_kernel`, or None to step in numpy.
    laws : diagnosed amplitude laws from :func:`laws_from_doc`; a line (same direction,
    |Δh| < LAW_H_TOL) with a law has amplitude A_ref·(|Ω|/Ω_ref)^p instead of C·Ω² (an imbalance
    line keeps its tangential term −i·C·Ω̇).  resonances, sidebands : diagnosed wheel-mode
    resonances and sidebands from :func:`effects_from_doc` (see there).  Sideband lines are appended
    after the model's lines (per sideband effect, per matching carrier: +f_mod then −f_mod; the
    order of ``rwadist.extended.apply_line_effects``) and the seed's phases are drawn over that
    whole list; they follow their carrier's imbalance/harmonics switch.

    ripples : diagnosed speed ripples (:func:`effects_from_doc`), each unless the FMU switch of its element is off
    (``switch_of``, ``**switches``: :func:`fmu_switches`, e.g. a speed ripple's): the rotor
    turns at the input speed plus r(t) = Σ ΔΩ_ref·(|Ω(t)|/Ω_ref)^q·sin(2π f_r t + θ) (t since t0; θ = 0
    without a seed, else uniform from ``default_rng((seed, 1))``).  Each step runs from Ω_n + r(t_n) to
    Ω_{n+1} + r(t_{n+1}) (linear in between, like any step), so the lines are phase and amplitude
    modulated through the same equations as a rippled input speed would be -- exactly the FMU fed that
    speed with the slope as acceleration (tested).  Switch it off when the input is a measured speed that
    already carries the ripple.  Input checks (finite, max_acceleration, jumps) apply to the input speed.

    floors : diagnosed broadband floors (:func:`effects_from_doc`), each unless its element's switch is off: each is
    added to its wheel-frame output channel (a blocked load, like the measurement it was fitted to) as
    g(Ω)·Σ_k a_k cos(2π f_k t + φ_k) with f_k = k·``floor_resolution`` (Hz) over the knots' span,
    a_k = sqrt(2·psd_ref(f_k)·df) and g = (|Ω|/Ω_ref)^{p/2} at the step's end speed: over one period
    1/df its mean square is Σ_k psd_ref(f_k)·df·g² (Parseval; the floor's integral) and its PSD at a
    resolution coarser than df is psd_ref·g².  Phases φ_k: independent, uniform, from
    ``default_rng((seed, 2))`` (``(FLOOR_DEFAULT_SEED, 2)`` without a seed): the channels and floors are
    incoherent with each other; two wheels need two seeds to be incoherent with each other (as their lines).
    The sum is kept as rotating phasors (one complex multiply per component per step), resynchronised to t
    every FLOOR_RESYNC steps.  The output is sampled at the host's steps: floor content above 1/(2h) folds
    back (the FMU slave warns once).
    """

    _floor_count: int           # steps since the floor phasors were set from the time (reset, floor_now)

    def __init__(self, params, lines, *, seed=None, imbalance=True, harmonics=True, modes=True,
                 start_steady=False, max_accel=500.0, max_step=0.01, dcm=None, position=None, kernel=None,
                 laws=None, resonances=None, sidebands=None, ripples=None, floors=None, switch_of=None,
                 floor_resolution=0.1, **switches):
        self.p = dict(params)
        names = [name for name, _ in fmu_switches()]
        unknown = sorted(set(switches) - set(names))
        if unknown:
            raise TypeError(f"WheelRuntime() got an unexpected keyword argument {unknown[0]!r} (effect switches: "
                            f"{', '.join(names)})")
        switched_off = {name for name in names if not switches.get(name, True)}
        if not (math.isfinite(max_accel) and max_accel > 0):
            raise ModelError(f"max_acceleration must be finite and > 0, got {max_accel!r}")
        if not (math.isfinite(max_step) and max_step > 0):
            raise ModelError(f"max_step_size must be finite and > 0, got {max_step!r}")
        self.max_accel, self.max_step = float(max_accel), float(max_step)
        self.modes, self.start_steady = bool(modes), bool(start_steady)
        self.suspension = bool(self.p.get("suspension", True))
        if self.modes and not self.suspension:
            raise ModelError("modes: on, but the model has no suspension (analytical: missing -- an empirical "
                             "fit, harmonics only); it runs hard-mounted: set modes = false")
        self._init_components(lines, laws, sidebands, list(resonances or []), seed, imbalance, harmonics)
        self._init_poles()
        self._cache: dict[float, tuple] = {}
        self._init_mounting(dcm, position)
        self._kernel = kernel
        if kernel is not None:
            self._init_kernel()
        ripples, self.ripple_switches = _switched(ripples, switch_of, "ripples", switched_off)
        floors, _ = _switched(floors, switch_of, "floors", switched_off)
        self._init_ripple(ripples, seed)
        self._init_floor(floors, seed, floor_resolution)
        self.reset()

    def _init_components(self, lines, laws, sidebands, resonances, seed, imbalance, harmonics):
        """The model's lines (with the laws' and sidebands' changes, :func:`expand_lines`) as rotating components,
        one per whirl sense of a line that the imbalance/harmonics switches keep: their arrays (speed factor σh,
        frequency offset, coefficient, C, direction, law) and the resonance table acting on them."""
        full, self.laws_used, self.sidebands_used = expand_lines(lines, laws, sidebands)
        n = len(full)
        self.n_lines = n
        ph = (np.random.default_rng(int(seed)).uniform(0, 2 * np.pi, n) if seed is not None else np.zeros(n))
        sh, woff, coef, C, imb, dirs, law_rows, res = [], [], [], [], [], [], [], []
        for (d, h, c, sense, is_imb, lw, off), q in zip(full, ph):
            if (is_imb and not imbalance) or (not is_imb and not harmonics):
                continue
            rs = [(2.0 * math.pi * f_r, 2.0 * g * z, 2.0 * z) for dd, f_r, z, g in resonances if d in dd]
            for sigma, cf in components(d, sense, float(q)):
                sh.append(sigma * h)
                woff.append(sigma * 2.0 * math.pi * off)
                coef.append(cf)
                C.append(c)
                imb.append(is_imb)
                dirs.append(DIRECTIONS.index(d))
                law_rows.append((1.0, *lw) if lw is not None else (0.0, 0.0, 1.0, 0.0))
                res.append(rs)
        self.sh = np.array(sh, dtype=float)
        self.woff = np.array(woff, dtype=float)
        self.has_off = bool(np.any(self.woff != 0.0))
        # resonance table: one row per (component, resonance): component index, 2π f_r, 2gζ, 2ζ
        self.res_comp = np.array([i for i, rs in enumerate(res) for _ in rs], dtype=int)
        tab = np.array([r for rs in res for r in rs], dtype=float).reshape(-1, 3)
        self.res_w, self.res_2gz, self.res_2z = tab[:, 0], tab[:, 1], tab[:, 2]
        self.res_sh, self.res_off = self.sh[self.res_comp], self.woff[self.res_comp]
        self.coef = np.array(coef, dtype=complex)
        self.C = np.array(C, dtype=float)
        self.imb = np.array(imb, dtype=float)
        self.dirs = np.array(dirs, dtype=int)
        self.sel = np.zeros((4, self.sh.size), dtype=complex)
        self.sel[self.dirs, np.arange(self.sh.size)] = 1.0
        self.at = self.dirs == 3
        self.ish = 1j * self.sh
        self.cC = self.coef * self.C
        self.cCi = -1j * self.coef * self.C * self.imb
        law = np.array(law_rows, dtype=float).reshape(-1, 4)
        self.law_idx = np.nonzero(law[:, 0] > 0)[0]             # components with a diagnosed law
        self.law_scale = self.coef[self.law_idx] * law[self.law_idx, 1]
        self.law_ref = law[self.law_idx, 2]
        self.law_p = law[self.law_idx, 3]
        self.cC[self.law_idx] = 0.0                              # C·Ω² replaced by the law
        self.rock = np.nonzero(self.dirs == 1)[0]

    def _init_poles(self):
        """The suspension's radial and axial poles, and the poles of every component's direction (λ per
        component, (n, 2))."""
        p = self.p
        if self.suspension:
            self.lam_r = quad_roots(p["mass"], p["c_r"], p["k_r"])
            self.lam_z = quad_roots(p["mass"], p["c_z"], p["k_z"])
        else:       # never used (modes are off); distinct poles keep the kernel's layout finite
            self.lam_r = self.lam_z = (-1.0 + 0j, -2.0 + 0j)
        lam = np.zeros((self.sh.size, 2), dtype=complex)
        for j, ls in ((0, self.lam_r), (2, self.lam_z)):
            lam[self.dirs == j] = ls
        # axial-torque components load no mode; a dummy pole keeps their (discarded) integrals
        # finite so that 0·x in the direction sums stays 0
        lam[self.dirs == 3] = -1.0
        self._lam_static = lam

    def _init_mounting(self, dcm, position):
        """The mounting of the spacecraft-frame outputs: DCM wheel -> spacecraft (checked rotation, default
        identity) and interface position (m, finite, default 0), as plain lists."""
        R = np.eye(3) if dcm is None else rotation_check(dcm)
        pos = np.zeros(3) if position is None else np.asarray(position, dtype=float).reshape(3)
        if not np.all(np.isfinite(pos)):
            raise ModelError(f"interface position r = {pos.tolist()!r} m is not finite")
        self.R = [list(map(float, row)) for row in R]
        self.pos = [float(v) for v in pos]

    def _init_kernel(self):
        """The native kernel's configuration array (its layout: :mod:`runtime_math`'s KERNEL_ constants, rwadist/fmu/native/rwadist_fmu_native.c), state and output
        arrays, and their addresses."""
        p = self.p
        n = self.sh.size
        cfg = np.zeros(KERNEL_COMP + KERNEL_STRIDE * n + KERNEL_RES * self.res_comp.size)
        cfg[0], cfg[1] = n, float(self.modes)
        cfg[2:12] = [p[k] for k in KERNEL_PARAMS]
        cfg[12:16] = np.array(self.lam_r, dtype=complex).view(float)
        cfg[16:20] = np.array(self.lam_z, dtype=complex).view(float)
        cfg[20:29] = np.ravel(self.R)
        cfg[29:32] = self.pos
        comp = cfg[KERNEL_COMP:KERNEL_COMP + KERNEL_STRIDE * n].reshape(n, KERNEL_STRIDE)
        comp[:, 0], comp[:, 1] = self.sh, self.dirs
        comp[:, 2:4] = self.cC.view(float).reshape(n, 2)
        comp[:, 4:6] = self.cCi.view(float).reshape(n, 2)
        comp[:, 8] = 1.0
        comp[self.law_idx, 6:8] = self.law_scale.view(float).reshape(-1, 2)
        comp[self.law_idx, 8] = self.law_ref
        comp[self.law_idx, 9] = self.law_p
        comp[:, 10] = self.woff
        base = KERNEL_COMP + KERNEL_STRIDE * n
        table = cfg[base:].reshape(-1, KERNEL_RES)
        table[:, 0], table[:, 1], table[:, 2] = self.res_w, self.res_2gz, self.res_2z
        for i in range(n):
            rows = np.nonzero(self.res_comp == i)[0]
            comp[i, 11] = rows.size
            comp[i, 12] = base + KERNEL_RES * rows[0] if rows.size else 0.0
        self._cfg = cfg
        self._st = np.zeros(2 + 2 * n + 12)
        self._kout = np.zeros(12)
        self._ptrs = (cfg.ctypes.data, self._st.ctypes.data, self._kout.ctypes.data)

    def _init_ripple(self, ripples, seed):
        rip = [tuple(float(v) for v in r) for r in (ripples or [])]
        self.has_ripple = bool(rip)
        theta = (np.random.default_rng((int(seed), 1)).uniform(0, 2 * np.pi, len(rip)) if seed is not None
                 else np.zeros(len(rip)))
        # (ΔΩ_ref, Ω_ref, q, 2π f_r, θ) per ripple; plain floats: one or two per model, called twice a step
        self.ripples = [(dw, w_ref, q, 2.0 * math.pi * f_r, float(th)) for (dw, w_ref, q, f_r), th in zip(rip, theta)]
        self.ripple_f_max = max((r[3] for r in rip), default=0.0)

    def ripple(self, omega, t):
        """Speed ripple r (rad/s) at input speed ``omega`` (rad/s) and time ``t`` since t0 (s)."""
        r = 0.0
        for dw, w_ref, q, w_r, th in self.ripples:
            r += (dw * (abs(omega) / w_ref) ** q if q else dw) * math.sin(w_r * t + th)
        return r

    def ripple_rate(self, omega, t):
        """dr/dt (rad/s²) of the speed ripple at input speed ``omega`` (held) and time ``t``."""
        r = 0.0
        for dw, w_ref, q, w_r, th in self.ripples:
            r += (dw * (abs(omega) / w_ref) ** q if q else dw) * w_r * math.cos(w_r * t + th)
        return r

    def _init_floor(self, floors, seed, df):
        if not (isinstance(df, (int, float)) and math.isfinite(df) and df > 0):
            raise ModelError(f"floor_resolution must be finite and > 0, got {df!r} Hz")
        floors = list(floors or [])
        self.has_floor = bool(floors)
        self.floor_f_max = 0.0
        if not self.has_floor:
            return
        spans = [(max(1, math.ceil(f_k[0] / df)), math.floor(f_k[-1] / df)) for _, f_k, _, _, _ in floors]
        n_max = sum(max(0, k1 - k0 + 1) for k0, k1 in spans)       # before allocating anything
        if n_max > FLOOR_MAX_COMPONENTS:
            raise ModelError(f"broadband floors need {n_max} sinusoids at floor_resolution = {df:g} Hz (limit "
                             f"{FLOOR_MAX_COMPONENTS}); use a coarser floor_resolution")
        amp: list[np.ndarray] = []
        wk: list[np.ndarray] = []
        chan, ref, expo, starts = [], [], [], []
        for (c, f_k, psd_k, w_ref, p), (k0, k1) in zip(floors, spans):
            k = np.arange(k0, k1 + 1)
            S = np.interp(k * df, f_k, psd_k, left=0.0, right=0.0)
            keep = S > 0
            if not keep.any():
                if np.any(psd_k > 0):
                    raise ModelError(f"a broadband floor of {CHANNELS[c]} ({f_k[0]:g}-{f_k[-1]:g} Hz) has no "
                                     f"sinusoid at floor_resolution = {df:g} Hz; use a finer floor_resolution")
                continue
            starts.append(sum(a.size for a in amp))
            amp.append(np.sqrt(2.0 * S[keep] * df))
            wk.append(2.0 * math.pi * df * k[keep])
            chan.append(c)
            ref.append(w_ref)
            expo.append(0.5 * p)
        self.has_floor = bool(amp)
        if not self.has_floor:
            return
        A, self.floor_w = np.concatenate(amp), np.concatenate(wk)
        self.floor_f_max = float(self.floor_w.max() / (2.0 * math.pi))
        # independent uniform phases for every sinusoid of every channel and floor (channels are
        # incoherent); without a seed from a fixed one, so the FMU stays deterministic
        ph = np.random.default_rng((FLOOR_DEFAULT_SEED if seed is None else int(seed), 2)).uniform(0, 2 * np.pi, A.size)
        self.floor_A = A * np.exp(1j * ph)
        self.floor_starts = np.array(starts, dtype=int)
        self.floor_chan = np.array(chan, dtype=int)
        self.floor_ref = np.array(ref)
        self.floor_half_p = np.array(expo)
        self.floor_rot = {}

    def floor_now(self, omega, t, advance=None):
        """(6,) floor loads at input speed ``omega`` and time ``t``: the phasors advanced by ``advance``
        seconds (a step) or, with None or every FLOOR_RESYNC steps, set from t exactly."""
        if advance is None or self._floor_count >= FLOOR_RESYNC:
            self._floor_Z = self.floor_A * np.exp(1j * self.floor_w * t)
            self._floor_count = 0
        else:
            rot = self.floor_rot.get(advance)
            if rot is None:
                if len(self.floor_rot) >= 4:         # a host with a varying step: a few sizes, bounded memory
                    self.floor_rot.clear()
                rot = self.floor_rot[advance] = np.exp(1j * self.floor_w * advance)
            self._floor_Z *= rot
            self._floor_count += 1
        sums = np.add.reduceat(self._floor_Z.real, self.floor_starts)
        g = (abs(omega) / self.floor_ref) ** self.floor_half_p
        return np.bincount(self.floor_chan, weights=g * sums, minlength=6)

    @property
    def native(self) -> bool:
        """True when steps run in the native kernel."""
        return self._kernel is not None

    def _pack(self):
        """Current state into the kernel's state array."""
        n = self.sh.size
        st = self._st
        st[0] = self.phi
        st[1] = self.t
        st[2:].view(complex)[:] = np.concatenate([self.S, self.eta_r, self.eta_z, self.x_rock])[: n + 6]

    # ------------------------------------------------------------ state
    def reset(self):
        """Back to t0: rotor angle 0, all modal states zero, no previous step."""
        self.phi = 0.0
        self.t = 0.0
        self.S = np.ones(self.sh.size, dtype=complex)
        self.eta_r = [0j, 0j]
        self.eta_z = [0j, 0j]
        self.x_rock = [0j, 0j]
        self.prev_alpha = None
        self.prev_end = None          # (Ω at the end of the previous step, step size)
        self.started = False
        self.out = np.zeros(6)
        self.y = [0.0] * 12
        self._floor_count = FLOOR_RESYNC      # the first floor value is set from t
        self._prev_start = 0.0      # the previous step's input start speed (read once prev_end is set)

    def _amp(self, w, wdot):
        """coef·C·(Ω² − iΩ̇·[imbalance]) per component (coef·A_ref·(|Ω|/Ω_ref)^p in place of
        coef·C·Ω² for a line with a diagnosed amplitude law)."""
        a = self.cC * (w * w) + self.cCi * wdot
        if self.law_idx.size:
            a[self.law_idx] += self.law_scale * (abs(w) / self.law_ref) ** self.law_p
        if self.res_comp.size:
            # quasi-static wheel-mode resonances at each component's whirl rate ν = σhΩ + ω_off
            r = (self.res_sh * w + self.res_off) / self.res_w
            base = 1.0 - r * r
            G = np.ones(a.size, dtype=complex)
            np.multiply.at(G, self.res_comp, (base + 1j * self.res_2gz * r) / (base + 1j * self.res_2z * r))
            a = a * G
        return a

    def _phase(self, phi, t):
        """e^{i(σhφ + ω_off t)} per component."""
        if self.has_off:
            return np.exp(1j * (self.sh * phi + self.woff * t))
        return np.exp(self.ish * phi)

    def _loads(self, w, wdot, phi):
        """Internal complex loads per direction (4,) at speed w, acceleration wdot, angle phi."""
        return self.sel @ (self._amp(w, wdot) * self._phase(phi, self.t))

    def _steady_init(self, w0, wdot0):
        p = self.p
        amp0 = self._amp(w0, wdot0)
        subs = ((p["mass"], p["c_r"], p["k_r"], 0.0), (p["I_rr"], p["c_rock"], p["k_rock"], p["I_zz"]),
                (p["mass"], p["c_z"], p["k_z"], 0.0))
        st = []
        for j, (m, c, k, g) in enumerate(subs):
            keep = self.dirs == j
            nu = self.sh[keep] * w0 + self.woff[keep]
            G = 1.0 / (k - m * nu**2 + g * w0 * nu + 1j * c * nu)
            st.append((complex(np.sum(G * amp0[keep])), complex(np.sum(1j * nu * G * amp0[keep]))))
        (q, qd), (qr, qdr), (qz, qdz) = st
        l1, l2 = self.lam_r
        self.eta_r = [(qd - l2 * q) / (l1 - l2), (l1 * q - qd) / (l1 - l2)]
        l1, l2 = self.lam_z
        self.eta_z = [(qdz - l2 * qz) / (l1 - l2), (l1 * qz - qdz) / (l1 - l2)]
        self.x_rock = [qr, qdr]

    def _lti_consts(self, h):
        """Per step size h: (λh (n,2) and e^{λh} (n,2) with the rocking rows left to fill, the
        smallest |Re λh| of the fixed modes, e^{λ_r h}, e^{λ_z h})."""
        c = self._cache.get(h)
        if c is None:
            if len(self._cache) > 64:
                self._cache.clear()
            lamh = self._lam_static * h
            fixed = np.concatenate([np.array(self.lam_r), np.array(self.lam_z)]) * h
            # the fixed modes' poles as Python complex: the per-step recursions below are scalar arithmetic,
            # ~10x cheaper on Python numbers than on numpy scalars
            c = (lamh, np.exp(lamh), float(np.min(np.abs(fixed.real))),
                 tuple(np.exp(np.array(self.lam_r) * h).tolist()), tuple(np.exp(np.array(self.lam_z) * h).tolist()))
            self._cache[h] = c
        return c

    # ------------------------------------------------------------ checks
    def check_step(self, omega, alpha, h):
        """ModelError naming the problem if (Ω, α, h) cannot be stepped; None if fine."""
        if not math.isfinite(h) or h <= 0:
            raise ModelError(f"communication step size {h!r} s is not a positive finite number")
        if h > self.max_step * (1 + 1e-12):
            raise ModelError(f"communication step size {h:.6g} s exceeds max_step_size = {self.max_step:.6g} s "
                             "(the frozen-speed rocking transition and the derived acceleration are only "
                             "resolved below it)")
        if h < 1e-9:
            raise ModelError(f"communication step size {h:.3g} s is below the 1 ns the FMU resolves")
        if self.has_ripple and h * self.ripple_f_max * RIPPLE_STEPS_PER_PERIOD > 1 + 1e-12:
            raise ModelError(f"communication step size {h:.6g} s does not resolve the speed ripple of "
                             f"{self.ripple_f_max:.6g} Hz (at most {1 / (RIPPLE_STEPS_PER_PERIOD * self.ripple_f_max):.6g}"
                             f" s: {RIPPLE_STEPS_PER_PERIOD} steps per period); use smaller steps"
                             + "".join(f" or {name} = false" for name in self.ripple_switches))
        if not math.isfinite(omega):
            raise ModelError(f"wheel_speed is not finite: {omega!r} rad/s")
        if alpha is not None and not math.isfinite(alpha):
            raise ModelError(f"wheel_acceleration is not finite: {alpha!r} rad/s²")
        if alpha is not None and abs(alpha) > self.max_accel:
            raise ModelError(f"wheel_acceleration {alpha:.6g} rad/s² exceeds max_acceleration = "
                             f"{self.max_accel:.6g} rad/s²")
        if self.prev_end is not None:
            w_end, h_prev = self.prev_end
            jump = abs(omega - w_end) / h_prev
            if jump > self.max_accel:
                raise ModelError(f"wheel_speed jumps from {w_end:.6g} to {omega:.6g} rad/s over one step "
                                 f"({h_prev:.6g} s): |dΩ/dt| = {jump:.3g} rad/s² > max_acceleration = "
                                 f"{self.max_accel:.6g} rad/s²")

    # ------------------------------------------------------------ step
    def step(self, omega, alpha, h, t=None):
        """Advance one communication step from speed ``omega`` (rad/s) with acceleration ``alpha``
        (rad/s²; None: derived as the previous step's mean rate, 0 on the first step) over ``h``
        seconds.  ``t``: the step's start as time since t0 (s): the host's communication point minus its
        start time, so the sideband, ripple and floor phases follow the host's clock; None: the end of the
        previous step (the sum of the steps, which drifts from the host's times by rounding, ~1e-13 s over
        2000 steps).  Returns the wheel-frame outputs at the step's end (6,).  Raises ModelError (state
        untouched) on bad input."""
        return np.array(self.step12(omega, alpha, h, t)[:6])

    def step12(self, omega, alpha, h, t=None):
        """As :meth:`step`, returning the 12 outputs (wheel frame, then spacecraft frame) as a list."""
        omega, h = float(omega), float(h)
        alpha = None if alpha is None else float(alpha)
        self.check_step(omega, alpha, h)
        t0 = self.t if t is None else float(t)
        if not math.isfinite(t0):
            raise ModelError(f"step start time {t0!r} s is not finite")
        if alpha is None:
            alpha = self._derived_acceleration(omega)
        w_in, w1_in = omega, omega + alpha * h
        t_end = t0 + h
        if self.has_ripple:      # the rotor's speed: input + ripple, linear over the step
            r0 = self.ripple(omega, t0)
            alpha = alpha + (self.ripple(w1_in, t_end) - r0) / h
            omega = omega + r0
        wd0 = alpha if self.prev_alpha is None else 0.5 * (self.prev_alpha + alpha)
        if not self.started:
            if self.start_steady and self.suspension:
                self._steady_init(omega, wd0)
            self.started = True
            if self._kernel is not None:
                self._pack()
        if self._kernel is not None:
            cfg, st, out = self._ptrs
            self._st[1] = t0                 # the kernel's clock (its sideband phases) from the step's start
            self._kernel(cfg, st, out, omega, wd0, alpha, h)
            self._prev_start = w_in
            self.prev_alpha = alpha
            self.prev_end = (w1_in, h)
            self.t = t_end
            if self.has_floor:
                self.out = self._kout[:6] + self.floor_now(w1_in, t_end, h)
                self.y = y = frame12(self.out, self.R, self.pos)
            else:
                self.y = y = self._kout.tolist()
            return y
        w1 = omega + alpha * h
        dphi = 0.5 * (omega + w1) * h
        phi1 = self.phi + dphi
        S1 = self._phase(phi1, t_end)
        a0 = self._amp(omega, wd0)
        a1 = self._amp(w1, alpha)
        loads1 = self.sel @ (a1 * S1)
        if self.modes and self.sh.size:
            self._advance_modes(0.5 * (omega + w1), dphi, h, S1, a0, a1)
        self.phi = phi1
        self.t = t_end
        self.S = S1
        self._prev_start = w_in
        self.prev_alpha = alpha
        self.prev_end = (w1_in, h)
        self.out = self._outputs(loads1)
        if self.has_floor:
            self.out = self.out + self.floor_now(w1_in, t_end, h)
        self.y = frame12(self.out, self.R, self.pos)
        return self.y

    def _derived_acceleration(self, omega):
        """The acceleration (rad/s²) of a step given none: the previous step's start speed to this step's start
        speed ``omega`` over the previous step (0 on the first step); ModelError above max_acceleration."""
        if self.prev_end is None:
            return 0.0
        _, h_prev = self.prev_end
        alpha = (omega - self._prev_start) / h_prev
        if abs(alpha) > self.max_accel:
            raise ModelError(f"derived wheel acceleration {alpha:.6g} rad/s² exceeds max_acceleration = "
                             f"{self.max_accel:.6g} rad/s²")
        return alpha

    def _advance_modes(self, w_mid, dphi, h, S1, a0, a1):
        """The suspension's modal states over one step of size ``h`` (s): the components' loads (amplitudes
        ``a0`` at the start, ``a1`` at the end, linear in between; phasors from ``self.S`` to ``S1``, rotor angle
        advancing by ``dphi`` rad) integrated exactly through the radial and axial modes' eigen-coordinates, and
        the rocking mode through its exact transition at the mean speed ``w_mid`` (rad/s)."""
        p = self.p
        lk1, lk2 = quad_roots(p["I_rr"], p["c_rock"] - 1j * p["I_zz"] * w_mid, p["k_rock"])
        lamh0, X0, min_re, Xr, Xz = self._lti_consts(h)
        e1, e2 = cmath.exp(lk1 * h), cmath.exp(lk2 * h)
        lamh, X = lamh0.copy(), X0.copy()
        lamh[self.rock] = (lk1 * h, lk2 * h)
        X[self.rock] = (e1, e2)
        z = ((1j * (self.sh * dphi + self.woff * h)) if self.has_off else (self.ish * dphi))[:, None] - lamh
        XS0 = X * self.S[:, None]
        S1c = S1[:, None]
        # |z| >= |Re z| = |Re λh|: the series is needed only if some |Re λh| < SMALL_Z
        if min(min_re, abs(lk1.real * h), abs(lk2.real * h)) >= SMALL_Z:
            t0 = (S1c - XS0) / z
            t1 = (S1c - t0) / z
        else:
            small = np.abs(z) < SMALL_Z
            zb = np.where(small, 1.0, z)
            t0 = (S1c - XS0) / zb
            t1 = (S1c - t0) / zb
            if small.any():
                zs = z[small]
                e0s = 1 + zs * (1 / 2 + zs * (1 / 6 + zs * (1 / 24 + zs / 120)))
                e1s = 1 / 2 + zs * (1 / 3 + zs * (1 / 8 + zs * (1 / 30 + zs / 144)))
                t0[small] = XS0[small] * e0s
                t1[small] = XS0[small] * e1s
        W = ((self.sel @ (a0[:, None] * t0 + (a1 - a0)[:, None] * t1)) * h).tolist()   # (4, 2)
        # radial and axial translation: eigen-coordinates η_j' = pole η_j + w_j/(m(λ_j − λ_k))
        for eta, (l1, l2), Xp, row, (m, c, k) in (
                (self.eta_r, self.lam_r, Xr, 0, (p["mass"], p["c_r"], p["k_r"])),
                (self.eta_z, self.lam_z, Xz, 2, (p["mass"], p["c_z"], p["k_z"]))):
            eta[0] = Xp[0] * eta[0] + W[row][0] / (m * (l1 - l2))
            eta[1] = Xp[1] * eta[1] + W[row][1] / (m * (l2 - l1))
        # rocking: exact transition at the mean speed of the step
        dl = lk1 - lk2
        q, qd = self.x_rock
        kI = p["k_rock"] / p["I_rr"]
        P00 = (e1 * (-lk2) - e2 * (-lk1)) / dl
        P01 = (e1 - e2) / dl
        P10 = (-kI) * (e1 - e2) / dl
        P11 = (e1 * lk1 - e2 * lk2) / dl
        w1r = W[1][0] / (p["I_rr"] * dl)
        w2r = W[1][1] / (-p["I_rr"] * dl)
        self.x_rock = [P00 * q + P01 * qd + w1r + w2r, P10 * q + P11 * qd + lk1 * w1r + lk2 * w2r]

    def outputs_now(self, omega, alpha=0.0):
        """Outputs at the current state for speed ``omega`` (used at t0 before the first step)."""
        w_in = float(omega)
        omega, alpha = w_in, float(alpha)
        if self.has_ripple:
            omega += self.ripple(w_in, self.t)
            alpha += self.ripple_rate(w_in, self.t)
        if not self.started and self.start_steady and self.suspension:
            self._steady_init(omega, alpha)
        loads = self._loads(omega, alpha, self.phi)
        self.out = self._outputs(loads)
        if self.has_floor:
            self.out = self.out + self.floor_now(w_in, self.t)
        self.y = frame12(self.out, self.R, self.pos)
        return self.out

    def _outputs(self, loads):
        p = self.p
        if self.modes:
            l1, l2 = self.lam_r
            q, qd = self.eta_r[0] + self.eta_r[1], l1 * self.eta_r[0] + l2 * self.eta_r[1]
            F = p["k_r"] * q + p["c_r"] * qd
            l1, l2 = self.lam_z
            qz, qdz = self.eta_z[0] + self.eta_z[1], l1 * self.eta_z[0] + l2 * self.eta_z[1]
            Fz = (p["k_z"] * qz + p["c_z"] * qdz).real
            Tc = p["k_rock"] * self.x_rock[0] + p["c_rock"] * self.x_rock[1]
        else:
            F, Fz, Tc = complex(loads[0]), float(loads[2].real), complex(loads[1])
        Tint = Tc + 1j * p["height"] * F
        return np.array([F.real, F.imag, Fz, Tint.real, Tint.imag, float(loads[3].real)])

    # ------------------------------------------------------------ convenience
    def run(self, t, omega, alpha="slope"):
        """Step through a uniform profile (t, omega) as a host would (step n starts at n·h since t0, h the
        mean spacing, like ``hosts.run_fmpy``); returns (n, 6) outputs with row 0 the t0 outputs.  alpha: 'slope' (each step gets (Ω_{n+1} − Ω_n)/h as
        wheel_acceleration), None (derived), or an array per sample."""
        t = np.asarray(t, dtype=float)
        w = np.asarray(omega, dtype=float)
        h = (t[-1] - t[0]) / (t.size - 1)
        acc: np.ndarray | list[None]
        if isinstance(alpha, str):
            acc = np.append(np.diff(w) / h, 0.0)
        elif alpha is None:
            acc = [None] * w.size
        else:
            acc = np.asarray(alpha, dtype=float)
        out = np.empty((t.size, 6))
        out[0] = self.outputs_now(w[0], 0.0 if acc[0] is None else acc[0])
        for n in range(t.size - 1):
            out[n + 1] = self.step(w[n], acc[n], h, n * h)
        return out
