"""`rwadist psd`'s outputs written fast and unchanged: CSV text character for character printf's (np.savetxt's), the
envelope as np.interp gives it, the plotted curves reduced without losing a peak."""
import io
import subprocess
import sys

import numpy as np
import pytest

from rwadist import broadband as bb
from rwadist import mounting as mt
from rwadist.model import Harmonic, WheelModel
from rwadist.psd_files import _peaks_kept, write_cross_csv, write_envelope_csv, write_psd_csv
from rwadist.text_table import format_rows
from rwadist.units import rpm_to_rad_s

W = float(rpm_to_rad_s(1.0))


def _printf(values, digits):
    return [f"%.{digits}e" % v for v in np.asarray(values, float).ravel()]


def _formatted(values, digits):
    return format_rows(np.asarray(values, float).reshape(-1, 1), digits).decode().splitlines()


@pytest.mark.parametrize("digits", [0, 1, 5, 8, 10, 12, 14])
def test_numbers_are_printfs_characters(digits):
    rng = np.random.default_rng(digits)
    x = 10 ** rng.uniform(-323, 20, 60_000) * rng.choice([-1, 1], 60_000)      # every decade, subnormals, |x| > 1e14
    m = rng.integers(10**digits, 10 ** (digits + 1), 20_000).astype(float)
    ties = np.concatenate([(m + 0.5) * 10.0 ** (e - digits) for e in (-300, -12, -1, 0, 3)])   # nearest to a tie
    powers = 10.0 ** np.arange(-323, 20)
    special = [0.0, -0.0, np.inf, -np.inf, np.nan, 5e-324, -5e-324, 0.5, 2.5, 0.125, 1.5e-5, 9.9999999999949999,
               9.99999999995, 1.7976931348623157e308, 2.2250738585072014e-308]
    values = np.concatenate([x, ties, powers, np.nextafter(powers, 0), np.nextafter(powers, np.inf), special])
    got, ref = _formatted(values, digits), _printf(values, digits)
    bad = [(r, g) for r, g in zip(ref, got) if r != g]
    assert len(got) == len(ref) and not bad, bad[:5]


def test_a_product_nearer_a_tie_than_the_double_doubles_error_is_printfs():
    # 2.378016066134295e-28·10^42 = 237801606613429.49999999999999999954 exactly (Fraction): printf rounds down; the
    # double-double of a·10^42 (error ~2^-104·v, 1.4e-17 here) rounded it up to ...430 (found by a lattice search for
    # doubles whose a·10^k, k > 22, lies within 1e-16 of a half-integer at 15 digits)
    hard = 2.378016066134295e-28
    assert _formatted([hard, -hard, 1.0, hard * 10], 14) == _printf([hard, -hard, 1.0, hard * 10], 14)
    assert _formatted([hard], 14) == ["2.37801606613429e-28"]


@pytest.mark.parametrize("shape", [(0, 3), (3, 0), (0, 0), (1, 1)])
def test_empty_and_single_tables_are_savetxts(shape):
    x = np.full(shape, -0.5)
    buf = io.BytesIO()
    np.savetxt(buf, x, delimiter=",", fmt="%.3e")
    assert format_rows(x, 3) == buf.getvalue()


def test_digits_beyond_a_doubles_mantissa_are_refused():
    with pytest.raises(ValueError, match="digits"):
        format_rows(np.ones((1, 1)), 15)


def _res():
    m = WheelModel(name="t")
    m.empirical["radial_force"] = [Harmonic(1.0, 3e-7), Harmonic(2.3, 1e-6, sense="counter")]
    m.empirical["axial_torque"] = [Harmonic(4.1, 2e-8)]
    lines = bb.empirical_lines(m)
    return lines, bb.broadband_psd(lines, bb.Uniform(-2000 * W, 3000 * W), 250.0, 3001,
                                   mounting=mt.preset_mountings("pyramid-4")[0])


def test_psd_files_are_what_savetxt_wrote(tmp_path):
    lines, res = _res()

    def savetxt(data, header, fmt):
        buf = io.BytesIO()
        np.savetxt(buf, data, delimiter=",", header=header, comments="", fmt=fmt)
        return buf.getvalue()

    p = write_psd_csv(res, tmp_path / "p.csv")
    assert p.read_bytes() == savetxt(np.column_stack([res.f, res.psd]), p.read_text().splitlines()[0], "%.10e")
    c = write_cross_csv(res, tmp_path / "c.csv")
    cols = [res.f]
    for a, b in bb.PAIRS:
        if a != b:
            cols += [res.csd[:, a, b].real, res.csd[:, a, b].imag]
    assert c.read_bytes() == savetxt(np.column_stack(cols), c.read_text().splitlines()[0], "%.10e")
    env = bb.line_envelope([(lines, None)], (-2000 * W, 3000 * W), res.f)
    e = write_envelope_csv(env, tmp_path / "e.csv")
    assert e.read_bytes() == savetxt(np.column_stack([env.f, env.amplitude]), e.read_text().splitlines()[0], "%.8e")


def _envelope_by_np_interp(lines, T, f, lo, hi, n_speeds):
    """The envelope line by line, channel by channel, both signs of speed: np.interp of each on its own."""
    ref = np.zeros((f.size, 6))
    for w in (np.linspace(0.0, hi, n_speeds), np.linspace(0.0, lo, n_speeds)):
        A = np.abs(lines.amplitudes(w) @ T.transform.T)
        fw = lines.freqs(w)
        for i in range(len(lines)):
            sel = (f >= fw[0, i]) & (f <= fw[-1, i])
            for c in range(6):
                if sel.any() and fw[-1, i] > fw[0, i]:
                    ref[sel, c] = np.maximum(ref[sel, c], np.interp(f[sel], fw[:, i], A[:, i, c]))
    return ref


@pytest.mark.parametrize("lo_rpm, hi_rpm", [(-600, 2400), (-1500, 1500)])
def test_envelope_is_np_interp_of_each_channel(lo_rpm, hi_rpm):
    """The envelope's interpolation of all channels at once gives np.interp's numbers, bit for bit, on a sideband
    folded below 0 Hz too (its frequencies do not increase with the speed); over a range symmetric about 0 rpm, where
    the lines the negative speeds repeat are drawn once, too."""
    m = WheelModel(name="t")
    m.empirical["radial_force"] = [Harmonic(1.0, 3e-7), Harmonic(2.0, 1e-6), Harmonic(2.7, 4e-7, sense="counter")]
    m.effects = [{"kind": "sidebands", "direction": "radial_force", "h": 2.0, "f_mod_Hz": 9.0, "depth": 0.4}]
    lines = bb.empirical_lines(m)
    T = mt.preset_mountings("pyramid-4")[2]
    f = np.linspace(0.0, 150.0, 7001)
    env = bb.line_envelope([(lines, T)], (lo_rpm * W, hi_rpm * W), f, n_speeds=500)
    assert np.array_equal(env.amplitude, _envelope_by_np_interp(lines, T, f, lo_rpm * W, hi_rpm * W, 500))


def test_envelope_of_lines_unlike_at_negative_speeds():
    """The extended model's lines differ between +Ω and −Ω (gyroscopic whirl modes split): over a symmetric range
    the envelope still holds both signs' lines, np.interp's numbers bit for bit."""
    lines = bb.preset_lines("ithaco-e")
    T = mt.preset_mountings("pyramid-4")[1]
    w = np.linspace(0.0, 1500 * W, 300)
    assert not np.array_equal(np.abs(lines.amplitudes(w) @ T.transform.T), np.abs(lines.amplitudes(-w) @ T.transform.T))
    f = np.linspace(0.0, 200.0, 4001)
    env = bb.line_envelope([(lines, T)], (-1500 * W, 1500 * W), f, n_speeds=300)
    assert np.array_equal(env.amplitude, _envelope_by_np_interp(lines, T, f, -1500 * W, 1500 * W, 300))


def test_plotted_curves_keep_every_peak():
    rng = np.random.default_rng(3)
    f = np.linspace(0.0, 500.0, 100_001)
    y = rng.lognormal(size=f.size)
    y[rng.random(f.size) < 0.2] = np.nan                      # zeros on a log axis
    x, v = _peaks_kept(f, y, 250.0)
    assert 2000 <= x.size / 2 <= 4100 and np.all(np.diff(x) >= 0)
    assert np.nanmax(v) == np.nanmax(y) and np.nanmin(v) == np.nanmin(y)
    # every original point lies between its bucket's kept minimum and maximum
    lo, hi = v[0::2], v[1::2]
    k = np.searchsorted(x[0::2], f, side="right") - 1
    ok = np.isnan(y) | ((y >= lo[k]) & (y <= hi[k]))
    assert ok.all()
    short = np.linspace(0.0, 1.0, 3000)
    assert _peaks_kept(short, short, 1.0)[0] is short           # few points: drawn as they are


def test_psd_command_loads_no_signal_stack():
    """`rwadist psd`'s modules, the wheel-source rule and the presets load neither scipy.signal nor scipy.stats (0.8 s
    of a 2 s command): the wheel description's dataclasses live apart from the test stand that needs them."""
    code = ("import sys, rwadist.cli, rwadist.wheel_source, rwadist.presets, rwadist.mounting, rwadist.psd_files; "
            "print(sorted(m for m in ('scipy.signal', 'scipy.stats') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"
