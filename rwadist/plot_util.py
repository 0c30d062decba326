"""Small helpers shared by the kit's plots: the band that holds the content, the log-axis floor,
channels that are identical or empty, and label positions that do not overlap.

Plots go into design reviews, so every frequency axis ends where the content ends (not at
Nyquist), a log axis spans a readable dynamic range instead of round-off floors, an all-zero
channel is left out, and two identical curves get one legend entry that names both.
"""
from __future__ import annotations

import re
from contextlib import contextmanager
from functools import lru_cache

import numpy as np

#: dynamic range shown on a log PSD axis below the largest value (1e-8 = 80 dB)
LOG_DYNAMIC_RANGE = 1e-8
#: minor ticks of the kit's log axes, per decade: a log axis spans up to 8 decades (LOG_DYNAMIC_RANGE), where a minor
#: tick at every integer (matplotlib's default) is dense, and each tick costs ~1 ms to draw (half of a 6-panel report
#: figure's CPU was minor ticks)
LOG_MINOR_SUBS = (2.0, 5.0)
#: zlib level of the kit's PNG files (0-9; PIL's default 6 takes twice the CPU for ~7 % smaller files, same pixels)
PNG_COMPRESS_LEVEL = 3


def save_png(fig, path, dpi: float):
    """Write ``fig`` (a ``matplotlib.figure.Figure``) to the PNG file ``path`` at ``dpi`` dots per inch; returns ``path``.

    The pixels of ``fig.savefig(path, dpi=dpi)``, in less CPU:

    - one draw: ``Figure.draw`` runs the figure's layout engine, if any, then renders (``savefig`` on a figure
      with a layout engine draws it twice: a draw-disabled pass for the layout, then the real draw);
    - zlib level :data:`PNG_COMPRESS_LEVEL`;
    - during that draw, the draw-time caches of :func:`_draw_caches` (tick updates and tick-label boxes computed
      once per axis position, math text parsed once per report).

    The figure keeps ``dpi`` (it is meant to be dropped afterwards).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    if not isinstance(fig.canvas, FigureCanvasAgg):
        FigureCanvasAgg(fig)
    fig.set_dpi(dpi)
    with _draw_caches(fig):
        fig.canvas.print_png(path, pil_kwargs={"compress_level": PNG_COMPRESS_LEVEL})
    return path


#: one math-text parser for every figure the kit saves: its cache of parsed labels (the log axes'
#: "10^-5" tick labels cost ~15 ms each to parse) then lasts across figures; Agg gives each new
#: renderer its own parser, whose cache starts empty
_MATHTEXT_PARSER = None


def _shared_mathtext_parser():
    global _MATHTEXT_PARSER
    if _MATHTEXT_PARSER is None:
        from matplotlib.mathtext import MathTextParser

        _MATHTEXT_PARSER = MathTextParser("path")       # the kind RendererAgg makes for itself
    return _MATHTEXT_PARSER


@contextmanager
def _draw_caches(fig):
    """Caches valid for one draw of ``fig`` on its Agg canvas (the same pixels, less CPU).

    - The renderer the draw will use (Agg reuses it for the same size and dpi) parses math text
      with one parser shared by all figures (its results depend only on the text, font and dpi).
    - Each axis computes its ticks, and their labels' boxes, once per (view limits, axes box, dpi):
      matplotlib recomputes every tick's position and label each time a tick extent is asked for
      (the constrained layout's two passes, the title position, the spines, the label alignment,
      then the draw: ~17 times per axis), and the answer changes only when the axes move or
      rescale.  Nothing else changes ticks while the figure is drawn; the caches are removed
      afterwards, so a later change to the figure is drawn as usual.
    """
    renderer = fig.canvas.get_renderer()
    if getattr(renderer, "mathtext_parser", None) is not None:
        renderer.mathtext_parser = _shared_mathtext_parser()
    axes_list = list(fig.get_axes())
    axes_list += [child for ax in axes_list for child in getattr(ax, "child_axes", ())]
    patched = []
    for ax in axes_list:
        for axis in getattr(ax, "_axis_map", {}).values():
            cached = _axis_caches(axis)
            if cached is None:
                continue                # not the matplotlib this was written for, or already cached
            for name, method in cached.items():
                setattr(axis, name, method)
            patched.append((axis, tuple(cached)))
    try:
        yield
    finally:
        for axis, names in patched:
            for name in names:
                delattr(axis, name)


def _axis_caches(axis) -> dict | None:
    """Replacements for ``axis._update_ticks`` and ``axis._get_ticklabel_bboxes`` that remember their last
    answer for the same view limits, axes box, dpi, locators and formatters (the tick labels' boxes: also
    for the same ticks); None when ``axis`` lacks either method or already has them replaced."""
    cls = type(axis)
    update, boxes = getattr(cls, "_update_ticks", None), getattr(cls, "_get_ticklabel_bboxes", None)
    if update is None or boxes is None or "_update_ticks" in vars(axis) or "_get_ticklabel_bboxes" in vars(axis):
        return None
    ticks_key: tuple | None = None      # the geometry the cached ticks were made for
    ticks: list = []
    boxes_key: tuple | None = None
    tick_boxes: tuple = ()

    def geometry():
        ax = axis.axes
        return (tuple(axis.get_view_interval()), tuple(ax.bbox.bounds), ax.figure.dpi,
                id(axis.get_major_locator()), id(axis.get_minor_locator()),
                id(axis.get_major_formatter()), id(axis.get_minor_formatter()))

    def update_ticks():
        nonlocal ticks_key, ticks
        key = geometry()
        if ticks_key != key:
            ticks = update(axis)
            ticks_key = key
        return list(ticks)

    def ticklabel_bboxes(shown_ticks, renderer):
        nonlocal boxes_key, tick_boxes
        key = (geometry(), tuple(map(id, shown_ticks)), id(renderer))
        if boxes_key != key:
            tick_boxes = boxes(axis, shown_ticks, renderer)
            boxes_key = key
        return tuple(list(b) for b in tick_boxes)

    return {"_update_ticks": update_ticks, "_get_ticklabel_bboxes": ticklabel_bboxes}


def log_axis(ax, which: str = "y") -> None:
    """Put the ``which`` ("x" or "y") axis of ``ax`` (a ``matplotlib.axes.Axes``) on a log scale with minor ticks at
    :data:`LOG_MINOR_SUBS` of each decade and tick labels in plain text (:func:`plain_log_formatter`; a later
    ``set_xscale``/``set_yscale`` resets them)."""
    from matplotlib.ticker import LogLocator

    getattr(ax, f"set_{which}scale")("log")
    axis = getattr(ax, f"{which}axis")
    axis.set_minor_locator(LogLocator(subs=LOG_MINOR_SUBS))
    axis.set_major_formatter(plain_log_formatter())
    axis.set_minor_formatter(plain_log_formatter(label_only_base=False))


#: the characters of an exponent written as a superscript
_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
#: the math text of matplotlib's log tick labels: [sign][coefficient \times]base^{exponent}, or a plain number
_LOG_LABEL = re.compile(r"\$\\mathdefault\{(-?)(?:([^{}]*?)\\times)?(\d+)\^\{(-?\d+)\}\}\$|\$\\mathdefault\{([^{}$]*)\}\$")


def plain_log_formatter(label_only_base: bool = True):
    """A ``matplotlib.ticker.LogFormatterSciNotation`` (base 10; the labels it chooses) whose labels are plain text with
    Unicode superscripts (``10⁻⁵``, ``2×10⁻³``) instead of math text: the same label without the math-text parser
    (building it on a command's first log axis, then parsing each label, was ~0.1 s of ``rwadist psd``'s plot)."""
    return _plain_log_formatter_class()(base=10.0, labelOnlyBase=label_only_base)


@lru_cache(maxsize=1)
def _plain_log_formatter_class():
    from matplotlib.ticker import LogFormatterSciNotation

    class PlainLogFormatter(LogFormatterSciNotation):
        """matplotlib's scientific-notation log labels as plain text (:func:`_plain_label`)."""

        def __call__(self, x, pos=None):
            return _plain_label(super().__call__(x, pos))

    return PlainLogFormatter


def _plain_label(text: str) -> str:
    """A log tick label of matplotlib's math text (``$\\mathdefault{2\\times10^{-3}}$``) as plain text (``2×10⁻³``);
    any other text unchanged."""
    m = _LOG_LABEL.fullmatch(text)
    if m is None:
        return text
    sign, coeff, base, exponent, number = m.groups()
    if number is not None:
        return number
    return f"{sign}{coeff + '×' if coeff else ''}{base}{exponent.translate(_SUPERSCRIPT)}"


def content_top(f, rows, dynamic_range: float = LOG_DYNAMIC_RANGE, margin: float = 1.05) -> float:
    """Upper edge (Hz) of the band that holds the content of ``rows``.

    Parameters
    ----------
    f : array, shape (n_f,)
        Frequencies, Hz, ascending.
    rows : array, shape (n_f,) or (n_f, n_channels)
        Non-negative spectra (PSD or amplitude) over ``f``.
    dynamic_range : float
        A bin holds content when it exceeds ``dynamic_range`` times the largest value.
    margin : float
        Factor on the highest such frequency (the result never exceeds ``f[-1]``).

    Returns
    -------
    float
        ``f[-1]`` when nothing is above the threshold (or the array is empty of content).
    """
    f = np.asarray(f, dtype=float)
    y = np.asarray(rows, dtype=float).reshape(len(f), -1)
    y = np.where(np.isfinite(y), y, 0.0)
    peak = float(y.max()) if y.size else 0.0
    if peak <= 0.0:
        return float(f[-1])
    hot = np.nonzero(np.any(y > dynamic_range * peak, axis=1))[0]
    return float(min(f[-1], margin * f[hot[-1]])) if hot.size else float(f[-1])


def log_floor(rows, dynamic_range: float = LOG_DYNAMIC_RANGE) -> float | None:
    """Lower limit of a log axis: the smallest positive value, raised to ``dynamic_range``
    times the largest; None when there is no positive value."""
    y = np.asarray(rows, dtype=float)
    y = y[np.isfinite(y) & (y > 0)]
    if not y.size:
        return None
    return float(max(y.min(), dynamic_range * y.max()))


def is_empty(values) -> bool:
    """True when ``values`` hold no finite non-zero number (an absent or all-zero channel)."""
    v = np.asarray(values, dtype=float)
    return not bool(np.any(np.isfinite(v) & (v != 0.0)))


def group_identical(columns, names, rtol: float = 1e-6) -> list:
    """Group curves that coincide on a plot (largest difference within ``rtol`` of the larger
    curve's peak), so one legend entry names every channel it draws.

    Parameters
    ----------
    columns : array, shape (n, n_curves)
    names : sequence of str, length n_curves

    Returns
    -------
    list of (column index, label)
        One entry per distinct curve, label ``"Fx = Fy"`` for coinciding curves.
    """
    c = np.asarray(columns, dtype=float)
    out, taken = [], set()
    for i in range(c.shape[1]):
        if i in taken:
            continue
        same = [j for j in range(i, c.shape[1]) if j not in taken and _coincide(c[:, i], c[:, j], rtol)]
        taken.update(same)
        out.append((i, " = ".join(names[j] for j in same)))
    return out


def _coincide(a: np.ndarray, b: np.ndarray, rtol: float) -> bool:
    a, b = np.nan_to_num(a), np.nan_to_num(b)
    scale = max(float(np.max(np.abs(a), initial=0.0)), float(np.max(np.abs(b), initial=0.0)))
    return float(np.max(np.abs(a - b), initial=0.0)) <= rtol * scale


def spread_labels(y, min_gap: float) -> np.ndarray:
    """Positions for labels wanted at ``y`` moved apart to at least ``min_gap`` (same units),
    keeping their order and staying as close to ``y`` as a one-pass push-up allows."""
    y = np.asarray(y, dtype=float)
    order = np.argsort(y, kind="stable")
    placed = y[order].copy()
    for k in range(1, len(placed)):
        placed[k] = max(placed[k], placed[k - 1] + min_gap)
    out = np.empty_like(placed)
    out[order] = placed
    return out


def content_top_above_floor(f, rows, factor: float = 10.0, margin: float = 1.2) -> float | None:
    """Upper edge (Hz) of the band that holds lines standing above a noise floor.

    Parameters
    ----------
    f : array, shape (n_f,)
        Frequencies, Hz, ascending.
    rows : array, shape (n_runs, n_f)
        Band powers or PSDs of measured data (noise included).
    factor : float
        A frequency holds content when some run exceeds ``factor`` times the floor (the
        median of all finite positive values, which noise dominates in a line spectrum).
    margin : float
        Factor on the highest such frequency (capped at ``f[-1]``).

    Returns
    -------
    float or None
        None when nothing stands above the floor (a channel of noise only).
    """
    f = np.asarray(f, dtype=float)
    y = np.asarray(rows, dtype=float).reshape(-1, len(f))
    good = np.isfinite(y) & (y > 0)
    if not good.any():
        return None
    floor = float(np.median(y[good]))
    hot = np.nonzero(np.any(good & (y > factor * floor), axis=0))[0]
    return float(min(f[-1], margin * f[hot[-1]])) if hot.size else None


def psd_title(kind: str, res) -> str:
    """The PSD plot's title: the model kind, the frame, the band and each wheel's own speed law
    (``res.meta["speed_laws"]``: a set's wheels each have theirs, or a tie), wrapped to the figure's width."""
    import textwrap

    laws = "; ".join(law if name is None else f"{name}: {law}" for name, law in res.meta.get("speed_laws", []))
    return textwrap.fill(f"{kind}, {res.frame} frame, 0–{float(res.f[-1]):g} Hz; speed: {laws}", 110)
