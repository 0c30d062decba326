"""Wheel-speed laws for the broadband PSD (densities over the signed speed, rad/s), their speed cells,
the CLI's ways to give one (``--dist``), and the exact interval binning the laws and the PSD share.
Part of :mod:`rwadist.broadband`, which re-exports these names (method and units there)."""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .data import DataError
from .units import RAD_S_TO_RPM, rpm_to_rad_s

#: Relative tolerance on a pdf's integral before it counts as not normalised.
PDF_RTOL = 1e-3


def _check_range(name, lo, hi):
    for key, v in (("lo", lo), ("hi", hi)):
        if not isinstance(v, (int, float, np.floating, np.integer)) or not math.isfinite(v):
            raise DataError(name, key, f"must be a finite speed in rad/s, got {v!r}")
    if not lo < hi:
        raise DataError(name, "lo/hi", f"empty or inverted speed range: lo = {lo!r} rad/s >= hi = {hi!r} rad/s")


@dataclass(frozen=True)
class Uniform:
    """Wheel speed uniform on [lo, hi], rad/s (signed; may straddle zero)."""

    lo: float
    hi: float

    def __post_init__(self):
        _check_range("Uniform", self.lo, self.hi)

    @property
    def support(self):
        return float(self.lo), float(self.hi)

    def pdf(self, omega):
        w = np.asarray(omega, float)
        return np.where((w >= self.lo) & (w <= self.hi), 1.0 / (self.hi - self.lo), 0.0)

    def cdf(self, omega):
        return np.clip((np.asarray(omega, float) - self.lo) / (self.hi - self.lo), 0.0, 1.0)

    def sample(self, rng, n):
        return rng.uniform(self.lo, self.hi, n)

    def breakpoints(self):
        return [self.lo, self.hi]

    def pieces(self):
        """(edges (2,), densities (1,)): the density is constant between the edges (rad/s, 1/(rad/s))."""
        return np.array([self.lo, self.hi], float), np.array([1.0 / (self.hi - self.lo)])


@dataclass(frozen=True)
class TruncatedNormal:
    """Wheel speed normal (mean, std rad/s) truncated to [lo, hi] rad/s and renormalised."""

    mean: float
    std: float
    lo: float
    hi: float

    def __post_init__(self):
        _check_range("TruncatedNormal", self.lo, self.hi)
        if not (math.isfinite(self.mean)):
            raise DataError("TruncatedNormal", "mean", f"must be finite, got {self.mean!r}")
        if not (math.isfinite(self.std) and self.std > 0):
            raise DataError("TruncatedNormal", "std", f"must be > 0 rad/s, got {self.std!r}")

    @property
    def support(self):
        return float(self.lo), float(self.hi)

    @property
    def _dist(self):
        from scipy import stats  # 0.7 s to import: only where a sample is drawn

        a, b = (self.lo - self.mean) / self.std, (self.hi - self.mean) / self.std
        return stats.truncnorm(a, b, loc=self.mean, scale=self.std)

    def _mass(self) -> float:
        """Φ(b) − Φ(a) of the standardised ends, from the tail nearer to them (no cancellation in a far tail);
        Φ(x) = erfc(−x/√2)/2 (math's: scipy.special takes 0.5 s to import)."""
        a, b = (self.lo - self.mean) / self.std, (self.hi - self.mean) / self.std

        def phi(x):
            return 0.5 * math.erfc(-x / math.sqrt(2.0))

        return phi(b) - phi(a) if a < 0 else phi(-a) - phi(-b)

    def pdf(self, omega):
        """φ((Ω − mean)/std)/(std·mass) inside [lo, hi], 0 outside (scipy.stats.truncnorm's, without its import)."""
        w = np.asarray(omega, float)
        return np.where((w >= self.lo) & (w <= self.hi), self.pdf_inside(w), 0.0)

    def pdf_inside(self, omega):
        """The density at speeds known to lie in [lo, hi] (no test of the range: the PSD's quadrature nodes)."""
        z = np.array(omega, dtype=float)
        z -= self.mean
        z *= 1.0 / self.std
        with np.errstate(over="ignore"):               # far out (a very narrow law): exp(-inf) = 0
            z *= z
        z *= -0.5
        np.exp(z, out=z)
        z *= 1.0 / (math.sqrt(2.0 * math.pi) * self.std * self._mass())
        return z

    def cdf(self, omega):
        from scipy.special import ndtr

        a = (self.lo - self.mean) / self.std
        z = (np.clip(np.asarray(omega, float), self.lo, self.hi) - self.mean) / self.std
        below = ndtr(z) - ndtr(a) if a < 0 else ndtr(-a) - ndtr(-z)
        return np.clip(below / self._mass(), 0.0, 1.0)

    def sample(self, rng, n):
        return self._dist.rvs(size=n, random_state=rng)

    def breakpoints(self):
        return [self.lo, self.hi]

    def pieces(self):
        """None: a smooth density (its scale :attr:`std`), not piecewise constant."""
        return None


@dataclass(frozen=True)
class Histogram:
    """Piecewise-constant speed density: ``pdf[k]`` (1/(rad/s)) on [edges[k], edges[k+1]] rad/s.

    Σ pdf·width must be 1 (relative tolerance :data:`PDF_RTOL`); use :meth:`from_weights` for
    relative weights (counts, time fractions) that are normalised for you.
    """

    edges: tuple
    pdf_values: tuple
    source: str = "Histogram"

    def __post_init__(self):
        e = np.asarray(self.edges, float)
        p = np.asarray(self.pdf_values, float)
        if e.ndim != 1 or e.size < 2 or p.shape != (e.size - 1,):
            raise DataError(self.source, "edges/pdf", f"need n+1 edges for n pdf values, got {e.size} edges and "
                            f"{p.size} values")
        if not (np.all(np.isfinite(e)) and np.all(np.isfinite(p))):
            raise DataError(self.source, "edges/pdf", "contain NaN or inf")
        if np.any(np.diff(e) <= 0):
            i = int(np.argmax(np.diff(e) <= 0))
            raise DataError(self.source, "edges", f"empty or inverted speed range: edge {i} = {e[i]!r} >= edge "
                            f"{i + 1} = {e[i + 1]!r} rad/s")
        if np.any(p < 0):
            i = int(np.argmax(p < 0))
            raise DataError(self.source, "pdf", f"negative density {p[i]!r} in bin {i}")
        total = float(np.sum(p * np.diff(e)))
        if abs(total - 1.0) > PDF_RTOL:
            raise DataError(self.source, "pdf", f"integrates to {total:.6g}, not 1 (tolerance {PDF_RTOL:g})")
        object.__setattr__(self, "edges", tuple(float(x) for x in e))
        object.__setattr__(self, "pdf_values", tuple(float(x) for x in p))

    @classmethod
    def from_weights(cls, edges, weights, source="Histogram"):
        """Density from relative bin weights (any positive total), normalised."""
        e = np.asarray(edges, float)
        w = np.asarray(weights, float)
        if e.ndim != 1 or e.size < 2 or w.shape != (e.size - 1,):
            raise DataError(source, "edges/weights", f"need n+1 edges for n weights, got {e.size} and {w.size}")
        if np.any(~np.isfinite(w)) or np.any(w < 0):
            raise DataError(source, "weight", "weights must be finite and >= 0")
        total = float(w.sum())
        if not total > 0:
            raise DataError(source, "weight", f"weights sum to {total!r}; need a positive total")
        if np.any(np.diff(e) <= 0):
            raise DataError(source, "speed", "speeds must be strictly increasing (empty or inverted range)")
        return cls(tuple(e), tuple(w / total / np.diff(e)), source)

    @property
    def support(self):
        return self.edges[0], self.edges[-1]

    def pdf(self, omega):
        w = np.asarray(omega, float)
        e = np.asarray(self.edges)
        k = np.clip(np.searchsorted(e, w, side="right") - 1, 0, len(self.pdf_values) - 1)
        return np.where((w >= e[0]) & (w <= e[-1]), np.asarray(self.pdf_values)[k], 0.0)

    def _cum(self):
        e = np.asarray(self.edges)
        c = np.concatenate([[0.0], np.cumsum(np.asarray(self.pdf_values) * np.diff(e))])
        return e, c / c[-1]

    def cdf(self, omega):
        e, c = self._cum()
        return np.interp(np.asarray(omega, float), e, c)

    def sample(self, rng, n):
        e, c = self._cum()
        return np.interp(rng.uniform(0.0, 1.0, n), c, e)

    def breakpoints(self):
        return list(self.edges)

    def pieces(self):
        """(edges (n+1,), densities (n,)): the density is constant between edges (rad/s, 1/(rad/s))."""
        return np.asarray(self.edges, float), np.asarray(self.pdf_values, float)


def row_edges(speeds, source="histogram", bounds=None, ends: str = "centres") -> np.ndarray:
    """Bin edges (rad/s) of a speed table's rows (rad/s, strictly increasing), halfway between rows, every row
    checked (at least 2, increasing, inside ``bounds`` (lo, hi) rad/s: the speed range the user gave).  ``ends``:
    "centres" -- the rows are bin centres, the outer bins as wide as their neighbours but never across zero speed
    when no row is on the other side (a wheel that never reverses) nor beyond ``bounds``; "rows" -- the table spans
    its first to its last row (a density sampled at the rows: on an even grid, Σ value·width is the trapezoid rule).
    :class:`DataError` naming ``source``, ``speed_rpm`` and the row."""
    c = np.asarray(speeds, float)
    if c.ndim != 1 or c.size < 2:
        raise DataError(source, "speed_rpm", f"need at least 2 histogram rows, got {c.size}")
    if np.any(np.diff(c) <= 0):
        i = int(np.argmax(np.diff(c) <= 0))
        raise DataError(source, "speed_rpm", f"must be strictly increasing: row {i + 1} "
                        f"({c[i + 1] * RAD_S_TO_RPM:g} rpm) <= row {i} ({c[i] * RAD_S_TO_RPM:g} rpm)")
    mid = 0.5 * (c[1:] + c[:-1])
    if ends == "rows":
        lo, hi = c[0], c[-1]
    else:
        lo, hi = c[0] - (mid[0] - c[0]), c[-1] + (c[-1] - mid[-1])
        if c[0] >= 0.0:
            lo = max(lo, 0.0)
        if c[-1] <= 0.0:
            hi = min(hi, 0.0)
    if bounds is not None:
        b_lo, b_hi = (float(x) for x in bounds)
        tol = 1e-9 * max(abs(b_lo), abs(b_hi), 1.0)        # the same speed converted twice (rpm -> rad/s)
        out = (c < b_lo - tol) | (c > b_hi + tol)
        if np.any(out):
            i = int(np.argmax(out))
            raise DataError(source, "speed_rpm", f"row {i} ({c[i] * RAD_S_TO_RPM:g} rpm) is outside the speed range "
                            f"{b_lo * RAD_S_TO_RPM:g}:{b_hi * RAD_S_TO_RPM:g} rpm (`speed_rpm`): give the range the "
                            "file covers")
        lo, hi = max(lo, b_lo), min(hi, b_hi)
    return np.concatenate([[lo], mid, [hi]])


def histogram_from_centres(speeds, weights, source="histogram", bounds=None) -> Histogram:
    """Histogram from bin centres (rad/s, strictly increasing) and relative weights (:func:`row_edges`, "centres")."""
    return Histogram.from_weights(row_edges(speeds, source, bounds), weights, source)


def from_time_profile(t, omega, n_bins: int = 2000, source="time profile") -> Histogram:
    """Speed law of a mission profile: fraction of time spent at each speed.

    t : sample times, s (increasing).  omega : speed at each sample, rad/s (linear between samples).
    Each interval spends its duration uniformly over [Ω_k, Ω_k+1] (exact for the linear profile);
    a constant-speed interval is a point mass, deposited by linear splitting between the two
    neighbouring bins.  Returns a :class:`Histogram` of ``n_bins`` equal bins over the profile range.
    """
    t = np.asarray(t, float)
    w = np.asarray(omega, float)
    if t.ndim != 1 or t.shape != w.shape or t.size < 2:
        raise DataError(source, "time_s/speed_rpm", f"need two equal 1-D columns with >= 2 rows, got {t.shape}, "
                        f"{w.shape}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(w))):
        raise DataError(source, "time_s/speed_rpm", "contain NaN or inf")
    dt = np.diff(t)
    if np.any(dt <= 0):
        i = int(np.argmax(dt <= 0))
        # plain numbers (not np.float64(5.0)), rows counted from 1 as the CSV reader counts its data rows
        raise DataError(source, "time_s", f"must increase: data row {i + 2} ({float(t[i + 1]):g} s) <= data row "
                        f"{i + 1} ({float(t[i]):g} s)")
    lo, hi = float(w.min()), float(w.max())
    if not hi > lo:
        raise DataError(source, "speed_rpm", f"constant speed {lo * RAD_S_TO_RPM:g} rpm: empty speed range "
                        "(a single speed is a line, not a distribution)")
    step = (hi - lo) / n_bins
    a = (np.minimum(w[:-1], w[1:]) - lo) / step - 0.5      # bin-centre units: bin k centred at k
    b = (np.maximum(w[:-1], w[1:]) - lo) / step - 0.5
    # a hold is a point mass split between the two bins beside it: at the range's ends (the profile's top or bottom
    # speed) into the end bin alone, not half past the grid (session 62's trial: a 10-s hold at the top speed after a
    # 10-s ramp weighed as 5 s, the RMS 9.5 % low)
    hold = b - a <= 1e-6
    a = np.where(hold, np.clip(a, 0.0, n_bins - 1.0), a)
    b = np.where(hold, np.clip(b, 0.0, n_bins - 1.0), b)
    bins = _spread(a, b, dt[None, :] / dt.sum(), n_bins).real[0]
    bins = np.maximum(bins, 0.0)
    return Histogram.from_weights(lo + step * np.arange(n_bins + 1), bins, source)


def speed_cells(law, n_speeds: int):
    """Cell edges over the law's support, split at Ω = 0 when it straddles zero, and each cell's
    exact probability.  Returns (lo_edges, hi_edges, mid, P) rad/s, rad/s, rad/s, 1."""
    lo, hi = law.support
    n_speeds = int(n_speeds)
    if n_speeds < 1:
        raise DataError("speed grid", "n_speeds", f"must be >= 1, got {n_speeds}")
    if lo < 0.0 < hi:
        n_neg = max(1, int(round(n_speeds * (-lo) / (hi - lo))))
        n_pos = max(1, n_speeds - n_neg)
        edges = np.concatenate([np.linspace(lo, 0.0, n_neg + 1), np.linspace(0.0, hi, n_pos + 1)[1:]])
    else:
        edges = np.linspace(lo, hi, n_speeds + 1)
    P = np.diff(law.cdf(edges))
    return edges[:-1], edges[1:], 0.5 * (edges[:-1] + edges[1:]), np.maximum(P, 0.0)


def abs_power_mean(law, p: float) -> float:
    """E[|Ω|^p] over the law (rad/s)^p, exact: in closed form on each piece of a piecewise-constant density
    (:meth:`Uniform.pieces`, :meth:`Histogram.pieces`), else by adaptive quadrature (relative 1e-13) split at
    zero speed, where |Ω|^p has its kink."""
    pieces = law.pieces() if hasattr(law, "pieces") else None
    if pieces is not None:
        edges, rho = pieces
        total = 0.0
        for lo, hi, r in zip(edges[:-1], edges[1:], rho):
            for a, b in ((max(lo, 0.0), max(hi, 0.0)), (max(-hi, 0.0), max(-lo, 0.0))):   # Ω > 0, Ω < 0 as |Ω|
                if b > a:
                    total += r * (b ** (p + 1) - a ** (p + 1)) / (p + 1)
        return float(total)
    from scipy import integrate

    lo, hi = law.support
    pts = sorted({float(x) for x in law.breakpoints() if lo < x < hi} | ({0.0} if lo < 0.0 < hi else set()))
    edges = [lo, *pts, hi]
    return float(sum(integrate.quad(lambda w: abs(w) ** p * float(law.pdf(w)), a, b, epsabs=0.0, epsrel=1e-13,
                                    limit=200)[0] for a, b in zip(edges[:-1], edges[1:])))


def law_from_spec(dist: str, min_rpm: float, max_rpm: float, std_rpm: float | None = None,
                  source: str = "dist") -> object:
    """Speed law from CLI-style arguments: 'uniform' on [min, max] rpm; 'normal' centred in the
    range, std ``std_rpm`` (default range/6, i.e. ±3σ), truncated to the range; otherwise a CSV file
    (:func:`law_from_csv`: the file's speeds, within the range -- a row outside it is refused, the outer bins
    end at it)."""
    if dist == "uniform":
        return Uniform(float(rpm_to_rad_s(min_rpm)), float(rpm_to_rad_s(max_rpm)))
    if dist == "normal":
        lo, hi = float(rpm_to_rad_s(min_rpm)), float(rpm_to_rad_s(max_rpm))
        _check_range("speed_rpm", lo, hi)
        std = (hi - lo) / 6.0 if std_rpm is None else float(rpm_to_rad_s(std_rpm))
        return TruncatedNormal(0.5 * (lo + hi), std, lo, hi)
    return law_from_csv(dist, bounds=(float(rpm_to_rad_s(min_rpm)), float(rpm_to_rad_s(max_rpm))))


def law_from_csv(path, n_bins: int = 2000, bounds=None):
    """Speed law from a CSV: columns (speed_rpm, weight) = histogram of relative weights at bin
    centres; (speed_rpm, pdf_per_rpm) = a density that must integrate to 1 over rpm; (time_s,
    speed_rpm) = a mission time profile (:func:`from_time_profile`).  ``bounds``: (lo, hi) rad/s, the
    speed range given beside the file: a speed of the file outside it is refused, and a histogram's
    outer bins end at it (:func:`histogram_from_centres`)."""
    path = Path(path)
    if not path.exists():
        raise DataError(path, "file", "does not exist (expected uniform, normal or a CSV file)")
    expected = "speed_rpm,weight or speed_rpm,pdf_per_rpm or time_s,speed_rpm"
    try:
        with open(path, newline="") as fh:
            first = next(csv.reader(fh), None)
        header = [h.strip() for h in first or []]
        arr = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2) if any(header) else np.empty((0, 0))
    except UnicodeDecodeError:
        raise DataError(path, "encoding", "not a UTF-8 text CSV file") from None
    except ValueError as exc:
        raise DataError(path, "data", f"not numeric CSV ({exc})") from None
    if not any(header):
        raise DataError(path, "header", f"empty file: expected a header line ({expected}) and rows")
    if arr.size == 0:
        raise DataError(path, "rows", f"no data rows under the header {header}")
    if arr.shape[1] != len(header):
        raise DataError(path, "columns", f"{arr.shape[1]} values per row, the header {header} names {len(header)}")
    if not np.all(np.isfinite(arr)):
        row, c = np.argwhere(~np.isfinite(arr))[0]
        raise DataError(path, f"{header[c]} (data row {row + 1})", f"{float(arr[row, c])!r}: not a finite number")
    col = {h: arr[:, i] for i, h in enumerate(header)}
    if "time_s" in col and "speed_rpm" in col:
        w = rpm_to_rad_s(col["speed_rpm"])
        if bounds is not None and w.size and (w.min() < bounds[0] - 1e-9 or w.max() > bounds[1] + 1e-9):
            raise DataError(path, "speed_rpm", f"the profile spans {w.min() * RAD_S_TO_RPM:g}:"
                            f"{w.max() * RAD_S_TO_RPM:g} rpm, outside the speed range {bounds[0] * RAD_S_TO_RPM:g}:"
                            f"{bounds[1] * RAD_S_TO_RPM:g} rpm (`speed_rpm`): give the range the file covers")
        return from_time_profile(col["time_s"], w, n_bins, str(path))
    if "speed_rpm" in col and "weight" in col:
        return histogram_from_centres(rpm_to_rad_s(col["speed_rpm"]), col["weight"], str(path), bounds)
    if "speed_rpm" in col and "pdf_per_rpm" in col:
        s, p = col["speed_rpm"], col["pdf_per_rpm"]
        # a density sampled at the rows spans the first to the last row whatever range is given beside the file (the
        # rows must lie in it); each bin's probability is its value times its width
        edges = row_edges(rpm_to_rad_s(s), str(path), bounds, ends="rows")
        widths = np.diff(np.asarray(edges)) * RAD_S_TO_RPM
        hist = Histogram.from_weights(edges, np.maximum(p, 0) * widths, str(path))
        total = float(np.sum(p * widths))
        if abs(total - 1.0) > PDF_RTOL:
            raise DataError(path, "pdf_per_rpm", f"integrates to {total:.6g} over rpm, not 1 "
                            f"(tolerance {PDF_RTOL:g}); give relative weights in a 'weight' column instead")
        return hist
    raise DataError(path, "header", f"{header}: expected columns speed_rpm,weight or speed_rpm,pdf_per_rpm "
                    "or time_s,speed_rpm")


# =========================================================================== binning

def _spread(a, b, weights, n_bins):
    """Bin powers of uniform densities on [a, b] (positions in bin-centre units: bin k covers
    [k − ½, k + ½]) carrying total ``weights`` (n_pairs, n_items) complex; exact overlap integrals
    (ramp second differences, linear split) for a < b, linear split at a for point masses.
    Returns (n_pairs, n_bins)."""
    a = np.asarray(a, float).ravel()
    b = np.asarray(b, float).ravel()
    W = np.asarray(weights)
    W = W.reshape(W.shape[0], -1)
    width = b - a
    wide = width > 1e-6
    slot = n_bins + 1                                        # trash slot for positions past the grid
    idx_parts, coef_parts = [], []
    # ramp starts/ends: positions on the edge grid (edge j at j − ½); deposit ±W/width split linearly
    for pos, sgn in ((a[wide] + 0.5, 1.0), (b[wide] + 0.5, -1.0)):
        m = np.floor(pos)
        t = pos - m
        m = np.clip(m, 0, slot).astype(np.int64)
        m1 = np.minimum(m + 1, slot)
        dens = sgn / width[wide]
        idx_parts += [m, m1]
        coef_parts += [(1 - t) * dens, t * dens]
    ramp_items = np.concatenate([np.nonzero(wide)[0]] * 4)
    idx_r = np.concatenate(idx_parts) if idx_parts else np.zeros(0, np.int64)
    coef_r = np.concatenate(coef_parts) if coef_parts else np.zeros(0)
    # point masses
    pt = np.nonzero(~wide)[0]
    u = 0.5 * (a[pt] + b[pt])
    k = np.floor(u)
    t = u - k
    k = np.clip(k, 0, slot).astype(np.int64)
    k1 = np.minimum(k + 1, slot)
    idx_p = np.concatenate([k, k1])
    coef_p = np.concatenate([1 - t, t])
    pt_items = np.concatenate([pt, pt])
    out = np.zeros((W.shape[0], n_bins), dtype=complex if np.iscomplexobj(W) else float)
    for p in range(W.shape[0]):
        for part in ("real", "imag") if np.iscomplexobj(W) else ("real",):
            wp = getattr(W[p], part)
            d2 = np.bincount(idx_r, weights=coef_r * wp[ramp_items], minlength=slot + 1)
            binned = np.cumsum(d2[:n_bins])
            binned += np.bincount(idx_p, weights=coef_p * wp[pt_items], minlength=slot + 1)[:n_bins]
            if part == "real":
                out[p] += binned
            else:
                out[p] += 1j * binned
    return out


def law_text(law) -> str:
    """A speed law in words for plot titles and reports: its kind and range in rpm (a file's name for a histogram)."""
    if isinstance(law, Uniform):
        return f"uniform {law.lo * RAD_S_TO_RPM:.6g}..{law.hi * RAD_S_TO_RPM:.6g} rpm"
    if isinstance(law, TruncatedNormal):
        return (f"normal {law.mean * RAD_S_TO_RPM:.6g} ± {law.std * RAD_S_TO_RPM:.4g} rpm in "
                f"{law.lo * RAD_S_TO_RPM:.6g}..{law.hi * RAD_S_TO_RPM:.6g}")
    if isinstance(law, Histogram):
        lo, hi = law.support
        return f"{Path(str(law.source)).name} ({lo * RAD_S_TO_RPM:.6g}..{hi * RAD_S_TO_RPM:.6g} rpm)"
    return repr(law)
