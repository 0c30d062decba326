"""NASTRAN random-response input: TABRND1 tables and RANDPS entries of a broadband CSD.

For a CSD matrix S_jk(f) (see :mod:`rwadist.broadband`; channels Fx, Fy, Fz, Tx, Ty, Tz) the
deck holds, for subcases j, k = ``subcases[channel]`` (default 1..6, one unit load per
channel in the user's deck)::

    RANDPS  SID  J  K  X  Y  TID          S_jk(f) = (X + iY)·G_TID(f)
    TABRND1 TID  LINEAR LINEAR  f1 g1 f2 g2 ... ENDT

Auto-spectra: one RANDPS (J = K, X = 1, Y = 0) per channel.  Cross-spectra (``cross=True``, the
default: the full 6×6 matrix): for j < k two entries with the same J, K -- (1, 0) on the table of
Re S_jk and (0, 1) on the table of Im S_jk -- assuming the solver sums RANDPS entries of one SID and
pair (check this against your solver's manual; the sign convention of the imaginary part is
S_jk = E[X_j X_k*]).  Without them (``cross=False``) the deck says so in its header, with the
largest coherence |S_jk|²/(S_jj·S_kk) each left-out pair carries (:func:`coherence_left_out`).
Table IDs: ``tid0 + n`` in the order written.  Formats: 'small' (8-character fixed fields;
numbers rounded to fit, about 5 significant digits) or 'free' (comma separated, 10 significant
digits).  Frequencies in Hz, PSDs in N²/Hz, N·N·m/Hz, (N·m)²/Hz.  The conventions in full (subcases,
SID, TIDs, the real/imaginary pairs, what the user's deck must hold): docs/nastran.md.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .units import CHANNELS


def field8(x: float) -> str:
    """A real number in at most 8 characters, NASTRAN style (exponent without 'E' when that fits
    better, e.g. 1.2346-5); always contains a decimal point."""
    x = float(x)
    if x == 0.0:
        return "0."
    if not np.isfinite(x):
        raise ValueError(f"cannot write non-finite value {x!r} to a NASTRAN field")
    best: tuple[float, str] | None = None      # (relative error, field)
    for p in range(7, -1, -1):
        # fixed notation
        s = f"{x:.{p}f}"
        if "." in s and len(s) <= 8 and float(s) != 0.0:
            cand = s.rstrip("0")
            err = abs(float(cand) - x) / abs(x)
            if best is None or err < best[0]:
                best = (err, cand)
        # exponent notation without 'E'
        m, exponent = f"{x:.{p}E}".split("E")
        e = int(exponent)
        if "." not in m:
            m += "."
        cand = f"{m}{'+' if e >= 0 else '-'}{abs(e)}"
        if len(cand) <= 8:
            err = abs(float(m) * 10.0**e - x) / abs(x)
            if best is None or err < best[0]:
                best = (err, cand)
    if best is None:
        raise ValueError(f"cannot fit {x!r} in 8 characters")
    return best[1]


def _card_small(name: str, fields: list) -> list:
    """Small-field card: 8 fields per line after the name, blank-field continuations."""
    lines = []
    first = fields[:8]
    lines.append(f"{name:<8}" + "".join(f"{f:>8}" for f in first))
    rest = fields[8:]
    for i in range(0, len(rest), 8):
        lines.append(" " * 8 + "".join(f"{f:>8}" for f in rest[i:i + 8]))
    return lines


def _fmt(x, fmt):
    if isinstance(x, str):
        return x
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    return field8(x) if fmt == "small" else f"{float(x):.10E}"


def _card(name, fields, fmt):
    vals = [_fmt(f, fmt) for f in fields]
    if fmt == "small":
        return _card_small(name, vals)
    # free field: first line = name + 8 fields, continuation lines start with a comma (blank field 1)
    out = [",".join([name] + vals[:8])]
    for i in range(8, len(vals), 8):
        out.append("," + ",".join(vals[i:i + 8]))
    return out


def tabrnd1(tid: int, f, g, fmt: str = "small") -> list:
    """Lines of a TABRND1 card (LINEAR/LINEAR) with points (f, g)."""
    fields = [int(tid), "LINEAR", "LINEAR", "", "", "", "", ""]
    for fi, gi in zip(np.asarray(f, float), np.asarray(g, float)):
        fields += [float(fi), float(gi)]
    fields.append("ENDT")
    return _card("TABRND1", fields, fmt)


def randps(sid: int, j: int, k: int, x: float, y: float, tid: int, fmt: str = "small") -> list:
    return _card("RANDPS", [int(sid), int(j), int(k), float(x), float(y), int(tid)], fmt)


def coherence_left_out(res, channels=CHANNELS) -> list:
    """[(coherence, channel j, channel k, f Hz)] of every pair of live channels (j before k), largest first: the
    largest ordinary coherence |S_jk|²/(S_jj·S_kk) over frequency (0..1) and where it peaks -- what a deck without
    cross-spectra leaves out (1: the two channels move together; 0: independent)."""
    idx = [CHANNELS.index(c) for c in channels]
    live = [a for a in idx if np.any(res.psd[:, a] > 0)]
    out = []
    for i, a in enumerate(live):
        for b in live[i + 1:]:
            den = res.psd[:, a] * res.psd[:, b]
            ok = den > 0
            if not ok.any():
                continue
            coh = np.zeros(res.f.size)
            coh[ok] = np.abs(res.csd[ok, a, b]) ** 2 / den[ok]
            k = int(np.argmax(coh))
            out.append((float(min(coh[k], 1.0)), CHANNELS[a], CHANNELS[b], float(res.f[k])))
    return sorted(out, reverse=True)


def left_out_text(res) -> str:
    """What a deck without cross-spectra leaves out, for the console: the pairs of largest coherence."""
    left = [c for c in coherence_left_out(res) if c[0] > 0.0]
    if not left:
        return "the channels are uncorrelated, nothing left out"
    shown = ", ".join(f"{j}-{k} {coh:.2f} at {f:.4g} Hz" for coh, j, k, f in left[:4])
    return f"cross-spectra left out, largest coherence {shown}{' ...' if len(left) > 4 else ''} (listed in the deck)"


def write_deck(res, path, sid: int = 1, tid0: int = 1000, fmt: str = "small", cross: bool = True,
               subcases=None, channels=CHANNELS) -> dict:
    """Write the RANDPS/TABRND1 bulk entries of ``res`` (a :class:`rwadist.broadband.BroadbandPSD`).

    Returns {table id: (j_channel, k_channel, 're'|'im'|'auto')} of what was written.  ``channels``
    selects the channels (default all six; channels whose PSD is identically zero are skipped).
    ``cross``: the cross-spectra too (the full 6×6 matrix, default); without them the deck's header names
    every pair left out with the largest coherence it carries (:func:`coherence_left_out`).
    """
    if fmt not in ("small", "free"):
        raise ValueError(f"fmt must be 'small' or 'free', got {fmt!r}")
    subcases = subcases or {ch: i + 1 for i, ch in enumerate(CHANNELS)}
    idx = [CHANNELS.index(c) for c in channels]
    lines = [f"$ rwadist broadband disturbance PSD ({res.frame} frame), one-sided, S_jk = E[X_j X_k*]",
             "$ subcases: " + ", ".join(f"{c}={subcases[c]}" for c in channels),
             "$ units: Hz; N^2/Hz, N*Nm/Hz, Nm^2/Hz",
             f"$ RANDPS SID {sid}; TABRND1 TIDs from {tid0}, LINEAR/LINEAR; conventions: rwadist docs/nastran.md"]
    if cross:
        lines.append("$ cross-spectra: included (full 6x6; each pair j<k as Re (X=1,Y=0) and Im (X=0,Y=1) tables)")
    else:
        left = [c for c in coherence_left_out(res, channels) if c[0] > 0.0]
        lines.append("$ CROSS-SPECTRA LEFT OUT (auto-spectra only): the channels are treated as uncorrelated; "
                     "largest coherence of each pair left out:")
        lines += [f"$   {j}-{k}: {coh:.3f} at {f:.4g} Hz" for coh, j, k, f in left] or ["$   none (all zero)"]
    written = {}
    tid = tid0
    live = [a for a in idx if np.any(res.psd[:, a] > 0)]
    for a in live:
        ch = CHANNELS[a]
        lines += randps(sid, subcases[ch], subcases[ch], 1.0, 0.0, tid, fmt)
        lines += tabrnd1(tid, res.f, res.psd[:, a], fmt)
        written[tid] = (ch, ch, "auto")
        tid += 1
    if cross:
        for i, a in enumerate(live):
            for b in live[i + 1:]:
                for part, (x, y) in (("re", (1.0, 0.0)), ("im", (0.0, 1.0))):
                    vals = getattr(res.csd[:, a, b], "real" if part == "re" else "imag")
                    if not np.any(vals != 0):
                        continue
                    lines += randps(sid, subcases[CHANNELS[a]], subcases[CHANNELS[b]], x, y, tid, fmt)
                    lines += tabrnd1(tid, res.f, vals, fmt)
                    written[tid] = (CHANNELS[a], CHANNELS[b], part)
                    tid += 1
    Path(path).write_text("\n".join(lines) + "\n")
    return written
