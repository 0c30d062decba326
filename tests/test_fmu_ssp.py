"""The SSP 1.0 file of a wheel assembly (issue 35): `rwadist fmu build --native --wheels wheels.json -o
assembly.ssp` on a four-wheel pyramid (two model files, a tied counter-rotating phase-locked pair), run by libcosim
from the .ssp file (CosimExecution.from_ssp_file), against the four wheels run one by one in fmpy with the mountings
read independently (rwadist.mounting.preset_mountings): the sum of the components' spacecraft-frame outputs equals
the sum of the single-wheel runs to 1e-12 of its peak.  fmpy's SSP reader (XSD validation included) reads the file
as a second check."""
from __future__ import annotations

import json
import os
import shutil
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from rwadist.fmu import hosts
from rwadist.fmu.build import native_supported

pytest.importorskip("fmpy")
pytestmark = pytest.mark.skipif(not (native_supported() and shutil.which(os.environ.get("CC", "cc"))),
                                reason="the native FMU's binary is built on Linux x86-64 with a C compiler")

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_fmu_native import LINE_EFFECTS, wheel_doc  # noqa: E402

from rwadist import model as model_io  # noqa: E402
from rwadist.mounting import preset_mountings  # noqa: E402
from rwadist.presets import preset  # noqa: E402

RPM = 2 * np.pi / 60
SC = ["Fx_sc", "Fy_sc", "Fz_sc", "Tx_sc", "Ty_sc", "Tz_sc"]


@pytest.fixture(scope="module")
def assembly(tmp_path_factory):
    """(wheels.json, assembly.ssp, {model name: path}) of a pyramid-4: RW1 and RW2 the wheel with every line effect,
    RW3 the E wheel preset, RW4 tied to RW1 at ratio -1 with a phase lock."""
    from rwadist.cli import main
    d = tmp_path_factory.mktemp("ssp")
    full = d / "full.json"
    full.write_text(json.dumps(wheel_doc(LINE_EFFECTS)))
    e_wheel = d / "e_wheel.json"
    model_io.save(preset("ithaco-e").to_model(), e_wheel)
    wheels = {"wheels": [
        {"name": "RW1", "model": "full.json", "mounting": {"preset": "pyramid-4", "index": 0},
         "speed": {"dist": "uniform", "min_rpm": 1000, "max_rpm": 3000}},
        {"name": "RW2", "model": "full.json", "mounting": {"preset": "pyramid-4", "index": 1},
         "speed": {"dist": "normal", "min_rpm": 500, "max_rpm": 2500}},
        {"name": "RW3", "model": "e_wheel.json", "mounting": {"preset": "pyramid-4", "index": 2},
         "speed": {"dist": "uniform", "min_rpm": 2000, "max_rpm": 2000.5}},
        {"name": "RW4", "model": "full.json", "mounting": {"preset": "pyramid-4", "index": 3},
         "tie": {"to": "RW1", "ratio": -1, "phase_lock": True}}]}
    path = d / "wheels.json"
    path.write_text(json.dumps(wheels))
    out = d / "assembly.ssp"
    assert main(["fmu", "build", "--native", "--wheels", str(path), "-o", str(out)]) == 0
    return path, out, {"full": full, "e": e_wheel}


def test_ssp_structure(assembly):
    """One component per wheel, one FMU per model, the mounting and speed law as parameters; fmpy reads it and
    validates it against the SSP 1.0 schema."""
    from fmpy.ssp.ssd import read_ssd
    _, ssp, _ = assembly
    names = zipfile.ZipFile(ssp).namelist()
    assert "SystemStructure.ssd" in names and sum(n.endswith(".fmu") for n in names) == 2
    ssd = read_ssd(str(ssp))                   # validates against fmpy's copy of the SSP 1.0 XSD
    comps = {c.name: c for c in ssd.system.elements}
    assert sorted(comps) == ["RW1", "RW2", "RW3", "RW4"]
    assert comps["RW1"].source == comps["RW4"].source != comps["RW3"].source
    kinds = {c.name: c.kind for c in comps["RW2"].connectors}
    assert kinds["wheel_speed"] == "input" and kinds["dcm_33"] == "parameter" and kinds["Tz_sc"] == "output"
    text = zipfile.ZipFile(ssp).read("SystemStructure.ssd").decode()
    assert 'tie_to="RW1"' in text and 'tie_ratio="-1"' in text and text.count("ssv:ParameterSet ") == 4


def fmpy_on_libcosim_clock(path, speed, params, name, h):
    """One wheel alone in fmpy, stepped on libcosim's clock: libcosim counts integer nanoseconds and passes the
    communication point t_n = n·h_ns / 1e9 s and the step t_(n+1) − t_n (in doubles: it varies in the last bits),
    where fmpy's own loop passes t0 + n·h and h (the kernel's derived acceleration and phases carry that difference:
    ~1e-13 .. 1e-11).  Returns the spacecraft-frame outputs after each step, row 0 zero."""
    h_ns = int(round(h * 1e9))
    inst = hosts.FmpyInstance(path, name, params, {"wheel_speed": float(speed[0])}, log=hosts.HostLog())
    out = np.zeros((speed.size, 6))
    try:
        for k in range(speed.size - 1):
            inst.fmu.setReal([0], [float(speed[k])])
            inst.fmu.doStep(k * h_ns / 1e9, (k + 1) * h_ns / 1e9 - k * h_ns / 1e9)
            out[k + 1] = inst.fmu.getReal(list(range(32, 38)))
    finally:
        inst.close()
    return out


def test_libcosim_assembly_equals_sum_of_single_wheels(assembly):
    """libcosim runs the .ssp (four components, parameters bound by the SSP) through a speed profile per wheel
    (RW4 = -RW1, as its tie says); the sum of the four components' spacecraft-frame loads equals the sum of the
    four wheels run one by one in fmpy (on libcosim's integer-nanosecond clock), each with its mounting from
    rwadist.mounting.preset_mountings and its seed (k + 1; RW4 shares RW1's), to 1e-12 of the sum's peak per
    channel."""
    pytest.importorskip("libcosimpy")
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    _, ssp, models = assembly
    h, n = 1e-3, 1500
    t = np.arange(n + 1) * h
    w1 = 2000 * RPM * np.minimum(1.0, t / 1.2)
    speeds = {"RW1": w1, "RW2": 1500 * RPM * np.sin(np.pi * t / 1.5), "RW3": 2000 * RPM + 0 * t, "RW4": -w1}
    log_output_level(CosimLogLevel.WARNING)
    ex = CosimExecution.from_ssp_file(str(ssp), step_size=int(round(h * 1e9)))
    man = CosimManipulator.create_override()
    ex.add_manipulator(manipulator=man)
    obs = CosimObserver.create_last_value()
    ex.add_observer(observer=obs)
    idx = {name: ex.slave_index_from_instance_name(name) for name in speeds}
    sc_vr = list(range(32, 38))
    total = np.zeros((n + 1, 6))
    for k in range(n):
        for name, i in idx.items():
            man.slave_real_values(i, [0], [float(speeds[name][k])])
        assert ex.step()
        total[k + 1] = sum(np.asarray(obs.last_real_values(i, sc_vr)) for i in idx.values())
    # the same wheels one by one in fmpy: native FMUs of the same model files, mountings read independently
    from rwadist.fmu.native_build import build_native_fmu
    d = Path(ssp).parent
    fmu = {k: build_native_fmu(p, d / f"single_{k}.fmu", windows=False) for k, p in models.items()}
    mounts = preset_mountings("pyramid-4")
    ref = np.zeros((n + 1, 6))
    for k, (name, model, seed) in enumerate((("RW1", "full", 1), ("RW2", "full", 2), ("RW3", "e", 3),
                                             ("RW4", "full", 1))):
        R, r = mounts[k].R, mounts[k].position_m
        params = {"seed": seed, **{f"r_{ax}": x for ax, x in zip("xyz", r)},
                  **{f"dcm_{i + 1}{j + 1}": R[i, j] for i in range(3) for j in range(3)}}
        ref += fmpy_on_libcosim_clock(fmu[model], speeds[name], params, name, h)
    scale = np.max(np.abs(ref[1:]), axis=0)
    err = np.max(np.abs(total[1:] - ref[1:]), axis=0) / scale
    print("libcosim SSP assembly vs sum of 4 fmpy single-wheel runs, per channel (rel. to its peak):",
          np.array2string(err, precision=3))
    assert np.all(scale > 0) and np.max(err) <= 1e-12


def test_bad_wheels_file_and_flags(tmp_path, assembly, capsys):
    """A wheels.json error names the file and field; --wheels needs --native, an .ssp output and FMI 2.0."""
    from rwadist.cli import main
    path, _, _ = assembly
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"wheels": [{"name": "RW1", "model": "nope.json", "dcm": np.eye(3).tolist()}]}))
    assert main(["fmu", "build", "--native", "--wheels", str(bad), "-o", str(tmp_path / "a.ssp")]) == 2
    assert "wheels[0].model" in capsys.readouterr().err
    for argv, flag in ((["--wheels", str(path), "-o", str(tmp_path / "b.ssp")], "--wheels"),
                       (["--native", "--wheels", str(path), "-o", str(tmp_path / "c.fmu")], "-o"),
                       (["--native", "--fmi-version", "3", "--wheels", str(path), "-o", str(tmp_path / "d.ssp")],
                        "--fmi-version")):
        assert main(["fmu", "build", *argv]) == 2
        assert flag in capsys.readouterr().err
    assert not list(tmp_path.glob("*.ssp"))
