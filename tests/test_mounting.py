"""Wheel mountings, the spacecraft-frame 6×6 CSD of several wheels, wheels.json, ties."""
import json

import numpy as np
import pytest

from rwadist import broadband as bb
from rwadist import mounting as mt
from rwadist.data import DataError
from rwadist.model import Harmonic, WheelModel, save
from rwadist.presets import preset
from rwadist.units import rpm_to_rad_s

W = float(rpm_to_rad_s(1.0))
E_MODEL = preset("ithaco-e").to_model()


def test_dcm_validation():
    with pytest.raises(DataError, match="not orthonormal"):
        mt.Mounting(((1, 0, 0), (0, 1.01, 0), (0, 0, 1)))
    with pytest.raises(DataError, match="det"):
        mt.Mounting(((1, 0, 0), (0, 1, 0), (0, 0, -1)))
    with pytest.raises(DataError, match="position_m"):
        mt.Mounting(np.eye(3), (0, 0))
    for name in ("pyramid-4", "ortho-3-skew"):
        ms = mt.preset_mountings(name)
        assert len(ms) == 4
        for m in ms:
            assert np.allclose(m.R.T @ m.R, np.eye(3)) and np.linalg.det(m.R) == pytest.approx(1.0)
    # pyramid: equal authority -- the sum of spin-axis outer products is (4/3) I at 35.26° elevation
    A = sum(np.outer(m.spin_axis, m.spin_axis) for m in mt.preset_mountings("pyramid-4"))
    np.testing.assert_allclose(A, 4 / 3 * np.eye(3), atol=1e-12)


def test_pure_force_with_lever_arm():
    """Axial force line only, wheel at r = (0.5, 0, 0) with identity DCM: T = r × F = (0, −0.5 Fz, 0)."""
    m = WheelModel(name="fz", empirical={"radial_force": [], "radial_torque": [], "axial_torque": [],
                                         "axial_force": [Harmonic(h=2.0, C=2e-6)]})
    law = bb.Uniform(500 * W, 3000 * W)
    mount = mt.Mounting(np.eye(3), (0.5, 0.0, 0.0))
    res = bb.broadband_psd(bb.empirical_lines(m), law, 120.0, 2001, 800, mounting=mount)
    Sz = res.psd[:, 2]
    np.testing.assert_allclose(res.psd[:, 4], 0.25 * Sz, rtol=1e-12, atol=0)
    np.testing.assert_allclose(res.csd[:, 2, 4].real, -0.5 * Sz, rtol=1e-12, atol=0)
    assert np.all(res.psd[:, [0, 1, 3, 5]] == 0)


def test_pyramid_csd_hermitian_psd_and_trace():
    ms = mt.preset_mountings("pyramid-4", radius_m=0.4)
    lines = bb.extended_lines_from_model(E_MODEL)
    laws = [bb.Uniform(-3000 * W, 3000 * W), bb.TruncatedNormal(1000 * W, 300 * W, 0, 2500 * W),
            bb.Uniform(500 * W, 2000 * W), bb.Uniform(-2500 * W, -100 * W)]
    wheels = [mt.WheelSpec(f"RW{i}", lines, m, law) for i, (m, law) in enumerate(zip(ms, laws))]
    res = mt.spacecraft_csd(wheels, 350.0, 3501, 1000)
    S = res.csd
    assert np.abs(S - np.conj(np.swapaxes(S, 1, 2))).max() == 0.0
    ev = np.linalg.eigvalsh(S)
    assert ev.min() >= -1e-12 * ev.max()
    # rotation invariance: trace of the force block = Σ wheels' own force PSDs (wheel frame)
    own = sum(bb.broadband_psd(lines, law, 350.0, 3501, 1000).psd[:, :3].sum(axis=1) for law in laws)
    np.testing.assert_allclose(np.einsum("kaa->k", S[:, :3, :3]).real, own, rtol=1e-9, atol=1e-12 * own.max())


def test_tied_wheels_phase_lock(tmp_path):
    m = tmp_path / "e.json"
    save(E_MODEL, m)
    same = {"dcm": np.eye(3).tolist(), "position_m": [0, 0, 0]}
    doc = {"wheels": [{"name": "A", "model": "e.json", **same, "speed": {"dist": "uniform", "min_rpm": 500,
                                                                       "max_rpm": 2500}},
                      {"name": "B", "model": "e.json", **same, "tie": {"to": "A", "phase_lock": False}}]}
    (tmp_path / "w.json").write_text(json.dumps(doc))
    one = bb.broadband_psd(bb.empirical_lines(E_MODEL), bb.Uniform(500 * W, 2500 * W), 300.0, 1001, 500)
    free = mt.spacecraft_csd(mt.load_wheels(tmp_path / "w.json", empirical=True), 300.0, 1001, 500)
    np.testing.assert_allclose(free.psd, 2 * one.psd, rtol=1e-12, atol=0)       # independent phases
    doc["wheels"][1]["tie"]["phase_lock"] = True
    (tmp_path / "w.json").write_text(json.dumps(doc))
    lock = mt.spacecraft_csd(mt.load_wheels(tmp_path / "w.json", empirical=True), 300.0, 1001, 500)
    np.testing.assert_allclose(lock.psd, 4 * one.psd, rtol=1e-12, atol=0)       # coherent, in phase
    doc["wheels"][1]["tie"]["phase_offset_deg"] = 180.0
    doc["wheels"][1]["tie"]["ratio"] = 1
    (tmp_path / "w.json").write_text(json.dumps(doc))
    anti = mt.spacecraft_csd(mt.load_wheels(tmp_path / "w.json", empirical=True), 300.0, 1001, 500)
    # rotors half a turn apart: odd-integer harmonics cancel, even ones add
    h1 = bb.broadband_psd(bb.empirical_lines(WheelModel(name="h1", empirical={
        "radial_force": [hm for hm in E_MODEL.harmonics("radial_force") if hm.h == 1.0],
        "radial_torque": [], "axial_force": [], "axial_torque": []})), bb.Uniform(500 * W, 2500 * W), 300.0, 1001,
        500)
    only_h1 = (h1.f > 8.5) & (h1.f < 16.5)            # Fx: h = 1 from 8.3 Hz, h = 2 from 16.7 Hz
    assert h1.psd[only_h1, 0].min() > 0
    assert anti.psd[only_h1, 0].max() < 1e-12 * one.psd[only_h1, 0].max()
    assert anti.psd[:, 0].sum() < lock.psd[:, 0].sum()


def test_wheels_file_errors(tmp_path):
    p = tmp_path / "w.json"
    p.write_text(json.dumps([{"model": "missing.json", "dcm": np.eye(3).tolist()}]))
    with pytest.raises(DataError, match=r"wheels\[0\]\.model.*missing\.json.*does not exist"):
        mt.load_wheels(p)
    p.write_text(json.dumps([{"preset": "ithaco-e", "dcm": [[1, 0, 0], [0, 2, 0], [0, 0, 1]],
                              "speed": {"dist": "uniform", "min_rpm": 0, "max_rpm": 100}}]))
    with pytest.raises(DataError, match=r"wheels\[0\]\.dcm.*not orthonormal"):
        mt.load_wheels(p)
    p.write_text(json.dumps([{"preset": "ithaco-e", "mounting": {"preset": "pyramid-4", "index": 0},
                              "speed": {"dist": "uniform", "min_rpm": 100, "max_rpm": 0}}]))
    with pytest.raises(DataError, match="empty or inverted"):
        mt.load_wheels(p)
    p.write_text(json.dumps([{"preset": "ithaco-e", "mounting": {"preset": "pyramid-4"},
                              "tie": {"to": "nobody"}}]))
    with pytest.raises(DataError, match="tie.to"):
        mt.load_wheels(p)


@pytest.mark.parametrize("wheel,field,message", [
    ({"preset": "ithaco-e", "dcm": np.eye(3).tolist(), "positon_m": [1, 0, 0]}, r"wheels\[0\]\.positon_m",
     r"unknown key \(did you mean 'position_m'\?\)"),
    ({"preset": "ithaco-e", "dcm": np.eye(3).tolist(), "sped": {"dist": "uniform"}}, r"wheels\[0\]\.sped",
     r"did you mean 'speed'"),
    ({"preset": "ithaco-e", "mountng": {"preset": "pyramid-4"}}, r"wheels\[0\]\.mountng", r"did you mean 'mounting'"),
    ({"preset": "ithaco-e", "mounting": {"preset": "pyramid-4", "indx": 1}}, r"wheels\[0\]\.mounting\.indx",
     r"did you mean 'index'"),
    ({"name": "B", "preset": "ithaco-e", "mounting": {"preset": "pyramid-4"}, "tie": {"to": "A"},
      "speed": {"dist": "uniform", "min_rpm": 0, "max_rpm": 100}}, r"wheels\[0\]\.speed",
     r"given beside 'tie', which decides it"),
    # each pair one of whose keys was ignored, the speed law's own keys, and objects that are not objects
    ({"preset": "ithaco-e", "mounting": {"preset": "pyramid-4", "index": 0}, "position_m": [1, 0, 0]},
     r"wheels\[0\]\.position_m", r"given beside 'mounting'"),
    ({"model": "m.json", "preset": "ithaco-e", "mounting": {"preset": "pyramid-4"}}, r"wheels\[0\]\.preset",
     r"given beside 'model'"),
    ({"preset": "ithaco-e", "mounting": {"preset": "pyramid-4"}, "speed": {"dist": "normal", "min_rpm": 0,
                                                                           "max_rpm": 100, "std_rmp": 10}},
     r"wheels\[0\]\.speed\.std_rmp", r"did you mean 'std_rpm'"),
    ({"preset": "ithaco-e", "mounting": "pyramid-4"}, r"wheels\[0\]\.mounting", r"must be an object"),
])
def test_wheels_file_keys_it_does_not_read_are_refused(tmp_path, wheel, field, message):
    """A typo of position_m put the wheel at the origin (its r × F torques gone: Ty 0.048 instead of 0.098 N·m),
    of speed took the command line's law, and speed beside tie was dropped: each is refused naming the key."""
    p = tmp_path / "w.json"
    p.write_text(json.dumps([{"name": "A", "preset": "ithaco-e", "mounting": {"preset": "pyramid-4", "index": 1},
                              "speed": {"dist": "uniform", "min_rpm": 0, "max_rpm": 100}}, wheel]))
    with pytest.raises(DataError, match=field.replace("0", "1") + ".*" + message):
        mt.load_wheels(p)


def test_wheels_file_names_are_unique(tmp_path):
    p = tmp_path / "w.json"
    w = {"name": "RW", "preset": "ithaco-e", "mounting": {"preset": "pyramid-4"},
         "speed": {"dist": "uniform", "min_rpm": 0, "max_rpm": 100}}
    p.write_text(json.dumps([w, w]))
    with pytest.raises(DataError, match=r"wheels\[0\]\.name.*'RW' names more than one wheel"):
        mt.load_wheels(p)


def test_wheels_file_top_level_keys_are_checked(tmp_path):
    """A top-level key beside 'wheels' (a speed law meant for every wheel) was dropped without a word."""
    p = tmp_path / "w.json"
    p.write_text(json.dumps({"wheels": [{"preset": "ithaco-e", "mounting": {"preset": "pyramid-4"}}],
                             "speed": {"dist": "uniform", "min_rpm": 0, "max_rpm": 100}}))
    with pytest.raises(DataError, match=r"document\.speed.*unknown key"):
        mt.load_wheels(p)


LAW = bb.Uniform(500 * W, 3000 * W)


def test_a_wheel_object_from_python_takes_the_model_itself(tmp_path):
    """From Python a wheel object's ``model`` may be the WheelModel: the same lines as its file (a round trip), read
    once for the set; anything else but a path is refused naming the field."""
    save(E_MODEL, tmp_path / "e.json")
    by_file = mt.load_wheels([{"model": str(tmp_path / "e.json"), "mounting": {"preset": "pyramid-4", "index": i}}
                              for i in range(2)], default_law=LAW, empirical=True)
    by_object = mt.load_wheels([{"model": E_MODEL, "mounting": {"preset": "pyramid-4", "index": i}}
                                for i in range(2)], default_law=LAW, empirical=True)
    for a, b in zip(by_file, by_object):
        np.testing.assert_array_equal(a.lines.h, b.lines.h)
        assert a.lines.spec == b.lines.spec and a.lines.kind == b.lines.kind == "empirical"
    assert by_object[0].lines is by_object[1].lines
    with pytest.raises(DataError, match=r"wheels\[0\]\.model.*a int: expected a model-file path"):
        mt.load_wheels([{"model": 3, "mounting": {"preset": "pyramid-4", "index": 0}}])


def test_each_wheel_of_a_set_is_enveloped_over_its_own_speeds():
    """The worst-case line envelope of a set: wheel A (identity, 0-3000 rpm) and wheel B (spin axis along x, its
    radial force on Fy and Fz, 1000-2000 rpm), one radial-force line h = 1 of C each.  Closed form: Fz holds B's line
    alone, C·Ω² (peak) for f in [1000, 2000]/60 Hz and nothing above (the set's range was B's before: Fz enveloped up
    to 50 Hz); Fx holds A's, C·Ω² up to 50 Hz."""
    import rwadist

    C = 2e-6
    m = WheelModel(name="one", empirical={"radial_force": [Harmonic(h=1.0, C=C)], "radial_torque": [],
                                          "axial_force": [], "axial_torque": []})
    along_x = [[0, 0, 1], [1, 0, 0], [0, 1, 0]]          # wheel x, y, z -> spacecraft y, z, x
    wheels = [{"name": "A", "model": m, "dcm": np.eye(3).tolist()},
              {"name": "B", "model": m, "dcm": along_x, "speed": {"dist": "uniform", "min_rpm": 1000, "max_rpm": 2000}}]
    res = rwadist.psd(wheels=wheels, speed_rpm=(0, 3000), empirical=True, envelope=True, fmax=60.0, n_freq=601)
    env = res.meta["envelope"]
    f, a = env.f, env.amplitude
    want = C * (2 * np.pi * f) ** 2
    inside = (f > 1000 / 60 + 0.2) & (f < 2000 / 60 - 0.2)
    above = f > 2000 / 60 + 0.2
    np.testing.assert_allclose(a[inside, 2], want[inside], rtol=1e-3)
    assert np.all(a[above, 2] == 0.0)
    below_top = (f > 1.0) & (f < 50.0 - 0.2)
    np.testing.assert_allclose(a[below_top, 0], want[below_top], rtol=1e-3)
    assert {row["wheel"] for row in env.table} == {0, 1}
    top_b = max(row["speed_rpm"] for row in env.table if row["wheel"] == 1)
    assert top_b == pytest.approx(2000.0, rel=1e-6)
