"""Lab file formats (issue 15): each format is written by its own library (pyuff, npTDMS, scipy.io, h5py),
never by rwadist, and must read to the same samples and the same fitted model as the CSV interchange."""
from __future__ import annotations

import json

import h5py
import numpy as np
import pytest
import pyuff
from nptdms import ChannelObject, GroupObject, RootObject, TdmsWriter
from scipy.io import savemat

from rwadist.data import (
    DataError,
    read_data,
    read_steady,
    write_steady,
    write_sweep,
)
from rwadist.empirical import fit_empirical
from rwadist.presets import preset
from rwadist.spectra import compute_spectra
from rwadist.teststand import simulate_steady, simulate_sweep
from rwadist.units import CHANNEL_COLUMN, CHANNELS, rad_s_to_rpm

FS = 3840.0
SPEEDS_RPM = np.linspace(600.0, 2400.0, 8)
DIRECTIONS = ("radial_force", "radial_torque", "axial_force", "axial_torque")
#: pyuff writes ASCII ordinates as %20.11e: 12 significant digits.
UFF_ASCII_RTOL = 5e-12


@pytest.fixture(scope="module")
def steady():
    return simulate_steady(preset("ithaco-e"), SPEEDS_RPM, sample_rate=FS, n_samples=4096, noise=0.01, seed=5)


@pytest.fixture(scope="module")
def reference(steady, tmp_path_factory):
    """The test through the CSV interchange, and its fitted model."""
    test = read_steady(write_steady(steady, tmp_path_factory.mktemp("csv")))
    return test, model_C(test)


@pytest.fixture(scope="module")
def sweep():
    return simulate_sweep(preset("ithaco-e"), rpm_start=300.0, rpm_end=2400.0, duration=4.0, sample_rate=FS,
                          seed=3, tach=True)


def model_C(test) -> dict:
    model = fit_empirical(compute_spectra(test), progress=False).model
    return {d: model.h_and_C(d) for d in DIRECTIONS}


def same_model(a: dict, b: dict) -> float:
    """Same harmonics in every direction; the largest relative difference of C."""
    assert sum(a[d][1].size for d in a) >= 10
    worst = 0.0
    for d in DIRECTIONS:
        np.testing.assert_array_equal(a[d][0], b[d][0])
        if a[d][1].size:
            worst = max(worst, float(np.max(np.abs(b[d][1] / a[d][1] - 1))))
    return worst


# --------------------------------------------------------------------------- independent writers

def uff_sets(signals: dict, fs: float, t0: float, binary: bool, speed_rpm=None) -> list:
    n = len(next(iter(signals.values())))
    x = t0 + np.arange(n) / fs
    common = dict(binary=int(binary), func_type=1, rsp_node=1, ref_node=0, ref_dir=0, x=x, abscissa_spacing=1,
                  abscissa_min=t0, abscissa_inc=1.0 / fs, abscissa_spec_data_type=17, ordinate_spec_data_type=13,
                  orddenom_spec_data_type=0, z_axis_spec_data_type=0, abscissa_axis_units_lab="s")
    sets = []
    for ch, y in signals.items():
        unit = "N" if ch.startswith("F") else "N·m"
        sets.append(pyuff.prepare_58(rsp_dir=CHANNELS.index(ch) + 1, id1=f"load cell {ch}", data=y,
                                     ordinate_axis_units_lab=unit, **common))
    if speed_rpm is not None:
        sets.append(pyuff.prepare_58(rsp_dir=0, id1="speed_rpm", data=speed_rpm, **common))
    return sets


def write_uff(path, signals, fs, t0=0.0, binary=False, speed_rpm=None):
    pyuff.UFF(str(path)).write_sets(uff_sets(signals, fs, t0, binary, speed_rpm), mode="add")


def write_tdms(path, signals, fs, t0=0.0, speed_rpm=None, names=None, group="run"):
    objects = [RootObject(), GroupObject(group)]
    for ch, y in signals.items():
        unit = "N" if ch.startswith("F") else "N·m"
        objects.append(ChannelObject(group, (names or {}).get(ch, ch), y, properties={
            "wf_increment": 1.0 / fs, "wf_start_offset": t0, "unit_string": unit}))
    if speed_rpm is not None:
        objects.append(ChannelObject(group, "speed_rpm", speed_rpm,
                                     properties={"wf_increment": 1.0 / fs, "wf_start_offset": t0}))
    with TdmsWriter(str(path)) as writer:
        writer.write_segment(objects)


def mat_columns(signals, fs, t0, speed_rpm=None):
    n = len(next(iter(signals.values())))
    cols = {"time_s": t0 + np.arange(n) / fs}
    cols.update({CHANNEL_COLUMN[ch]: y for ch, y in signals.items()})
    if speed_rpm is not None:
        cols["speed_rpm"] = speed_rpm
    return cols


def write_mat5(path, signals, fs, t0=0.0, speed_rpm=None):
    savemat(str(path), {k: v.reshape(-1, 1) for k, v in mat_columns(signals, fs, t0, speed_rpm).items()})


def write_mat73(path, signals, fs, t0=0.0, speed_rpm=None):
    """A MATLAB v7.3 file as MATLAB writes it: HDF5 with a 512-byte header, vectors stored transposed (1 x n)."""
    with h5py.File(path, "w", userblock_size=512) as fh:
        for name, v in mat_columns(signals, fs, t0, speed_rpm).items():
            fh.create_dataset(name, data=v.reshape(1, -1)).attrs["MATLAB_class"] = np.bytes_("double")
    with open(path, "r+b") as fh:
        fh.write(b"MATLAB 7.3 MAT-file, written by h5py for a test".ljust(116) + bytes(8) + b"\x00\x02IM")


WRITERS = {
    "uff": (".uff", lambda p, s, fs, t0, v=None: write_uff(p, s, fs, t0, False, v)),
    "uff-binary": (".uff", lambda p, s, fs, t0, v=None: write_uff(p, s, fs, t0, True, v)),
    "tdms": (".tdms", write_tdms),
    "mat": (".mat", write_mat5),
    "mat73": (".mat", write_mat73),
}


def write_lab_steady(test, directory, fmt, meta=None):
    ext, writer = WRITERS[fmt]
    directory.mkdir()
    lines = ["file,speed_rpm"]
    for i, run in enumerate(test.runs):
        name = f"run_{i:02d}{ext}"
        writer(directory / name, {c: run.signals[c] for c in run.channels}, run.sample_rate, run.t0)
        lines.append(f"{name},{float(rad_s_to_rpm(run.speed))!r}")
    (directory / "runs.csv").write_text("\n".join(lines) + "\n")
    (directory / "meta.json").write_text(json.dumps(meta if meta is not None else {"sample_rate_hz": FS}))
    return directory


# --------------------------------------------------------------------------- every format = the interchange

@pytest.mark.parametrize("fmt", list(WRITERS))
def test_steady_in_lab_format_reads_as_the_interchange(tmp_path, steady, reference, fmt):
    ref_test, ref_model = reference
    back = read_steady(write_lab_steady(steady, tmp_path / fmt, fmt))
    assert len(back.runs) == len(ref_test.runs)
    for a, b in zip(ref_test.runs, back.runs):
        assert a.speed == b.speed and a.sample_rate == b.sample_rate and a.channels == b.channels
        for ch in a.channels:
            if fmt == "uff":
                np.testing.assert_allclose(b.signals[ch], a.signals[ch], rtol=UFF_ASCII_RTOL, atol=0)
            else:
                assert np.array_equal(a.signals[ch].view(np.uint64), b.signals[ch].view(np.uint64))
    assert same_model(ref_model, model_C(back)) <= 1e-6


def test_uff_ascii_rounded_rate_without_meta(tmp_path, steady, reference):
    """Without meta.json the rate is the 6-digit abscissa increment's: accepted, and the model barely moves."""
    d = write_lab_steady(steady, tmp_path / "u", "uff", meta={})
    back = read_steady(d)
    fs = back.runs[0].sample_rate
    assert fs != FS and abs(fs / FS - 1) < 5e-6  # 1/2.60417e-4 s
    assert same_model(reference[1], model_C(back)) <= 1e-5


@pytest.mark.parametrize("fmt", ["csv"] + list(WRITERS))
def test_sweep_in_one_file(tmp_path, sweep, fmt):
    speed_rpm = rad_s_to_rpm(sweep.tach)
    signals = {c: sweep.signals[c] for c in sweep.channels}
    if fmt == "csv":
        path = write_sweep(sweep, tmp_path / "s.csv")
    else:
        ext, writer = WRITERS[fmt]
        path = tmp_path / f"sweep{ext}"
        writer(path, signals, FS, float(sweep.time[0]), speed_rpm)
        path.with_suffix(".meta.json").write_text(json.dumps({"sample_rate_hz": FS}))
    back = read_data(path)
    # the CSV sweep has no meta.json: its rate is the time stamps' least-squares step
    assert back.sample_rate == pytest.approx(FS, rel=1e-12 if fmt == "csv" else 0)
    assert back.channels == sweep.channels
    rtol = UFF_ASCII_RTOL if fmt == "uff" else 0.0
    for ch in sweep.channels:
        np.testing.assert_allclose(back.signals[ch], sweep.signals[ch], rtol=rtol, atol=0)
    np.testing.assert_allclose(back.tach, sweep.tach, rtol=max(rtol, 1e-15), atol=0)
    np.testing.assert_allclose(back.time, sweep.time, rtol=1e-15, atol=1e-15)  # t0 + i/fs, to the ulp


def test_tdms_group_per_run_in_one_file(tmp_path, steady, reference):
    """One TDMS file, one group per run, runs.csv naming FILE.tdms:GROUP."""
    path = tmp_path / "d" / "test.tdms"
    path.parent.mkdir()
    objects, lines = [RootObject()], ["file,speed_rpm"]
    for i, run in enumerate(steady.runs):
        g = f"run {i}"
        objects.append(GroupObject(g))
        for ch in run.channels:
            objects.append(ChannelObject(g, CHANNEL_COLUMN[ch], run.signals[ch],
                                         properties={"wf_increment": 1 / FS, "wf_start_offset": 0.0}))
        lines.append(f"test.tdms:{g},{float(rad_s_to_rpm(run.speed))!r}")
    with TdmsWriter(str(path)) as w:
        w.write_segment(objects)
    (path.parent / "runs.csv").write_text("\n".join(lines) + "\n")
    back = read_steady(path.parent)
    assert "unlisted_files" not in back.meta
    for a, b in zip(reference[0].runs, back.runs):
        for ch in a.channels:
            np.testing.assert_array_equal(a.signals[ch], b.signals[ch])


# --------------------------------------------------------------------------- channel map

LBF = 4.4482216152605
IN_LBF = 0.1129848290276167
FT_LBF = 1.3558179483314004
#: lab channel -> (our channel, unit, factor to SI, sign): names swapped, imperial units, two signs flipped
LAB_MAP = {"LC_A": ("Fy", "lbf", LBF, -1), "LC_B": ("Fx", "lbf", LBF, 1), "LC_C": ("Fz", "kN", 1000.0, 1),
           "LC_D": ("Ty", "in·lbf", IN_LBF, 1), "LC_E": ("Tx", "in-lbf", IN_LBF, -1), "LC_F": ("Tz", "ft·lbf", FT_LBF, 1)}


def calibration_matrix():
    rng = np.random.default_rng(42)
    return np.eye(6) + 0.05 * rng.standard_normal((6, 6))  # cross-talk of a real 6-axis load cell


def write_mapped(test, directory, matrix, unit_override=None):
    """The SI test as a lab writes it: channels LC_A..LC_F in lbf/in·lbf, raw = matrix^-1 · calibrated."""
    directory.mkdir()
    names = list(LAB_MAP)
    lines = ["file,speed_rpm"]
    for i, run in enumerate(test.runs):
        calibrated = np.vstack([run.signals[LAB_MAP[n][0]] / (LAB_MAP[n][2] * LAB_MAP[n][3]) for n in names])
        raw = np.linalg.solve(matrix, calibrated)
        t = run.t0 + np.arange(run.n_samples) / run.sample_rate
        np.savetxt(directory / f"lab_{i}.csv", np.column_stack([t, raw.T]), delimiter=",", fmt="%.17g",
                   header=",".join(["time_s"] + names), comments="")
        lines.append(f"lab_{i}.csv,{float(rad_s_to_rpm(run.speed))!r}")
    (directory / "runs.csv").write_text("\n".join(lines) + "\n")
    channels = {n: {"channel": ch, "unit": unit, "sign": sign} for n, (ch, unit, _, sign) in LAB_MAP.items()}
    channels.update(unit_override or {})
    meta = {"sample_rate_hz": FS,
            "channel_map": {"calibration": {"inputs": names, "matrix": matrix.tolist()}, "channels": channels}}
    (directory / "meta.json").write_text(json.dumps(meta))
    return directory


def test_channel_map_imperial_units_calibration_and_swapped_names(tmp_path, steady, reference):
    back = read_steady(write_mapped(steady, tmp_path / "lab", calibration_matrix()))
    worst = 0.0
    for a, b in zip(reference[0].runs, back.runs):
        assert a.channels == b.channels
        for ch in a.channels:
            worst = max(worst, float(np.max(np.abs(b.signals[ch] - a.signals[ch])) / np.max(np.abs(a.signals[ch]))))
    assert worst < 1e-12  # a 6x6 solve and product mixing channels 1000x apart in size: round-off only
    assert same_model(reference[1], model_C(back)) <= 1e-6


def test_channel_map_unknown_unit_names_the_channel(tmp_path, steady):
    d = write_mapped(steady, tmp_path / "lab", calibration_matrix(),
                     unit_override={"LC_D": {"channel": "Ty", "unit": "oz·in", "sign": 1}})
    with pytest.raises(DataError, match=r"channel_map\.channels\.LC_D\.unit \(file channel 'LC_D'\): unit 'oz·in' "
                                        r"is not known"):
        read_steady(d)


def test_channel_map_singular_calibration_refused(tmp_path, steady):
    m = calibration_matrix()
    m[3] = m[1] * 2.0  # two rows dependent
    d = write_mapped(steady, tmp_path / "lab", calibration_matrix())
    meta = json.loads((d / "meta.json").read_text())
    meta["channel_map"]["calibration"]["matrix"] = m.tolist()
    (d / "meta.json").write_text(json.dumps(meta))
    with pytest.raises(DataError, match=r"meta.json: channel_map.calibration.matrix: is singular \(condition number"):
        read_steady(d)


def test_channel_map_force_unit_on_a_torque_refused(tmp_path, steady):
    d = write_mapped(steady, tmp_path / "lab", calibration_matrix(),
                     unit_override={"LC_F": {"channel": "Tz", "unit": "lbf", "sign": 1}})
    with pytest.raises(DataError, match=r"LC_F.*'lbf' is a force unit, but channel Tz is a torque"):
        read_steady(d)



@pytest.mark.parametrize("unit,channel,factor", [
    ("mN", "Fx", 1e-3), ("millinewton", "Fz", 1e-3), ("mN·m", "Tx", 1e-3), ("mNm", "Ty", 1e-3),
    ("N·mm", "Tz", 1e-3), ("Nmm", "Tx", 1e-3), ("N", "Fy", 1.0), ("kN", "Fx", 1e3), ("Nm", "Tz", 1.0),
    ("nm", "Tz", 1.0), ("LBF", "Fx", 4.4482216152605)])
def test_unit_factors_by_the_si_prefixes(unit, channel, factor):
    """SI: milli is 1e-3, kilo 1e3 (exact), the pound-force 4.4482216152605 N (exact by definition); a spelling
    whose case is an SI prefix is read by its case ("mN" a millinewton, not N·m: a torque channel in "mN" was read
    1000x too large)."""
    from rwadist.formats.channels import unit_factor

    assert unit_factor(unit, channel, "meta.json", "unit") == factor


@pytest.mark.parametrize("unit,channel,message", [
    ("mN", "Tx", r"'mN' is a force unit, but channel Tx is a torque"),
    ("MN", "Fx", r"unit 'MN' is not known"),
    ("mN·m", "Fy", r"'mN·m' is a torque unit, but channel Fy is a force"),
    ("N·MM", "Tz", r"unit 'N·MM' is not known")])
def test_unit_spellings_that_are_not_what_they_look_like_refused(unit, channel, message):
    from rwadist.formats.channels import unit_factor

    with pytest.raises(DataError, match=message):
        unit_factor(unit, channel, "meta.json", "unit")


# --------------------------------------------------------------------------- bad input per format

def _one_run(steady):
    run = steady.runs[0]
    return {c: run.signals[c] for c in run.channels}


def test_uff_truncated(tmp_path, steady):
    path = tmp_path / "r.uff"
    write_uff(path, _one_run(steady), FS)
    text = path.read_text()
    cut = text[: int(len(text) * 0.55)]  # mid-way through the 4th of 6 datasets
    path.write_text(cut)
    with pytest.raises(DataError, match=r"r\.uff: file: is truncated"):
        read_data(path)
    path.write_text(cut[: cut.rindex("\n")] + "\n    -1\n")  # closed by hand after a cut: header count disagrees
    with pytest.raises(DataError, match=r"r\.uff: dataset \d: holds \d+ samples, its header states 4096"):
        read_data(path)


@pytest.mark.parametrize("func_type, name", [(4, "frequency response function"), (2, "auto spectrum"),
                                             (9, "power spectral density")])
def test_uff_dataset_of_another_function_type(tmp_path, steady, func_type, name):
    sets = uff_sets(_one_run(steady), FS, 0.0, binary=False)
    f = np.arange(64) * 2.0
    sets.insert(2, pyuff.prepare_58(func_type=func_type, rsp_node=1, rsp_dir=3, ref_node=1, ref_dir=3, id1="H33",
                                    data=np.exp(1j * f / 30) if func_type == 4 else 1 + f, x=f, abscissa_spacing=1, abscissa_min=0.0,
                                    abscissa_inc=2.0, abscissa_spec_data_type=18, ordinate_spec_data_type=13,
                                    orddenom_spec_data_type=13, z_axis_spec_data_type=0))
    path = tmp_path / "r.uff"
    pyuff.UFF(str(path)).write_sets(sets, mode="add")
    with pytest.raises(DataError, match=rf"r\.uff: dataset 3: function type {func_type} \({name}\), expected 1"):
        read_data(path)


def test_tdms_without_waveform_properties(tmp_path, steady):
    path = tmp_path / "s.tdms"
    with TdmsWriter(str(path)) as w:
        w.write_segment([RootObject(), GroupObject("g"),
                         ChannelObject("g", "Fx_N", steady.runs[0].signals["Fx"], properties={"unit_string": "N"})])
    with pytest.raises(DataError, match=r"s\.tdms: /g/Fx_N: has no NI waveform property wf_increment"):
        read_data(path)


@pytest.mark.parametrize("v73", [False, True])
def test_mat_matrix_of_unknown_orientation(tmp_path, steady, v73):
    run = steady.runs[0]
    matrix = np.column_stack([run.signals[c] for c in run.channels])  # n x 6
    path = tmp_path / "s.mat"
    if v73:
        with h5py.File(path, "w", userblock_size=512) as fh:
            fh["loads"] = matrix.T
            fh["sample_rate_hz"] = np.array([[FS]])
    else:
        savemat(str(path), {"loads": matrix, "sample_rate_hz": FS})
    with pytest.raises(DataError, match=r"s\.mat: variable loads: is a \d+x\d+ matrix: its orientation"):
        read_data(path)


def test_mixed_sample_rates_across_runs(tmp_path, steady):
    d = write_lab_steady(steady, tmp_path / "t", "tdms", meta={})
    write_tdms(d / "run_03.tdms", _one_run(steady), 2 * FS)
    with pytest.raises(DataError, match=r"run_03\.tdms: sample rate: 7680.0 Hz differs from run_00\.tdms's 3840.0 Hz"):
        read_steady(d)


def test_unknown_unit_in_a_tdms_file(tmp_path, steady):
    path = tmp_path / "s.tdms"
    with TdmsWriter(str(path)) as w:
        w.write_segment([RootObject(), GroupObject("g"), ChannelObject(
            "g", "Tx", steady.runs[0].signals["Tx"],
            properties={"wf_increment": 1 / FS, "wf_start_offset": 0.0, "unit_string": "kgf·cm"})])
    with pytest.raises(DataError, match=r"s\.tdms: /g/Tx: unit 'kgf·cm' is not known"):
        read_data(path)


def test_uff_units_from_label_or_exponents(tmp_path, steady):
    """Ordinate label 'lbf' is converted; an empty label falls back to the unit exponents (force 1, length 1: N·m);
    exponents of another quantity are refused naming the dataset."""
    run = steady.runs[0]
    common = dict(binary=0, func_type=1, rsp_node=1, ref_node=0, ref_dir=0, abscissa_spacing=1, abscissa_min=0.0,
                  abscissa_inc=1 / FS, x=np.arange(run.n_samples) / FS, abscissa_spec_data_type=17,
                  ordinate_spec_data_type=13, orddenom_spec_data_type=0, z_axis_spec_data_type=0)
    sets = [pyuff.prepare_58(rsp_dir=1, data=run.signals["Fx"] / LBF, ordinate_axis_units_lab="lbf", **common),
            pyuff.prepare_58(rsp_dir=-6, data=-run.signals["Tz"], ordinate_len_unit_exp=1, ordinate_force_unit_exp=1,
                             **common)]
    path = tmp_path / "r.uff"
    pyuff.UFF(str(path)).write_sets(sets, mode="add")
    (tmp_path / "r.meta.json").write_text(json.dumps({"sample_rate_hz": FS}))
    back = read_data(path)
    np.testing.assert_allclose(back.signals["Fx"], run.signals["Fx"], rtol=1e-11)
    np.testing.assert_allclose(back.signals["Tz"], run.signals["Tz"], rtol=1e-11)  # direction -6: sign flipped
    path.unlink()
    sets[1] = pyuff.prepare_58(rsp_dir=6, data=run.signals["Tz"], ordinate_len_unit_exp=2, ordinate_force_unit_exp=0,
                               **common)
    pyuff.UFF(str(path)).write_sets(sets, mode="add")
    with pytest.raises(DataError, match=r"r\.uff: dataset 2 \(Tz\): unit 'unit exponents length 2, force 0' is not"):
        read_data(path)


@pytest.mark.parametrize("fmt", ["uff-binary", "tdms", "mat"])
def test_sweep_tach_pulse_in_lab_formats(tmp_path, sweep, fmt):
    """A once-per-rev pulse recorded in the lab file (UFF direction-0 dataset named 'tach', a TDMS channel, a .mat
    vector) gives the sweep's speed."""
    angle = np.concatenate([[0.0], np.cumsum(0.5 * (sweep.tach[1:] + sweep.tach[:-1]) / FS)])
    pulse = 5.0 * ((angle / (2 * np.pi)) % 1.0 < 0.5)
    n = len(pulse)
    path = tmp_path / f"s{WRITERS[fmt][0]}"
    if fmt == "uff-binary":
        sets = uff_sets({"Fx": sweep.signals["Fx"]}, FS, 0.0, True)
        sets.append(pyuff.prepare_58(binary=1, func_type=1, rsp_node=1, rsp_dir=0, ref_node=0, ref_dir=0, id1="tach",
                                     data=pulse, x=np.arange(n) / FS, abscissa_spacing=1, abscissa_min=0.0,
                                     abscissa_inc=1 / FS, abscissa_spec_data_type=17, ordinate_spec_data_type=0,
                                     orddenom_spec_data_type=0, z_axis_spec_data_type=0))
        pyuff.UFF(str(path)).write_sets(sets, mode="add")
    elif fmt == "tdms":
        wf = {"wf_increment": 1 / FS, "wf_start_offset": 0.0}
        with TdmsWriter(str(path)) as w:
            w.write_segment([RootObject(), GroupObject("sweep"),
                             ChannelObject("sweep", "Fx_N", sweep.signals["Fx"], properties=wf),
                             ChannelObject("sweep", "tach", pulse, properties=wf)])
    else:
        savemat(str(path), {"Fx_N": sweep.signals["Fx"][:, None], "tach": pulse[:, None], "sample_rate_hz": FS})
    path.with_suffix(".meta.json").write_text(json.dumps({"sample_rate_hz": FS, "tach": {"channel": "tach"}}))
    back = read_data(path)
    # a 4-s sweep at 55 rad/s² sampled at 3840 Hz: inside, the local fits see both sides (measured 3.8e-4);
    # within 0.25 s of the record's ends they are one-sided and extrapolate (measured 2.2e-3 there)
    inside = (sweep.time > 0.25) & (sweep.time < sweep.time[-1] - 0.25)
    assert np.max(np.abs(back.tach[inside] / sweep.tach[inside] - 1)) < 5e-4
    assert np.max(np.abs(back.tach / sweep.tach - 1)) < 5e-3


def test_mat_time_vector_and_sample_rate_must_agree(tmp_path, steady):
    """A .mat with both a microsecond-rounded time vector and a sample rate: consistent reads, 0.1 % off is refused."""
    run = steady.runs[0]
    t = np.round(np.arange(run.n_samples) / FS, 6)
    path = tmp_path / "s.mat"
    savemat(str(path), {"time_s": t[:, None], "Fx_N": run.signals["Fx"][:, None], "sample_rate_hz": FS})
    assert read_data(path).sample_rate == FS
    savemat(str(path), {"time_s": t[:, None], "Fx_N": run.signals["Fx"][:, None], "sample_rate_hz": FS * 1.001})
    with pytest.raises(DataError, match=r"s\.mat: variable time_s: sample rate from the time stamps .*disagrees with "
                                        r"variable sample_rate_hz"):
        read_data(path)


def test_a_nan_sample_is_named_as_a_reader_reads_it(tmp_path, steady):
    """A NaN in a MATLAB file: the message names the variable, the index and 'nan' (it showed 'np.float64(nan)')."""
    sig = _one_run(steady)
    sig = {c: v.copy() for c, v in sig.items()}
    sig["Fz"][17] = np.nan
    path = tmp_path / "r.mat"
    write_mat5(path, sig, FS)
    with pytest.raises(DataError, match=r"non-finite sample at index 17, value nan$"):
        read_data(path)


def _tdms_lab(tmp_path, steady, unit_string, map_unit):
    """One TDMS run (written by npTDMS) with its load channels named LC1..LC6, each stating ``unit_string`` (force
    channels; torques 'N·m'), mapped to Fx..Tz in meta.json with unit ``map_unit`` for LC1 (None: no 'unit')."""
    d = tmp_path / "lab"
    d.mkdir(parents=True)
    run = steady.runs[0]
    objects = [RootObject(), GroupObject("g")]
    for k, ch in enumerate(CHANNELS):
        objects.append(ChannelObject("g", f"LC{k + 1}", run.signals[ch], properties={
            "wf_increment": 1 / FS, "wf_start_offset": 0.0, "unit_string": unit_string if ch[0] == "F" else "N·m"}))
    with TdmsWriter(str(d / "s.tdms")) as w:
        w.write_segment(objects)
    (d / "runs.csv").write_text(f"file,speed_rpm\ns.tdms:g,{float(rad_s_to_rpm(run.speed))!r}\n")
    entries = {f"LC{k + 1}": {"channel": ch, "unit": unit_string if ch[0] == "F" else "N·m"}
               for k, ch in enumerate(CHANNELS)}
    if map_unit is None:
        del entries["LC1"]["unit"]
    else:
        entries["LC1"]["unit"] = map_unit
    (d / "meta.json").write_text(json.dumps({"channel_map": {"channels": entries}}))
    return d


def test_channel_map_unit_against_the_unit_the_file_states(tmp_path, steady):
    # a map unit that contradicts the file's own (lbf over a channel the file says is in N) scaled the channel 4.45x
    # without a word: refused naming both; the map may leave the unit out and take the file's; the same unit in
    # another spelling is no contradiction
    d = _tdms_lab(tmp_path, steady, "N", "lbf")
    with pytest.raises(DataError, match=r"meta\.json: channel_map\.channels\.LC1\.unit: 'lbf' \(x4\.44822 to SI\) "
                                        r"contradicts the unit the file states for channel 'LC1', 'N' \(x1\) at .*s\.tdms"):
        read_steady(d)
    for unit_string, map_unit, factor in (("lbf", None, LBF), ("N", "newton", 1.0)):
        d = _tdms_lab(tmp_path / unit_string, steady, unit_string, map_unit)
        got = read_steady(d).runs[0].signals["Fx"]
        np.testing.assert_allclose(got, steady.runs[0].signals["Fx"] * factor, rtol=1e-15)


def test_model_records_how_its_data_were_read(tmp_path, steady):
    # the model file says how the data were read: the channel map (names, units, signs, calibration) and the tach
    # channel of meta.json, which the data themselves no longer show once converted to SI; saved and loaded back
    from rwadist.api import fit
    from rwadist.model import load, save

    d = write_mapped(steady, tmp_path / "lab", calibration_matrix())
    meta = json.loads((d / "meta.json").read_text())
    model = fit(d).model
    assert model.provenance["reading"] == {"channel_map": meta["channel_map"]}
    back = load(save(model, tmp_path / "m.json"))
    assert back.provenance["reading"] == {"channel_map": meta["channel_map"]}
    assert "reading" not in fit(steady).model.provenance           # in memory, read from nothing: nothing said


def test_model_of_a_sliced_sweep_records_the_slicing(tmp_path, sweep):
    from rwadist.api import fit, read

    path = write_sweep(sweep, tmp_path / "sweep.csv")
    test = read(path, slice_samples=2048, speed_source="tach")
    slicing = fit(test).model.provenance["reading"]["slicing"]
    assert slicing["slice_samples"] == 2048 and slicing["speed_source"] == "tach"
    assert slicing["n_kept"] == len(test.runs)
