"""The SSP 1.0 file of a wheel assembly (issue 35): `rwadist fmu build --native --wheels wheels.json -o
assembly.ssp` on a four-wheel assembly (two model files and a preset; three pyramid mountings and one explicit DCM;
a uniform and a normal speed law; a counter-rotating phase-locked tie).  Checked against what the test computes
itself: the mountings (the pyramid's geometry through scipy's rotations, not rwadist's mounting code), the speed laws'
means (closed forms), the tie ratios; libcosim runs the .ssp (CosimExecution.from_ssp_file) driven through the
assembly's speed inputs, and the sum of the wheels' spacecraft-frame loads equals the sum of four single-wheel FMUs
run one by one in fmpy, each driven with the speed its connection carries, to 1e-12 of the sum's peak.  fmpy's SSP
reader (XSD validation included) reads the file as a second check; a second build gives the same bytes."""
from __future__ import annotations

import json
import os
import shutil
import sys
import xml.etree.ElementTree as ET
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
from rwadist.presets import preset  # noqa: E402

RPM = 2 * np.pi / 60
SC = ["Fx_sc", "Fy_sc", "Fz_sc", "Tx_sc", "Ty_sc", "Tz_sc"]
NS = {"ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
      "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
      "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues"}


def pyramid(k: int):
    """(DCM wheel -> spacecraft, interface point m) of pyramid-4 wheel k, from the geometry: spin axis at azimuth
    45° + 90°·k and elevation atan(1/√2), wheel x the part of spacecraft z normal to it, interface 0.3 m out at that
    azimuth -- as rotations Rz(az)·Ry(90° − el)·Rz(180°) (scipy), not rwadist's mounting code."""
    from scipy.spatial.transform import Rotation
    az, el = np.radians(45.0 + 90.0 * k), np.arctan(1 / np.sqrt(2))
    return Rotation.from_euler("ZYZ", [az, np.pi / 2 - el, np.pi]).as_matrix(), 0.3 * np.array([np.cos(az),
                                                                                                 np.sin(az), 0.0])


def explicit_mounting():
    """RW2's mounting, given as a DCM and a position in wheels.json: a rotation and a point of the test's own."""
    from scipy.spatial.transform import Rotation
    return Rotation.from_euler("XYZ", [0.3, -1.1, 2.4]).as_matrix(), np.array([0.12, -0.31, 0.05])


#: wheel -> (model, mounting, seed, speed-law mean rad/s (own law) or (root, ratio) (tie)); means in closed form
WHEELS = {"RW1": ("full", pyramid(0), 1, 0.5 * (1000 + 3000) * RPM),
          "RW2": ("full", explicit_mounting(), 2, 0.5 * (500 + 2500) * RPM),   # truncated normal, centred
          "RW3": ("e", pyramid(2), 3, 0.5 * (2000 + 2000.5) * RPM),
          "RW4": ("full", pyramid(3), 1, ("RW1", -1.0))}


@pytest.fixture(scope="module")
def assembly(tmp_path_factory):
    """(wheels.json, assembly.ssp, {model: path}): RW1, RW2 and RW4 the wheel with every line effect (a model file),
    RW3 the E wheel (the preset), RW4 tied to RW1 at ratio -1 with a phase lock."""
    from rwadist.cli import main
    d = tmp_path_factory.mktemp("ssp")
    full = d / "full.json"
    full.write_text(json.dumps(wheel_doc(LINE_EFFECTS)))
    e_wheel = d / "e_wheel.json"
    model_io.save(preset("ithaco-e").to_model(), e_wheel)
    R2, r2 = explicit_mounting()
    wheels = {"wheels": [
        {"name": "RW1", "model": "full.json", "mounting": {"preset": "pyramid-4", "index": 0},
         "speed": {"dist": "uniform", "min_rpm": 1000, "max_rpm": 3000}},
        {"name": "RW2", "model": "full.json", "dcm": R2.tolist(), "position_m": r2.tolist(),
         "speed": {"dist": "normal", "min_rpm": 500, "max_rpm": 2500}},
        {"name": "RW3", "preset": "ithaco-e", "mounting": {"preset": "pyramid-4", "index": 2},
         "speed": {"dist": "uniform", "min_rpm": 2000, "max_rpm": 2000.5}},
        {"name": "RW4", "model": "full.json", "mounting": {"preset": "pyramid-4", "index": 3},
         "tie": {"to": "RW1", "ratio": -1, "phase_lock": True}}]}
    path = d / "wheels.json"
    path.write_text(json.dumps(wheels))
    out = d / "assembly.ssp"
    assert main(["fmu", "build", "--native", "--wheels", str(path), "-o", str(out)]) == 0
    return path, out, {"full": full, "e": e_wheel}


def _ssd(ssp) -> ET.Element:
    return ET.fromstring(zipfile.ZipFile(ssp).read("SystemStructure.ssd"))


def _bound(element) -> dict:
    """{parameter: value} of an element's inline parameter bindings."""
    out = {}
    for p in element.findall("ssd:ParameterBindings/ssd:ParameterBinding/ssd:ParameterValues/ssv:ParameterSet/"
                             "ssv:Parameters/ssv:Parameter", NS):
        value = next(iter(p)).get("value")
        out[p.get("name")] = value
    return out


def test_ssp_structure_start_values_and_ties(assembly):
    """fmpy reads and validates it (SSP 1.0 XSD); the system is named after the file (a preset wheel did rename it);
    one component per wheel and the speed command; each wheel's wheel_speed connected from its root's command output
    (factor = tie ratio: -1 for RW4); the command's inputs start at the speed laws' means; the mountings bound on the
    wheels and at the system equal the geometry's to 1e-15; the laws and the tie as system parameters."""
    from fmpy.ssp.ssd import read_ssd
    _, ssp, _ = assembly
    names = zipfile.ZipFile(ssp).namelist()
    assert "SystemStructure.ssd" in names and sum(n.endswith(".fmu") for n in names) == 3
    ssd = read_ssd(str(ssp))                   # validates against fmpy's copy of the SSP 1.0 XSD
    assert ssd.name == ssd.system.name == "assembly"
    root = _ssd(ssp)
    comps = {c.get("name"): c for c in root.findall("ssd:System/ssd:Elements/ssd:Component", NS)}
    assert sorted(comps) == ["RW1", "RW2", "RW3", "RW4", "speed_command"]
    assert comps["RW1"].get("source") == comps["RW4"].get("source") != comps["RW3"].get("source")
    links = {c.get("endElement"): (c.get("startElement"), c.get("startConnector"),
                                   float(c.find("ssc:LinearTransformation", NS).get("factor"))
                                   if c.find("ssc:LinearTransformation", NS) is not None else 1.0)
             for c in root.findall("ssd:System/ssd:Connections/ssd:Connection", NS)}
    system = _bound(root.find("ssd:System", NS))
    starts = _bound(comps["speed_command"])
    for name, (_, (R, r), seed, law) in WHEELS.items():
        root_name, ratio = law if isinstance(law, tuple) else (name, 1.0)
        assert links[name] == ("speed_command", f"wheel_speed_{root_name}", ratio)
        if not isinstance(law, tuple):
            assert float(starts[f"speed_{name}"]) == pytest.approx(law, rel=1e-12)
            assert float(system[f"{name}_speed_mean"]) == pytest.approx(law, rel=1e-12)
        bound = _bound(comps[name])
        assert int(bound["seed"]) == seed
        for where in (bound, {k[len(name) + 1:]: v for k, v in system.items() if k.startswith(name + "_")}):
            got = np.array([[float(where[f"dcm_{i}{j}"]) for j in (1, 2, 3)] for i in (1, 2, 3)])
            assert np.max(np.abs(got - R)) < 1e-15
            assert np.allclose([float(where[f"r_{ax}"]) for ax in "xyz"], r, rtol=0, atol=1e-15)
    assert system["RW1_speed_law"] == "uniform" and system["RW2_speed_law"] == "truncated normal"
    assert float(system["RW2_speed_normal_std"]) == pytest.approx((2500 - 500) / 6 * RPM, rel=1e-12)
    assert (system["RW4_tie_to"], float(system["RW4_tie_ratio"]), system["RW4_phase_lock"]) == ("RW1", -1.0, "true")


def test_ssp_is_reproducible(assembly, tmp_path):
    """The same wheels.json built again (in another folder, through the library) gives the same bytes."""
    from rwadist.fmu.ssp import build_assembly_ssp
    path, ssp, _ = assembly
    again, _ = build_assembly_ssp(path, tmp_path / "assembly.ssp")
    assert Path(again).read_bytes() == Path(ssp).read_bytes()


def fmpy_on_libcosim_clock(path, speed, params, name, h):
    """One wheel alone in fmpy, stepped on libcosim's clock: libcosim counts integer nanoseconds and passes the
    communication point t_n = n·h_ns / 1e9 s and the step t_(n+1) − t_n (in doubles: it varies in the last bits),
    where fmpy's own loop passes t0 + n·h and h.  ``speed[n]``: the wheel speed of step n (``speed[0]`` also at
    initialisation).  Returns the spacecraft-frame outputs after each step, row 0 zero."""
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


def _run_libcosim(ssp, commands: dict, h: float, n: int) -> np.ndarray:
    """The sum of the wheels' Fx_sc .. Tz_sc after each of n steps of libcosim, the command inputs set to
    ``commands`` {wheel: speed per step} (rad/s) before each step."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    log_output_level(CosimLogLevel.WARNING)
    ex = CosimExecution.from_ssp_file(str(ssp), step_size=int(round(h * 1e9)))
    man = CosimManipulator.create_override()
    ex.add_manipulator(manipulator=man)
    obs = CosimObserver.create_last_value()
    ex.add_observer(observer=obs)
    idx = {s.name.decode(): s.index for s in ex.slave_infos()}
    total = np.zeros((n + 1, 6))
    for k in range(n):
        for j, name in enumerate(commands):          # the command's inputs, value references 0, 1, ...
            man.slave_real_values(idx["speed_command"], [j], [float(commands[name][k])])
        assert ex.step()
        total[k + 1] = sum(np.asarray(obs.last_real_values(idx[w], list(range(32, 38)))) for w in WHEELS)
    return total


def test_libcosim_assembly_equals_sum_of_single_wheels(assembly):
    """libcosim runs the .ssp driven through the assembly's three speed inputs (each from its law's mean: a ramp, a
    sine, a constant); the sum of the four wheels' spacecraft-frame loads equals the sum of four single-wheel FMUs
    (native FMUs of the same model files) run one by one in fmpy, each given the speed its connection carries (the
    ratio times its root's command, one communication step later: libcosim passes a connection's value at the next
    step; at the first step the laws' means), its mounting computed by the test and its seed (RW4 shares RW1's), to
    1e-12 of the sum's peak per channel."""
    pytest.importorskip("libcosimpy")
    _, ssp, models = assembly
    h, n = 1e-3, 1500
    t = np.arange(n + 1) * h
    mean = {w: law for w, (_, _, _, law) in WHEELS.items() if not isinstance(law, tuple)}
    commands = {"RW1": mean["RW1"] + 300 * RPM * np.minimum(1.0, t / 1.2),
                "RW2": mean["RW2"] + 30.0 * np.sin(np.pi * t / 1.5), "RW3": mean["RW3"] + 0 * t}
    total = _run_libcosim(ssp, commands, h, n)
    from rwadist.fmu.native_build import build_native_fmu
    d = Path(ssp).parent
    fmu = {k: build_native_fmu(p, d / f"single_{k}.fmu", windows=False) for k, p in models.items()}
    ref = np.zeros((n + 1, 6))
    for name, (model, (R, r), seed, law) in WHEELS.items():
        root, ratio = law if isinstance(law, tuple) else (name, 1.0)
        speed = ratio * np.concatenate([[mean[root]], commands[root][:-1]])     # one step behind the command
        params = {"seed": seed, **{f"r_{ax}": x for ax, x in zip("xyz", r)},
                  **{f"dcm_{i + 1}{j + 1}": R[i, j] for i in range(3) for j in range(3)}}
        ref += fmpy_on_libcosim_clock(fmu[model], speed, params, name, h)
    scale = np.max(np.abs(ref[1:]), axis=0)
    err = np.max(np.abs(total[1:] - ref[1:]), axis=0) / scale
    print("libcosim SSP assembly vs sum of 4 fmpy single-wheel runs, per channel (rel. to its peak):",
          np.array2string(err, precision=3))
    assert np.all(scale > 0) and np.max(err) <= 1e-12


def test_bad_wheels_file_and_flags(tmp_path, assembly, capsys):
    """A wheels.json error names the file and field (an inverted speed range its rpm values too); --wheels needs
    --native, an .ssp output and FMI 2.0; nothing is written."""
    from rwadist.cli import main
    path, _, _ = assembly
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"wheels": [{"name": "RW1", "model": "nope.json", "dcm": np.eye(3).tolist()}]}))
    assert main(["fmu", "build", "--native", "--wheels", str(bad), "-o", str(tmp_path / "a.ssp")]) == 2
    assert "wheels[0].model" in capsys.readouterr().err
    inverted = tmp_path / "inverted.json"
    inverted.write_text(json.dumps({"wheels": [{"name": "RW1", "preset": "ithaco-e", "dcm": np.eye(3).tolist(),
                                                "speed": {"dist": "uniform", "min_rpm": 3000, "max_rpm": 1000}}]}))
    assert main(["fmu", "build", "--native", "--wheels", str(inverted), "-o", str(tmp_path / "i.ssp")]) == 2
    err = capsys.readouterr().err
    assert all(s in err for s in ("inverted.json", "wheels[0]", "speed.min_rpm/max_rpm", "3000 rpm", "1000 rpm")), err
    for argv, flag in ((["--wheels", str(path), "-o", str(tmp_path / "b.ssp")], "--wheels"),
                       (["--native", "--wheels", str(path), "-o", str(tmp_path / "c.fmu")], "-o"),
                       (["--native", "--fmi-version", "3", "--wheels", str(path), "-o", str(tmp_path / "d.ssp")],
                        "--fmi-version")):
        assert main(["fmu", "build", *argv]) == 2
        assert flag in capsys.readouterr().err
    assert not list(tmp_path.glob("*.ssp"))
