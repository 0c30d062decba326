"""The broadband CSD is Melody's closed form integrated over each frequency bin, on every evaluation path.

Reference, written here without the module's separation into patterns and scalars: the pointwise closed form
S(f) = Σ_i Σ_{Ω: f_i(Ω) = f} p(Ω)·v_i(Ω) v_i(Ω)^H / 2 · 2π/h_i with v_i from :meth:`WheelLines.amplitudes` (every
member through its transform, with its rotor-angle phase when locked), integrated over each bin by
scipy.integrate.quad_vec between the frequencies where S jumps (law edges, histogram edges, a folded sideband's
turning point)."""
import numpy as np
import pytest
from scipy import integrate

from rwadist import broadband as bb
from rwadist import extended as ext
from rwadist import mounting as mt
from rwadist.model import Harmonic, WheelModel
from rwadist.speed_laws import abs_power_mean
from rwadist.units import rpm_to_rad_s

W = float(rpm_to_rad_s(1.0))


def _model(effects=(), analytical=False, planar=False):
    m = WheelModel(name="t")
    m.empirical["radial_force"] = [Harmonic(1.0, 3.0e-7), Harmonic(2.0, 1.0e-6, sense="planar" if planar else "co")]
    m.empirical["radial_torque"] = [Harmonic(3.0, 4.0e-8, sense="counter")]
    m.empirical["axial_force"] = [Harmonic(2.7, 2.0e-6)]
    m.effects = list(effects)
    if analytical:
        m.analytical = ext.params_to_dict(ext.from_table_4_2())
    return m


def _closed_form(members, law, f):
    """(72,) reals of S(f) (6×6 complex, row-major) from the amplitudes at the roots of f_i(Ω) = f."""
    S = np.zeros((6, 6), complex)
    lines = members[0].lines
    for i in range(len(lines)):
        h, off = float(lines.h[i]), float(lines.offsets.get(i, 0.0))
        for phi in {f, -f}:
            u = 2 * np.pi * (phi - off) / h
            if u < 0:
                continue
            for s in (1.0, -1.0):
                w = s * u
                p = float(law.pdf(w))
                if p == 0.0:
                    continue
                v = np.zeros(6, complex)
                for m in members:
                    T = np.eye(6) if m.transform is None else m.transform.transform
                    a = m.lines.amplitudes([m.ratio * w], [i])[0, 0] @ T.T
                    if len(members) > 1 and m.phase_offset:
                        a = a * np.exp(1j * np.sign(m.ratio * w) * h * m.phase_offset)
                    v += a
                S += p * np.outer(v, np.conj(v)) / 2 * 2 * np.pi / h
    return S.view(float).ravel()


def _jumps(members, law):
    """Frequencies where S(f) jumps: every law breakpoint and zero speed through every line, and each line's
    frequency offset (a folded sideband's turning point)."""
    lines = members[0].lines
    bps = list(law.breakpoints()) + [0.0]
    out = []
    for i in range(len(lines)):
        h, off = float(lines.h[i]), float(lines.offsets.get(i, 0.0))
        out += [abs(h * abs(b) / (2 * np.pi) + off) for b in bps] + [abs(off)]
    return np.array(out)


def _check_bins(res, members, law, bins, rtol=1e-9):
    """Each bin within ``rtol`` of its largest entry (and 1e-13 of the largest PSD value, for empty bins)."""
    df = res.f[1] - res.f[0]
    jumps = _jumps(members, law)
    floor = 1e-13 * np.abs(res.csd).max()
    for k in bins:
        a, b = max(res.f[k] - df / 2, 0.0), res.f[k] + df / 2
        cuts = np.unique(np.concatenate([[a, b], jumps[(jumps > a) & (jumps < b)]]))
        ref = sum(integrate.quad_vec(lambda x: _closed_form(members, law, x), lo, hi, epsabs=0.1 * floor * (hi - lo),
                                     epsrel=1e-11)[0] for lo, hi in zip(cuts[:-1], cuts[1:])) / df
        got = res.csd[k].view(float).ravel()
        err = np.abs(got - ref).max()
        assert err <= rtol * np.abs(ref).max() + floor, (k, err / max(np.abs(ref).max(), 1e-300))


def _bins_to_check(res, members, law, n_random=5, seed=0):
    """Bins holding a jump of S (partial bins), bin 0, the peak and its neighbours, a few random bins with power."""
    df = res.f[1] - res.f[0]
    jumps = _jumps(members, law)
    edge = np.unique(np.floor(jumps[jumps < res.f[-1]] / df + 0.5).astype(int))
    live = np.nonzero(res.psd.sum(axis=1) > 0)[0]
    rng = np.random.default_rng(seed)
    peak = int(np.argmax(res.psd.max(axis=1)))
    return sorted(set(edge[:6]) | {0, peak - 1, peak, peak + 1} | set(rng.choice(live, n_random, replace=False)))


CASES = {
    # power laws on piecewise-constant laws: closed form
    "uniform, both spins": (lambda: bb.empirical_lines(_model()), bb.Uniform(-2000 * W, 3000 * W)),
    "histogram": (lambda: bb.empirical_lines(_model()),
                  bb.histogram_from_centres(np.linspace(400, 2800, 7) * W, [1, 3, 0.5, 2, 0, 1, 2])),
    "amplitude law": (lambda: bb.empirical_lines(_model([{"kind": "amplitude_law", "direction": "radial_force",
                                                          "h": 2.0, "exponent": 2.5, "amplitude_ref": 2.0,
                                                          "omega_ref_rad_s": 200.0}])),
                      bb.Uniform(300 * W, 3000 * W)),
    # Gauss-Legendre: a normal law, a resonance, a folded sideband, the extended model's modes
    "normal": (lambda: bb.empirical_lines(_model()), bb.TruncatedNormal(800 * W, 600 * W, -500 * W, 3000 * W)),
    "wheel-mode resonance": (lambda: bb.empirical_lines(_model([{"kind": "fixed_resonance", "f_Hz": 60.0,
                                                                 "zeta": 0.02, "peak_gain": 5.0,
                                                                 "role": "wheel_mode",
                                                                 "directions": ["radial_force"]}])),
                             bb.Uniform(300 * W, 3000 * W)),
    "sharp resonance, coarse bins": (lambda: bb.empirical_lines(_model([{"kind": "fixed_resonance", "f_Hz": 60.0,
                                                                         "zeta": 0.002, "peak_gain": 20.0,
                                                                         "role": "wheel_mode",
                                                                         "directions": ["radial_force"]}])),
                                     bb.Uniform(300 * W, 3000 * W)),
    "narrow normal law": (lambda: bb.empirical_lines(_model()), bb.TruncatedNormal(1500 * W, 10 * W, 1400 * W,
                                                                                     1600 * W)),
    "folded sideband": (lambda: bb.empirical_lines(_model([{"kind": "sidebands", "direction": "radial_force",
                                                            "h": 2.0, "f_mod_Hz": 9.0, "depth": 0.4}])),
                        bb.Uniform(-600 * W, 2400 * W)),
    "extended, planar": (lambda: bb.extended_lines_from_model(_model(analytical=True, planar=True)),
                         bb.Uniform(-3000 * W, 3000 * W)),
}


@pytest.mark.parametrize("name", list(CASES))
def test_each_bin_is_the_closed_form_integrated_over_it(name):
    make, law = CASES[name]
    lines = make()
    mount = mt.preset_mountings("pyramid-4")[1]
    res = bb.broadband_psd(lines, law, 200.0, 2001, mounting=mount)
    members = [bb.Member(lines, mount)]
    _check_bins(res, members, law, _bins_to_check(res, members, law))


def test_phase_locked_pair_is_the_closed_form_of_its_summed_amplitudes():
    """Two locked wheels (ratio −1, rotor-angle offset 0.7 rad): their amplitudes add before the outer product."""
    lines = bb.empirical_lines(_model())
    ms = mt.preset_mountings("pyramid-4")
    law = bb.Uniform(-1000 * W, 3000 * W)
    members = [bb.Member(lines, ms[0]), bb.Member(lines, ms[2], -1.0, 0.7)]
    res = bb.csd_groups([(members, law)], 200.0, 2001, frame="spacecraft")
    _check_bins(res, members, law, _bins_to_check(res, members, law))


def test_result_is_exactly_hermitian_positive_and_free_of_a_speed_grid():
    lines = bb.extended_lines_from_model(_model(analytical=True, planar=True))
    law = bb.TruncatedNormal(0.0, 1500 * W, -3000 * W, 3000 * W)
    a = bb.broadband_psd(lines, law, 200.0, 4001, 300, mounting=mt.preset_mountings("pyramid-4")[0])
    b = bb.broadband_psd(lines, law, 200.0, 4001, 30000, mounting=mt.preset_mountings("pyramid-4")[0])
    assert np.array_equal(a.csd, b.csd)
    assert np.array_equal(a.csd, np.conj(np.swapaxes(a.csd, 1, 2)))
    ev = np.linalg.eigvalsh(a.csd)
    assert ev.min() >= -1e-12 * ev.max()


@pytest.mark.parametrize("law", [bb.Uniform(-1000 * W, 3000 * W), bb.TruncatedNormal(500 * W, 900 * W, -800 * W,
                                                                                      2000 * W),
                                 bb.histogram_from_centres(np.array([-900, -100, 700, 1500]) * W, [1, 2, 0.5, 3])])
@pytest.mark.parametrize("p", [0.0, 1.0, 2.7])
def test_abs_power_mean_is_the_laws_moment(law, p):
    lo, hi = law.support
    edges = sorted(set([lo, hi, 0.0] + list(law.breakpoints())))
    edges = [e for e in edges if lo <= e <= hi]
    ref = sum(integrate.quad(lambda w: abs(w) ** p * float(law.pdf(w)), a, b, epsabs=0, epsrel=1e-13)[0]
              for a, b in zip(edges[:-1], edges[1:]))
    assert abs_power_mean(law, p) == pytest.approx(ref, rel=1e-11)


def test_truncated_normal_without_scipy_stats_is_scipys():
    from scipy import stats

    law = bb.TruncatedNormal(1500 * W, 400 * W, 300 * W, 3000 * W)
    d = stats.truncnorm((law.lo - law.mean) / law.std, (law.hi - law.mean) / law.std, loc=law.mean, scale=law.std)
    w = np.linspace(0, 3300 * W, 777)
    np.testing.assert_allclose(law.pdf(w), d.pdf(w), rtol=1e-13, atol=0)
    np.testing.assert_allclose(law.cdf(w), d.cdf(w), rtol=1e-13, atol=1e-16)
    far = bb.TruncatedNormal(0.0, 1.0, 6.0, 9.0)                     # a far tail: no cancellation in its mass
    df = stats.truncnorm(6.0, 9.0)
    np.testing.assert_allclose(far.pdf([6.0, 7.0]), df.pdf([6.0, 7.0]), rtol=1e-10)


def test_a_normal_law_narrower_than_rounding_is_its_mean_speed():
    """std from 1e-300 to 1e-5 rpm: the PSD's power is the lines' at the mean speed (to (std/mean)·q); at 1e-300 the
    density's nodes were all zero (no power, silently) and at 1e-12 its breakpoints fell within a few ulps."""
    lines = bb.extended_lines_from_model(_model(analytical=True, planar=True))
    for mean in (1500.0, -900.0):
        A = lines.amplitudes([mean * W])
        ref = np.sqrt((np.abs(A) ** 2 / 2).sum(axis=1))[0]
        for std in (1e-300, 1e-12, 1e-5):
            law = bb.TruncatedNormal(mean * W, std * W, -2400 * W, 2400 * W)
            rms = bb.broadband_psd(lines, law, 200.0, 2001).rms()
            np.testing.assert_allclose(rms, ref, rtol=1e-9, atol=1e-12 * ref.max())
