"""The coefficient plots of a report are readable as drawn: the title, the panels' titles, the note on what the
uncertainties cover and the legend do not overprint one another and stay inside the figure (a new user's report: the
note, written at a fixed height, overprinted the title and the top row's titles, and the title ran off both edges
of a 3-panel row).  Measured on the rendered figure's text extents."""
import numpy as np
import pytest

import rwadist
from rwadist.report import plot_coefficients


@pytest.fixture(scope="module")
def lines():
    test = rwadist.simulate_test("ithaco-e", speeds_rpm=np.linspace(300, 2400, 40), n_samples=4096, seed=1)
    return rwadist.fit(test).lines


def _boxes(fig):
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    boxes = {f"figure text {i}": t.get_window_extent(r) for i, t in enumerate(fig.texts) if t.get_text()}
    boxes.update({f"legend {i}": leg.get_window_extent(r) for i, leg in enumerate(fig.legends)})
    for i, ax in enumerate(fig.axes):
        if ax.get_visible():
            boxes[f"title {i}"] = ax.title.get_window_extent(r)
    return boxes, fig.bbox


@pytest.mark.parametrize("direction", ["radial_force", "axial_force", "radial_torque"])
def test_no_text_overprints_another_or_leaves_the_figure(lines, direction):
    fig, _ = plot_coefficients(lines, direction)
    boxes, frame = _boxes(fig)
    names = list(boxes)
    for i, a in enumerate(names):
        box = boxes[a]
        assert box.x0 >= frame.x0 - 1 and box.x1 <= frame.x1 + 1 and box.y0 >= frame.y0 - 1 and box.y1 <= frame.y1 + 1, a
        for b in names[i + 1:]:
            assert not box.overlaps(boxes[b]), (a, b)
