"""``plot_util.save_png`` writes the pixels matplotlib's own ``savefig`` writes, and leaves the figure
as it found it (its draw-time caches do not outlive the draw)."""
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from PIL import Image

from rwadist.plot_util import save_png

DPI = 90


def busy_figure(ylim=None) -> Figure:
    """What the report draws: constrained layout, log axes with minor grid lines, shared x axes,
    math-text tick labels, a colorbar, a figure legend outside the axes and a suptitle."""
    fig = Figure(figsize=(7.0, 5.0), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(2, 2, sharex="col")
    f = np.linspace(1.0, 300.0, 400)
    for k, ax in enumerate(axes[0]):
        ax.semilogy(f, 1e-6 * (1 + k) * (1.0 + 1e4 * np.exp(-((f - 50.0 * (k + 1)) / 3.0) ** 2)), label=f"data {k}")
        ax.grid(True, which="both", alpha=0.3)
        ax.set_title(f"panel {k}")
        ax.set_ylabel("Amplitude (N)")
        if ylim is not None:
            ax.set_ylim(*ylim)
    mesh = axes[1, 0].pcolormesh(np.arange(5.0), np.arange(4.0), np.arange(12.0).reshape(3, 4))
    fig.colorbar(mesh, ax=axes[1, 0], label="log10 PSD (N²/Hz)")
    axes[1, 1].plot(f, np.cumsum(f) / f.sum(), label="cumulative")
    axes[1, 1].set_xlabel("Frequency (Hz)")
    fig.legend(*axes[0, 0].get_legend_handles_labels(), loc="outside lower center")
    fig.suptitle("a busy figure")
    return fig


def pixels(path) -> np.ndarray:
    with Image.open(path) as im:
        return np.asarray(im.convert("RGBA"))


def test_save_png_writes_the_pixels_of_savefig(tmp_path):
    busy_figure().savefig(tmp_path / "savefig.png", dpi=DPI)
    save_png(busy_figure(), tmp_path / "save_png.png", DPI)
    assert np.array_equal(pixels(tmp_path / "save_png.png"), pixels(tmp_path / "savefig.png"))


def test_a_figure_changed_after_save_png_is_drawn_as_changed(tmp_path):
    """The tick caches live for one draw only: new limits after a save show new ticks, as they do
    when matplotlib's ``savefig`` saves the same figure before and after the change (a figure
    redrawn under constrained layout starts from its previous layout, so a fresh figure is no
    reference)."""
    def save_change_save(save, tag):
        fig = busy_figure()
        save(fig, tmp_path / f"{tag}_first.png")
        for ax in fig.axes[:2]:
            ax.set_ylim(1e-9, 1e-1)
        save(fig, tmp_path / f"{tag}_changed.png")
        return fig

    fig = save_change_save(lambda fig, path: save_png(fig, path, DPI), "kit")
    save_change_save(lambda fig, path: fig.savefig(path, dpi=DPI), "mpl")
    assert not any("_update_ticks" in vars(axis) or "_get_ticklabel_bboxes" in vars(axis)
                   for ax in fig.axes for axis in (ax.xaxis, ax.yaxis))
    assert np.array_equal(pixels(tmp_path / "kit_changed.png"), pixels(tmp_path / "mpl_changed.png"))
    assert not np.array_equal(pixels(tmp_path / "kit_changed.png"), pixels(tmp_path / "kit_first.png"))


def test_matplotlib_imported_for_a_command_draws_the_same_pixels_and_sets_the_same_properties(tmp_path):
    """``import_matplotlib_for_command`` (a fresh process: this one has matplotlib imported) skips only the generated
    signatures and docstrings of the artists' ``set``: every property still set by ``set``, the class hook restored
    (a class defined later gets its docstring), the same pixels as this process's fully imported matplotlib."""
    import subprocess
    import sys
    from pathlib import Path

    child = f"""
import sys
sys.path.insert(0, {str(Path(__file__).parent)!r})
from rwadist.plot_util import import_matplotlib_for_command, save_png
import_matplotlib_for_command()
from matplotlib.artist import Artist
from matplotlib.lines import Line2D
line = Line2D([], [])
line.set(lw=3.5, color="r", label="x")
assert (line.get_linewidth(), line.get_color(), line.get_label()) == (3.5, "r", "x")
assert "Supported properties" not in (Line2D.set.__doc__ or "")
class Later(Artist):
    pass
assert "Supported properties" in Later.set.__doc__
from test_save_png import DPI, busy_figure
save_png(busy_figure(), sys.argv[1], DPI)
"""
    subprocess.run([sys.executable, "-c", child, str(tmp_path / "command.png")], check=True)
    save_png(busy_figure(), tmp_path / "library.png", DPI)
    assert np.array_equal(pixels(tmp_path / "command.png"), pixels(tmp_path / "library.png"))
    from matplotlib.lines import Line2D
    assert "Supported properties" in Line2D.set.__doc__    # this process's matplotlib left as it was
