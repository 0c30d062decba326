"""The FMU of the extended wheel model (issue 5): runtime vs rwadist.extended_time.simulate_time,
steady amplitudes vs the closed-form modal gain, fmpy validation, four instances, bad input
through the host, step-size convergence, CLI, and (slow) a fresh venv without rwadist."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import zipfile
from pathlib import Path

import numpy as np
import pytest

from rwadist import extended as ext
from rwadist import model as model_io
from rwadist.extended_time import simulate_time
from rwadist.fmu import hosts
from rwadist.fmu import runtime as rt
from rwadist.fmu.build import build_fmu, has_native, native_supported
from rwadist.presets import preset

pytest.importorskip("pythonfmu")
fmpy = pytest.importorskip("fmpy")

RPM = 2 * np.pi / 60

#: status of a refused input: fmi2Error through the FMU's native layer (built wherever it can
#: be: Linux x86-64 with a C compiler, as CI), fmi2Discard through pythonfmu's plain library
REFUSED = 3 if native_supported() and shutil.which(os.environ.get("CC", "cc")) else 2


def wheel_model():
    """The E-wheel preset plus an axial-torque line and a planar radial line (every branch)."""
    m = preset("ithaco-e").to_model()
    m.empirical["axial_torque"] = [model_io.Harmonic(h=2.0, C=3.0e-7)]
    m.empirical["radial_force"].append(model_io.Harmonic(h=2.7, C=4.0e-7, sense="planar"))
    return m


@pytest.fixture(scope="module")
def model():
    return wheel_model()


@pytest.fixture(scope="module")
def model_path(tmp_path_factory, model):
    return model_io.save(model, tmp_path_factory.mktemp("m") / "wheel.json")


@pytest.fixture(scope="module")
def wheel_fmu(tmp_path_factory, model):
    return build_fmu(model, tmp_path_factory.mktemp("fmu") / "wheel.fmu")


def reference(model, t, w, seed):
    p = ext.params_from_model(model)
    return simulate_time(p, ext.lines_from_model(model, p), t, w, seed=seed)


def spin_up(dt=1e-3, T=8.0):
    t = np.arange(int(round(T / dt)) + 1) * dt
    return t, 3000 * RPM * t / T


def reversal(dt=1e-3, T=6.0):
    t = np.arange(int(round(T / dt)) + 1) * dt
    return t, 1500 * RPM * (1 - 2 * t / T)


def slope(t, w):
    return np.append(np.diff(w) / (t[1] - t[0]), 0.0)


def rel_err(out, ref):
    scale = np.max(np.abs(ref), axis=0)
    return np.max(np.abs(out - ref), axis=0) / scale


# ------------------------------------------------------------------ runtime = simulate_time

@pytest.mark.parametrize("profile", [spin_up, reversal])
def test_runtime_equals_simulate_time(model_path, model, profile):
    """The FMU's stepping runtime reproduces the batch time-domain model (1e-9 relative)."""
    t, w = profile()
    params, lines = rt.load_model(model_path)
    for seed in (None, 11):
        ref = reference(model, t, w, seed)
        out = rt.WheelRuntime(params, lines, seed=seed, max_step=0.01).run(t, w)
        err = rel_err(out, ref)
        assert np.all(err < 1e-9), err


@pytest.fixture(scope="module")
def kernel(tmp_path_factory):
    """The native step kernel compiled here (None where no C compiler / not Linux x86-64)."""
    from rwadist.fmu.build import NativeBuildError, compile_native
    if REFUSED != 3:
        return None
    try:
        return rt.load_kernel(compile_native(tmp_path_factory.mktemp("native") / "k.so"))
    except NativeBuildError:
        return None


def assert_native_equals_numpy(a, b, w, acc, h, what=""):
    """Step the numpy runtime ``a`` and the native one ``b`` through speeds ``w`` with accelerations ``acc``
    (step ``h``): the 12 outputs agree to 1e-12 of each channel's peak (a channel with no content stays 0)."""
    assert b.native and not a.native
    ya = np.array([a.step12(w[n], acc[n], h) for n in range(len(w) - 1)])
    yb = np.array([b.step12(w[n], acc[n], h) for n in range(len(w) - 1)])
    scale = np.max(np.abs(ya), axis=0)
    assert np.all(np.abs(yb - ya) <= 1e-12 * scale), (what, np.max(np.abs(yb - ya), axis=0) / scale)


NATIVE_ONLY = pytest.mark.skipif(REFUSED != 3, reason="no C compiler / not Linux x86-64: the FMU steps in numpy")


@NATIVE_ONLY
@pytest.mark.parametrize("profile", [spin_up, reversal])
def test_native_kernel_equals_numpy_runtime(model_path, model, kernel, profile):
    """The C kernel and the numpy runtime step the same equations: every switch and start, both
    acceleration modes, and a mounting for the spacecraft-frame outputs (1e-12 relative); and
    the kernel alone reproduces simulate_time (1e-9)."""
    assert kernel is not None     # REFUSED == 3: the native layer compiles here
    t, w = profile()
    params, lines = rt.load_model(model_path)
    R = [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    for kw in (dict(), dict(start_steady=True), dict(modes=False), dict(harmonics=False), dict(imbalance=False)):
        for alpha in ("slope", None):
            a = rt.WheelRuntime(params, lines, seed=4, dcm=R, position=[0.1, 0.2, -0.3], **kw)
            b = rt.WheelRuntime(params, lines, seed=4, dcm=R, position=[0.1, 0.2, -0.3], kernel=kernel, **kw)
            acc = slope(t, w) if alpha == "slope" else [None] * t.size
            assert_native_equals_numpy(a, b, w, acc, t[1] - t[0], (kw, alpha))
    ref = reference(model, t, w, 11)
    out = rt.WheelRuntime(params, lines, seed=11, kernel=kernel).run(t, w)
    assert np.all(rel_err(out, ref) < 1e-9)


def test_fmu_in_fmpy_equals_simulate_time(wheel_fmu, model):
    """Through fmpy: spin-up 0→3000 rpm and reversal +1500→−1500 rpm, 12 outputs, 1e-9."""
    R = np.array([[0.0, -1.0, 0.0], [np.sqrt(0.5), 0.0, -np.sqrt(0.5)], [np.sqrt(0.5), 0.0, np.sqrt(0.5)]])
    r = np.array([0.3, -0.2, 0.5])
    params = {"use_wheel_acceleration": True, "seed": 3, "r_x": r[0], "r_y": r[1], "r_z": r[2]}
    params.update({f"dcm_{i + 1}{j + 1}": R[i, j] for i in range(3) for j in range(3)})
    for t, w in (spin_up(T=4.0), reversal(T=4.0)):
        ref = reference(model, t, w, 3)
        out = hosts.run_fmpy(wheel_fmu, t, {"wheel_speed": w, "wheel_acceleration": slope(t, w)}, params)
        assert np.all(rel_err(out[:, :6], ref) < 1e-9), rel_err(out[:, :6], ref)
        # spacecraft frame, checked with an independent cross product
        F = ref[:, :3] @ R.T
        sc = np.hstack([F, ref[:, 3:] @ R.T + np.cross(r, F)])
        assert np.all(rel_err(out[:, 6:], sc) < 1e-9)


def test_derived_acceleration_close_to_reference(model_path, model):
    """Without the acceleration input the FMU uses the previous step's rate; on a ramp that
    starts from a hold it then differs from the reference only through the kink."""
    t = np.arange(6001) * 1e-3
    w = np.clip((t - 1.0) / 5.0, 0, 1) * 3000 * RPM
    params, lines = rt.load_model(model_path)
    ref = reference(model, t, w, 2)
    out = rt.WheelRuntime(params, lines, seed=2).run(t, w, alpha=None)
    err = rel_err(out, ref)
    assert np.all(err < 1e-3), err


# ------------------------------------------------------------------ steady amplitudes

def modal_gain(p, direction, nu, omega):
    """|interface/internal| of a whirl load e^{iνt}, written out here from the equations of motion."""
    if direction == "radial_force":
        m, c, k, g = p.mass, p.c_r, p.k_r, 0.0
    elif direction == "radial_torque":
        m, c, k, g = p.I_rr, p.c_rock, p.k_rock, p.I_zz
    elif direction == "axial_force":
        m, c, k, g = p.mass, p.c_z, p.k_z, 0.0
    else:
        return 1.0
    return abs((k + 1j * c * nu) / (k - m * nu**2 + g * omega * nu + 1j * c * nu))


@pytest.mark.parametrize("rpm", [2400.0, -1100.0])
def test_constant_speed_amplitudes(wheel_fmu, model, rpm):
    """At constant speed each line's amplitude (least squares on the FMU output) is
    C·Ω²·|coef|·|modal gain| within 0.5 %."""
    check_amplitudes(wheel_fmu, model, rpm, lambda ln, omega: ln.C * omega**2)


#: diagnosed amplitude laws (as ``rwadist diagnose`` writes them): the imbalance, a radial-force
#: harmonic and an axial one
LAWS = [{"kind": "amplitude_law", "direction": "radial_force", "h": 1.0, "exponent": 1.7,
         "amplitude_ref": 0.02, "omega_ref_rad_s": 200.0, "channel": ["Fx", "Fy"]},
        {"kind": "amplitude_law", "direction": "radial_force", "h": 2.0, "exponent": 2.5,
         "amplitude_ref": 0.004, "omega_ref_rad_s": 200.0, "channel": ["Fx", "Fy"]},
        {"kind": "amplitude_law", "direction": "axial_force", "h": 1.98, "exponent": 3.0,
         "amplitude_ref": 0.01, "omega_ref_rad_s": 150.0, "channel": ["Fz"]}]


@pytest.mark.parametrize("rpm", [2400.0, -1100.0])
def test_fmu_reads_amplitude_laws(tmp_path, model, rpm):
    """A model file improved by diagnose: each line with an amplitude law has amplitude
    A_ref·(|Ω|/Ω_ref)^p·|coef|·|modal gain| at constant speed (0.5 %), the others stay C·Ω²."""
    doc = model_io.to_json(model)
    doc["effects"] = LAWS
    path = build_fmu(doc, tmp_path / "laws.fmu")

    def amp(ln, omega):
        for e in LAWS:
            if e["direction"] == ln.direction and abs(e["h"] - ln.h) < 1e-3:
                return e["amplitude_ref"] * (abs(omega) / e["omega_ref_rad_s"]) ** e["exponent"]
        return ln.C * omega**2
    check_amplitudes(path, model, rpm, amp)


def test_amplitude_law_of_exponent_two_is_the_model(model_path, kernel):
    """A law with p = 2 and A_ref = C·Ω_ref² is C·Ω² again: outputs equal the law-free runtime on a
    spin-up (numpy and native), the imbalance's tangential term included; a law matching no line
    is reported as unused."""
    params, lines = rt.load_model(model_path)
    laws = {(d, h): (C * 180.0**2, 180.0, 2.0) for d, h, C, _, _ in lines}
    laws[("axial_force", 7.77)] = (1.0, 100.0, 2.0)
    t, w = spin_up(T=4.0)
    for k in (None, kernel):
        a = rt.WheelRuntime(params, lines, seed=5, kernel=k).run(t, w)
        W = rt.WheelRuntime(params, lines, seed=5, kernel=k, laws=laws)
        b = W.run(t, w)
        assert ("axial_force", 7.77) not in W.laws_used and len(W.laws_used) == len(lines)
        assert np.all(np.abs(b - a) <= 1e-12 * np.max(np.abs(a), axis=0)), rel_err(b, a)


def test_bad_amplitude_law_is_refused(model):
    doc = model_io.to_json(model)
    doc["effects"] = [dict(LAWS[0], exponent=-1.0)]
    with pytest.raises(rt.ModelError, match=r"effects\[0\].*exponent"):
        build_fmu(doc, "/nonexistent/x.fmu")


def check_amplitudes(fmu_path, model, rpm, amplitude):
    """Least-squares line amplitudes of the FMU output at constant ``rpm`` against
    amplitude(line, Ω)·|coef|·|modal gain| (0.5 %).  Returns (worst |amplitude/expected − 1|,
    number of line components checked)."""
    wheel_fmu = fmu_path
    p = ext.params_from_model(model)
    lines = ext.lines_from_model(model, p)
    omega = rpm * RPM
    dt = 1e-4
    t = np.arange(5001) * dt
    w = np.full(t.size, omega)
    out = hosts.run_fmpy(wheel_fmu, t, {"wheel_speed": w}, {"start_steady": True, "seed": 4})
    out = out[1:]
    tt = t[1:]
    F = out[:, 0] + 1j * out[:, 1]
    signals = {"radial_force": F, "radial_torque": out[:, 3] + 1j * out[:, 4] - 1j * p.height * F,
               "axial_force": out[:, 2], "axial_torque": out[:, 5]}
    checked, worst = 0, 0.0
    for d, sig in signals.items():
        comps = [(ln, s, c) for ln in lines if ln.direction == d for s, c in ln.components()]
        if d in ("axial_force", "axial_torque"):       # real signal: e^{±i hΩ t}
            freqs = [s * ln.h * abs(omega) for ln, s, _ in comps] + [-ln.h * abs(omega) for ln, _, _ in comps]
        else:
            freqs = [s * ln.h * omega for ln, s, _ in comps]
        A = np.exp(1j * np.outer(tt, freqs))
        coef, *_ = np.linalg.lstsq(A, sig.astype(complex), rcond=None)
        for k, (ln, s, cf) in enumerate(comps):
            nu = s * ln.h * omega
            expect = amplitude(ln, omega) * abs(cf) * modal_gain(p, d, nu, omega)
            got = abs(coef[k]) * (2 if d.startswith("axial") else 1)
            assert got == pytest.approx(expect, rel=5e-3), (d, ln.h, s, got, expect)
            worst = max(worst, abs(got / expect - 1))
            checked += 1
    assert checked == sum(len(ln.components()) for ln in lines)
    return worst, checked


# ------------------------------------------------------------------ model description

def test_fmpy_validate_and_model_description(wheel_fmu):
    from fmpy.validation import validate_fmu
    assert validate_fmu(str(wheel_fmu)) == []
    md = fmpy.read_model_description(str(wheel_fmu))
    names = [v.name for v in md.modelVariables]
    for ch in ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz"):
        assert ch in names and ch + "_sc" in names
    for v in md.modelVariables:
        assert v.description, v.name
        if v.causality in ("output", "input", "parameter"):
            assert v.start is not None, v.name
        if v.type == "Real":
            assert v.unit, v.name
        if v.causality == "output":
            assert v.initial == "exact"
    units = {v.name: v.unit for v in md.modelVariables if v.type == "Real"}
    assert units["Fx"] == "N" and units["Tz_sc"] == "N.m" and units["wheel_speed"] == "rad/s"
    files = zipfile.ZipFile(wheel_fmu).namelist()
    assert "resources/wheel_model.json" in files and "resources/rwadist_fmu_runtime.py" in files
    # the shipped runtime is this package's runtime, byte for byte
    shipped = zipfile.ZipFile(wheel_fmu).read("resources/rwadist_fmu_runtime.py")
    assert shipped == Path(rt.__file__).read_bytes()
    # and so are its sibling modules, each under its resource name
    for stem in rt.SIBLINGS:
        source = Path(rt.__file__).with_name(f"{stem}.py")
        assert zipfile.ZipFile(wheel_fmu).read(f"resources/{rt.fmu_file_name(stem)}") == source.read_bytes(), stem
    # and its reader of the model file is rwadist's one schema, byte for byte
    from rwadist import schema
    assert zipfile.ZipFile(wheel_fmu).read(f"resources/{rt.SCHEMA_FILE}") == Path(schema.__file__).read_bytes()


# ------------------------------------------------------------------ four instances

def test_four_instances_one_process(tmp_path, model):
    """A pyramid of four wheels: two separate builds (different models, unique module names) and
    two instances of each, each with its own speed, seed and mounting, stepped in lockstep."""
    m2 = wheel_model()
    for d in m2.empirical:
        for hm in m2.empirical[d]:
            hm.C *= 1.7
    f1 = build_fmu(model, tmp_path / "a.fmu")
    f2 = build_fmu(m2, tmp_path / "b.fmu")
    beta = np.radians(54.74)
    t = np.arange(1501) * 1e-3
    insts, paths, refs = [], [], []
    for k in range(4):
        az = k * np.pi / 2
        spin = np.array([np.cos(az) * np.sin(beta), np.sin(az) * np.sin(beta), np.cos(beta)])
        x = np.cross([0, 0, 1.0], spin)
        x /= np.linalg.norm(x)
        R = np.column_stack([x, np.cross(spin, x), spin])
        r = 0.25 * np.array([np.cos(az), np.sin(az), 0.1])
        w = (800 + 400 * k) * RPM * (1 - (2 if k % 2 else 0.5) * t / t[-1])
        params = {"use_wheel_acceleration": True, "seed": 10 + k, "r_x": r[0], "r_y": r[1], "r_z": r[2]}
        params.update({f"dcm_{i + 1}{j + 1}": R[i, j] for i in range(3) for j in range(3)})
        insts.append((f"wheel{k}", {"wheel_speed": w, "wheel_acceleration": slope(t, w)}, params))
        paths.append(f1 if k < 2 else f2)
        ref = reference(model if k < 2 else m2, t, w, 10 + k)
        refs.append(np.hstack([ref, rt.to_spacecraft(ref, R, r)]))
    outs = hosts.run_fmpy_many(paths, t, insts)
    for out, ref in zip(outs, refs):
        assert np.all(rel_err(out, ref) < 1e-9)
    assert not np.allclose(outs[0], outs[2][:, :], rtol=1e-3)


# ------------------------------------------------------------------ bad input through the host

def _instance(path, params=None, log=None, exit_init=True):
    # a logger of its own for every instance: fmpy (<= 0.3.32) keeps ONE native logger proxy per process, and
    # fmpy.simulate_fmu(logger=...) (rwadist fmu check) leaves it pointing at a freed callback, so a later instance
    # with fmpy's default callbacks crashes the process at the first error the FMU logs
    return hosts.FmpyInstance(path, "bad", params or {}, {"wheel_speed": 100.0}, log=log or hosts.HostLog(),
                              exit_init=exit_init)


def _goes_on(inst, t):
    """After a refusal: with the native layer the instance is in FMI 2.0's error state (a step is refused) and a
    reset starts a new run that steps; without it (pythonfmu alone) the same instance steps on at ``t``."""
    from fmpy.fmi1 import FMICallException
    if REFUSED == 3:
        with pytest.raises(FMICallException):
            inst.fmu.doStep(t, 1e-3)
        assert "in the error state" in inst.log.messages(3)[-1]
        inst.fmu.reset()
        inst.fmu.setupExperiment(startTime=0.0)
        inst.fmu.enterInitializationMode()
        inst.set("wheel_speed", 100.0)
        inst.fmu.exitInitializationMode()
        t = 0.0
    inst.fmu.doStep(t, 1e-3)
    assert all(np.isfinite(inst.get()))



def test_native_layer_is_built_where_it_can_be(wheel_fmu):
    assert has_native(wheel_fmu) == (REFUSED == 3)
    with zipfile.ZipFile(wheel_fmu) as z:
        names = z.namelist()
    ident = hosts._describe(wheel_fmu)[0].coSimulation.modelIdentifier
    assert f"binaries/linux64/{ident}.so" in names
    assert (f"binaries/linux64/{ident}_pythonfmu.so" in names) == (REFUSED == 3)


def test_plain_pythonfmu_build_reports_discard(tmp_path, model):
    """native=False: pythonfmu's own library, a refused step is fmi2Discard; results identical."""
    from fmpy.fmi1 import FMICallException
    plain = build_fmu(model, tmp_path / "plain.fmu", native=False)
    assert not has_native(plain)
    t, w = spin_up(T=2.0)
    t, w = t[:501], w[:501]
    a = hosts.run_fmpy(plain, t, {"wheel_speed": w})
    b = hosts.run_fmpy(build_fmu(model, tmp_path / "n.fmu"), t, {"wheel_speed": w})
    assert np.all(rel_err(b, a) < 1e-12)      # numpy steps vs the C kernel
    inst = _instance(plain)
    try:
        inst.set("wheel_speed", float("nan"))
        with pytest.raises(FMICallException) as exc:
            inst.fmu.doStep(0.0, 1e-3)
        assert exc.value.status == 2
    finally:
        inst.close()


@pytest.mark.parametrize("case", ["nan_speed", "inf_speed", "speed_jump", "step_too_large", "bad_acceleration"])
def test_bad_input_is_refused_and_host_survives(wheel_fmu, case):
    from fmpy.fmi1 import FMICallException
    log = hosts.HostLog()
    params = {"use_wheel_acceleration": True} if case == "bad_acceleration" else {}
    inst = _instance(wheel_fmu, params, log)
    try:
        inst.fmu.doStep(0.0, 1e-3)
        y_good = inst.get()
        h, speed, acc = 1e-3, 100.0, 0.0
        if case == "nan_speed":
            speed = float("nan")
        elif case == "inf_speed":
            speed = float("inf")
        elif case == "speed_jump":
            speed = 200.0
        elif case == "step_too_large":
            h = 0.05
        else:
            acc = float("nan")
        inst.set("wheel_speed", speed)
        inst.set("wheel_acceleration", acc)
        with pytest.raises(FMICallException) as exc:
            inst.fmu.doStep(1e-3, h)
        assert exc.value.status == REFUSED, exc.value.status
        errors = log.messages(min_status=3)
        key = {"nan_speed": "wheel_speed is not finite", "inf_speed": "wheel_speed is not finite",
               "speed_jump": "jumps", "step_too_large": "exceeds max_step_size",
               "bad_acceleration": "wheel_acceleration is not finite"}[case]
        assert any(key in m for m in errors), errors
        assert inst.get() == y_good                 # state untouched
        if REFUSED != 3:
            inst.set("wheel_speed", 100.0)
            inst.set("wheel_acceleration", 0.0)
        _goes_on(inst, 1e-3)
    finally:
        inst.close()


@pytest.mark.parametrize("case", ["missing_file", "invalid_json", "no_analytical", "bad_dcm", "bad_seed"])
def test_bad_model_or_parameter(wheel_fmu, tmp_path, case):
    from fmpy.fmi1 import FMICallException
    params = {}
    if case == "missing_file":
        params["model_file"] = str(tmp_path / "nope.json")
        key = "cannot be read"
    elif case == "invalid_json":
        (tmp_path / "bad.json").write_text("{not json")
        params["model_file"] = str(tmp_path / "bad.json")
        key = "not valid JSON"
    elif case == "no_analytical":
        doc = model_io.to_json(preset("ithaco-e").to_model())
        doc.pop("analytical")
        (tmp_path / "m.json").write_text(json.dumps(doc))
        params["model_file"] = str(tmp_path / "m.json")
        key = "analytical: missing"
    elif case == "bad_dcm":
        params["dcm_11"] = 2.0
        key = "not a proper rotation"
    else:
        params["seed"] = -5
        key = "seed must be"
    log = hosts.HostLog()
    inst = _instance(wheel_fmu, params, log, exit_init=False)
    try:
        if REFUSED == 3:
            with pytest.raises(FMICallException) as exc:
                inst.fmu.exitInitializationMode()
            assert exc.value.status == 3
        else:
            inst.fmu.exitInitializationMode()
        assert any(key in m for m in log.messages(3)), log.records
        with pytest.raises(FMICallException) as exc:
            inst.fmu.doStep(0.0, 1e-3)
        assert exc.value.status == REFUSED
        if REFUSED == 3:        # the native layer: FMI 2.0's error state, saying what to do
            assert "fmi2DoStep: illegal call sequence: the instance is in the error state" in log.messages(3)[-1]
        else:                   # pythonfmu alone: the slave repeats why
            assert any("cannot step" in m and key in m for m in log.messages(3))
    finally:
        inst.close()
    # the host process still runs other instances
    good = hosts.run_fmpy(wheel_fmu, np.arange(11) * 1e-3, {"wheel_speed": np.full(11, 50.0)})
    assert np.all(np.isfinite(good))


def test_alternative_model_file_parameter(wheel_fmu, tmp_path, model):
    """The model_file string parameter points the FMU at another wheel."""
    m2 = wheel_model()
    m2.analytical = dict(m2.analytical, U_s_kg_m=3 * m2.analytical["U_s_kg_m"])
    path = model_io.save(m2, tmp_path / "other.json")
    t, w = reversal(T=1.0)
    out = hosts.run_fmpy(wheel_fmu, t, {"wheel_speed": w, "wheel_acceleration": slope(t, w)},
                         {"model_file": str(path), "use_wheel_acceleration": True})
    assert np.all(rel_err(out[:, :6], reference(m2, t, w, None)) < 1e-9)
    assert not np.allclose(out[:, :6], reference(model, t, w, None), rtol=1e-3)


# ------------------------------------------------------------------ effects, frames

def test_effect_switches_and_rigid_mounting(model_path, model):
    """modes off: the interface sees the internal loads C·Ω²·coef·e^{iσhφ} directly; imbalance /
    harmonics off remove exactly their lines (superposition)."""
    params, lines = rt.load_model(model_path)
    t = np.arange(801) * 1e-3
    w = 1200 * RPM + 20 * t
    full = rt.WheelRuntime(params, lines, seed=1).run(t, w)
    imb = rt.WheelRuntime(params, lines, seed=1, harmonics=False).run(t, w)
    har = rt.WheelRuntime(params, lines, seed=1, imbalance=False).run(t, w)
    assert np.max(np.abs(imb + har - full)) < 1e-12 * np.max(np.abs(full))
    rigid = rt.WheelRuntime(params, lines, seed=1, modes=False).run(t, w)
    p = ext.params_from_model(model)
    ph = np.random.default_rng(1).uniform(0, 2 * np.pi, len(lines))
    phi = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * 1e-3)])
    F = np.zeros(t.size, complex)
    T = np.zeros(t.size, complex)
    Fz = np.zeros(t.size)
    wdot = np.full(t.size, 20.0)
    for ln, q in zip(ext.lines_from_model(model, p), ph):
        line = ext.Line(ln.direction, ln.h, ln.C, ln.sense, q, ln.angle, ln.imbalance)
        amp = ln.C * (w**2 - 1j * wdot * ln.imbalance)
        for s, cf in line.components():
            load = cf * amp * np.exp(1j * s * ln.h * phi)
            if ln.direction == "radial_force":
                F += load
            elif ln.direction == "radial_torque":
                T += load
            elif ln.direction == "axial_force":
                Fz += load.real
    T = T + 1j * p.height * F
    expect = np.column_stack([F.real, F.imag, Fz, T.real, T.imag, rigid[:, 5]])
    assert np.allclose(rigid[1:], expect[1:], rtol=0, atol=1e-12 * np.max(np.abs(expect)))


def test_rotation_check():
    rt.rotation_check(np.eye(3))
    with pytest.raises(rt.ModelError):
        rt.rotation_check(np.diag([1.0, 1.0, -1.0]))     # a reflection
    with pytest.raises(rt.ModelError):
        rt.rotation_check(1.01 * np.eye(3))


# ------------------------------------------------------------------ convergence in the step size

def test_step_size_convergence(model_path, model):
    """Spin-up 0→3000 rpm in 4 s through every resonance; outputs at common times for steps
    1e-4, 1e-3, 1e-2 s against simulate_time at 1e-5 s.  With the acceleration input the error
    (frozen-speed rocking transition, linear amplitude over a step) is second order in the step:
    measured ~1e-7 / 1e-5 / 1e-3 relative.  With the derived acceleration (one-step lag) it is
    about first order: ~1e-5 / 1e-4 / 1e-2."""
    params, lines = rt.load_model(model_path)
    T = 4.0
    t_ref = np.arange(int(round(T / 1e-5)) + 1) * 1e-5
    ref = reference(model, t_ref, 3000 * RPM * t_ref / T, 6)[::1000]        # every 10 ms
    scale = np.max(np.abs(ref), axis=0)
    errs = {}
    for mode in ("slope", None):
        for h in (1e-4, 1e-3, 1e-2):
            n = int(round(T / h))
            t = np.arange(n + 1) * h
            out = rt.WheelRuntime(params, lines, seed=6).run(t, 3000 * RPM * t / T, alpha=mode)
            every = int(round(1e-2 / h))
            errs[(mode, h)] = float(np.max(np.max(np.abs(out[::every] - ref), axis=0) / scale))
    print("step-size convergence (max rel. error vs simulate_time at 1e-5 s):", errs)
    assert errs[("slope", 1e-2)] < 5e-3 and errs[("slope", 1e-3)] < 5e-5 and errs[("slope", 1e-4)] < 5e-7
    assert errs[("slope", 1e-3)] < 0.03 * errs[("slope", 1e-2)]          # second order
    assert errs[(None, 1e-2)] < 3e-2 and errs[(None, 1e-3)] < 4e-4 and errs[(None, 1e-4)] < 5e-5


def test_runtime_refuses_unresolvable_steps(model_path):
    params, lines = rt.load_model(model_path)
    wr = rt.WheelRuntime(params, lines, max_step=0.01)
    for h in (0.0, -1e-3, float("nan"), 0.02, 1e-12):
        with pytest.raises(rt.ModelError):
            wr.step(10.0, 0.0, h)


# ------------------------------------------------------------------ CLI

def test_cli_fmu_build_and_check(tmp_path, model_path, capsys):
    from rwadist.cli import main
    out = tmp_path / "w.fmu"
    assert main(["fmu", "build", str(model_path), "-o", str(out)]) == 0
    assert main(["fmu", "check", str(out), "--stop-time", "0.5"]) == 0
    text = capsys.readouterr().out
    assert "fmpy validation: 0 problem(s)" in text and "Fx_sc" in text and "(501 samples)" in text
    assert "missing input" not in text.lower() and "warning" not in text.lower()     # every input has its signal
    # 1500 rpm in 0.2 s is 785 rad/s², above the FMU's max_acceleration (500): the check's own ramp is refused before
    # it runs, naming the flag and the shortest ramp (it ran, failed with exit 1, and read as a broken FMU)
    assert main(["fmu", "check", str(out), "--stop-time", "0.2"]) == 2
    err = capsys.readouterr().err
    assert "--stop-time: value:" in err and "785.4 rad/s²" in err and "max_acceleration of 500" in err
    assert "give --stop-time 0.32 s or more" in err
    assert main(["fmu", "build", "--preset", "ithaco-e", "-o", str(tmp_path / "e.fmu")]) == 0
    bad = tmp_path / "bad.json"
    bad.write_text("{}")
    assert main(["fmu", "build", str(bad), "-o", str(tmp_path / "x.fmu")]) == 2
    assert "schema" in capsys.readouterr().err


# ------------------------------------------------------------------ fresh venv, second host

@pytest.mark.slow
def test_fresh_venv_fmpy_and_libcosim(tmp_path, wheel_fmu, model, fresh_fmpy_venv):
    """A new virtual environment with only numpy, fmpy (+ its XML reader) and libcosimpy -- no
    rwadist, no pythonfmu -- runs the FMU in both hosts and reproduces simulate_time.
    (The environment is built once per run in conftest.py and shared with test_fmu_native.py.)"""
    py = fresh_fmpy_venv
    t, w = reversal(T=1.0)
    np.savez(tmp_path / "prof.npz", t=t, omega=w, alpha=slope(t, w), seed=8)
    script = tmp_path / "hosts.py"
    shutil.copy2(hosts.__file__, script)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    res = subprocess.run([str(py), str(script), str(wheel_fmu), str(tmp_path / "prof.npz"),
                          str(tmp_path / "out.npz")], capture_output=True, text=True, timeout=300,
                         cwd=tmp_path, env=env)
    assert res.returncode == 0, res.stderr[-3000:]
    got = np.load(tmp_path / "out.npz")
    assert not bool(got["rwadist_importable"])
    ref = reference(model, t, w, 8)
    assert np.all(rel_err(got["fmpy"][:, :6], ref) < 1e-9)
    assert np.all(rel_err(got["libcosim"][1:, :6], ref[1:]) < 1e-9)


def test_runtime_imbalance_rule_matches_the_kit():
    """The self-contained runtime reads model files exactly as rwadist does (h ≈ 1 co-rotating = imbalance)."""
    assert rt.IMBALANCE_H_TOL == ext.IMBALANCE_H_TOL
    from rwadist import catalogue

    m = catalogue.load("ithaco-b")   # fundamentals listed at h = 0.99
    p = ext.params_from_model(m)
    kit = ext.lines_from_model(m, p)
    _, lines = rt.model_from_doc(model_io.to_json(m))
    assert len(lines) == len(kit)


def test_get_real_of_parameters_inputs_and_outputs(wheel_fmu):
    """The slave's direct Real paths return what was set (parameters, inputs) and what was
    computed (outputs), in any order and mix, and a non-Real reference is still refused (the instance then goes
    on as FMI 2.0 says)."""
    from fmpy.fmi1 import FMICallException
    inst = _instance(wheel_fmu, {"dcm_11": 0.0, "dcm_12": -1.0, "dcm_21": 1.0, "dcm_22": 0.0, "r_y": 0.25,
                                 "max_step_size": 0.005})
    try:
        inst.set("wheel_speed", 120.0)
        inst.fmu.doStep(0.0, 1e-3)
        v = inst.vars
        names = ["Tz_sc", "dcm_12", "wheel_speed", "r_y", "Fx", "max_step_size", "Fy_sc", "dcm_33"]
        got = inst.fmu.getReal([v[n].valueReference for n in names])
        y = dict(zip(inst.output_names, inst.get()))
        assert got == [y["Tz_sc"], -1.0, 120.0, 0.25, y["Fx"], 0.005, y["Fy_sc"], 1.0]
        assert y["Fy_sc"] == y["Fx"]                     # row 2 of the DCM is (1, 0, 0)
        # a wrong type is refused the FMI way (no exception into pythonfmu: it would double-free the
        # slave when the host frees the instance), and the instance still works and closes cleanly
        with pytest.raises(FMICallException) as exc:
            inst.fmu.getReal([v["seed"].valueReference])
        assert exc.value.status == REFUSED
        with pytest.raises(FMICallException) as exc:
            inst.fmu.setReal([v["seed"].valueReference], [3.0])
        assert exc.value.status == REFUSED
        with pytest.raises(FMICallException) as exc:
            inst.fmu.getInteger([v["Fx"].valueReference])
        assert exc.value.status == REFUSED
        _goes_on(inst, 1e-3)
    finally:
        inst.close()
    import gc
    gc.collect()


@pytest.mark.parametrize("profile", [spin_up, reversal])
def test_fmu_with_laws_equals_simulate_time_with_laws(tmp_path, model, profile):
    """A diagnosed model file through fmpy equals rwadist.extended_time.simulate_time of the lines
    lines_from_model builds from the same file (laws attached), 1e-9 relative."""
    doc = model_io.to_json(model)
    doc["effects"] = LAWS
    improved = model_io.from_json(doc)
    p = ext.params_from_model(improved)
    lines = ext.lines_from_model(improved, p)
    assert sum(ln.law is not None for ln in lines) == 3
    t, w = profile(T=4.0)
    ref = simulate_time(p, lines, t, w, seed=8)
    out = hosts.run_fmpy(build_fmu(doc, tmp_path / "laws.fmu"), t,
                         {"wheel_speed": w, "wheel_acceleration": slope(t, w)},
                         {"use_wheel_acceleration": True, "seed": 8})
    assert np.all(rel_err(out[:, :6], ref) < 1e-9), rel_err(out[:, :6], ref)


# ------------------------------------------------------------------ wheel-mode resonances and sidebands (issue 7)

#: diagnosed effects as ``rwadist diagnose`` writes them: two wheel-mode resonances (radial force; rocking and
#: axial torque together), a test-stand resonance (a fixture artefact the FMU must leave out), and sidebands on
#: the imbalance (tangential term), a planar radial line, a rocking line and an axial-torque line
EFFECTS = [{"kind": "fixed_resonance", "role": "wheel_mode", "f_Hz": 95.0, "zeta": 0.05, "peak_gain": 4.0,
            "directions": ["radial_force"], "channel": ["Fx", "Fy"]},
           {"kind": "fixed_resonance", "role": "wheel_mode", "f_Hz": 60.0, "zeta": 0.08, "peak_gain": 0.3,
            "directions": ["radial_torque", "axial_torque"], "channel": ["Tx", "Ty", "Tz"]},
           {"kind": "fixed_resonance", "role": "test_stand", "f_Hz": 70.0, "zeta": 0.03, "peak_gain": 5.0,
            "directions": list(ext.DIRECTIONS), "channel": ["Fx", "Fy", "Fz", "Tx", "Ty", "Tz"]},
           {"kind": "sidebands", "direction": "radial_force", "h": 1.0, "f_mod_Hz": 7.0, "depth": 0.3},
           {"kind": "sidebands", "direction": "radial_force", "h": 2.7, "f_mod_Hz": 9.5, "depth": 0.2},
           {"kind": "sidebands", "direction": "radial_torque", "h": 4.42, "f_mod_Hz": 11.0, "depth": 0.4},
           {"kind": "sidebands", "direction": "axial_torque", "h": 2.0, "f_mod_Hz": 5.0, "depth": 0.5}]


def effects_doc(model, effects=EFFECTS):
    doc = model_io.to_json(model)
    doc["effects"] = [dict(e) for e in effects]
    return doc


def effects_runtime(doc, **kw):
    params, lines = rt.model_from_doc(doc)
    return rt.WheelRuntime(params, lines, **rt.effects_from_doc(doc), **kw)


@pytest.mark.parametrize("profile", [spin_up, reversal])
def test_fmu_with_resonances_and_sidebands_equals_simulate_time(tmp_path, model, profile):
    """A model file with wheel-mode resonances and sidebands (round-tripped through the model-file
    JSON) through fmpy and through the numpy runtime equals rwadist.extended_time.simulate_time of the
    lines lines_from_model builds from it, 1e-9 relative; the test-stand resonance is left out."""
    doc = effects_doc(model)
    improved = model_io.from_json(json.loads(json.dumps(doc)))
    assert model_io.to_json(improved)["effects"] == doc["effects"]
    p = ext.params_from_model(improved)
    lines = ext.lines_from_model(improved, p)
    assert sum(ln.f_offset != 0 for ln in lines) == 8
    assert all(res[0] != 70.0 for ln in lines for res in ln.resonances)
    t, w = profile(T=4.0)
    for seed in (None, 8):
        ref = simulate_time(p, lines, t, w, seed=seed)
        out = effects_runtime(doc, seed=seed).run(t, w)
        assert np.all(rel_err(out, ref) < 1e-9), rel_err(out, ref)
    fmu_path = build_fmu(doc, tmp_path / "effects.fmu")
    with zipfile.ZipFile(fmu_path) as z:
        shipped = json.loads(z.read("resources/wheel_model.json"))
    assert shipped["effects"] == doc["effects"]
    out = hosts.run_fmpy(fmu_path, t, {"wheel_speed": w, "wheel_acceleration": slope(t, w)},
                         {"use_wheel_acceleration": True, "seed": 8})
    assert np.all(rel_err(out[:, :6], ref) < 1e-9), rel_err(out[:, :6], ref)


def resonance_magnitude(direction, f_hz):
    """|Π H| of the wheel-mode resonances of EFFECTS on ``direction`` at |f| (rwadist.diagnose.resonance)."""
    from rwadist.diagnose import resonance
    g = 1.0
    for e in EFFECTS:
        if e["kind"] == "fixed_resonance" and e["role"] == "wheel_mode" and direction in e["directions"]:
            g *= abs(resonance(abs(f_hz), e["f_Hz"], e["zeta"], e["peak_gain"]))
    return g


@pytest.mark.parametrize("rpm", [2400.0, -1100.0])
def test_resonance_and_sideband_amplitudes_at_constant_speed(tmp_path, model, rpm):
    """At constant speed (fmpy, least squares on the output): every carrier has C·Ω²·|coef|·|modal gain|
    ·|H(f)| and each of its sidebands, whose whirl rate is σ(hΩ ± 2πf_mod), (m/2)·C·Ω²·|coef|·|modal
    gain|·|H| at the sideband's own frequency (0.5 %).  Written out from the effects, not from Line."""
    p = ext.params_from_model(model)
    base = ext.lines_from_model(model, p)          # no effects: the carriers
    comps = []                                     # (direction, whirl rate ν rad/s, expected amplitude)
    omega = rpm * RPM
    for ln in base:
        for s, cf in ln.components():
            a = ln.C * omega**2 * abs(cf)
            parts = [(s * ln.h * omega, a)]
            for e in EFFECTS:
                if e["kind"] == "sidebands" and e["direction"] == ln.direction and abs(e["h"] - ln.h) < 1e-3:
                    wm = 2 * np.pi * e["f_mod_Hz"]
                    parts += [(s * (ln.h * omega + wm), 0.5 * e["depth"] * a),
                              (s * (ln.h * omega - wm), 0.5 * e["depth"] * a)]
            for nu, amp in parts:
                amp *= modal_gain(p, ln.direction, nu, omega) * resonance_magnitude(ln.direction, nu / (2 * np.pi))
                comps.append((ln.direction, nu, amp))
    assert len(comps) == sum(len(ln.components()) for ln in base) + 2 * 5
    path = build_fmu(effects_doc(model), tmp_path / "effects.fmu")
    dt = 1e-4
    t = np.arange(5001) * dt
    out = hosts.run_fmpy(path, t, {"wheel_speed": np.full(t.size, omega)}, {"start_steady": True, "seed": 4})[1:]
    tt = t[1:]
    F = out[:, 0] + 1j * out[:, 1]
    signals = {"radial_force": F, "radial_torque": out[:, 3] + 1j * out[:, 4] - 1j * p.height * F,
               "axial_force": out[:, 2], "axial_torque": out[:, 5]}
    worst = 0.0
    for d, sig in signals.items():
        mine = [(nu, amp) for dd, nu, amp in comps if dd == d]
        freqs = [nu for nu, _ in mine]
        if d.startswith("axial"):                  # real signal: e^{±iνt}
            freqs = freqs + [-nu for nu in freqs]
        coef, *_ = np.linalg.lstsq(np.exp(1j * np.outer(tt, freqs)), sig.astype(complex), rcond=None)
        for k, (nu, amp) in enumerate(mine):
            got = abs(coef[k]) * (2 if d.startswith("axial") else 1)
            assert got == pytest.approx(amp, rel=5e-3), (d, nu / (2 * np.pi), got, amp)
            worst = max(worst, abs(got / amp - 1))
    print(f"\n{rpm} rpm: largest relative amplitude error over {len(comps)} components {worst:.2e}")

@NATIVE_ONLY
@pytest.mark.parametrize("profile", [spin_up, reversal])
def test_native_kernel_with_resonances_and_sidebands_equals_numpy(model, kernel, profile):
    """C kernel = numpy runtime with resonances and sidebands (1e-12 relative), every switch and start."""
    assert kernel is not None
    t, w = profile(T=3.0)
    doc = effects_doc(model)
    h = t[1] - t[0]
    acc = slope(t, w)
    for kw in (dict(), dict(start_steady=True), dict(modes=False), dict(harmonics=False), dict(imbalance=False)):
        assert_native_equals_numpy(effects_runtime(doc, seed=4, **kw), effects_runtime(doc, seed=4, kernel=kernel, **kw),
                                   w, acc, h, kw)


def test_test_stand_resonance_is_left_out(model_path, model):
    """A test-stand resonance (and a load-cell offset) is a measurement artefact: the FMU output is the
    effect-free one, bit for bit."""
    doc = effects_doc(model, [EFFECTS[2], {"kind": "cross_coupling", "r_m": [0.0, 0.0, 0.05]}])
    t, w = spin_up(T=2.0)
    params, lines = rt.load_model(model_path)
    a = rt.WheelRuntime(params, lines, seed=3).run(t, w)
    b = effects_runtime(doc, seed=3).run(t, w)
    assert np.array_equal(a, b)


@pytest.mark.parametrize("index, field, value", [
    (0, "f_Hz", float("nan")), (0, "zeta", 0.0), (0, "peak_gain", -1.0), (1, "directions", ["sideways"]),
    (1, "role", "fixture"), (3, "depth", -0.1), (4, "f_mod_Hz", 0.0), (5, "h", float("inf")),
    (6, "direction", "radial")])
def test_bad_resonance_or_sideband_entry_is_refused(model, index, field, value):
    """A bad entry is refused naming effects[i].<field>: by the FMU build (ModelError) and by
    rwadist.extended.lines_from_model (ValueError)."""
    effects = [dict(e) for e in EFFECTS]
    effects[index][field] = value
    doc = effects_doc(model, effects)
    pattern = rf"effects\[{index}\]\.{field}"
    with pytest.raises(rt.ModelError, match=pattern):
        build_fmu(doc, "/nonexistent/x.fmu")
    p = ext.params_from_model(model)
    with pytest.raises(ValueError, match=pattern):     # the one schema refuses it at load already
        improved = model_io.from_json(json.loads(json.dumps(doc, allow_nan=True)))
        ext.lines_from_model(improved, p)


def test_unmatched_sidebands_warn(model):
    """Sidebands of a harmonic the model does not have add nothing, and the build says so."""
    from rwadist.fmu.build import model_document
    doc = effects_doc(model, [{"kind": "sidebands", "direction": "axial_force", "h": 6.5, "f_mod_Hz": 3.0,
                               "depth": 0.2}])
    with pytest.warns(RuntimeWarning, match="sidebands of axial_force h=6.5"):
        model_document(doc)
    W = effects_runtime(doc)
    assert W.sidebands_used == set() and W.n_lines == len(rt.model_from_doc(doc)[1])


def test_cli_fmu_check_a_damaged_description_is_bad_input(tmp_path, capsys):
    """A zip whose modelDescription.xml is not XML: one line naming the file (exit 2), not an internal error (the
    ramp check read the description before fmpy's validation caught it)."""
    import zipfile

    from rwadist.cli import main
    bad = tmp_path / "bad.fmu"
    with zipfile.ZipFile(bad, "w") as z:
        z.writestr("modelDescription.xml", "<fmiModelDescription garbage")
    assert main(["fmu", "check", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "bad.fmu" in err and "cannot be read by fmpy" in err and "internal error" not in err
