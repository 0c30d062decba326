"""A proposed fixed resonance must stay at one frequency across the speeds (issue 33, "an open-world loop").

A resonance whose centre moves with the speed (a disc's umbrella mode stiffening with speed) lifts the lines of the
slower runs near one frequency and those of the faster runs near another; one fixed resonance fitted to it sits
between them, and the search added it as a ``fixed_resonance`` of role wheel_mode (family matrix, kind
``moving_resonance``: wheels 0, 4 and 7).  :func:`rwadist.effects.fixed_resonance_diagnose.speed_split` fits one
shape with a centre for each half of the runs; the resonance is refused when the two centres lie more than its
half-power half-width apart and the data want the split.

References: the generator's own laws (tests/family_effects.py, written without rwadist): the moving resonance
f_r² = f0² + (1.5 f_spin)² and its gain :func:`family_effects.peak_resonance`; family wheel 4 (tests/family_wheel.py)
at the family matrix's conditions.
"""
import sys
import tempfile
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_effects as fe  # noqa: E402
import family_wheel as fw  # noqa: E402

import rwadist.effects.fixed_resonance_diagnose as frd  # noqa: E402
from rwadist.effects.fixed_resonance_diagnose import FixedResonance  # noqa: E402

#: family wheel 4's axial lines (h) and speeds (300-3000 rpm, 24 runs), the matrix's moving resonance on it
HS = (1.0, 2.0, 3.0, 4.62, 9.24)
RPM = np.linspace(300.0, 3000.0, 24)
F0, ZETA, GAIN = 148.8, 0.03, 5.0


def _points(law, rng):
    """A fake (ctx, points of the runs asked) of the axial lines h·f_spin lifted by ``law(f Hz, spin Hz) -> H``
    (the generator's gain), with 0.05 of scatter on each log power gain."""
    omega = RPM / 60.0 * 2 * np.pi
    ctx = SimpleNamespace(runs=np.arange(RPM.size), omega=omega, channels=("Fx", "Fy", "Fz", "Tx", "Ty", "Tz"),
                          df=0.9375, k_lo=16, k_hi=1024)
    noise = rng.normal(0.0, 0.05, (RPM.size, len(HS)))

    def points(ctx_, state, chans, runs):
        spin = omega[runs] / (2 * np.pi)
        f = (np.asarray(HS)[None, :] * spin[:, None])
        y = np.log(np.abs(law(f, spin[:, None])) ** 2) + noise[runs]
        ok = (f > ctx.k_lo * ctx.df) & (f < ctx.k_hi * ctx.df)
        return f[ok], y[ok], np.ones(int(ok.sum())), np.full(int(ok.sum()), "axial_force")
    return ctx, points


def _moving(f, spin):
    m = fe.MovingResonance(f0_hz=F0, stiffening=1.5, zeta=ZETA, gain=GAIN)
    return fe.peak_resonance(f, m.f_r(2 * np.pi * spin), ZETA, GAIN)


def test_a_resonance_stiffening_with_speed_is_refused_and_a_fixed_one_kept(monkeypatch):
    rng = np.random.default_rng(4)
    law = fe.MovingResonance(f0_hz=F0, stiffening=1.5)
    spin = RPM / 60.0
    f_lo, f_hi = law.f_r(2 * np.pi * spin[0]), law.f_r(2 * np.pi * spin[-1])
    assert f_lo == pytest.approx(149.0, abs=0.1) and f_hi == pytest.approx(166.7, abs=0.1)    # 12 % over the speeds
    ctx, points = _points(_moving, rng)
    monkeypatch.setattr(frd, "_line_gain_points", points)
    # what the search proposed on the matrix's wheel 4: one fixed resonance between the ends
    proposed = FixedResonance(158.3, 0.026, 5.3, ("Fz",), "wheel_mode")
    split = frd.speed_split(ctx, None, proposed)
    # each half's centre lies on the generator's track within the half's own speeds (± the half-power half-width)
    half = RPM.size // 2
    track = law.f_r(2 * np.pi * spin[:half]), law.f_r(2 * np.pi * spin[half:])
    assert track[0].min() * (1 - ZETA) <= split["f_slow_Hz"] <= track[0].max() * (1 + ZETA), split
    assert track[1].min() * (1 - ZETA) <= split["f_fast_Hz"] <= track[1].max() * (1 + ZETA), split
    assert split["f_fast_Hz"] > split["f_slow_Hz"]                      # stiffening: the faster half's is higher
    assert split["moved"] > split["zeta"] and split["evidence"] > 0
    assert frd.moves_with_speed(ctx, None, proposed)

    # the same resonance held at one frequency (a housing mode at 158 Hz): the halves agree, it is kept
    ctx, points = _points(lambda f, s: fe.peak_resonance(f, 158.0 + 0 * s, ZETA, GAIN), np.random.default_rng(4))
    monkeypatch.setattr(frd, "_line_gain_points", points)
    split = frd.speed_split(ctx, None, proposed)
    assert split["f_slow_Hz"] == pytest.approx(158.0, rel=0.005) and split["f_fast_Hz"] == pytest.approx(158.0, rel=0.005)
    assert split["moved"] < 0.2 * split["zeta"]
    assert not frd.moves_with_speed(ctx, None, proposed)

    # halves of fewer than SPLIT_MIN_RUNS runs tell nothing: kept
    few = SimpleNamespace(**{**vars(ctx), "runs": np.arange(2 * frd.SPLIT_MIN_RUNS - 1)})
    assert frd.speed_split(few, None, proposed) is None and not frd.moves_with_speed(few, None, proposed)


def test_family_wheel_4_stiffening_disc_mode_is_described_not_added():
    """Family wheel 4 at the matrix's conditions (24 speeds 300-3000 rpm, 4096 samples at 3840 Hz, noise 1 %, seed
    401) with the matrix's moving resonance on the axial force (f0 148.8 Hz, 149.0 -> 166.7 Hz over the speeds): no
    ``fixed_resonance`` is added (before: a wheel mode at 158.5 Hz), and a ``moving_resonance`` on Fz is described,
    stiffening, its ends within 5 % of the generator's law; the wheel's modes within 2 %."""
    from rwadist import api
    from rwadist.data import read_steady

    wheel = replace(fw.family()[4], n_speeds=24, n_samples=4096)
    effect = fe.default_effect("moving_resonance", wheel)
    data = fw.steady(wheel, noise=0.01, seed=401, effects=[effect])
    with tempfile.TemporaryDirectory() as tmp:
        d = api.diagnose(read_steady(fw.write_steady(data, Path(tmp) / "data", wheel.name)))
    kinds = [e["kind"] for e in d.model.effects]
    assert "fixed_resonance" not in kinds and kinds == ["suspension_modes"], kinds
    (u,) = [x for x in d.unexplained if x.signature == "moving_resonance"]
    assert u.channels == ("Fz",)
    lo_rpm, hi_rpm = u.speed_rpm
    truth_lo, truth_hi = (effect.f_r(rpm * fw.RPM) for rpm in (lo_rpm, hi_rpm))
    assert u.parameters["f_at_lowest_speed_Hz"] == pytest.approx(truth_lo, rel=0.05)
    assert u.parameters["f_at_highest_speed_Hz"] == pytest.approx(truth_hi, rel=0.05)
    assert u.parameters["slope_Hz_per_Hz_of_spin"] > 0
    modes = d.model.effects[0]
    for name, f in wheel.modes_hz().items():
        assert modes[f"{name}_Hz"] == pytest.approx(f, rel=0.02)
