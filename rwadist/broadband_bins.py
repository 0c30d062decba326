"""Melody's closed form integrated exactly over each frequency bin: the broadband CSD as one matrix product.
Part of :mod:`rwadist.broadband` (the model, conventions and units are described there).

Separation.  On a branch of constant spin sign a line source's amplitude vector (output frame) is a sum of
fixed channel patterns u_j with scalar speed functions, v(Ω) = Σ_j a_j(|Ω|)·u_j: Melody's line is C·Ω² times
its rotating or axial pattern (an amplitude law or a wheel-mode resonance changes a_j, not u_j); an extended
line is its whirl components' transmitted loads (ν > 0 and ν < 0 have their own x/y pattern); phase-locked
wheels add their members' components, each through its mounting.  The line's bin power is then::

    P_k = Σ_{j,j'} u_j u_j'^H · ∫_{Ω: f(Ω) ∈ bin k} p(Ω) a_j(|Ω|) conj(a_j'(|Ω|)) / 2 dΩ

so the CSD is a sum of fixed Hermitian 6×6 matrices H_c times real scalar densities x_c(f) ("columns"):
csd = X·H, one (n_f × K)·(K × 36) product that writes the output once.  A column is shared by every line with
the same pattern pair (one wheel, direction and rotation sense, spin sign); a pair j ≠ j' gives two columns
(real and imaginary part of its complex density, matrices M + M^H and i(M − M^H), M = u_j u_j'^H); a
broadband floor is a column of its own (matrix t t^T, t the transform's column of its channel).

Each column's bin values are exact bin integrals of the closed form, with no speed grid:

* a pattern pair whose scalar is a power law, a_j·conj(a_j') = κ·|Ω|^q (C·Ω², a diagnosed amplitude law),
  on a piecewise-constant density (uniform, histogram) and a line without frequency offset: in closed form,
  ρ·κ·[|Ω|^{q+1}/(q+1)] between the bin's edges mapped to speed, Ω = 2πf/h (a full bin is
  ρ·κ·β^{q+1}·((k+½)^{q+1} − (k−½)^{q+1})/(q+1), β = 2π·df/h);
* otherwise (a normal law, a resonance, the extended model's modes, a sideband's offset): 3-point
  Gauss–Legendre on each bin's speed interval, split at the law's breakpoints and around each resonance peak and
  normal law's mean, and subdivided below 1/32 of a resonance's local scale (its half-width or the distance to its
  peak) and 1/16 of the law's standard deviation (relative error < 1e-12 per bin; measured on a Lorentzian and a
  Gaussian).

Cost O(n_f × lines) with no dependence on any speed grid; memory: the output and the columns (K × n_f reals,
evaluated in batches of wheels whose columns fit in half the output's size).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from . import extended as ext
from .speed_laws import abs_power_mean

_GL_X, _GL_W = np.polynomial.legendre.leggauss(3)
#: Gauss–Legendre subintervals per resonance half-width (3 nodes: ~3e-13 relative on a Lorentzian)
LORENTZ_STEPS = 32
#: Gauss–Legendre subintervals per standard deviation of a normal speed law (~4e-13 relative)
GAUSS_STEPS = 16
#: most Gauss–Legendre parts of one sub-interval (next to a peak the breakpoints keep sub-intervals narrow)
MAX_STEPS = 256
#: quadrature parts evaluated at once (bounds the temporaries)
_CHUNK = 1 << 16
_BASE = {"radial_force": 0, "radial_torque": 3, "axial_force": 2, "axial_torque": 5}


@dataclass
class Component:
    """One term a(|Ω|)·vector of a source's amplitude on a branch.  key: identifies the vector (columns of equal
    keys are shared).  vector: (6,) complex, output frame.  scalar: |Ω| (rad/s, array) -> a, complex.  power:
    (κ, p) when a = κ·|Ω|^p exactly, else None.  peaks: the resonances of ``scalar`` as (|Ω| at the peak,
    half-power half-width), rad/s: where the quadrature must look closely."""

    key: tuple
    vector: np.ndarray
    scalar: Callable
    power: tuple | None
    peaks: tuple = ()


# ============================================================================ components of a source

def _resonance_peaks(f_r: float, zeta: float, h: float, off: float) -> list:
    """(|Ω|, half-width) rad/s where a line at |h·|Ω|/2π + off| Hz meets a resonance at f_r Hz of half-width ζ·f_r."""
    return [(2 * math.pi * (sgn * f_r - off) / h, 2 * math.pi * zeta * f_r / h) for sgn in (1.0, -1.0)
            if sgn * f_r - off > 0]


def _empirical(lines, i: int, sign: float) -> list:
    """Melody's source ``i`` at spin sign ``sign``: C·Ω²·(law factor) times its rotating/axial pattern
    (:meth:`rwadist.broadband.WheelLines.amplitudes`)."""
    d, C, mode = lines.spec[i]
    base = _BASE[d]
    vec = np.zeros(6, complex)
    if mode in ("axial", "x"):
        vec[base] = 1.0
    elif mode == "y":
        vec[base + 1] = 1.0
    else:
        vec[base] = 1.0
        vec[base + 1] = (-1j if mode == "co" else 1j) * sign
    res = [(f_r, zeta) for dirs, f_r, zeta, *_ in lines.resonances if d in dirs]
    idx = np.array([i])

    def scalar(u):
        w = sign * np.asarray(u, float)
        a = C * w**2
        return a * lines._law_factor(w, idx)[:, 0] if (lines.laws or lines.resonances) else a.astype(complex)

    if i in lines.laws:                     # the law replaces C·Ω² (and, as in WheelLines, the resonance gain)
        a_ref, w_ref, p = lines.laws[i]
        return [Component(("emp", d, mode, sign), vec, scalar, (a_ref / w_ref**p, float(p)))]
    off, h = float(lines.offsets.get(i, 0.0)), float(lines.h[i])
    peaks = tuple(pk for f_r, zeta in res for pk in _resonance_peaks(f_r, zeta, h, off))
    return [Component(("emp", d, mode, sign), vec, scalar, None if res else (C, 2.0), peaks)]


def _mode_peaks(params, direction: str, h: float, sigma: int) -> list:
    """The transmissibility's resonance along a line of harmonic ``h`` whose whirl component has sense ``sigma``:
    D = k − (m·h² − σ·g·h)·Ω² + i·c·σ·h·Ω nearly vanishes at Ω0² = k/A, A = m·h² − σ·g·h, over ±c·h/(2A) in Ω:
    [(Ω0, c·h/(2A))], none when A <= 0."""
    sub = ext._subsystem(params, direction)
    if sub is None:
        return []
    m, c, k, g = sub
    A = m * h * h - sigma * g * h
    return [(math.sqrt(k / A), c * h / (2 * A))] if A > 0 and math.isfinite(k / A) else []


def _extended(lines, i: int, sign: float, u_at: float) -> list:
    """The extended model's source ``i`` (a group of coherent lines) at spin sign ``sign``: each whirl
    component's transmitted load (:func:`rwadist.extended.steady_lines`) with the pattern of its whirl sense at
    speeds near ``u_at`` (a line with a frequency offset changes whirl sense at one speed)."""
    p = lines.params
    idx = np.array([i])
    out = []
    for n, ln in enumerate(lines.groups[i]):
        for sigma, coef in ln.components():
            pos = float(ln.nu(sigma, sign * u_at)) >= 0
            vec = np.zeros(6, complex)
            ext._add_to_channels(vec, ln.direction, p.height, np.array(1.0 + 0j), np.array(1.0 if pos else -1.0))

            def scalar(u, ln=ln, sigma=sigma, coef=coef, pos=pos):
                w = sign * np.asarray(u, float)
                nu = ln.nu(sigma, w)
                resp = ext.transmissibility(p, ln.direction, nu, w) * coef * ln.amplitude(w)
                if ln.resonances:
                    resp = resp * ln.gain(nu)
                resp = resp if pos else np.conj(resp)
                return resp * lines._law_factor(w, idx)[:, 0] if (lines.laws or lines.resonances) else resp

            off = float(lines.offsets.get(i, 0.0))
            peaks = _mode_peaks(p, ln.direction, ln.h, sigma)
            peaks += [pk for f, z, *_ in ln.resonances for pk in _resonance_peaks(f, z, ln.h, 0.0)]
            if i not in lines.laws:
                peaks += [pk for dirs, f_r, zeta, *_ in lines.resonances if ln.direction in dirs
                          for pk in _resonance_peaks(f_r, zeta, ln.h, off)]
            out.append(Component(("ext", n, ln.direction, sigma, pos, sign), vec, scalar, None, tuple(peaks)))
    return out


def _whirl_breaks(lines, i: int, sign: float) -> list:
    """Speeds |Ω| (rad/s) where a whirl component of extended source ``i`` changes sense (a line with a
    frequency offset: ν = σ(hΩ + 2π·f_offset) = 0)."""
    if lines.kind != "extended":
        return []
    return [-2 * math.pi * ln.f_offset / (ln.h * sign) for ln in lines.groups[i]
            if ln.f_offset and -2 * math.pi * ln.f_offset / (ln.h * sign) > 0]


def source_components(members, i: int, sign: float, u_at: float, transforms) -> list:
    """Components of source ``i`` of a group of ``members`` (:class:`rwadist.broadband.Member`) at group spin
    sign ``sign``, in the output frame: each member at its own sign (ratio·sign), through its transform, with
    its rotor-angle phase e^{i·sign·h·δ} when the group is phase-locked."""
    out = []
    locked = len(members) > 1
    for mi, (m, T) in enumerate(zip(members, transforms)):
        s = float(np.sign(m.ratio)) * sign
        lines = m.lines
        comps = _empirical(lines, i, s) if lines.kind == "empirical" else _extended(lines, i, s, u_at)
        phase = np.exp(1j * s * lines.h[i] * m.phase_offset) if locked and m.phase_offset else 1.0
        for c in comps:
            scalar = c.scalar if phase == 1.0 else (lambda u, f=c.scalar, ph=phase: f(u) * ph)
            power = c.power if (c.power is None or phase == 1.0) else (c.power[0] * phase, c.power[1])
            v = T @ c.vector
            out.append(Component((mi, v.tobytes()), v, scalar, power, c.peaks))   # one column per pattern
    return out


# ============================================================================ columns

class Columns:
    """Real scalar densities per bin (rows of ``data``, one per column) and their Hermitian 6×6 matrices.  Keys are
    registered first (:meth:`pair`, :meth:`floor` before :meth:`allocate` return None), then filled."""

    def __init__(self):
        self.keys: dict = {}
        self.matrices: list = []
        self.data: np.ndarray | None = None
        self.signed_diagonal = False        # a column whose matrix has a negative diagonal entry (cross pairs)

    def __len__(self):
        return len(self.matrices)

    def allocate(self, data: np.ndarray) -> None:
        """Rows of ``data`` (len(self), n), zeroed, hold the densities from now on."""
        data[:] = 0.0
        self.data = data

    def _row(self, key, matrix):
        c = self.keys.get(key)
        if c is None:
            if self.data is not None:
                raise AssertionError(f"column {key!r} was not registered before allocation")
            matrix = 0.5 * (matrix + matrix.conj().T)          # Hermitian to the last bit (FMA rounding aside)
            matrix[np.diag_indices(6)] = matrix.diagonal().real
            c = self.keys[key] = len(self.matrices)
            self.matrices.append(matrix)
            self.signed_diagonal |= bool(np.any(np.real(np.diag(matrix)) < 0))
        return None if self.data is None else self.data[c]

    def pair(self, cj: Component, ck: Component):
        """(real row, imaginary row or None, factor of the real part, of the imaginary part) of the pattern pair
        (j, k): its density d adds d·M + conj(d)·M^H, M = u_j u_k^H; j = k is one real row (matrix u u^H), two
        components with one pattern add 2·Re(d)·u u^H."""
        if cj.key == ck.key:
            row = self._row(("auto", cj.key), np.outer(cj.vector, np.conj(cj.vector)))
            return row, None, (1.0 if cj is ck else 2.0), 0.0
        flip = repr(cj.key) > repr(ck.key)
        a, b = (ck, cj) if flip else (cj, ck)
        M = np.outer(a.vector, np.conj(b.vector))
        re = self._row(("re", a.key, b.key), M + M.conj().T)
        im = self._row(("im", a.key, b.key), 1j * (M - M.conj().T))
        return re, im, 1.0, (-1.0 if flip else 1.0)

    def floor(self, key, t: np.ndarray):
        """Row of a broadband floor on the channel whose output-frame column is ``t`` (6,) real."""
        return self._row(("floor", key), np.outer(t, t).astype(complex))


# ============================================================================ bin integrals

def _full_bin_powers(q: float, n: int, cache: dict) -> np.ndarray:
    """((k+½)^{q+1} − (k−½)^{q+1})/(q+1) for k = 0..n−1 (k = 0 unused), without cancellation."""
    P = cache.get(q)
    if P is None:
        k = np.arange(n, dtype=float)
        if q == 4.0:
            P = k**4 + 0.5 * k**2 + 1.0 / 80.0
        else:
            t = k + 0.5
            with np.errstate(divide="ignore", invalid="ignore"):
                P = -(t ** (q + 1)) * np.expm1((q + 1) * np.log1p(-1.0 / t)) / (q + 1)
            P[0] = 0.0
        cache[q] = P
    return P


def _power_bins(ua, ub, rho, q: float, beta: float, n: int, cache: dict):
    """Σ_pieces ρ·∫_{bin ∩ piece} u^q du of pieces [ua, ub] (u = |Ω|, ascending, disjoint) with densities ``rho``
    on bins of width ``beta`` in u (bin k: [β(k−½), β(k+½))).  Returns (k0, values over bins k0..)."""
    top = beta * (n - 0.5)
    keep = (ub > ua) & (rho > 0) & (ua < top)
    ua, ub, rho = ua[keep], np.minimum(ub[keep], top), rho[keep]
    if ua.size == 0:
        return 0, np.zeros(0)
    qa = q + 1.0
    ka = np.floor(ua / beta + 0.5).astype(np.int64)
    kb = np.minimum(np.floor(ub / beta + 0.5).astype(np.int64), n - 1)
    k0 = int(ka[0])
    vals = np.zeros(int(kb[-1]) - k0 + 1)
    P = _full_bin_powers(q, n, cache)
    cnt = np.maximum(kb - ka - 1, 0)
    scale = rho * beta**qa
    if ua.size == 1:
        if cnt[0]:
            np.multiply(P[ka[0] + 1:kb[0]], scale[0], out=vals[1:1 + cnt[0]])
    elif cnt.sum():
        first = np.repeat(ka + 1 - k0 - (np.cumsum(cnt) - cnt), cnt) + np.arange(cnt.sum())
        vals[first] = np.repeat(scale, cnt) * P[first + k0]
    # partial bins: from each piece's start to the end of its first bin, from the start of its last bin to its end
    hi_first = np.minimum(ub, beta * (ka + 0.5))
    lo_last = beta * (kb - 0.5)
    two = kb > ka
    bins = np.concatenate([ka, kb[two]]) - k0
    part = np.concatenate([rho * (hi_first**qa - ua**qa), rho[two] * (ub[two]**qa - lo_last[two]**qa)]) / qa
    part = np.maximum(part, 0.0)                  # an end on a bin edge: a zero-width piece, not -1e-30
    np.add.at(vals, bins, part)
    return k0, vals


def _subintervals(ua: float, ub: float, h: float, off: float, df: float, n: int, breaks) -> tuple:
    """Sub-intervals of [ua, ub] (u = |Ω|) that each lie in one frequency bin and one piece of the law:
    (edges (m+1,), bin of each (m,), mask of the non-empty ones (m,)).  The line sits at f = |h·u/2π + off|."""
    top = (n - 0.5) * df
    ua = max(ua, 2 * math.pi * (-top - off) / h)
    ub = min(ub, 2 * math.pi * (top - off) / h)
    if not ub > ua:
        return np.zeros(1), np.zeros(0, np.int64), np.zeros(0, bool)
    pa, pb = h * ua / (2 * math.pi) + off, h * ub / (2 * math.pi) + off
    parts = [np.array([ua])]
    if pa < 0:                                       # folded part: bin edges at φ = −(j − ½)·df
        j = np.arange(max(1, math.floor(-min(pb, 0.0) / df + 0.5)), math.ceil(-pa / df + 0.5) + 1)
        parts.append(2 * math.pi * (-(j - 0.5) * df - off) / h)
    if pb > 0:                                       # bin edges at φ = (j − ½)·df inside (pa, pb)
        j = np.arange(max(1, math.floor(max(pa, 0.0) / df + 0.5) + 1), math.ceil(pb / df + 0.5))
        parts.append(2 * math.pi * ((j - 0.5) * df - off) / h)
    inner = sorted({b for b in breaks if ua < b < ub})
    edges = np.concatenate(parts + [np.array([ub])])
    if inner and pa >= 0:              # a few breaks into ascending edges: merged, not sorted (np.unique: ~1 ms a line)
        edges = np.insert(edges, np.searchsorted(edges, inner), inner)
    if pa < 0 or (inner and np.any(edges[1:] < edges[:-1])):   # a folded part descends; rounding may put one below ua
        edges = np.unique(np.concatenate([edges, inner]))
    edges = edges[(edges >= ua) & (edges <= ub)]
    mid = 0.5 * (edges[:-1] + edges[1:])
    k = np.floor(np.abs(h * mid / (2 * math.pi) + off) / df + 0.5).astype(np.int64)
    return edges, k, np.diff(edges) > 0


def _steps(a: np.ndarray, b: np.ndarray, peaks, law) -> np.ndarray:
    """Gauss–Legendre parts of each sub-interval [a, b] (u = |Ω|): 1/:data:`LORENTZ_STEPS` of the local scale of a
    resonance (its half-width, or the distance to its peak, the larger), 1/:data:`GAUSS_STEPS` of a normal law's std
    within 8 std of its mean (beyond, its density is below e^-32 of the peak); at most :data:`MAX_STEPS`."""
    n = np.ones(a.size)
    for u0, du in peaks:
        dist = np.maximum(np.maximum(a - u0, u0 - b), 0.0)
        n = np.maximum(n, np.ceil(LORENTZ_STEPS * (b - a) / np.maximum(du, dist)))
    if law is not None:
        mu, std, reach = law
        near = np.maximum(np.maximum(a - mu, mu - b), 0.0) < reach * std
        n = np.where(near, np.maximum(n, np.ceil(GAUSS_STEPS * (b - a) / std)), n)
    return np.minimum(n, MAX_STEPS).astype(np.int64)


def _feature_breaks(ua: float, ub: float, peaks, law) -> list:
    """Speeds that isolate each resonance peak (±1, 2, 4 ... 64 half-widths) and a normal law's mean (±1, 2, 4, 8
    std) inside (ua, ub), so that the sub-intervals next to them are no wider than their scale."""
    out = [u0 + sgn * k * du for u0, du in peaks for k in (0, 1, 2, 4, 8, 16, 32, 64) for sgn in (1.0, -1.0)]
    if law is not None and math.isfinite(law[2]):
        out += [law[0] + sgn * k * law[1] for k in (0, 1, 2, 4, 8) for sgn in (1.0, -1.0)]
    return [x for x in out if ua < x < ub]


def _gauss_bins(edges, k, keep, steps: np.ndarray, weight, terms, dtype=complex) -> tuple:
    """Per-bin Gauss–Legendre sums of ``weight(u)``·term(u) over sub-intervals (``steps[i]`` equal parts each).
    terms: list of callables u (3, m) -> values.  Returns (k0, [values over bins k0.. per term])."""
    a, b, kk, st = edges[:-1][keep], edges[1:][keep], k[keep], steps[keep]
    if kk.size == 0:
        return 0, [np.zeros(0, dtype) for _ in terms]
    k0, k1 = int(kk.min()), int(kk.max())
    sums = [np.zeros(k1 - k0 + 1, dtype) for _ in terms]
    ones = bool(np.all(st == 1))
    direct = ones and kk.size == k1 - k0 + 1 and bool(np.all(np.diff(kk) == 1))   # one sub-interval a bin
    ends = np.cumsum(st)
    c0 = 0
    while c0 < a.size:                                   # chunks of about _CHUNK parts
        c1 = max(c0 + 1, int(np.searchsorted(ends, ends[c0] - st[c0] + _CHUNK, side="right")))
        aa, bb, kc, sc = a[c0:c1], b[c0:c1], kk[c0:c1], st[c0:c1]
        if ones:
            half = (bb - aa) / 2
            centre = aa + half
        else:
            idx = np.repeat(np.arange(aa.size), sc)
            part = np.arange(idx.size) - np.repeat(np.cumsum(sc) - sc, sc)          # which part of its interval
            width = (bb - aa)[idx] / sc[idx]
            half = width / 2
            centre = aa[idx] + width * (part + 0.5)
            kc = kc[idx]
        # nodes along the first axis: numpy's loops then run along the m parts (an (m, 3) layout runs them 3 long)
        u = _GL_X[:, None] * half
        u += centre                                                                    # (3, m)
        w = weight(u)
        w *= _GL_W[:, None] * half
        for s, term in zip(sums, terms):
            tw = term(u) * w
            v = tw[0] + tw[1]
            v += tw[2]
            if direct:
                s[kc[0] - k0:kc[-1] - k0 + 1] += v
            else:
                s += np.bincount(kc - k0, weights=v.real, minlength=s.size)
                if np.iscomplexobj(v):
                    s += 1j * np.bincount(kc - k0, weights=v.imag, minlength=s.size)
        c0 = c1
    return k0, sums


def _power(u: np.ndarray, q: float) -> np.ndarray:
    """u**q, by products for small integer q (np.power is several times slower)."""
    if q == 4.0:
        u2 = u * u
        return u2 * u2
    if q == 2.0:
        return u * u
    return u**q


# ============================================================================ the CSD

def _law_pieces_u(law, sign: float):
    """The law on the branch of spin sign ``sign`` as |Ω| = u: (u_lo, u_hi, piecewise (edges_u, rho) or None,
    breakpoints in u, (centre u, std, reach in std) of a smooth density or None), or None when the law has no speeds
    of that sign.  A smooth density other than the normal law: resolved everywhere to 1/1000 of its support."""
    lo, hi = law.support
    if sign > 0 and hi > 0:
        ua, ub = max(lo, 0.0), hi
    elif sign < 0 and lo < 0:
        ua, ub = max(-hi, 0.0), -lo
    else:
        return None
    pieces = law.pieces() if hasattr(law, "pieces") else None
    if pieces is not None:
        e, rho = (np.asarray(x, float) for x in pieces)
        if sign < 0:
            e, rho = -e[::-1], rho[::-1]
        e = np.clip(e, ua, ub)
        return ua, ub, (e, rho), list(e[1:-1]), None
    bps = [sign * float(x) for x in (law.breakpoints() if hasattr(law, "breakpoints") else [])]
    if hasattr(law, "std") and hasattr(law, "mean"):
        return ua, ub, None, bps, (sign * float(law.mean), float(law.std), 8.0)
    return ua, ub, None, bps, (0.5 * (ua + ub), (ub - ua) / 1000.0, math.inf)


def _add_source(cols: Columns, members, transforms, i: int, law, sign: float, f: np.ndarray, cache: dict) -> None:
    """Register (before ``cols`` is allocated) or add (after) the bin powers of source ``i`` of a group on one
    spin-sign branch of ``law``."""
    branch = _law_pieces_u(law, sign)
    if branch is None:
        return
    ua, ub, pieces, bps, smooth = branch
    lines = members[0].lines
    h, off = float(lines.h[i]), float(lines.offsets.get(i, 0.0))
    if smooth is not None and math.isfinite(smooth[2]) and smooth[1] <= 1e-9 * max(abs(smooth[0]), 1.0):
        _add_point_mass(cols, members, transforms, i, sign, smooth[0], (h, off), f)     # narrower than rounding
        return
    cuts = sorted({ua, ub, *(b for m in members for b in _whirl_breaks(m.lines, i, float(np.sign(m.ratio)) * sign)
                            if ua < b < ub)})
    for sa, sb in zip(cuts[:-1], cuts[1:]):
        comps = source_components(members, i, sign, 0.5 * (sa + sb), transforms)
        pairs = [(cj, ck) for j, cj in enumerate(comps) for ck in comps[j:]]
        if cols.data is None:
            for cj, ck in pairs:
                cols.pair(cj, ck)
            continue
        if pieces is None:
            density = getattr(law, "pdf_inside", law.pdf)      # nodes lie inside the support

            def rho_fn(u):
                return density(sign * u)
        else:
            e, r = pieces

            def rho_fn(u):
                return r[np.clip(np.searchsorted(e, u, side="right") - 1, 0, r.size - 1)]
        if all(c.power is not None for c in comps):
            _add_power_pairs(cols, pairs, (sa, sb), pieces, bps, smooth, rho_fn, (h, off), f, cache)
        else:
            _add_general_pairs(cols, comps, pairs, (sa, sb), bps, smooth, rho_fn, (h, off), f)


def _add_point_mass(cols, members, transforms, i: int, sign: float, u_mean: float, line, f) -> None:
    """A normal law narrower than a billionth of its mean (its density no longer resolvable in double precision):
    the whole probability at the mean speed |Ω| = ``u_mean`` of this branch (zero speed counts as positive), its
    lines' power in the bin of their frequency there -- within (std/mean)·q of the exact bin integral."""
    if not (u_mean > 0 or (u_mean == 0 and sign > 0)):
        return
    (h, off), df, n = line, float(f[1] - f[0]), f.size
    k = int(math.floor(abs(h * u_mean / (2 * math.pi) + off) / df + 0.5))
    comps = source_components(members, i, sign, max(u_mean, 1e-300), transforms)
    for j, cj in enumerate(comps):
        for ck in comps[j:]:
            re, im, f_re, f_im = cols.pair(cj, ck)
            if re is None or k >= n:
                continue
            u = np.array([u_mean])
            d = 0.5 * complex(cj.scalar(u)[0] * np.conj(ck.scalar(u)[0])) / df
            re[k] += f_re * d.real
            if im is not None:
                im[k] += f_im * d.imag


def _add_power_pairs(cols, pairs, span, pieces, bps, smooth, rho_fn, line, f, cache) -> None:
    """Pairs whose scalar products are power laws κ·u^q: one bin shape per exponent q (closed form on a
    piecewise-constant law without frequency offset, Gauss–Legendre otherwise), times κ into the columns."""
    (sa, sb), (h, off), df, n = span, line, float(f[1] - f[0]), f.size
    by_q: dict = {}
    for cj, ck in pairs:
        with np.errstate(over="ignore", invalid="ignore"):     # a non-finite result is refused by the caller
            kappa = 0.5 * cj.power[0] * np.conj(ck.power[0])
        by_q.setdefault(cj.power[1] + ck.power[1], []).append((cj, ck, kappa))
    for q, items in by_q.items():
        if pieces is not None and off == 0.0:
            e, r = pieces
            k0, shape = _power_bins(np.clip(e[:-1], sa, sb), np.clip(e[1:], sa, sb), r, q, 2 * math.pi * df / h, n,
                                    cache)
        else:
            edges, k, keep = _subintervals(sa, sb, h, off, df, n, bps + _feature_breaks(sa, sb, (), smooth))
            steps = _steps(edges[:-1], edges[1:], (), smooth)
            k0, (shape,) = _gauss_bins(edges, k, keep, steps, rho_fn, [lambda u, q=q: _power(u, q)], float)
        if shape.size == 0:
            continue
        shape = shape / df
        sl = slice(k0, k0 + shape.size)
        for cj, ck, kappa in items:
            re, im, f_re, f_im = cols.pair(cj, ck)
            re[sl] += (f_re * kappa.real) * shape
            if im is not None and kappa.imag:
                im[sl] += (f_im * kappa.imag) * shape


def _add_general_pairs(cols, comps, pairs, span, bps, smooth, rho_fn, line, f) -> None:
    """Every pattern pair of the components by Gauss–Legendre on sub-intervals finer than their resonances and the
    law's scale (:func:`_steps`)."""
    (sa, sb), (h, off), df, n = span, line, float(f[1] - f[0]), f.size
    peaks = sorted({pk for c in comps for pk in c.peaks})
    edges, k, keep = _subintervals(sa, sb, h, off, df, n, bps + _feature_breaks(sa, sb, peaks, smooth))
    steps = _steps(edges[:-1], edges[1:], peaks, smooth)
    last: dict = {}

    def scalar(c, u):                    # each component once per batch of nodes
        if last.get(id(c), (None,))[0] is not u:
            last[id(c)] = (u, c.scalar(u.ravel()).reshape(u.shape))
        return last[id(c)][1]

    terms = [lambda u, cj=cj, ck=ck: 0.5 * scalar(cj, u) * np.conj(scalar(ck, u)) for cj, ck in pairs]
    k0, sums = _gauss_bins(edges, k, keep, steps, rho_fn, terms)
    for (cj, ck), s in zip(pairs, sums):
        if s.size == 0:
            continue
        s = s / df
        sl = slice(k0, k0 + s.size)
        re, im, f_re, f_im = cols.pair(cj, ck)
        re[sl] += f_re * s.real
        if im is not None:
            im[sl] += f_im * s.imag


def _add_floors(cols: Columns, members, transforms, law, f: np.ndarray) -> None:
    """Register or add the broadband floors: S(f)·E_Ω[(|ratio·Ω|/Ω_ref)^p] on their channel (incoherent with
    everything)."""
    for mi, (m, T) in enumerate(zip(members, transforms)):
        for c, f_k, psd_k, w_ref, p in m.lines.floors:
            row = cols.floor((mi, c), T[:, c])
            if row is not None:
                gain = abs(m.ratio) ** p * abs_power_mean(law, p) / w_ref**p
                row += gain * np.interp(f, f_k, psd_k, left=0.0, right=0.0)


def _group_pass(cols: Columns, group, f: np.ndarray, transform_of) -> None:
    members, law = group
    transforms = [transform_of(m.transform) for m in members]
    _add_floors(cols, members, transforms, law, f)
    cache: dict = {}
    for i in range(len(members[0].lines)):
        for sign in (1.0, -1.0):
            _add_source(cols, members, transforms, i, law, sign, f, cache)


#: columns evaluated before the product into the output: their densities take at most half the output's memory
COLUMN_BUDGET = 36
#: frequency bins per block of the product (its temporaries: a few MB)
_BLOCK = 1 << 13
def closed_form_csd(groups, f: np.ndarray, transform_of, progress: bool = False) -> np.ndarray:
    """(n, 6, 6) CSD of independent ``groups`` of coherent wheels on the uniform grid ``f`` (Hz, from 0)."""
    n = f.size
    out = np.empty((n, 6, 6), dtype=complex)
    planned = []
    for g in groups:
        cols = Columns()
        _group_pass(cols, g, f, transform_of)
        planned.append((g, cols))
    batches: list = [[]]
    for g, cols in planned:
        if batches[-1] and sum(len(c) for _, c in batches[-1]) + len(cols) > COLUMN_BUDGET:
            batches.append([])
        batches[-1].append((g, cols))
    bar = None
    if progress and len(groups) >= 4:
        from .progress import tqdm

        bar = tqdm(total=len(groups), desc="broadband PSD", unit="wheel", leave=False)
    for b, batch in enumerate(batches):
        X = np.empty((max(1, sum(len(c) for _, c in batch)), n))
        X[-1] = 0.0                                    # a batch without columns (no lines) still writes zeros
        row = 0
        for g, cols in batch:
            cols.allocate(X[row:row + len(cols)])
            row += len(cols)
            _group_pass(cols, g, f, transform_of)
            if bar is not None:
                bar.update()
        if X.shape[0] or b == 0:
            _add_product(out, X, [m for _, c in batch for m in c.matrices] or [np.zeros((6, 6))], b == 0)
        del X
    if bar is not None:
        bar.close()
    if any(c.signed_diagonal for _, c in planned):
        _clip_rounding(out)
    return out


def _add_product(out: np.ndarray, X: np.ndarray, matrices: list, first: bool) -> None:
    """out (n, 6, 6) = (``first``) or += Σ_c X[c]·H_c: one (n × K)·(K × 72) product of reals (a later batch's in
    blocks).  The H_c are Hermitian to the bit, so each lower-triangle entry is the same dot product as its
    upper-triangle conjugate: the CSD comes out exactly Hermitian with a real diagonal (tests check it)."""
    H = np.array([np.ascontiguousarray(m).view(np.float64).ravel() for m in matrices])      # (K, 72)
    flat = out.view(np.float64).reshape(out.shape[0], 72)
    if first:
        with np.errstate(over="ignore", invalid="ignore"):
            np.matmul(X.T, H, out=flat)
        return
    for s0 in range(0, out.shape[0], _BLOCK):
        flat[s0:s0 + _BLOCK] += X[:, s0:s0 + _BLOCK].T @ H


def _clip_rounding(csd: np.ndarray) -> None:
    """In place, bins whose auto-spectra rounding left below zero (pattern pairs' cancelling terms): those
    clipped to 0 and their cross terms scaled to Cauchy–Schwarz, sqrt(S_aa·S_bb)."""
    idx = np.arange(6)
    bad = np.nonzero(np.any(csd[:, idx, idx].real < 0, axis=1))[0]
    if bad.size == 0:
        return
    sub = csd[bad]
    auto = np.maximum(sub[:, idx, idx].real, 0.0)
    bound = np.sqrt(auto[:, :, None] * auto[:, None, :])
    mag = np.abs(sub)
    sub = sub * np.where(mag > bound, bound / np.where(mag > 0, mag, 1.0), 1.0)
    sub[:, idx, idx] = auto
    csd[bad] = sub
