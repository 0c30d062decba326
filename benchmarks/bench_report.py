"""Benchmark: CPU time of writing the fit report and the extended report (23 PNG figures and the
tables of ``rwadist fit --extended`` on a small E-wheel test), with the kit's ``save_png`` and with
the way figures were saved before its draw-time caches (the baseline), measured in the same run.

The baseline is the former ``save_png`` reproduced below (one draw through the figure's layout
engine, zlib level 3): the figures are built by the same code, only the saving differs.  Both ways
must write byte-identical PNG files (checked: exit 1 otherwise).  CPU time (``time.process_time``)
is the figure of merit: the machine is shared, wall time is not.  The fit itself is not timed.

    python benchmarks/bench_report.py [--repeat 3] [--out DIR]
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path
from unittest import mock

import numpy as np

from rwadist import api, report, report_extended
from rwadist.plot_util import PNG_COMPRESS_LEVEL


def baseline_save_png(fig, path, dpi: float):
    """``save_png`` before the draw-time caches: the same single draw and zlib level, no caches."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    if not isinstance(fig.canvas, FigureCanvasAgg):
        FigureCanvasAgg(fig)
    fig.set_dpi(dpi)
    fig.canvas.print_png(path, pil_kwargs={"compress_level": PNG_COMPRESS_LEVEL})
    return path


def write_both(fit, efit, out: Path) -> list:
    files = report.write_report(fit, out)
    files += report_extended.write_extended_report(efit, fit, out)
    return files


def cpu_of(fn) -> float:
    t0 = time.process_time()
    fn()
    return time.process_time() - t0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="timed repeats of each way, interleaved (best is kept)")
    ap.add_argument("--out", help="directory for the two reports (default: a temporary one)")
    args = ap.parse_args(argv)

    test = api.simulate_test("ithaco-e", np.linspace(600.0, 2400.0, 8), sample_rate=1920.0, n_samples=2048)
    fit = api.fit(test, name="bench", progress=False)
    efit, _ = api.fit_extended(test, fit, preset="ithaco-e")

    with tempfile.TemporaryDirectory() as tmp:
        root = Path(args.out) if args.out else Path(tmp)
        new_dir, old_dir = root / "new", root / "baseline"

        def new():
            return write_both(fit, efit, new_dir)

        def old():
            with mock.patch.object(report, "save_png", baseline_save_png):
                return write_both(fit, efit, old_dir)

        files = new()                  # warm-up: imports, font cache, the kit's shared caches
        old()
        best_new = best_old = np.inf
        for _ in range(args.repeat):
            best_old = min(best_old, cpu_of(old))
            best_new = min(best_new, cpu_of(new))
        pngs = [Path(f).name for f in files if str(f).endswith(".png")]
        differ = [n for n in pngs if (new_dir / n).read_bytes() != (old_dir / n).read_bytes()]

    print(f"report + extended report, {len(pngs)} PNG figures, best of {args.repeat} (CPU s):")
    print(f"  baseline (save_png without draw-time caches): {best_old:6.2f}")
    print(f"  kit save_png:                                 {best_new:6.2f}")
    print(f"  ratio baseline / kit: {best_old / best_new:.2f}x")
    if differ:
        print(f"FAIL: PNG files differ between the two ways: {', '.join(differ)}")
        return 1
    print("PNG files byte-identical between the two ways")
    return 0


if __name__ == "__main__":
    sys.exit(main())
