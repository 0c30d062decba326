"""Known effects injected into virtual-stand data, so a user can try ``rwadist diagnose`` on a known case.

``rwadist simulate-test OUT --preset ithaco-e --inject KIND:PARAM=VALUE,...`` (``--inject`` may be
repeated).  Every injection is recorded in ``meta.json`` under ``injected`` (kind and parameters in
SI), which is the truth to compare the diagnosis with.  The injections are those the project's
diagnose tests make (tests/test_diagnose*.py), exposed.

The kinds, their parameters (with defaults) and what each does are their elements' (``rwadist/effects/<kind>.py``:
``INJECT`` and the ``inject_*`` hooks of :class:`rwadist.effects.element.Element`); :func:`kinds` lists them.  This
module knows no kind: it parses ``KIND:PARAM=VALUE`` against the element's table, and hands each element a
:class:`Stand` -- the stand's wheel, random numbers and ways to add content to a run.

Where each kind acts.  With --physics extended the wheel-load kinds are loads on the rotor: like every line of the
simulation they reach the load cell through the suspension modes (:func:`rwadist.extended.steady_lines` at the run's
speed, each component at its own whirl rate, the line's rotation sense from the preset: a line the wheel has keeps
its sense, a missing harmonic is co-rotating) and then through the stand's fixture resonances (those the simulation
applied); see :meth:`Stand.add_wheel_loads`.  The kinds that are not wheel loads stay where they physically act: a
fixture resonance is a filter applied by the simulation to everything it passes; a load-cell offset is the load
cell's own geometry, applied last (``INJECT_LAST``), on the total force the cell measures (the simulation's and every
noise-free content added here); a broadband floor stays a per-channel floor at the load cell (its channels are
given, not its load direction).  With --physics simple every added line reaches the load cell as it is (the simple
physics' resonances are not applied to it).
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from scipy import signal

from .data import DataError
from .effects import elements
from .units import CHANNELS, DIRECTION_CHANNELS

#: The load directions a ``direction`` parameter may name (the stand simulates lines of these).
_DIRS = ("radial_force", "radial_torque", "axial_force")


def kinds() -> dict:
    """{kind: its element class} of every kind the stand injects (``INJECT`` set), in the elements' order."""
    return {c.KIND: c for c in elements() if c.INJECT is not None}


def _bad(spec, field, why):
    return DataError("`inject`", field, f"{spec!r}: {why}")


def parse(spec: str) -> dict:
    """``KIND:PARAM=VALUE,...`` -> {"kind": KIND, params with defaults filled}; DataError on anything wrong."""
    kind, _, rest = spec.partition(":")
    kind = kind.strip()
    known = kinds()
    if kind not in known:
        raise _bad(spec, "kind", f"unknown kind {kind!r}; known: {', '.join(known)}")
    cls = known[kind]
    out: dict[str, str | float | tuple[str, ...]] = {"kind": kind}
    given: dict[str, str | float] = {}
    for item in filter(None, (x.strip() for x in rest.split(","))):
        key, eq, value = item.partition("=")
        key = key.strip()
        if not eq:
            raise _bad(spec, key, f"{item!r} is not PARAM=VALUE")
        if key not in cls.INJECT:
            raise _bad(spec, key, f"unknown parameter {key!r} of {kind}; known: {', '.join(cls.INJECT)}")
        if key in cls.INJECT_TEXT:
            given[key] = value.strip()
            continue
        try:
            v = float(value)
        except ValueError:
            raise _bad(spec, key, f"{key}={value!r} is not a number") from None
        positive, signed = key in cls.INJECT_POSITIVE, key in cls.INJECT_SIGNED
        if not math.isfinite(v) or (positive and v <= 0) or v < 0 and not signed:
            raise _bad(spec, key, f"{key}={value!r} must be a finite number"
                       + (" > 0" if positive else " >= 0" if not signed else ""))
        given[key] = v
    for key, default in cls.INJECT.items():
        out[key] = given.get(key, default)
    if "direction" in out and out["direction"] not in _DIRS:
        raise _bad(spec, "direction", f"{out['direction']!r}; expected one of {', '.join(_DIRS)}")
    if "channels" in out:
        chans = tuple(c.strip() for c in str(out["channels"]).split("+") if c.strip())
        bad = [c for c in chans if c not in CHANNELS]
        if bad or not chans:
            raise _bad(spec, "channels", f"{out['channels']!r}; give channels joined by '+', from {'+'.join(CHANNELS)}")
        out["channels"] = chans
    cls.inject_check(out, lambda field, why: _bad(spec, field, why))
    return out


class Stand:
    """The virtual stand as an element's injection sees it (:class:`rwadist.effects.element.Element` ``inject_*``).

    wheel : the preset as given (a :class:`rwadist.teststand.WheelDescription`, before :func:`prepare_wheel`).
    physics : the simulation's, "simple" or "extended" (:attr:`extended`).  rng : the injections' random numbers
    (one stream, drawn in spec order, run by run).  w_max, w_mid : the test's largest and median |Ω|, rad/s.
    clean : the noise-free simulation of the prepared wheel with the same seed, or None.  forces_before : per run,
    the forces Fx, Fy, Fz before any injection (a load-cell offset takes the forces the cell measures).  fixture :
    the stand's active fixture resonances (:class:`rwadist.teststand.Mode`) the simulation applied."""

    def __init__(self, wheel, physics: str = "simple", rng=None, w_max: float = 0.0, w_mid: float = 0.0,
                 clean=None, forces_before=None, fixture=()):
        self.wheel, self.physics, self.rng = wheel, physics, rng
        self.extended = physics != "simple"
        self.w_max, self.w_mid = w_max, w_mid
        self.clean, self.forces_before, self.fixture = clean, forces_before, fixture

    @staticmethod
    def error(field, why) -> DataError:
        """The error of a wrong injection (the parameter ``inject``, the field, what to do; a parameter it names is
        in backquotes, for the command line to name its flag)."""
        return DataError("`inject`", field, why)

    @staticmethod
    def time(run) -> np.ndarray:
        """The run's sample times from its start, s."""
        return np.arange(run.n_samples) / run.sample_rate

    @staticmethod
    def harmonic(wheel, spec, direction, h) -> tuple:
        """(h, C) of the wheel's line (direction, h) (|Δh| <= 1e-6); the error naming the lines it has otherwise."""
        for hh, C in wheel.harmonics.get(direction, []):
            if abs(hh - h) <= 1e-6:
                return hh, C
        known = ", ".join(f"{hh:g}" for hh, _ in wheel.harmonics.get(direction, []))
        raise DataError("`inject`", "h", f"{spec['kind']}: the wheel has no {direction} line at h = {h:g} "
                        f"(it has h = {known})")

    @staticmethod
    def without(wheel, direction, h):
        """The wheel without its line (direction, h)."""
        return replace(wheel, harmonics={d: [(hh, C) for hh, C in v if not (d == direction and abs(hh - h) <= 1e-6)]
                                         for d, v in wheel.harmonics.items()})

    @staticmethod
    def is_imbalance(direction, h) -> bool:
        """True for a radial h = 1 line (the rotor's imbalance with extended physics)."""
        return direction != "axial_force" and abs(h - 1.0) <= 0.011

    def sense(self, direction, h) -> str:
        """The rotation sense the preset gives the line (direction, h) ('co' when it has none; axial: 'co')."""
        return next((v for (d, hh), v in self.wheel.senses.items() if d == direction and abs(hh - h) <= 1e-6), "co")

    @staticmethod
    def mode(name, f_hz, zeta, gain, channels, gain_above=1.0):
        """A fixed-frequency resonance of the stand's simulation (:class:`rwadist.teststand.Mode`; ``gain_above``: H far
        above it, :mod:`rwadist.resonance`)."""
        from .teststand import Mode

        return Mode(name, f_hz, zeta, gain, channels, gain_above=gain_above)

    @staticmethod
    def add_line(run, direction, amp, phase, sense=1.0) -> None:
        """Add a line to the channels of ``direction``; amp, phase: (n_samples,) arrays; co-rotating x = a cos,
        y = a sin (sense −1: y = −a sin)."""
        chans = DIRECTION_CHANNELS[direction]
        run.signals[chans[0]] = run.signals[chans[0]] + amp * np.cos(phase)
        if len(chans) > 1:
            run.signals[chans[1]] = run.signals[chans[1]] + sense * amp * np.sin(phase)

    @staticmethod
    def line(direction, h, C, sense, phase, law=None, f_offset=0.0):
        """A wheel load (:class:`rwadist.extended.Line`) for :meth:`add_wheel_loads`."""
        from .extended import Line

        return Line(direction, h, C, sense, phase, law=law, f_offset=f_offset)

    def add_wheel_loads(self, run, lines) -> None:
        """Add wheel loads ``lines`` (:meth:`line`) to ``run`` through the suspension modes of the wheel
        (:func:`rwadist.extended.steady_lines` at the run's signed speed) and the stand's fixture resonances (as the
        simulation applies them to its own lines): every channel each line reaches; a line at or above Nyquist is
        not recorded (as the simulation drops it)."""
        from . import extended as ext
        from .teststand import _fixture_gain

        f, A = ext.steady_lines(self.wheel.extended, lines, [run.speed])
        f, A = f[0], A[0]                                           # (n_lines,), (n_lines, 6)
        if self.fixture:
            A = A * _fixture_gain(list(self.fixture), f)
        t = self.time(run)
        for j in np.flatnonzero(f < 0.5 * run.sample_rate):
            z = np.exp(2j * np.pi * f[j] * t)
            for i, c in enumerate(CHANNELS):
                if c in run.signals and A[j, i] != 0:
                    run.signals[c] = run.signals[c] + (A[j, i] * z).real

    def lowpass_noise(self, fc_hz, run) -> np.ndarray:
        """Gaussian noise (n_samples,) from :attr:`rng` through a 2nd-order Butterworth low pass at ``fc_hz``, its
        start-up transient (1024 samples) dropped."""
        b, a = signal.butter(2, fc_hz, fs=run.sample_rate)
        return signal.lfilter(b, a, self.rng.normal(size=run.n_samples + 1024))[1024:]


def prepare_wheel(wheel, specs: list, physics: str):
    """The wheel to simulate: lines an injection replaces are taken out (or scaled), resonances added
    (each kind's ``inject_prepare``)."""
    stand = Stand(wheel, physics)
    known = kinds()
    for s in specs:
        wheel = known[s["kind"]].inject_prepare(wheel, s, stand)
    return wheel


def apply(test, wheel, specs: list, seed: int = 0, clean=None, physics: str = "simple", fixture=()):
    """Add the post-simulation parts of ``specs`` to ``test`` (in place) and record them in its meta.

    wheel : the preset as given (before :func:`prepare_wheel`).  clean : noise-free simulation of the
    prepared wheel with the same seed (needed by the kinds with ``INJECT_CLEAN``; without it a load-cell offset
    takes the noisy forces).  physics : that of the simulation ("extended": every wheel load goes through the
    suspension modes, :meth:`Stand.add_wheel_loads`).  fixture : the stand's active fixture resonances
    (:class:`rwadist.teststand.Mode`, those the simulation applied): with extended physics a wheel load
    added here passes through them as the simulated lines do."""
    known = kinds()
    speeds = np.array([abs(r.speed) for r in test.runs])
    stand = Stand(wheel, physics, np.random.default_rng(np.random.SeedSequence([int(seed), 14])),
                  float(speeds.max()), float(np.median(speeds)), clean,
                  [{c: r.signals[c].copy() for c in ("Fx", "Fy", "Fz")} for r in test.runs], fixture)
    record = [{key: (list(v) if isinstance(v, tuple) else v) for key, v in s.items()} for s in specs]
    # a kind acting on what the load cell measures (INJECT_LAST) comes after every other
    ordered = [s for s in specs if not known[s["kind"]].INJECT_LAST] + \
        [s for s in specs if known[s["kind"]].INJECT_LAST]
    for s in ordered:
        cls = known[s["kind"]]
        for run_i, r in enumerate(test.runs):
            cls.inject_run(s, r, run_i, stand)
    test.meta["injected"] = record
    return test


def simulate_with_injections(wheel, specs: list, speeds_rpm, physics: str = "simple", seed: int = 0, **kwargs):
    """:func:`rwadist.teststand.simulate_steady` of ``wheel`` with ``specs`` (parsed) injected."""
    from .teststand import _fixture_modes, simulate_steady

    specs = [dict(s) for s in specs]
    known = kinds()
    stand = Stand(wheel, physics)
    for s in specs:
        known[s["kind"]].inject_requires(s, physics, bool(kwargs.get("modes", True)), stand)
    prepared = prepare_wheel(wheel, specs, physics)
    test = simulate_steady(prepared, speeds_rpm, physics=physics, seed=seed, **kwargs)
    clean = None
    if any(known[s["kind"]].INJECT_CLEAN for s in specs):
        clean = simulate_steady(prepared, speeds_rpm, physics=physics, seed=seed, **{**kwargs, "noise": 0.0})
    fixture = _fixture_modes(prepared, kwargs.get("test_stand", True)) if physics != "simple" else ()
    return apply(test, wheel, specs, seed=seed, clean=clean, physics=physics, fixture=fixture)
