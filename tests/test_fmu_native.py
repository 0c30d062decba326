"""The native C FMU (issue 16): the same numbers as the pythonfmu FMU and rwadist.extended_time.simulate_time
with every effect class on, the same floor multisine for a seed, FMI conformance (fmpy validate, the
pythonfmu FMU's variables), FMU state that restores a run bit for bit, fmi2Error on bad input, four
instances, libcosim, a C host without Python, a rebuild from the FMU's sources/, no libpython."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import zipfile

import numpy as np
import pytest

from rwadist import extended as ext
from rwadist import model as model_io
from rwadist.extended_time import simulate_time
from rwadist.fmu import hosts
from rwadist.fmu import runtime as rt
from rwadist.fmu.build import build_fmu, native_supported
from rwadist.presets import preset

pytest.importorskip("pythonfmu")
fmpy = pytest.importorskip("fmpy")
pytestmark = pytest.mark.skipif(not (native_supported() and shutil.which(os.environ.get("CC", "cc"))),
                                reason="the native FMU's binary is built on Linux x86-64 with a C compiler")

from rwadist.fmu.native_build import VARIABLES, build_native_fmu, compile_c_host  # noqa: E402

RPM = 2 * np.pi / 60

#: every effect class the FMU models: amplitude law, wheel-mode resonances (one per subsystem), sidebands
#: (on the imbalance, a planar line, an axial-torque line), a speed ripple and broadband floors on three channels
EFFECTS = [
    {"kind": "amplitude_law", "direction": "radial_torque", "h": 3.0, "amplitude_ref": 2.0e-3,
     "omega_ref_rad_s": 200.0, "exponent": 2.5},
    {"kind": "fixed_resonance", "role": "wheel_mode", "f_Hz": 95.0, "zeta": 0.05, "peak_gain": 4.0,
     "directions": ["radial_force"]},
    {"kind": "fixed_resonance", "role": "wheel_mode", "f_Hz": 60.0, "zeta": 0.08, "peak_gain": 0.3,
     "directions": ["radial_torque", "axial_torque"]},
    {"kind": "fixed_resonance", "role": "test_stand", "f_Hz": 70.0, "zeta": 0.03, "peak_gain": 5.0,
     "directions": ["axial_force"]},
    {"kind": "sidebands", "direction": "radial_force", "h": 1.0, "f_mod_Hz": 7.0, "depth": 0.3},
    {"kind": "sidebands", "direction": "radial_force", "h": 2.7, "f_mod_Hz": 9.5, "depth": 0.2},
    {"kind": "sidebands", "direction": "axial_torque", "h": 2.0, "f_mod_Hz": 5.0, "depth": 0.5},
    {"kind": "speed_ripple", "f_ripple_Hz": 4.0, "delta_omega_rad_s": 3.0, "omega_ref_rad_s": 200.0,
     "speed_exponent": 0.5},
    {"kind": "broadband_floor", "channel": ["Fx", "Fz", "Tz"], "exponent": 2.0, "omega_ref_rad_s": 200.0,
     "f_Hz": [5.0, 60.0, 140.0, 300.0], "psd_ref": [1.0e-5, 4.0e-5, 4.0e-5, 0.5e-5]},
]
LINE_EFFECTS = [e for e in EFFECTS if e["kind"] not in ("speed_ripple", "broadband_floor")]
R = [[0.0, -1.0, 0.0], [np.sqrt(0.5), 0.0, -np.sqrt(0.5)], [np.sqrt(0.5), 0.0, np.sqrt(0.5)]]
POS = [0.3, -0.2, 0.5]


def wheel_doc(effects=EFFECTS):
    """The E-wheel preset plus an axial-torque line and a planar radial line, with ``effects``."""
    m = preset("ithaco-e").to_model()
    m.empirical["axial_torque"] = [model_io.Harmonic(h=2.0, C=3.0e-7)]
    m.empirical["radial_force"].append(model_io.Harmonic(h=2.7, C=4.0e-7, sense="planar"))
    doc = model_io.to_json(m)
    doc["effects"] = json.loads(json.dumps(effects))
    return doc


def spin_up(dt=1e-3, T=2.0):
    t = np.arange(int(round(T / dt)) + 1) * dt
    return t, 3000 * RPM * t / T


def reversal(dt=1e-3, T=2.0):
    t = np.arange(int(round(T / dt)) + 1) * dt
    return t, 1500 * RPM * (1 - 2 * t / T)


def slope(t, w):
    return np.append(np.diff(w) / (t[1] - t[0]), 0.0)


def mount_params(seed):
    p = {"use_wheel_acceleration": True, "seed": seed, "r_x": POS[0], "r_y": POS[1], "r_z": POS[2]}
    p.update({f"dcm_{i + 1}{j + 1}": R[i][j] for i in range(3) for j in range(3)})
    return p


def worst(out, ref):
    """max |out − ref| per channel / the channel's peak (a channel 0 in ref must be 0 in out)."""
    scale = np.max(np.abs(ref), axis=0)
    diff = np.max(np.abs(out - ref), axis=0)
    return np.where(scale > 0, diff / np.where(scale > 0, scale, 1.0), np.where(diff > 0, np.inf, 0.0))


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    """(doc, native FMU, pythonfmu FMU) of the wheel with every effect."""
    d = tmp_path_factory.mktemp("native")
    doc = wheel_doc()
    return doc, build_native_fmu(doc, d / "wheel_c.fmu", windows=False), build_fmu(doc, d / "wheel_py.fmu")


@pytest.fixture(scope="module")
def line_fmus(tmp_path_factory):
    d = tmp_path_factory.mktemp("native_lines")
    doc = wheel_doc(LINE_EFFECTS)
    return doc, build_native_fmu(doc, d / "lines_c.fmu", windows=False)


# ------------------------------------------------------------------ same numbers

@pytest.mark.parametrize("profile", [spin_up, reversal])
def test_native_equals_pythonfmu_with_every_effect(fmus, profile):
    """Spin-up 0→3000 rpm and reversal ±1500 rpm, every effect class on, mounting for the spacecraft
    frame: the native FMU's 12 outputs equal the pythonfmu FMU's to 1e-12 of each channel's peak."""
    _, native, python = fmus
    t, w = profile()
    inputs = {"wheel_speed": w, "wheel_acceleration": slope(t, w)}
    a = hosts.run_fmpy(native, t, inputs, mount_params(5))
    b = hosts.run_fmpy(python, t, inputs, mount_params(5))
    err = worst(a, b)
    print(f"native vs pythonfmu ({profile.__name__}, every effect): max rel. error {np.max(err):.3g}")
    assert np.all(err <= 1e-12), err


@pytest.mark.parametrize("profile", [spin_up, reversal])
def test_native_equals_simulate_time(line_fmus, profile):
    """With the line effects (amplitude law, resonances, sidebands; simulate_time has no ripple or floor):
    native FMU = rwadist.extended_time.simulate_time of lines_from_model, seed 5, to 1e-12 of each channel's peak
    (simulate_time integrates the same equations by another route, lfilter and a blocked scan; the FMU's clock is
    the host's communication point, as simulate_time's t − t0, not a sum of steps)."""
    doc, native = line_fmus
    t, w = profile()
    m = model_io.from_json(doc)
    p = ext.params_from_model(m)
    ref = simulate_time(p, ext.lines_from_model(m, p), t, w, seed=5)
    out = hosts.run_fmpy(native, t, {"wheel_speed": w, "wheel_acceleration": slope(t, w)},
                         {"use_wheel_acceleration": True, "seed": 5})
    err = worst(out[:, :6], ref)
    print(f"native vs simulate_time ({profile.__name__}): max rel. error {np.max(err):.3g}")
    assert np.all(err <= 1e-12), err


@pytest.mark.parametrize("seed", [-1, 0, 7])
def test_floor_multisine_same_seed(fmus, seed):
    """Floors alone (lines and ripple off): the native multisine equals the pythonfmu FMU's and the numpy
    runtime's for the same seed (phases of numpy's default_rng((seed, 2)) in both) to 1e-12."""
    doc, native, python = fmus
    t = np.arange(1501) * 1e-3
    w = np.full(t.size, 2000 * RPM)
    par = {"seed": seed, "imbalance": False, "harmonics": False, "speed_ripple": False}
    a = hosts.run_fmpy(native, t, {"wheel_speed": w}, par)
    b = hosts.run_fmpy(python, t, {"wheel_speed": w}, par)
    params, lines = rt.model_from_doc(doc)
    eff = rt.effects_from_doc(doc)
    run = rt.WheelRuntime(params, lines, seed=None if seed == -1 else seed, imbalance=False, harmonics=False,
                          speed_ripple=False, **eff)
    c = run.run(t, w, alpha=None)
    assert np.max(np.abs(a[:, [0, 2, 5]])) > 0
    assert np.all(worst(a, b) <= 1e-12) and np.all(worst(a[:, :6], c) <= 1e-12), (worst(a, b), worst(a[:, :6], c))


# ------------------------------------------------------------------ FMI conformance

def test_fmpy_validate_and_same_variables(fmus, tmp_path):
    """fmpy validate: 0 problems; the variables (names, value references, types, causality, variability,
    start values, units) are the pythonfmu FMU's; state capabilities declared; sources/ listed and shipped."""
    from fmpy import read_model_description
    from fmpy.validation import validate_fmu
    _, native, python = fmus
    assert validate_fmu(str(native)) == []
    a, b = read_model_description(native), read_model_description(python)

    def key(v):
        return (v.name, v.valueReference, v.type, v.causality, v.variability, v.start, v.unit)
    assert [key(v) for v in a.modelVariables] == [key(v) for v in b.modelVariables]
    assert len(VARIABLES) == len(a.modelVariables)
    cs = a.coSimulation
    assert cs.canGetAndSetFMUstate and cs.canSerializeFMUstate and not cs.needsExecutionTool
    files = a.buildConfigurations[0].sourceFileSets[0].sourceFiles
    with zipfile.ZipFile(native) as z:
        names = z.namelist()
    assert files == ["rwadist_wheel_fmu.c"]
    assert {f"sources/{f}" for f in ("rwadist_wheel_fmu.c", "rwadist_kernel.h", "rwadist_rng.h", "wheel_model.h",
                                      "fmi2Functions.h")} <= set(names)
    assert not any(n.endswith(".py") for n in names)
    assert "diagnosed effects" in a.description


def test_no_libpython(fmus, tmp_path):
    """ldd of the native binary: libc and libm only, no libpython."""
    _, native, _ = fmus
    with zipfile.ZipFile(native) as z:
        so = [n for n in z.namelist() if n.endswith(".so")]
        assert len(so) == 1
        z.extract(so[0], tmp_path)
    res = subprocess.run(["ldd", str(tmp_path / so[0])], capture_output=True, text=True, check=True)
    assert "python" not in res.stdout.lower(), res.stdout
    assert "libm" in res.stdout


def _steps(inst, t0, w, h):
    out = []
    for n, wn in enumerate(w):
        inst.fmu.setReal([0], [float(wn)])
        inst.fmu.doStep(t0 + n * h, h)
        out.append(inst.fmu.getReal(list(range(26, 38))))
    return np.array(out)


def test_state_get_set_and_serialize_restore_bit_for_bit(fmus):
    """Take the state at 0.2 s, run on; set it back (and deserialize it into a second, fresh instance with
    other parameters): the replay is bit-identical (floors and ripple on, so their phasors are in the state)."""
    _, native, _ = fmus
    h = 1e-3
    w = 300 * RPM * np.sin(np.linspace(0, 3, 600))
    a = hosts.FmpyInstance(native, "a", {"seed": 11}, {"wheel_speed": w[0]})
    b = hosts.FmpyInstance(native, "b", {"seed": 2, "modes": False}, {"wheel_speed": 0.0})
    try:
        _steps(a, 0.0, w[:200], h)
        state = a.fmu.getFMUstate()
        blob = a.fmu.serializeFMUstate(state)
        first = _steps(a, 200 * h, w[200:], h)
        a.fmu.setFMUstate(state)
        again = _steps(a, 200 * h, w[200:], h)
        assert np.array_equal(first, again)
        s2 = b.fmu.deSerializeFMUstate(blob)
        b.fmu.setFMUstate(s2)
        other = _steps(b, 200 * h, w[200:], h)
        assert np.array_equal(first, other)
        a.fmu.freeFMUstate(state)
        b.fmu.freeFMUstate(s2)
    finally:
        a.close()
        b.close()


@pytest.mark.parametrize("case", ["nan_speed", "backwards_time", "nan_time", "huge_step", "jump"])
def test_bad_input_is_fmi2error_and_a_stored_state_goes_on(fmus, case):
    """Bad input: fmi2Error with a logged message, outputs unchanged; the instance is then in FMI 2.0's error state
    (a step at the right point is refused, saying what to do) and the state stored before the bad input restores the
    run: its next step equals that of an instance never given the bad input."""
    from fmpy.fmi1 import FMICallException
    _, native, _ = fmus
    log = hosts.HostLog()
    inst = hosts.FmpyInstance(native, "bad", {}, {"wheel_speed": 100.0}, log=log)
    clean = hosts.FmpyInstance(native, "clean", {}, {"wheel_speed": 100.0})
    try:
        for f in (inst, clean):
            f.fmu.doStep(0.0, 1e-3)
        y0 = inst.get()
        stored = inst.fmu.getFMUstate()
        t, h, key = 1e-3, 1e-3, ""
        if case == "nan_speed":
            inst.set("wheel_speed", float("nan"))
            key = "not finite"
        elif case == "backwards_time":
            t, key = 0.0, "does not continue"
        elif case == "nan_time":
            t, key = float("nan"), "does not continue"
        elif case == "huge_step":
            h, key = 1.0, "max_step_size"
        else:
            inst.set("wheel_speed", 1e5)
            key = "jumps"
        with pytest.raises(FMICallException) as exc:
            inst.fmu.doStep(t, h)
        assert exc.value.status == 3
        assert any(key in m for m in log.messages(3)), log.records
        assert inst.get() == y0
        with pytest.raises(FMICallException):
            inst.fmu.doStep(1e-3, 1e-3)
        assert "in the error state" in log.messages(3)[-1] and "fmi2SetFMUstate" in log.messages(3)[-1]
        inst.fmu.setFMUstate(stored)
        inst.fmu.freeFMUstate(stored)
        for f in (inst, clean):
            f.set("wheel_speed", 100.0)
            f.fmu.doStep(1e-3, 1e-3)
        assert inst.get() == clean.get() and all(np.isfinite(inst.get()))
    finally:
        inst.close()
        clean.close()


def test_bad_parameter_is_fmi2error(fmus):
    from fmpy.fmi1 import FMICallException
    _, native, _ = fmus
    log = hosts.HostLog()
    inst = hosts.FmpyInstance(native, "badpar", {"seed": -5}, {"wheel_speed": 1.0}, log=log, exit_init=False)
    try:
        with pytest.raises(FMICallException) as exc:
            inst.fmu.exitInitializationMode()
        assert exc.value.status == 3 and any("seed must be" in m for m in log.messages(3))
        with pytest.raises(FMICallException):
            inst.set("model_file", "/some/other.json")
    finally:
        inst.close()


def test_four_instances_one_process(fmus):
    """Four instances (two seeds, two mountings) stepped in lockstep equal the same instances run alone."""
    _, native, _ = fmus
    t, w = spin_up(T=1.0)
    cases = [(f"w{k}", {"wheel_speed": w * (1 + 0.1 * k)}, {"seed": k, **({"r_x": 0.5} if k % 2 else {})})
             for k in range(4)]
    together = hosts.run_fmpy_many(native, t, cases)
    for (name, inputs, params), out in zip(cases, together):
        assert np.array_equal(out, hosts.run_fmpy(native, t, inputs, params, name=name))
    assert not np.allclose(together[0], together[2])


def test_libcosim_runs_the_native_fmu(fmus):
    """libcosim (libcosimpy) runs the native FMU: same outputs as fmpy (1e-9, its integer-ns clock)."""
    pytest.importorskip("libcosimpy")
    _, native, _ = fmus
    t, w = reversal(T=1.0)
    a = hosts.run_libcosim(native, t, {"wheel_speed": w, "wheel_acceleration": slope(t, w)}, mount_params(3))
    b = hosts.run_fmpy(native, t, {"wheel_speed": w, "wheel_acceleration": slope(t, w)}, mount_params(3))
    # libcosim counts time in integer nanoseconds: its step sizes and communication points differ from
    # fmpy's doubles in the last bits, which the ripple and floor phases (absolute time) carry (~1e-11)
    assert np.all(worst(a[1:], b[1:]) <= 1e-9), worst(a[1:], b[1:])


def _extract(fmu, dest):
    with zipfile.ZipFile(fmu) as z:
        z.extractall(dest)
    from fmpy import read_model_description
    return read_model_description(dest)


def test_c_host_without_python(fmus, tmp_path):
    """A C program (dlopen, fmi2Instantiate ... fmi2DoStep) runs the native FMU with no Python in the process;
    its outputs after a 0→2000 rpm ramp equal fmpy's bit for bit."""
    _, native, _ = fmus
    md = _extract(native, tmp_path / "u")
    host = compile_c_host(tmp_path / "c_host")
    lib = tmp_path / "u" / "binaries" / "linux64" / f"{md.coSimulation.modelIdentifier}.so"
    n, h, w1 = 500, 1e-3, 2000 * RPM
    res = subprocess.run([str(host), str(lib), md.guid, str(n), str(h), "0", str(w1), "i4=9", "b3=1"],
                         capture_output=True, text=True, timeout=60)
    assert res.returncode == 0, res.stderr
    y = np.array([float(v) for v in res.stdout.split()])
    k = np.arange(n + 1)
    w = 0.0 + (w1 - 0.0) * k / n
    ref = hosts.run_fmpy(native, k * h, {"wheel_speed": w, "wheel_acceleration": np.full(k.size, w1 / (n * h))},
                         {"seed": 9, "use_wheel_acceleration": True})
    assert np.array_equal(y, ref[-1])


@pytest.mark.slow
def test_rebuild_from_sources_gives_identical_outputs(fmus, tmp_path):
    """fmpy's build_platform_binary (CMake, its own flags) recompiles binaries/ from the FMU's sources/;
    the rebuilt FMU's outputs equal the shipped binary's bit for bit."""
    # cmake is a dependency of fmpy (the test extra installs it): a missing one is a broken install, not a skip
    assert shutil.which("cmake") is not None, "cmake not found (it comes with fmpy: reinstall '.[test]')"
    from fmpy.build import build_platform_binary
    _, native, _ = fmus
    md = _extract(native, tmp_path / "u")
    so = tmp_path / "u" / "binaries" / "linux64" / f"{md.coSimulation.modelIdentifier}.so"
    so.unlink()
    (tmp_path / "build").mkdir()
    build_platform_binary(tmp_path / "u", build_dir=tmp_path / "build")
    assert so.is_file()
    rebuilt = tmp_path / "rebuilt.fmu"
    with zipfile.ZipFile(rebuilt, "w") as z:
        for f in sorted((tmp_path / "u").rglob("*")):
            if f.is_file():
                z.write(f, f.relative_to(tmp_path / "u").as_posix())
    t, w = spin_up(T=1.0)
    inputs = {"wheel_speed": w, "wheel_acceleration": slope(t, w)}
    assert np.array_equal(hosts.run_fmpy(rebuilt, t, inputs, mount_params(4)),
                          hosts.run_fmpy(native, t, inputs, mount_params(4)))


@pytest.mark.slow
def test_fresh_venv_without_rwadist(fmus, tmp_path, fresh_fmpy_venv):
    """A new virtual environment with fmpy and what fmpy itself imports (numpy, lxml, attrs) -- no rwadist, no
    pythonfmu -- simulates the native FMU and reproduces this process's outputs bit for bit.  (The environment
    is built once per run in conftest.py and shared with test_fmu.py, which adds libcosimpy to it.)"""
    _, native, _ = fmus
    py = fresh_fmpy_venv
    t, w = reversal(T=1.0)
    np.savez(tmp_path / "prof.npz", t=t, omega=w, alpha=slope(t, w), seed=8)
    script = tmp_path / "hosts.py"
    shutil.copy2(hosts.__file__, script)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    res = subprocess.run([str(py), str(script), str(native), str(tmp_path / "prof.npz"), str(tmp_path / "out.npz")],
                         capture_output=True, text=True, timeout=300, cwd=tmp_path, env=env)
    assert res.returncode == 0, res.stderr[-3000:]
    got = np.load(tmp_path / "out.npz")
    assert not bool(got["rwadist_importable"])
    chk = subprocess.run([str(py), "-c", "import pythonfmu"], capture_output=True, env=env, cwd=tmp_path)
    assert chk.returncode != 0
    ref = hosts.run_fmpy(native, t, {"wheel_speed": w, "wheel_acceleration": slope(t, w)},
                         {"use_wheel_acceleration": True, "seed": 8})
    assert np.array_equal(got["fmpy"], ref)


SINCOS_CHECK = r'''
#include <stdio.h>
#include <stdlib.h>
#include "rwadist_kernel.h"
int main(void)
{
    /* arguments of every size the line phases take (small, ~1e2, up to the 8e5 limit, near multiples of
     * pi/2), plus the libm fallback beyond; largest |error| against libm in units of 2^-52 */
    double worst = 0.0;
    srand48(7);
    for (long i = 0; i < 4000000; i++) {
        const long k = i % 5;
        double x = (drand48() * 2 - 1) * (k == 0 ? 3.5 : k == 1 ? 100.0 : k == 2 ? 8.2e5 : 3e6);
        if (k == 4)
            x = (double)(lrand48() % 400000 - 200000) * 1.5707963267948966 + (drand48() - 0.5) * 1e-6;
        double s, c;
        rw_sincos(x, &s, &c);
        const double e = fmax(fabs(s - sin(x)), fabs(c - cos(x))) / 2.220446049250313e-16;
        worst = fmax(worst, e);
    }
    printf("%.6g\n", worst);
    return 0;
}
'''


def test_kernel_sincos_is_libm_within_an_ulp(tmp_path):
    """The kernel's inline sin/cos of the line phases (rwadist_kernel.h: Cody-Waite reduction, fdlibm
    polynomials) equals libm's to 1 ulp of the unit phasor over 4 M arguments from 1e-6 to 3e6 rad."""
    from rwadist.fmu.native_build import NATIVE
    src = tmp_path / "sincos_check.c"
    src.write_text(SINCOS_CHECK)
    cc = shutil.which(os.environ.get("CC", "cc"))
    subprocess.run([cc, "-O2", f"-I{NATIVE}", "-o", str(tmp_path / "chk"), str(src), "-lm"], check=True)
    worst = float(subprocess.run([str(tmp_path / "chk")], capture_output=True, text=True, check=True).stdout)
    assert worst <= 1.0 + 1e-9, worst


def test_fmu_check_says_which_fmu_it_checked(fmus, capsys):
    """``rwadist fmu check`` of the native FMU says it is C only (it printed 'native layer ...: no', read as a missing
    part); of the packaged one, whether its native layer is there."""
    from rwadist.cli import main

    _, native, python = fmus
    assert main(["fmu", "check", str(native), "--stop-time", "0.5"]) == 0
    out = capsys.readouterr().out
    assert "native FMU: C only, no Python needed by the host" in out and "native layer" not in out
    assert main(["fmu", "check", str(python), "--stop-time", "0.5"]) == 0
    assert "native layer (fmi2Error on bad input, C step kernel):" in capsys.readouterr().out
