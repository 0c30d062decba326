"""Whole-run discrete Fourier transforms at arbitrary frequencies (not on the FFT grid).

The extended fit reads each radial line's rotation sense from the x/y phase of the whole record
(:func:`rwadist.line_senses.line_senses`), and ``rwadist diagnose`` measures lines, sidebands and phasors
on the whole record of every run (:meth:`rwadist.diagnose.engine.Context.phasors`,
:func:`rwadist.effects.speed_sidebands_diagnose._run_line_power`).  Those sums are computed here: one run
(:func:`windowed_dft`) or a stack of equally long runs at once (:func:`windowed_dfts`: one batched matrix
product per chunk of runs instead of a dozen small array operations per run), and the transform of the
periodic Hann window in closed form (:func:`hann_transform`: the leakage of a line into its neighbours).
"""
from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from scipy import signal

#: elements (runs × frequencies × the larger of the block and blocks × channels) of one chunk of
#: :func:`windowed_dfts`: the temporaries stay a few tens of MB however many runs are stacked
CHUNK_ELEMENTS = 1 << 16


@functools.lru_cache(maxsize=16)
def run_window(name, n: int) -> tuple:
    """(w (n,), Σw, Σw²) of the window ``name`` (:func:`scipy.signal.get_window`, periodic) over a record of ``n``
    samples, computed once per (name, n): every run of a test has the same length, and the whole-run phasors ask
    for it on every search step.  ``w`` is read-only (it is shared)."""
    w = signal.get_window(name, n)
    w.flags.writeable = False
    return w, float(np.sum(w)), float(np.sum(w**2))


def unit_phasors(f_hz: np.ndarray, dt: float, count: int, running: bool = False) -> np.ndarray:
    """e^{−2πj f k·dt} (L, count) for k = 0 … count − 1 at ``f_hz`` (L,) Hz, ``dt`` s: as a product of two tables of
    about √count exponentials each, k = k_lo + m·k_hi (complex exponentials cost far more than the product of two
    unit phasors, which is the same number to rounding).

    ``running``: each of the two tables as the running product of its one step e^{−2πj f dt} (or e^{−2πj f m·dt}), two
    exponentials per frequency instead of ~2√count (a cumulative product ~√count deep: the same numbers to ~1e-14),
    and a power-of-two ``count`` split into powers of two (the product is then the table itself, no copy cut from
    it): 35-40 % less time for :func:`windowed_dfts`'s short tables.  Off for the virtual test stand's
    record-long carriers, whose numbers stay those of the exponentials."""
    f = np.asarray(f_hz, dtype=float)
    m = max(int(np.ceil(np.sqrt(count))), 1)
    if not running:
        lo = np.exp(-2j * np.pi * np.outer(f, np.arange(m) * dt))                                # (L, m)
        hi = np.exp(-2j * np.pi * np.outer(f, np.arange(-(-count // m)) * (m * dt)))          # (L, ⌈count/m⌉)
        return (hi[:, :, None] * lo[:, None, :]).reshape(f.size, -1)[:, :count]
    if count & (count - 1) == 0:
        m = 1 << (m - 1).bit_length()                  # 128 = 16·8, 64 = 8·8

    def powers(step: np.ndarray, k: int) -> np.ndarray:
        table = np.empty((f.size, k), dtype=complex)
        table[:, 0] = 1.0
        table[:, 1:] = step[:, None]
        return np.cumprod(table, axis=1)

    lo = powers(np.exp(-2j * np.pi * dt * f), m)                                    # (L, m)
    hi = powers(np.exp(-2j * np.pi * (m * dt) * f), -(-count // m))                 # (L, ⌈count/m⌉)
    out = (hi[:, :, None] * lo[:, None, :]).reshape(f.size, -1)
    return out if out.shape[1] == count else out[:, :count]


def windowed_records(records, w: np.ndarray) -> np.ndarray:
    """(R, n, K) array of ``records`` (R lists of K equally long 1-D signals, n samples each) times the window ``w``
    (n,): the input of :func:`windowed_dfts`, written in place (one array, not a stack of per-record copies)."""
    out = np.empty((len(records), w.size, len(records[0]) if records else 0))
    for i, chans in enumerate(records):
        for k, x in enumerate(chans):
            np.multiply(x, w, out=out[i, :, k])
    return out


@dataclass(frozen=True, eq=False)
class BlockedRecords:
    """R windowed records of ``n`` samples and ``channels`` channels in the layout :func:`windowed_dfts` multiplies by its
    tables of phasors: sample j·block + b of channel k at ``values[r, b, j·K + k]`` ((R, block, J·K), J = ⌈n/block⌉
    blocks, zero past n), made once (:func:`blocked_records`) for records transformed at several sets of frequencies.
    ``values`` is read-only (it may be shared)."""

    values: np.ndarray
    n: int
    channels: int
    block: int

    def __len__(self) -> int:
        return self.values.shape[0]

    @functools.cached_property
    def single(self) -> np.ndarray:
        """``values`` in single precision (the samples of :func:`windowed_dfts` with ``single``), read-only."""
        out = self.values.astype(np.float32)
        out.flags.writeable = False
        return out


def blocked_records(records, w: np.ndarray, block: int = 128) -> BlockedRecords:
    """:class:`BlockedRecords` of ``records`` (R lists of K equally long 1-D signals, n samples each) times the window
    ``w`` (n,): the numbers of :func:`windowed_records` (each sample times its window value), written straight into the
    blocked layout (one pass over the samples instead of a windowed stack and its transposition per transform)."""
    n = w.size
    k = len(records[0]) if records else 0
    n_blocks = -(-n // block)
    out = np.zeros((len(records), block, n_blocks * k))
    view = out.reshape(len(records), block, n_blocks, k)
    row = np.zeros(n_blocks * block)                      # a record's windowed samples, zero past n
    for i, chans in enumerate(records):
        for j, x in enumerate(chans):
            np.multiply(x, w, out=row[:n])
            view[i, :, :, j] = row.reshape(n_blocks, block).T
    out.flags.writeable = False
    return BlockedRecords(out, n, k, block)


def demeaned_windowed(signals, w: np.ndarray) -> np.ndarray:
    """(R, n) array of each of ``signals`` (R 1-D signals, n samples each) less its mean, times the window ``w``
    (n,): (x − x̄)·w, the records of a spectrum or a whole-run phasor."""
    out = np.empty((len(signals), w.size))
    for i, x in enumerate(signals):
        x = np.asarray(x, dtype=float)
        out[i] = (x - x.mean()) * w
    return out


def windowed_dfts(x: "np.ndarray | BlockedRecords", sample_rate: float, f_hz: np.ndarray, block: int = 128,
                  single: bool = False) -> np.ndarray:
    """Σ_n x[r, n, k]·e^{−2πj f[r, l] t_n} (t_n = n/sample_rate) of a stack of R equally long records ``x``
    (R, n, K) at frequencies ``f_hz`` (R, L) Hz, each record at its own frequencies; returns (R, L, K) complex.

    The samples are cut into blocks of ``block``: e^{−2πj f (t_b + t_j)} = e^{−2πj f t_b}·e^{−2πj f t_j}, so
    only L·(block + n/block) exponentials are needed per record instead of L·n (a product of two unit phasors:
    the same sum to rounding), and each of those two tables is itself such a product (:func:`unit_phasors`).
    With the samples of a block along the rows and (block, channel) along the columns the fine sums are one
    (2L, B) @ (B, J·K) product per record (real and imaginary parts stacked), batched over the records of a
    chunk (:data:`CHUNK_ELEMENTS`), and the coarse sums one (1, J) @ (J, K) product per frequency.

    ``single``: the fine sums in single precision (float32 phasors and samples: the product, most of the time, in
    half of it).  Each phasor then carries ~1e-7 of the record's strongest line (measured: 9e-8 of a Hann-windowed
    carrier's |X| at 8192 samples): for a scan that compares line powers with the noise, not for a fit's amplitude
    read to the last digit.

    ``x`` may be :class:`BlockedRecords` (:func:`blocked_records`, its ``block``): the same sums, its layout read as it is
    (no transposition, and in single precision no conversion, per call)."""
    if isinstance(x, BlockedRecords):
        n_rec, n, k, block = len(x), x.n, x.channels, x.block
        source = x.single if single else x.values

        def blocks(s: int, r: int) -> np.ndarray:                 # (r, B, J·K)
            return source[s:s + r]
    else:
        records = np.asarray(x, dtype=float)
        n_rec, n, k = records.shape

        def blocks(s: int, r: int) -> np.ndarray:
            xs = records[s:s + r]
            if n != n_blocks * block:
                pad = np.zeros((xs.shape[0], n_blocks * block, k))
                pad[:, :n] = xs
                xs = pad
            xt = xs.reshape(-1, n_blocks, block, k).transpose(0, 2, 1, 3).reshape(-1, block, n_blocks * k)
            return xt.astype(np.float32) if single else xt
    f_hz = np.asarray(f_hz, dtype=float).reshape(n_rec, -1)
    n_f = f_hz.shape[1]
    n_blocks = -(-n // block)
    out = np.empty((n_rec, n_f, k), dtype=complex)
    if n_rec == 0 or n_f == 0:
        return out
    step = max(1, CHUNK_ELEMENTS // (n_f * max(block, n_blocks * k)))
    for s in range(0, n_rec, step):
        xt = blocks(s, step)                                                                           # (r, B, J·K)
        r = xt.shape[0]
        f = f_hz[s:s + step].ravel()
        fine = unit_phasors(f, 1.0 / sample_rate, block, running=True).reshape(r, n_f, block)          # (r, L, B)
        coarse = unit_phasors(f, block / sample_rate, n_blocks, running=True).reshape(r, n_f, 1, n_blocks)
        if single:
            table = np.empty((r, 2 * n_f, block), dtype=np.float32)
            table[:, :n_f], table[:, n_f:] = fine.real, fine.imag
        else:
            table = np.concatenate([fine.real, fine.imag], axis=1)
        parts = table @ xt                                                                             # (r, 2L, J·K)
        # the complex fine sums written part by part (the numbers of parts[:, :L] + 1j·parts[:, L:], no temporaries)
        sums = np.empty((r, n_f, n_blocks * k), dtype=complex)
        sums.real, sums.imag = parts[:, :n_f], parts[:, n_f:]
        inner = sums.reshape(r, n_f, n_blocks, k)                                                      # (r, L, J, K)
        out[s:s + step] = (coarse @ inner)[:, :, 0, :]
    return out


def windowed_dft(x: np.ndarray, sample_rate: float, f_hz: np.ndarray, block: int = 128) -> np.ndarray:
    """Σ_n x[n]·e^{−2πj f t_n} (t_n = n/sample_rate) of the columns of ``x`` (n, K) at frequencies ``f_hz``
    (L,) Hz, any f (not on the FFT grid); returns (L, K) complex (:func:`windowed_dfts` of one record)."""
    x = np.asarray(x, dtype=float)
    return windowed_dfts(x[None], sample_rate, np.asarray(f_hz, dtype=float).reshape(1, -1), block)[0]


def hann_transform(n: int, sample_rate: float, f_hz: np.ndarray) -> np.ndarray:
    """W(f) = Σ_{m<n} w[m]·e^{−2πj f m/sample_rate} of the periodic Hann window w[m] = ½ − ½cos(2πm/n)
    (:func:`scipy.signal.get_window` ``"hann"``) at ``f_hz`` (any shape) Hz, in closed form: with θ = 2πf/f_s
    and the Dirichlet sum D(θ) = Σ_{m<n} e^{−jθm} = e^{−jθ(n−1)/2}·sin(nθ/2)/sin(θ/2) (= n at θ ≡ 0 mod 2π),
    W = ½D(θ) − ¼D(θ − 2π/n) − ¼D(θ + 2π/n).  W(0) = n/2 = Σw; complex (any shape of ``f_hz``).

    The three kernels share their phase and numerator: with φ = θ/2, sin(n(φ ∓ π/n)) = −sin(nφ) and
    e^{−j(φ ∓ π/n)(n−1)} = e^{−jφ(n−1)}·e^{±jπ(n−1)/n}, so W = e^{−jφ(n−1)}·sin(nφ)·(½/sin φ + ¼e^{jπ(n−1)/n}/sin(φ − π/n)
    + ¼e^{−jπ(n−1)/n}/sin(φ + π/n)), sin(φ ∓ π/n) = sin φ·cos(π/n) ∓ cos φ·sin(π/n): five functions of φ per point
    instead of twelve.  Near a vanishing denominator (θ ≡ 0 or ±2π/n, mod 2π: the window's own bin and its neighbours)
    the three kernels are summed as they are (:func:`_hann_transform_terms`, each kernel's limit at its own zero)."""
    theta = 2 * np.pi * np.asarray(f_hz, dtype=float) / sample_rate
    phi = 0.5 * theta
    s, c = np.sin(phi), np.cos(phi)
    sp, cp = np.sin(np.pi / n), np.cos(np.pi / n)
    below, above = s * cp - c * sp, s * cp + c * sp                      # sin(φ − π/n), sin(φ + π/n)
    # within 1e-6 of a kernel's singular point its denominator loses digits (1e-6 of them just 1e-9 bins beside it):
    # there the three kernels are summed as they are
    tol = 1e-6 * np.maximum(np.abs(phi) + np.pi / n, 1.0)
    singular = (np.abs(s) <= tol) | (np.abs(below) <= tol) | (np.abs(above) <= tol)
    turn = np.exp(1j * np.pi * (n - 1) / n)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.exp(-1j * phi * (n - 1)) * np.sin(n * phi) * (0.5 / s + 0.25 * turn / below + 0.25 * np.conj(turn) / above)
    if np.any(singular):
        out = np.where(singular, _hann_transform_terms(n, theta, singular), out)
    return out


def _hann_transform_terms(n: int, theta: np.ndarray, where: np.ndarray) -> np.ndarray:
    """:func:`hann_transform` at the angles θ of ``where`` (0 elsewhere) as the sum of its three Dirichlet kernels, each
    at θ ≡ 0 (mod 2π) by its limit n·cos(θ/2)^(n−1) (every term of its sum is 1 there)."""
    out = np.zeros(theta.shape, dtype=complex)
    th0 = theta[where]
    part = np.zeros(th0.shape, dtype=complex)
    for weight, shift in ((0.5, 0.0), (-0.25, -2 * np.pi / n), (-0.25, 2 * np.pi / n)):
        th = th0 + shift
        half = np.sin(0.5 * th)
        at_zero = np.abs(half) <= 1e-12 * np.maximum(np.abs(th), 1.0)
        ratio = np.where(at_zero, n * np.cos(0.5 * th) ** (n - 1), np.sin(0.5 * n * th) / np.where(at_zero, 1.0, half))
        part += weight * np.exp(-0.5j * th * (n - 1)) * ratio
    out[where] = part
    return out
