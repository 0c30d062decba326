"""Tables written as CSV text: numeric arrays fast, printf's ``%.{d}e`` for whole arrays at once (:func:`write_csv`);
the report and result tables row by row, each cell as every table writes it (:func:`cell`, :func:`write_rows`).

``np.savetxt`` formats number after number in Python (~0.3 µs each: 2.5 s for the 76 MB of a spacecraft CSD's
tables).  Here the digits come from numpy arithmetic on the whole array, the same characters printf writes:

* x = m·10^e with m rounded to d + 1 significant digits: v = |x|·10^(d−e) as a double-double (Dekker's exact
  product of |x| and 10^k, k = d − e, whose double-double value is exact for k <= 22 and within ~2^-104·v above);
  m = v rounded to nearest, ties to even (the exact decimal value's tie, as glibc's printf under the default
  rounding mode; for k <= 22 the product is exact, for k > 22 no tie can occur at these magnitudes, but v can lie
  closer to one than the double-double's error: 2.378016066134295e-28 at 14 digits is ...429.4999999999999999998
  units of the last digit; such a number is left to Python);
* e from log10, corrected by one where v fell outside [10^d, 10^(d+1)) or rounded up to 10^(d+1);
* each number in a fixed-width slot of bytes, the absent minus sign and third exponent digit squeezed out.

Numbers the double-double does not serve (|x| >= 10^d, inf, nan, a product too near a tie) are formatted by Python
itself.
Checked character for character against ``"%.{d}e" % x`` (tests/test_psd_output.py).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

_SPLIT = 134217729.0                        # 2^27 + 1: Veltkamp's split of a double into two 26-bit halves
_K_MIN, _K_MAX = 0, 345
#: both factors scaled by a power of two (exact) so that neither a subnormal |x| nor 10^300 leaves the range
_SHIFT = 200


def _powers_of_ten() -> tuple:
    """10^k·2^-_SHIFT for k in [_K_MIN, _K_MAX] as double-double (hi, lo): hi the double nearest, lo the rest,
    exact to 2^-106 (Python's fractions: exact)."""
    from fractions import Fraction

    hi, lo = [], []
    for k in range(_K_MIN, _K_MAX + 1):
        exact = Fraction(10) ** k / Fraction(2) ** _SHIFT
        h = float(exact)
        hi.append(h)
        lo.append(float(exact - Fraction(h)))
    return np.array(hi), np.array(lo)


_P_HI, _P_LO = _powers_of_ten()


def _two_product(a: np.ndarray, b: np.ndarray) -> tuple:
    """(p, err) with p + err == a·b exactly (Dekker; |a|, |b| < 1e300 and |a·b| well inside the range)."""
    p = a * b
    c = _SPLIT * a
    ah = c - (c - a)
    al = a - ah
    c = _SPLIT * b
    bh = c - (c - b)
    bl = b - bh
    return p, ((ah * bh - p) + ah * bl + al * bh) + al * bl


def _scaled(a: np.ndarray, k: np.ndarray) -> tuple:
    """a·10^k (k >= 0) as a double-double (hi, lo)."""
    a = a * 2.0**_SHIFT
    p, err = _two_product(a, _P_HI[k - _K_MIN])
    return p, err + a * _P_LO[k - _K_MIN]


def _digits_and_exponent(a: np.ndarray, d: int) -> tuple:
    """For |x| = ``a`` (finite, below 10^d): (m, e, undecided) with m·10^(e−d) = a rounded to d + 1 significant
    digits, ties to even; m integer in [10^d, 10^(d+1)) (0 for a = 0); ``undecided`` (bool) marks the numbers whose
    rounding even the double-double cannot decide (their m is one of two).  A plain product a·10^k (relative error
    < 2.3e-16) decides every number whose rounding it cannot get wrong; the others, near a tie or a power of ten,
    take the double-double path."""
    zero = a == 0
    safe = np.where(zero, 1.0, a)
    e = np.floor(np.log10(safe)).astype(np.int64)
    scaled = safe * 2.0**_SHIFT
    p = scaled * _P_HI[d - e]
    m = np.floor(p)
    frac = p - m
    lo_bound, hi_bound = 10.0**d, 10.0 ** (d + 1)
    margin = 1e-15 * hi_bound                      # > 4x the product's error
    unsure = (np.abs(frac - 0.5) < margin) | (p < lo_bound + margin) | (p > hi_bound - margin)
    m += frac > 0.5
    carry = m >= hi_bound                          # 9.99...96 rounded up: 1.0 of the next decade
    m[carry] = lo_bound
    e += carry
    undecided = np.zeros(a.shape, bool)
    idx = np.nonzero(unsure & ~zero)[0]
    if idx.size:
        m[idx], e[idx], undecided[idx] = _exact(safe[idx], e[idx], d)
    return np.where(zero, 0, m).astype(np.int64), np.where(zero, 0, e), undecided


def _exact(a: np.ndarray, e: np.ndarray, d: int) -> tuple:
    """(m, e, undecided) of :func:`_digits_and_exponent` from the double-double a·10^(d−e), the exponent settled
    first."""
    lo_bound, hi_bound = 10.0**d, 10.0 ** (d + 1)
    for _ in range(3):                       # log10 may be one off next to a power of ten
        vh, vl = _scaled(a, d - e)
        below = (vh - lo_bound) + vl < 0         # vh − bound is exact where it matters (Sterbenz)
        above = (vh - hi_bound) + vl >= 0
        if not (below.any() or above.any()):
            break
        e = e - below + above
    else:
        raise AssertionError("decimal exponent did not settle")
    m = np.floor(vh)
    # nearest integer to vh + vl: |vl| <= ulp(vh) <= 1/8, so m or m + 1; vh − m − 0.5 is exact and the sign of a
    # rounded sum is the sign of the exact one
    past_half = (vh - m - 0.5) + vl
    # for k > 22 the double-double is within ~2^-104·v of v (10^k's two halves, a times the low one, their sum),
    # and v may lie nearer a tie than that: such a number's rounding is not decided here
    undecided = (d - e > 22) & (np.abs(past_half) <= 2.0**-100 * hi_bound)
    m = m + ((past_half > 0) | ((past_half == 0) & (np.fmod(m, 2.0) == 1.0)))
    carry = m >= hi_bound
    return np.where(carry, lo_bound, m), e + carry, undecided


_E_MIN, _E_MAX = -340, 340
#: the exponent's four characters (sign, hundreds, tens, units) for each exponent from _E_MIN to _E_MAX
_EXPONENTS = np.frombuffer("".join(f"{'-' if k < 0 else '+'}{abs(k):03d}" for k in range(_E_MIN, _E_MAX + 1))
                           .encode(), np.uint8).reshape(-1, 4)


#: the four characters of each number 0000..9999, as one 32-bit item each (in memory order, whatever the byte order)
_QUADS = np.frombuffer("".join(f"{i:04d}" for i in range(10000)).encode(), np.uint32)
#: :data:`_EXPONENTS` as one 4-byte item each
_EXPONENT_ITEMS = np.ascontiguousarray(_EXPONENTS).view("V4")[:, 0]


def _slot_type(digits: int) -> np.dtype:
    """One number's fixed-width slot as a record of byte fields: '-', the leading digit, '.', the other ``digits``
    digits, 'e', the exponent's sign and three digits, the separator.  Whole fields are copied per number (a 2-D byte
    array's column ranges are copied a few bytes at a time)."""
    names, formats, offsets = ["sign", "lead", "point"], ["u1", "u1", "u1"], [0, 1, 2]
    if digits:
        names, formats, offsets = names + ["frac"], formats + [f"V{digits}"], offsets + [3]
    names += ["e", "exponent", "sep"]
    formats += ["u1", "V4", "u1"]
    offsets += [digits + 3, digits + 4, digits + 8]
    return np.dtype({"names": names, "formats": formats, "offsets": offsets, "itemsize": digits + 9})


def format_rows(values: np.ndarray, digits: int) -> bytes:
    """The rows of ``values`` (n, c) as CSV text: each number as printf's ``%.{digits}e``, ',' between columns,
    '\\n' after each row."""
    if not 0 <= digits <= 14:
        raise ValueError(f"digits must be 0..14 (the mantissa must fit a double exactly), got {digits}")
    x = np.ascontiguousarray(values, dtype=float)
    n, c = x.shape
    if c == 0:                               # np.savetxt's empty line per row
        return b"\n" * n
    flat = x.ravel()
    width = digits + 8                       # '-', d, '.', digits, 'e', '±', e2, e1, e0 ... and the separator
    a = np.abs(flat)
    fast = np.isfinite(a) & (a < 10.0**digits)
    m, e, undecided = _digits_and_exponent(np.where(fast, a, 1.0), digits)
    fast &= ~undecided
    # the d + 1 significant digits four at a time (the characters of 0000..9999 from a table), '0's ahead to fill
    n_quads = (digits + 4) // 4
    pad = 4 * n_quads - (digits + 1)
    quads = np.empty((flat.size, n_quads), np.uint32)
    for k in range(n_quads - 1, -1, -1):
        m, r = np.divmod(m, 10000)
        np.take(_QUADS, r, out=quads[:, k], mode="wrap")        # r is 0..9999; 'wrap' writes straight into out
    chars = quads.view(np.uint8)
    rec = np.empty(flat.size, _slot_type(digits))
    rec["sign"], rec["point"], rec["e"], rec["sep"] = ord("-"), ord("."), ord("e"), ord(",")
    rec.reshape(n, c)["sep"][:, -1] = ord("\n")
    rec["lead"] = chars[:, pad]
    if digits:
        rec["frac"] = chars[:, pad + 1:].view(f"V{digits}")[:, 0]
    rec["exponent"] = _EXPONENT_ITEMS[e - _E_MIN]
    slot = rec.view(np.uint8).reshape(flat.size, width + 1)
    keep = np.ones(slot.shape, bool)
    keep[:, 0] = np.signbit(flat)
    keep[:, 2] = digits > 0                  # printf's %.0e has no point
    keep[:, digits + 5] = (e <= -100) | (e >= 100)
    for i in np.nonzero(~fast)[0]:           # what the double-double does not serve: Python's own formatting
        text = (f"%.{digits}e" % flat[i]).encode()
        slot[i, :len(text)] = np.frombuffer(text, np.uint8)
        keep[i, :width] = False
        keep[i, :len(text)] = True
    return slot[keep].tobytes()


def write_csv(path, header: str, columns: np.ndarray, digits: int, chunk: int = 1 << 16) -> Path:
    """``header`` then the rows of ``columns`` (n, c) as :func:`format_rows` (printf ``%.{digits}e``): the file
    ``np.savetxt(path, columns, delimiter=",", header=header, comments="", fmt=f"%.{digits}e")`` writes, formatted
    ``chunk`` numbers at a time."""
    path = Path(path)
    columns = np.asarray(columns, dtype=float)
    if columns.ndim != 2:
        raise ValueError(f"columns must be 2-D (rows, columns), got shape {columns.shape}")
    with open(path, "wb") as fh:
        fh.write((header + "\n").encode())
        rows = max(1, chunk // max(1, columns.shape[1]))          # ~chunk numbers at a time: temporaries in cache
        for s in range(0, columns.shape[0], rows):
            fh.write(format_rows(columns[s:s + rows], digits))
    return path



def cell(value, digits: int | None = None) -> str:
    """One cell of a report or result table (docs/formats.md section 6), the same in every table.

    Parameters
    ----------
    value : bool, int, float, str or None
        The value, in the unit its column names.
    digits : int or None
        Significant digits of a float (``%.{digits}g``); None: every digit (``repr``, read back bit for bit).

    Returns
    -------
    str
        ``true``/``false`` for a boolean, an integer as it is, a float as above, the empty string for NaN, ±inf or
        None (a value that could not be computed), anything else as ``str``.
    """
    if value is None:
        return ""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        if not np.isfinite(value):
            return ""
        return repr(float(value)) if digits is None else format(float(value), f".{digits}g")
    return str(value)


def write_rows(path, columns: list, rows, digits: int | None = None) -> Path:
    """A table of ``rows`` (dicts, or sequences in the order of ``columns``) as CSV through the csv module (a
    comma or quote inside a text cell is quoted, never a new column): ``columns`` as the header, each value as
    :func:`cell` writes it; ``digits`` as there.  Returns the path."""
    import csv

    path = Path(path)
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(columns)
        for r in rows:
            values = [r[c] for c in columns] if isinstance(r, dict) else r
            w.writerow([cell(v, digits) for v in values])
    return path
