"""``rwadist fit`` writes each radial line's rotation sense as the x/y phase reads it.

Session 61's new-user trial (a 3-kg wheel, a counter-rotating line): the plain fit's model held no sense, so every
consumer (``model show``, the FMU, the PSD's x/y pattern) read the counter-rotating line co-rotating, while
``rwadist diagnose`` of the same data said counter.

Data: family wheels (tests/family_wheel.py, time-integrated physics), whose bearing lines have a known co-rotating share
of their power (the cage counter-rotating, BPFI 0.8 co, 2xBSF planar) and random phases per run."""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import family_wheel as fw  # noqa: E402
from cli_run import run  # noqa: E402


def _expected(co: float):
    """The sense a line of co-rotating share ``co`` is written with (rwadist.line_senses.SENSE_SHARE 0.75 either way),
    with a margin for the noise of its x/y phase: none for a planar line (the FMU would take 'planar' for a load along
    x, where the fit's C is each channel's amplitude: read co-rotating, it keeps both channels' power); '' where the
    share is too near a threshold to say."""
    return "co" if co >= 0.85 else "counter" if co <= 0.15 else None if 0.35 <= co <= 0.65 else ""


@pytest.mark.parametrize("index", [2, 5])
def test_plain_fit_model_holds_the_measured_senses(tmp_path, capsys, index):
    """The command a user types (``rwadist fit DATA -o model.json``, then ``rwadist model show``): every radial line of
    the wheel the fit finds carries the sense its generator's co-rotating share gives (the cage 'counter', a
    co-rotating ball pass 'co'; a planar line none); the imbalance none (co-rotating, the diagnosis' counter_rotation
    measures it); and the table shows them."""
    from rwadist import api

    wheel = fw.family()[index]
    data = fw.write_steady(fw.steady(wheel, seed=1 + 100 * index), tmp_path / "data")
    code, out, err = run(capsys, "fit", data, "-o", tmp_path / "model.json", "--no-report")
    assert code == 0, err
    model = api.load_model(tmp_path / "model.json")
    checked = 0
    for line in (ln for ln in wheel.lines if ln.direction in ("radial_force", "radial_torque")):
        got = [hm for hm in model.harmonics(line.direction) if abs(hm.h - line.h) < 2e-3 * line.h]
        if not got:
            continue
        if abs(line.h - 1.0) < 1e-3:
            assert got[0].sense is None, (line.name, got[0])
            continue
        want = _expected(line.co)
        if want != "":
            assert got[0].sense == want, (line.direction, line.name, line.h, line.co, got[0].sense)
            checked += 1
    assert checked >= 3, checked
    code, shown, err = run(capsys, "model", "show", tmp_path / "model.json")
    assert code == 0, err
    counter = [ln for ln in wheel.lines if ln.co <= 0.15 and ln.direction == "radial_force"]
    assert counter and any(f"{counter[0].h:7.3f} counter" in row for row in shown.splitlines()), shown


def test_a_pair_missing_a_channel_gives_no_sense_and_keeps_the_imbalance(tmp_path, capsys):
    """Fy left out of every run (the pair's x/y phase unreadable): ``rwadist fit`` warns that the senses cannot be read
    and writes none on any radial force line (main: every one 'counter', its co-rotating share read as 0 of no power),
    and ``rwadist fit --extended``
    keeps the static imbalance U_s within 5 % of the generator's (main: U_s 0, the 1x force put in a counter part)."""
    import csv

    from rwadist import api

    wheel = fw.family()[2]
    data = fw.write_steady(fw.steady(wheel, seed=201), tmp_path / "data")
    for path in sorted(data.glob("run_*.csv")):
        rows = list(csv.reader(path.open()))
        drop = rows[0].index("Fy_N")
        path.write_text("\n".join(",".join(r[:drop] + r[drop + 1:]) for r in rows) + "\n")
    code, _, err = run(capsys, "fit", data, "-o", tmp_path / "model.json", "--no-report")
    assert code == 0, err
    assert "Fy in no run: the radial force lines' rotation senses cannot be read" in err, err
    model = api.load_model(tmp_path / "model.json")
    assert model.harmonics("radial_force") and all(hm.sense is None for hm in model.harmonics("radial_force")), \
        model.harmonics("radial_force")
    code, _, err = run(capsys, "fit", data, "-o", tmp_path / "ext.json", "--extended", "--no-report")
    assert code == 0, err
    U_s = api.load_model(tmp_path / "ext.json").analytical["U_s_kg_m"]       # per unit mass: the C of U_s·Ω²
    imbalance = next(ln for ln in wheel.lines if ln.direction == "radial_force" and ln.name == "imbalance")
    assert U_s == pytest.approx(imbalance.C, rel=0.05), (U_s, imbalance.C)


def test_a_pair_never_read_together_is_said(tmp_path, capsys):
    """Fx left out of the even runs and Fy out of the odd ones (each channel in half the runs, never both at once: no
    x/y phase anywhere): ``rwadist fit`` says the radial force senses cannot be read, naming the pair, and writes none
    (before: no word, while every consumer took the counter-rotating lines co-rotating)."""
    import csv

    from rwadist import api

    wheel = fw.family()[2]
    data = fw.write_steady(fw.steady(wheel, seed=201), tmp_path / "data")
    for i, path in enumerate(sorted(data.glob("run_*.csv"))):
        rows = list(csv.reader(path.open()))
        drop = rows[0].index("Fy_N" if i % 2 else "Fx_N")
        path.write_text("\n".join(",".join(r[:drop] + r[drop + 1:]) for r in rows) + "\n")
    code, _, err = run(capsys, "fit", data, "-o", tmp_path / "model.json", "--no-report")
    assert code == 0, err
    assert "Fx and Fy in no run together: the radial force lines' rotation senses cannot be read" in err, err
    assert "radial torque" not in err, err
    model = api.load_model(tmp_path / "model.json")
    assert model.harmonics("radial_force") and all(hm.sense is None for hm in model.harmonics("radial_force"))
    assert any(hm.sense is not None for hm in model.harmonics("radial_torque")), model.harmonics("radial_torque")
