"""Campbell table, plot and the `rwadist campbell` command (issue 3 item 5)."""
import csv
import math

import numpy as np
import pytest

from rwadist import extended as ex
from rwadist import model as model_io
from rwadist.campbell import campbell_crossings, campbell_table, plot_campbell, write_campbell_csv
from rwadist.cli import main
from rwadist.presets import preset

RPM = 2 * np.pi / 60
MODE_COLS = ["radial_translation_Hz", "rocking_forward_Hz", "rocking_backward_Hz", "axial_translation_Hz"]


def read_csv(path):
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    return rows[0], np.array(rows[1:], dtype=float)


def test_campbell_table_columns_and_values(tmp_path):
    p = preset("ithaco-e").extended
    speeds = np.arange(-3000.0, 3000.1, 250.0)
    tab = campbell_table(p, speeds)
    assert list(tab) == ["speed_rpm"] + MODE_COLS
    wf = ex.whirl_frequencies(p, speeds * RPM)
    for col in MODE_COLS:
        np.testing.assert_array_equal(tab[col], wf[col[:-3]])
    # independent: at rest the Table 4.2 numbers, the whirl pair from the quadratic I_rr ν² − I_zz Ω ν − k = 0
    i0 = int(np.argmin(np.abs(speeds)))
    assert tab["radial_translation_Hz"][i0] == pytest.approx(227.7, abs=0.05)
    assert tab["rocking_forward_Hz"][i0] == pytest.approx(54.9, abs=0.05) == tab["rocking_backward_Hz"][i0]
    for s, ff, fb in zip(speeds, tab["rocking_forward_Hz"], tab["rocking_backward_Hz"]):
        nu = np.sort(np.abs(np.roots([p.I_rr, -p.I_zz * abs(s) * RPM, -p.k_rock]))) / (2 * np.pi)
        assert (fb, ff) == pytest.approx(tuple(nu), rel=1e-12)
    path = write_campbell_csv(tab, tmp_path / "c.csv")
    head, arr = read_csv(path)
    assert head == ["speed_rpm"] + MODE_COLS
    np.testing.assert_array_equal(arr[:, 0], speeds)
    for k, col in enumerate(MODE_COLS):
        np.testing.assert_array_equal(arr[:, k + 1], tab[col])     # repr round trip: exact


def test_plot_campbell_marks_every_crossing():
    from matplotlib.figure import Figure

    wheel = preset("ithaco-e")
    lines = wheel.extended_lines()
    fig = plot_campbell(wheel.extended, np.arange(0, 3001, 100.0), lines)
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    markers = [ln for ln in ax.lines if ln.get_marker() == "o"]
    rows = campbell_crossings(wheel.extended, np.arange(0, 3001, 100.0), lines)
    assert len(markers) == len(rows) > 10
    # the crossing markers sit on the harmonic line: f = h·rpm/60
    for m in markers:
        x, y = m.get_xdata()[0], m.get_ydata()[0]
        assert any(abs(y - r["f_Hz"]) < 1e-9 and abs(x - r["speed_rpm"]) < 1e-9 for r in rows)


def _printed_crossings(out):
    rows = []
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 7 and parts[6] in ("yes", "no"):
            rows.append((float(parts[0]), parts[1], parts[2], parts[3], float(parts[4]), parts[6] == "yes"))
    return rows


def test_cli_campbell_preset_and_model_file(tmp_path, capsys):
    wheel = preset("ithaco-e")
    out = tmp_path / "pre" / "campbell.csv"
    assert main(["campbell", "--preset", "ithaco-e", "--speeds-rpm", "0:3000:100", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    head, arr = read_csv(out)
    assert head == ["speed_rpm"] + MODE_COLS
    np.testing.assert_array_equal(arr[:, 0], np.arange(0, 3001, 100.0))
    wf = ex.whirl_frequencies(wheel.extended, arr[:, 0] * RPM)
    for k, col in enumerate(MODE_COLS):
        np.testing.assert_allclose(arr[:, k + 1], wf[col[:-3]], rtol=1e-15)
    png = out.with_suffix(".png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # printed crossings = extended.crossings of the wheel's lines over 0-3000 rpm
    expected = ex.crossings(wheel.extended, wheel.extended_lines(), (0.0, 3000 * RPM))
    got = _printed_crossings(printed)
    assert len(got) == len(expected) > 20
    key = lambda r: (r[3], r[1], r[0])                                      # noqa: E731
    exp_rows = sorted(((r["h"], r["direction"], r["sense"], r["mode"], r["speed_rpm"], r["excited"])
                       for r in expected), key=key)
    for g, e in zip(sorted(got, key=key), exp_rows):
        assert g[:4] == e[:4] and g[5] == e[5]
        assert g[4] == pytest.approx(e[4], abs=0.006)
    # the thesis's E-wheel example: h = 2 (counter) meets the backward whirl at f0/√(h(h+2)) -> 1165 rpm
    h2 = [g for g in got if g[0] == 2.0 and g[1] == "radial_torque" and g[3] == "rocking_backward"][0]
    f0 = wheel.extended.omega_rock / (2 * np.pi)
    assert h2[4] == pytest.approx(60 * f0 / math.sqrt(8), abs=0.006) and h2[5] and h2[2] == "counter"

    # a model file with the analytical section gives the same table
    mpath = model_io.save(wheel.to_model(), tmp_path / "m.json")
    out2 = tmp_path / "file" / "c.csv"
    assert main(["campbell", str(mpath), "--speeds-rpm", "0:3000:100", "-o", str(out2)]) == 0
    assert _printed_crossings(capsys.readouterr().out) == got
    np.testing.assert_array_equal(read_csv(out2)[1], arr)


def test_cli_campbell_bad_input(tmp_path, capsys):
    m = preset("ithaco-e").to_model()
    m.analytical = None
    path = model_io.save(m, tmp_path / "empirical_only.json")
    assert main(["campbell", str(path), "-o", str(tmp_path / "c.csv")]) == 2
    err = capsys.readouterr().err
    assert "analytical" in err and "empirical_only.json" in err
    assert not (tmp_path / "c.csv").exists()
    # a field missing inside the section is named
    m.analytical = {k: v for k, v in ex.params_to_dict(preset("ithaco-e").extended).items() if k != "k_r_N_per_m"}
    model_io.save(m, path)
    assert main(["campbell", str(path), "-o", str(tmp_path / "c.csv")]) == 2
    assert "analytical.k_r_N_per_m" in capsys.readouterr().err
    # model file and preset are mutually exclusive, and one is required
    with pytest.raises(SystemExit) as exc:
        main(["campbell", str(path), "--preset", "ithaco-e"])
    assert exc.value.code == 2
    with pytest.raises(SystemExit):
        main(["campbell"])
    assert main(["campbell", "--preset", "no-such-wheel", "-o", str(tmp_path / "c.csv")]) == 2
