"""A channel's copy of another read on the records' noise floor, where the target's own lines are not: the copy
:func:`~rwadist.diagnose.channel_copy.find_channel_copies` misses on the lines when the target carries lines of its
own at the source's ratios (trial21: Tx += 0.03 × Fy on an 11-kg wheel; Tx's own radial-torque lines at h 0.42, 1,
3.3 as strong as 0.03 × Fy's, the ratios Tx/Fy scattering 0.01-0.5 from line to line, no cluster at κ).

A copy carries the source's every component, its noise too: between the lines, in bins where neither channel has a
line, the target's transform is κ × the source's plus the target's own noise, independent of the source's.  The
cross-spectrum of the pair over those bins, summed over Welch segments, stands out of its null scatter
(|Σ S_ts| / sqrt(Σ S_ss·S_tt / M), M segments) by a z of hundreds for a copy at 3 % (trial21: 172 in every run,
the other pairs 0.5-3), with one ratio κ = Σ S_ts / Σ S_ss in every run and every part of the band.  A physical
pair's broadband coherence (a structure's response to the wheel's random loads) has a transfer that changes with
the frequency through the modes: one κ across the band (:data:`BAND_PARTS` parts, each within
:data:`~rwadist.diagnose.channel_copy.CLUSTER_TOLERANCE` plus its noise's scatter) and across the runs is asked
for.  A load-cell offset's r × F of noisy forces (a lever-arm correction) reads the same way on a force-torque pair
(T_x = −r_z·F_y) but puts the mirror term of r's component into another torque too (T_y = r_z·F_x; T_x = r_y·F_z
with T_z = −r_y·F_x; T_y = −r_x·F_z with T_z = r_x·F_y): a copy whose mirror pair carries −κ alike, or cannot be
read, is left to the ``cross_coupling`` class (:func:`offset_mirror`).
"""
from __future__ import annotations

import numpy as np

from ..units import CHANNEL_DIRECTION, RADIAL_PAIRS

#: The two channels of a radial pair (Fx-Fy, Tx-Ty), either way round: read on the real part of their noise floors'
#: cross-spectrum.  A crosstalk inside the pair (Fy += 0.2·Fx: one bridge of the cell reading the other, a calibration
#: matrix without its off-diagonal term) is a real gain; the pair's own coherence is the rotating lines' skirts, in
#: quadrature (±90°: clean data read z 2-5 at −82°, which biased the band's lowest part of trial 30's Fy += 0.2·Fx
#: past the tolerance), and a whirl's broadband response is in quadrature too
RADIAL_PAIR_WAYS = {p for a, b in RADIAL_PAIRS for p in ((a, b), (b, a))}

#: A run's noise-bin cross-spectrum over its null scatter, at least (an independent pair: |z| ~ 1, Rayleigh).
MIN_Z = 8.0
#: Fraction of the runs that must hold the copy (z and κ).
MIN_RUN_FRACTION = 0.6
#: Parts of the noise bins (contiguous in frequency) whose κ must agree: a copy is flat in frequency.
BAND_PARTS = 4
#: A bin is a noise bin of a channel where its Welch power is under this factor of the channel's median.
NOISE_FACTOR = 3.0
#: Welch segment length (samples, at most; the record's eighth when shorter).
NPERSEG = 2048
#: A load-cell offset's mirror pair reads −κ within this fraction of |κ| (besides its noise's scatter):
#: :func:`offset_mirror`
MIRROR_TOLERANCE = 0.3


def _segments(run, chans):
    """(f (F,), Z (M, F, K)): the Hann-windowed FFTs of the run's half-overlapping segments of every channel."""
    x = np.stack([np.asarray(run.signals[c], dtype=float) for c in chans])            # (K, n)
    n = x.shape[1]
    L = int(min(NPERSEG, 2 ** int(np.log2(max(n // 8, 16)))))
    starts = np.arange(0, n - L + 1, L // 2)
    w = np.hanning(L + 1)[:-1]
    seg = np.stack([x[:, s:s + L] for s in starts])                                   # (M, K, L)
    seg = (seg - seg.mean(axis=-1, keepdims=True)) * w
    Z = np.fft.rfft(seg, axis=-1).transpose(0, 2, 1)                                  # (M, F, K)
    return np.arange(Z.shape[1]) * run.sample_rate / L, Z


def _channel_stats(Z) -> tuple:
    """(P, quiet) of one run's segments ``Z`` (M, F, K): each channel's mean segment power P[k] (F,) and its noise
    bins quiet[k] (F,) bool, power under :data:`NOISE_FACTOR` x its median above bin 4.  Made once per run and
    channel, not once per pair: each channel is in up to 2(K-1) pairs (the same expressions, so the same bits)."""
    P = [np.mean(np.abs(Z[:, :, k]) ** 2, axis=0) for k in range(Z.shape[2])]
    quiet = [p < NOISE_FACTOR * np.median(p[4:]) for p in P]
    return P, quiet


def _run_stats(Z, stats: tuple, s: int, t: int, real: bool = False):
    """(κ, z, parts κ, parts σ) of the pair (s, t) on one run's segments: over the bins where both are noise;
    ``stats``: the run's :func:`_channel_stats`.  The parts (read only of a run where z reaches :data:`MIN_Z`) are
    None below it.  Sums by ``np.add.reduce`` (what ``np.sum`` calls, without its Python layers: ~20 sums per pair
    and run).  ``real``: the cross-spectrum's real part alone (a radial pair, :func:`find_broadband_copies`), its
    null scatter half the complex one's."""
    P, quiet = stats
    noise = quiet[s] & quiet[t]
    noise[:4] = False
    idx = np.flatnonzero(noise)
    Pss = P[s][idx]
    total = np.add.reduce(Pss)
    if idx.size < 4 * BAND_PARTS or total <= 0:
        return None
    M = Z.shape[0]
    both = Pss * P[t][idx]
    null = np.add.reduce(both) / M
    if null <= 0:
        return None
    # the cross-spectrum of every bin, from the channels' strided columns: a product of contiguous copies of the
    # noise bins alone takes numpy's vector loop, whose complex products differ in the last bit
    Pst = np.mean(np.conj(Z[:, :, s]) * Z[:, :, t], axis=0)[idx]
    if real:
        Pst, null = Pst.real, null / 2
    cross = np.add.reduce(Pst)
    kappa = complex(cross / total)
    z = float(abs(cross) / np.sqrt(null))
    if z < MIN_Z:
        return kappa, z, None
    # BAND_PARTS contiguous parts of the noise bins
    parts = zip(*(np.array_split(x, BAND_PARTS) for x in (Pst, Pss, both)))
    return kappa, z, [(np.add.reduce(a), np.add.reduce(b), np.add.reduce(c) / M / (2 if real else 1))
                      for a, b, c in parts]


def find_broadband_copies(test, runs, chans, tolerance: float, skip=(), mirror=None) -> list:
    """[(source, target, κ, runs, z median)] of the channel pairs of ``chans`` (not one direction's but a radial
    pair's two channels, not in ``skip``) whose noise floors share one κ in :data:`MIN_RUN_FRACTION` of ``runs``
    (indices of ``test.runs``) and
    across the band (``tolerance``: the relative agreement asked for, besides the noise's own scatter).  ``mirror``:
    (source, target) -> the pair a load-cell offset's r × F would fill with −κ alongside (the same component of r,
    :func:`offset_mirror`); a pair's copy is dropped when its mirror reads −κ or cannot be read, and so is the pair
    read backwards (a torque in a force), judged with the force's own κ in the torque (an offset r_y read T_x -> F_z
    at 1/κ survived its forward pair's drop and was taken out of the records as a copy: review of 6f9006e)."""
    per_run = []
    for r in runs:
        _, Z = _segments(test.runs[r], chans)
        per_run.append((r, Z, _channel_stats(Z)))
    out = []
    K = len(chans)
    mirror = mirror or {}
    for s in range(K):
        for t in range(K):
            cs, ct = chans[s], chans[t]
            radial = (cs, ct) in RADIAL_PAIR_WAYS
            if s == t or (CHANNEL_DIRECTION[cs] == CHANNEL_DIRECTION[ct] and not radial) or (cs, ct) in skip:
                continue
            got = _pair(per_run, s, t, tolerance, real=radial)
            if got is None:
                continue
            pair = (cs, ct) if (cs, ct) in mirror else (ct, cs) if (ct, cs) in mirror else None
            if pair is not None:
                # a torque read in a force (T -> F) is that pair read backwards: judged by the force's own reading
                ms, mt = mirror[pair]
                kappa = got[0] if pair == (cs, ct) else mirror_reading(per_run, t, s, 0j)[0]
                if ms not in chans or mt not in chans or \
                        offset_mirror(per_run, chans.index(ms), chans.index(mt), kappa):
                    continue
            out.append((cs, ct) + got)
    return out


def _pair(per_run, s: int, t: int, tolerance: float, real: bool = False):
    """(κ, runs, z median) of the copy of channel s in t over ``per_run`` [(run, Z, its channel stats)], or None;
    ``real``: read on the cross-spectrum's real part (:func:`_run_stats`)."""
    stats = [(r, _run_stats(Z, cs, s, t, real)) for r, Z, cs in per_run]
    stats = [(r, x) for r, x in stats if x is not None]
    if not stats:
        return None
    strong = [(r, x) for r, x in stats if x[1] >= MIN_Z]
    if len(strong) < MIN_RUN_FRACTION * len(per_run):
        return None
    num = sum(sum(p[0] for p in x[2]) for _, x in strong)
    den = sum(sum(p[1] for p in x[2]) for _, x in strong)
    kappa = complex(num / den)
    # one ratio in every run (within the tolerance and the run's own scatter, |κ|/z)
    agree = [r for r, x in strong if abs(x[0] - kappa) <= tolerance * abs(kappa) + 3.0 * abs(x[0]) / x[1]]
    if len(agree) < MIN_RUN_FRACTION * len(per_run):
        return None
    # and in every part of the band: a copy is flat in frequency (a structure's transfer is not)
    for j in range(BAND_PARTS):
        st = sum(x[2][j][0] for _, x in strong)
        ss = sum(x[2][j][1] for _, x in strong)
        var = sum(x[2][j][2] for _, x in strong)
        if ss <= 0 or abs(st / ss - kappa) > tolerance * abs(kappa) + 3.0 * np.sqrt(var) / ss:
            return None
    return kappa, tuple(int(r) for r in agree), float(np.median([x[1] for _, x in strong]))


def mirror_reading(per_run, ms: int, mt: int, kappa: complex) -> tuple:
    """(κ_m, z_m, z_expected) of the mirror pair (channel ``ms`` in ``mt``) over every run of ``per_run``, pooled
    on the bins where both are noise: its ratio Σ S_ts / Σ S_ss, its null-scatter z, and the z that −``kappa`` × the
    source would give there (|κ|·Σ S_ss / sqrt(Σ S_ss·S_tt / M): whether the mirror can be read at all)."""
    cross, total, null = 0j, 0.0, 0.0
    for _, Z, (P, quiet) in per_run:
        noise = quiet[ms] & quiet[mt]
        noise[:4] = False
        idx = np.flatnonzero(noise)
        cross += complex(np.add.reduce(np.mean(np.conj(Z[:, :, ms]) * Z[:, :, mt], axis=0)[idx]))
        total += float(np.add.reduce(P[ms][idx]))
        null += float(np.add.reduce(P[ms][idx] * P[mt][idx])) / Z.shape[0]
    if total <= 0 or null <= 0:
        return 0j, 0.0, 0.0
    return cross / total, abs(cross) / np.sqrt(null), abs(kappa) * total / np.sqrt(null)


def offset_mirror(per_run, ms: int, mt: int, kappa: complex) -> bool:
    """Whether a copy κ of a force in a torque is a load-cell offset's r × F (a ``cross_coupling`` / a lever-arm
    correction's ``lever_arm_noise``): r's component puts its other term into another torque at −κ (T_x = −r_z·F_y
    with T_y = r_z·F_x; T_z = −r_y·F_x with T_x = r_y·F_z; T_z = r_x·F_y with T_y = −r_x·F_z), so the mirror pair
    (channel ``ms`` in ``mt``, pooled over ``per_run``, :func:`mirror_reading`) reads −κ within
    :data:`MIRROR_TOLERANCE` plus its noise's scatter; or it cannot be read (−κ × its source would not reach
    :data:`MIN_Z` over the mirror target's noise): then the two are not told apart and the pair is left to the
    offset's classes.  A cross-sensitive channel or a calibration matrix missing one force-to-moment term reads one
    force, the mirror pair stays at z ~ 1 (trial24, T_z += 0.02·F_x: the mirror F_z -> T_x would stand at z ~ 170,
    it reads z ~ 1)."""
    k_m, _, z_exp = mirror_reading(per_run, ms, mt, kappa)
    if z_exp < MIN_Z:
        return True
    return bool(abs(k_m + kappa) <= MIRROR_TOLERANCE * abs(kappa) + 3.0 * abs(kappa) / z_exp)
