"""An FMU for every model file (issue 16): empirical-only models run hard-mounted with C·Ω² lines;
the modelDescription says which physics an FMU carries; wheels with assumed suspension modes run
hard-mounted unless opted in, and say so when they do not."""
from __future__ import annotations

import json

import numpy as np
import pytest

from rwadist import catalogue
from rwadist.fmu import hosts
from rwadist.fmu import runtime as rt
from rwadist.fmu.build import build_fmu

pytest.importorskip("pythonfmu")
fmpy = pytest.importorskip("fmpy")

RPM = 2 * np.pi / 60


def empirical_only(name="ithaco-e"):
    """A catalogue wheel's model file with its analytical section removed (an empirical fit)."""
    doc = json.loads(catalogue.path(name).read_text())
    doc.pop("analytical", None)
    return doc


def closed_form_lines(doc, omega, t):
    """(n, 6) wheel-frame loads of the empirical harmonics at constant speed ``omega`` (rad/s), the model file's
    phases (0): each line C·Ω² rotating at hΩ (co +, counter −; planar: C·Ω²·cos(hΩt) on x and on y, the fit's
    C on each channel), axial lines C·Ω²·cos(hΩt); rotor angle Ωt."""
    out = np.zeros((t.size, 6))
    phi = omega * t
    for d, items in doc["empirical"].items():
        for item in items:
            h, a, sense = item["h"], item["C"] * omega**2, item.get("sense") or "co"
            if d in ("radial_force", "radial_torque"):
                z = {"co": np.exp(1j * h * phi), "counter": np.exp(-1j * h * phi),
                     "planar": (1 + 1j) * np.cos(h * phi)}[sense] * a
                k = 0 if d == "radial_force" else 3
                out[:, k] += z.real
                out[:, k + 1] += z.imag
            else:
                out[:, 2 if d == "axial_force" else 5] += a * np.cos(h * phi)
    return out


@pytest.fixture(scope="module")
def empirical_fmu(tmp_path_factory):
    doc = empirical_only()
    return doc, build_fmu(doc, tmp_path_factory.mktemp("emp") / "emp.fmu")


@pytest.mark.parametrize("rpm", [3000.0, -1700.0])
def test_empirical_only_fmu_outputs_are_the_lines(empirical_fmu, rpm):
    """An empirical fit (no analytical section) builds and runs in fmpy; at constant speed its
    outputs are the C·Ω² lines at their own h and sense to 1e-9 of the peak, all six channels."""
    doc, path = empirical_fmu
    t = np.arange(1001) * 1e-3
    w = np.full(t.size, rpm * RPM)
    out = hosts.run_fmpy(path, t, {"wheel_speed": w}, {})
    ref = closed_form_lines(doc, rpm * RPM, t)
    assert np.max(np.abs(out[:, :6] - ref)) <= 1e-9 * np.max(np.abs(ref))
    assert np.allclose(out[:, 6:], out[:, :6], rtol=0, atol=1e-20)     # identity mounting


def with_planar_lines(doc):
    """``doc`` with its fundamentals, a planar radial force line (h 2.7) and a planar radial torque line (h 3.3)."""
    emp = doc["empirical"]
    emp["radial_force"] = emp["radial_force"][:1] + [{"h": 2.7, "C": 4.0e-7, "sense": "planar"}]
    emp["radial_torque"] = emp["radial_torque"][:1] + [{"h": 3.3, "C": 2.0e-8, "sense": "planar"}]
    emp["axial_force"] = emp["axial_force"][:1]
    return doc


def line_phasor(y, t, f):
    """Complex amplitude of the line at ``f`` Hz in ``y`` (n, k) over whole periods (t spans them)."""
    return 2.0 * np.mean(y * np.exp(-2j * np.pi * f * t)[:, None], axis=0)


NATIVE = __import__("rwadist.fmu.build", fromlist=["x"]).native_supported()


@pytest.mark.parametrize("native", [False, pytest.param(True, marks=pytest.mark.skipif(
    not NATIVE, reason="native FMU: Linux x86-64"))])
def test_empirical_planar_line_puts_its_power_on_both_channels(tmp_path, native):
    """A planar radial line of an empirical fit (``rwadist diagnose`` on the empirical base writes them) has the
    fit's C on each channel of its pair, as the model file defines C (C²Ω⁴/2 on each channel) and as the PSD
    reads it (:func:`rwadist.broadband.empirical_lines`: independent x and y sources): with a seed, |Fx| = |Fy|
    = C·Ω² at the line's frequency and x and y have phases of their own (two loads, not one along x, which
    put nothing on Fy).  Python runtime and native FMU alike, and equal to each other."""
    from rwadist import model as model_io
    from rwadist.broadband import empirical_lines

    doc = with_planar_lines(empirical_only())
    path = build_fmu(doc, tmp_path / "planar.fmu", native=native)
    w = 2400 * RPM
    t = np.arange(2000) * (2 * np.pi / w / 200)          # 10 turns: whole periods of h 2.7 (27) and 3.3 (33)
    wheel = np.full(t.size, w)
    out = hosts.run_fmpy(path, t, {"wheel_speed": wheel}, {"seed": 11})
    params, lines = rt.model_from_doc(doc)
    py = rt.WheelRuntime(params, lines, seed=11, modes=False).run(t, wheel)
    assert np.max(np.abs(out[:, :6] - py[:, :6])) <= 1e-9 * np.max(np.abs(py[:, :6]))
    src = empirical_lines(model_io.from_json(doc))
    for (cx, cy), h, C in (((0, 1), 2.7, 4.0e-7), ((3, 4), 3.3, 2.0e-8)):
        a = line_phasor(out[:, [cx, cy]], t, h * w / (2 * np.pi))
        assert np.allclose(np.abs(a), C * w**2, rtol=1e-6), (h, np.abs(a) / (C * w**2))
        dphi = np.angle(a[1] / a[0])
        assert min(abs(dphi), abs(abs(dphi) - np.pi)) > 0.05        # not one load along a line
        # the PSD's own sources: two of them for this line, each of the fit's C
        own = [s for s in src.spec if s[0] in ("radial_force", "radial_torque") and s[1] == C]
        assert sorted(m for _, _, m in own) == ["x", "y"]
    # the file's phases (seed -1): both channels C·Ω²·cos(hΩt), the closed form
    ref = closed_form_lines(doc, w, t)
    out0 = hosts.run_fmpy(path, t, {"wheel_speed": wheel}, {})
    assert np.max(np.abs(out0[:, :6] - ref)) <= 1e-9 * np.max(np.abs(ref))


def test_model_description_states_the_physics(empirical_fmu, tmp_path):
    """The modelDescription's description names the physics: empirical / measured modes / assumed modes,
    and the diagnosed effects; ``modes`` starts false where the wheel has no (or assumed) suspension."""
    from fmpy import read_model_description

    def described(path):
        md = read_model_description(path)
        modes = next(v for v in md.modelVariables if v.name == "modes")
        return md.description, modes.start

    desc, modes = described(empirical_fmu[1])
    assert "empirical harmonics only" in desc and "hard-mounted" in desc and modes == "false"
    doc = json.loads(catalogue.path("ithaco-e").read_text())
    doc["effects"] = [{"kind": "speed_ripple", "f_ripple_Hz": 4.0, "delta_omega_rad_s": 1.0,
                       "omega_ref_rad_s": 200.0, "speed_exponent": 0.0}]
    desc, modes = described(build_fmu(doc, tmp_path / "e.fmu"))
    assert "measured suspension modes" in desc and "speed ripple" in desc and modes == "true"


def test_empirical_only_refuses_modes_on():
    """An empirical-only model has no suspension: asking for modes is an error naming the switch."""
    params, lines = rt.model_from_doc(empirical_only())
    assert params["suspension"] is False and len(lines) == 18
    with pytest.raises(rt.ModelError, match="modes"):
        rt.WheelRuntime(params, lines, modes=True)
    with pytest.raises(rt.ModelError, match="analytical"):
        rt.model_from_doc({**empirical_only(), "analytical": [1, 2]})


# ------------------------------------------------------------------ measured vs assumed modes

HR16 = "honeywell-hr16-75"


def test_catalogue_marks_assumed_modes():
    """Datasheet wheels (Honeywell, S2E) carry analytical.modes_assumed; the Ithaco wheels (fitted or maker's
    modes) do not; the builder writes what the files hold."""
    from rwadist.catalogue import build_catalogue, modes_assumed
    models = build_catalogue.all_models()
    for name in catalogue.names():
        m = catalogue.load(name)
        assert modes_assumed(m) == (name.startswith("honeywell") or name == "s2e-sample-rw"), name
        assert m.analytical == models[name].analytical, name


def fundamental_amplitudes(out):
    """|F_radial|, |T_radial| per sample of (n, 12) FMU outputs."""
    return np.hypot(out[:, 0], out[:, 1]), np.hypot(out[:, 3], out[:, 4])


@pytest.fixture(scope="module")
def hr16_fmus(tmp_path_factory):
    d = tmp_path_factory.mktemp("hr16")
    doc = json.loads(catalogue.path(HR16).read_text())
    return doc, build_fmu(doc, d / "default.fmu"), build_fmu(doc, d / "assumed.fmu", assumed_modes=True)


@pytest.mark.parametrize("rpm", [3000.0, 6000.0])
def test_hr16_fmu_is_hard_mounted_by_default(hr16_fmus, rpm):
    """HR16-75 by default: |F| = U_s·Ω² and |T| = U_d·Ω² at every sample (1e-6); with the build's
    --assumed-modes the modes are on (other amplitudes) and the FMU logs a warning at instantiation."""
    doc, default, assumed = hr16_fmus
    an = doc["analytical"]
    w = rpm * RPM
    t = np.arange(201) * 1e-3
    f, tq = fundamental_amplitudes(hosts.run_fmpy(default, t, {"wheel_speed": np.full(t.size, w)}, {}))
    assert np.max(np.abs(f / (an["U_s_kg_m"] * w**2) - 1)) < 1e-6
    assert np.max(np.abs(tq / (an["U_d_kg_m2"] * w**2) - 1)) < 1e-6
    log = hosts.HostLog()
    inst = hosts.FmpyInstance(assumed, "a", {"start_steady": True}, {"wheel_speed": w}, log=log)
    try:
        inst.fmu.doStep(0.0, 1e-3)
        y = np.array(inst.get())
    finally:
        inst.close()
    assert any("ASSUMED" in m for m in log.messages(1)), log.records
    f_a, t_a = np.hypot(y[0], y[1]), np.hypot(y[3], y[4])
    assert abs(f_a / (an["U_s_kg_m"] * w**2) - 1) > 0.04 and abs(t_a / (an["U_d_kg_m2"] * w**2) - 1) > 0.4


def test_hr16_psd_is_hard_mounted_by_default(tmp_path, capsys):
    """`rwadist psd` on HR16-75: the line envelope at 3000 and 6000 rpm is U_s·Ω², U_d·Ω² (1e-6) by default;
    with --assumed-modes it differs (+23 % force, −77 % torque at 6000 rpm) and a note file says so."""
    from rwadist.cli import main
    an = json.loads(catalogue.path(HR16).read_text())["analytical"]
    ratios = {}
    for flag in ([], ["--assumed-modes"]):
        out = tmp_path / f"p{len(flag)}.csv"
        assert main(["psd", "--preset", HR16, "--speed-rpm", "0:6000", "--fmax", "120", "--n-freq", "1201",
                     "--n-speeds", "200", "-o", str(out), *flag]) == 0
        env = np.loadtxt(tmp_path / f"p{len(flag)}_envelope.csv", delimiter=",", skiprows=1)
        for rpm in (3000, 6000):
            i = int(np.argmin(np.abs(env[:, 0] - rpm / 60)))
            w = rpm * RPM
            ratios[len(flag), rpm] = (env[i, 1] / (an["U_s_kg_m"] * w**2), env[i, 4] / (an["U_d_kg_m2"] * w**2))
        notes = list(tmp_path.glob(f"p{len(flag)}_ASSUMED_MODES.txt"))
        assert len(notes) == len(flag)
    for rpm in (3000, 6000):
        assert np.allclose(ratios[0, rpm], 1.0, rtol=0, atol=1e-6), ratios
    assert abs(ratios[1, 6000][0] - 1.23) < 0.01 and abs(ratios[1, 6000][1] - 0.234) < 0.01, ratios
    err = capsys.readouterr().err
    assert "ASSUMED" in err


def test_simulate_test_extended_on_assumed_modes_needs_the_flag(tmp_path, capsys):
    """simulate-test --physics extended on HR16-75 is refused without --assumed-modes (exit 2, naming the
    flag); with it the data's metadata carries the assumed-modes note."""
    from rwadist.cli import main
    base = ["simulate-test", str(tmp_path / "st"), "--preset", HR16, "--physics", "extended",
            "--speeds-rpm", "1000,2000", "--samples", "256"]
    assert main(base) == 2
    assert "--assumed-modes" in capsys.readouterr().err
    assert main(base + ["--assumed-modes"]) == 0
    assert "ASSUMED" in json.loads((tmp_path / "st" / "meta.json").read_text())["modes_assumed"]


@pytest.mark.skipif(not __import__("rwadist.fmu.build", fromlist=["x"]).native_supported(), reason="native FMU: Linux x86-64")
def test_native_fmu_empirical_and_hr16_default(tmp_path, capsys):
    """The native FMU (rwadist fmu build --native) of an empirical fit gives the C·Ω² lines (1e-9); of HR16-75
    it is hard-mounted by default (U_s·Ω², U_d·Ω² to 1e-6 at 3000 and 6000 rpm) and with --assumed-modes it
    starts with modes on and warns at instantiation."""
    from rwadist.cli import main
    doc = empirical_only()
    (tmp_path / "emp.json").write_text(json.dumps(doc))
    assert main(["fmu", "build", "--native", str(tmp_path / "emp.json"), "-o", str(tmp_path / "emp.fmu")]) == 0
    assert "native FMU" in capsys.readouterr().out
    t = np.arange(501) * 1e-3
    w = 3000 * RPM
    out = hosts.run_fmpy(tmp_path / "emp.fmu", t, {"wheel_speed": np.full(t.size, w)}, {})
    ref = closed_form_lines(doc, w, t)
    assert np.max(np.abs(out[:, :6] - ref)) <= 1e-9 * np.max(np.abs(ref))
    an = json.loads(catalogue.path(HR16).read_text())["analytical"]
    assert main(["fmu", "build", "--native", "--preset", HR16, "-o", str(tmp_path / "hr.fmu")]) == 0
    assert main(["fmu", "build", "--native", "--assumed-modes", "--preset", HR16, "-o", str(tmp_path / "hra.fmu")]) == 0
    for rpm in (3000.0, 6000.0):
        w = rpm * RPM
        f, tq = fundamental_amplitudes(hosts.run_fmpy(tmp_path / "hr.fmu", t, {"wheel_speed": np.full(t.size, w)}, {}))
        assert np.max(np.abs(f / (an["U_s_kg_m"] * w**2) - 1)) < 1e-6
        assert np.max(np.abs(tq / (an["U_d_kg_m2"] * w**2) - 1)) < 1e-6
    log = hosts.HostLog()
    inst = hosts.FmpyInstance(tmp_path / "hra.fmu", "a", {}, {"wheel_speed": 100.0}, log=log)
    inst.close()
    assert any("ASSUMED" in m for m in log.messages(1)), log.records


def test_coupling_warns_on_assumed_modes():
    """The coupling kit keeps a model's analytical section as it is, and says when its modes are assumed."""
    from rwadist.coupling.performance import wheel_spec_from_model
    with pytest.warns(RuntimeWarning, match="ASSUMED"):
        wheel_spec_from_model(catalogue.load(HR16))
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        wheel_spec_from_model(catalogue.load("ithaco-e"))
