"""A resonance of ONE channel of a radial pair (a load-cell channel's bridge, amplifier or cabling, or a fixture mode
along one axis) is described as such, and no wheel mode is named for it (rwadist.diagnose.describe_split's
``channel_resonance``; rwadist.effects.fixed_resonance_diagnose.one_channel_of_pair).

The new-user trial (session 51, an independent generator): a resonance on Fy alone (200 Hz, ζ 0.03, peak gain 5) was
named a 'wheel mode' of peak gain 3.6 on Fx and Fy -- the pair's power sums average 25x on Fy with 1x on Fx,
sqrt(13) = 3.6 -- and its model predicted 3.6x on the untouched Fx; on Tx, once, nothing was said.

Here the family generator's wheels carry the resonance at the cell on one channel (its ``gain`` hook): the closed
form H = (1 − r² + 2jζgr)/(1 − r² + 2jζr) on that column only.  A resonance of the same shape on both channels of the
pair is a wheel's mode: named, as the family matrix's ``fixed_resonance`` class is."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist.diagnose.describe_split import fit_channel_resonance, fit_split  # noqa: E402
from rwadist.resonance import resonance  # noqa: E402


class ChannelResonance:
    """The family generator's hook: channels ``columns`` (indices of fw.CHANNELS) through one resonance at the cell."""

    def __init__(self, columns, f_r, zeta=0.03, gain=5.0):
        self.columns, self.f_r, self.zeta, self.g = tuple(columns), f_r, zeta, gain

    def gain(self, f_hz, omega):
        out = np.ones((np.size(f_hz), 6), dtype=complex)
        for j in self.columns:
            out[:, j] = resonance(np.asarray(f_hz, dtype=float), self.f_r, self.zeta, self.g)
        return out


def _diagnose(index, effect, seed=3):
    wheel = fw.family()[index]
    return api.diagnose(family_test.steady_test(fw.steady(wheel, seed=seed, noise=0.01, effects=[effect])))


def _channel_resonances(diag):
    return [u for u in diag.unexplained if u.signature == "line_property"
            and u.parameters.get("property") == "channel_resonance"]


def _wheel_modes(diag):
    return [e for e in diag.model.effects if e["kind"] == "fixed_resonance" and e.get("role") == "wheel_mode"]


@pytest.mark.parametrize("index, channel, factor", [(0, "Fy", 0.75), (3, "Tx", 1.3), (6, "Fx", 1.25)])
def test_a_resonance_of_one_channel_is_described_on_that_channel_and_named_no_wheel_mode(index, channel, factor):
    """Family wheels 0, 3 and 6, a resonance (ζ 0.03, peak gain 5) between their modes on one channel: no wheel mode;
    one channel_resonance on that channel, its frequency within 1 %, its gain within 15 % and its damping within 30 %
    (the lines sample the peak at their own frequencies only)."""
    wheel = fw.family()[index]
    f_r = factor * wheel.f_trans
    diag = _diagnose(index, ChannelResonance([fw.CHANNELS.index(channel)], f_r))
    assert _wheel_modes(diag) == []
    (u,) = _channel_resonances(diag)
    assert u.channels == (channel,)
    assert u.parameters["f_r_Hz"] == pytest.approx(f_r, rel=0.01)
    assert u.parameters["peak_gain"] == pytest.approx(5.0, rel=0.15)
    assert u.parameters["zeta"] == pytest.approx(0.03, rel=0.3)
    assert u.causes[0].startswith(f"a resonance of {channel} alone at")


def test_the_same_resonance_on_both_channels_of_the_pair_is_a_wheel_mode():
    """Family wheel 0 with that resonance on Fx and Fy alike: a wheel mode within 1 % (as the search named it before),
    and no channel_resonance."""
    wheel = fw.family()[0]
    f_r = 0.75 * wheel.f_trans
    diag = _diagnose(0, ChannelResonance([0, 1], f_r))
    (e,) = _wheel_modes(diag)
    assert e["f_Hz"] == pytest.approx(f_r, rel=0.01)
    assert _channel_resonances(diag) == []


def test_the_channel_resonance_fit_returns_the_closed_form_and_is_no_split():
    """fit_channel_resonance on its closed form (Fx's resonance at 240 Hz, ζ 0.03, gain 5: d = −20·log10|H|) returns
    it off its grids; a split translation's course (x at 200 Hz, y at 190 Hz) fits a split better than one channel's
    resonance, and a resonance's course a resonance better than a split."""
    f = np.linspace(100.0, 400.0, 150)
    d = -20 * np.log10(np.abs(resonance(f, 240.0, 0.03, 5.0)))
    fit = fit_channel_resonance(f, d)
    assert fit["sign"] == -1.0
    assert fit["f_r_Hz"] == pytest.approx(240.0, rel=1e-3)
    assert fit["zeta"] == pytest.approx(0.03, rel=0.02) and fit["peak_gain"] == pytest.approx(5.0, rel=0.02)
    assert fit["misfit_dB"] < fit_split(f, d)["misfit_dB"]

    def L(f0):
        r = f / f0
        return 10 * np.log10((1 + (0.04 * r) ** 2) / ((1 - r**2) ** 2 + (0.04 * r) ** 2))

    split = L(190.0) - L(200.0)
    assert fit_split(f, split)["misfit_dB"] < fit_channel_resonance(f, split)["misfit_dB"]


def test_a_channel_resonance_is_divided_out_before_a_gain_is_read(tmp_path):
    """The session-51 new-user generator's own wheel W4 (8 kg, I_zz/I_rr 1.85, 500-6000 rpm; benchmarks/
    newuser_generator_s51.py, written from the physics alone), Tx through a resonance at 380 Hz (ζ 0.03, gain 5):
    the h 5.37 line passes it from ~4300 rpm, and on f10986f a "Tx's gain changed by x 1.11" step was described
    beside the resonance.  A gain is one factor at every frequency: the resonance's course divided out of Tx's lines,
    no gain remains (rwadist.diagnose.describe_gain.channel_gain's ``resonances``)."""
    import subprocess

    root = Path(__file__).resolve().parents[1]
    out = tmp_path / "w4_tx"
    subprocess.run([sys.executable, str(root / "benchmarks" / "newuser_generator_s51.py"), "W4", "tx_res", str(out),
                    "--seed", "1"], check=True, capture_output=True)
    diag = api.diagnose(str(out))
    (u,) = _channel_resonances(diag)
    assert u.channels == ("Tx",) and u.parameters["f_r_Hz"] == pytest.approx(380.0, rel=0.01)
    gains = [v for v in diag.unexplained if v.parameters.get("property") == "channel_gain"]
    assert gains == [], [v.causes[0][:120] for v in gains]
    assert _wheel_modes(diag) == []
