"""figure.png fits the model: equal scales, no empty band around the section, a colour
bar as tall as the plot (issue 16)."""
from pathlib import Path

import numpy as np
import pytest

from dec3d.ssdem import plot
from dec3d.ssdem.analysis import run_problem
from dec3d.ssdem.readers.toml_input import read_toml

WIDE = """
title = "wide and low"
[profile]
points = [[0.0, 0.0], [20.0, 0.0], [40.0, 10.0], [80.0, 10.0]]
[[layer]]
c = 10.0
phi = 25.0
gamma = 20.0
kn = 3.5e5
ks = 1.0e5
[mesh]
size = 4.0
bottom = -4.0
[analysis]
steps = 1
"""


@pytest.mark.parametrize("text", [WIDE, WIDE.replace("[40.0, 10.0], [80.0, 10.0]", "[24.0, 40.0], [30.0, 40.0]")])
def test_axes_fit_the_model_and_the_colour_bar_fits_the_axes(text, tmp_path):
    an = run_problem(read_toml(Path("f.toml"), text=text))
    fig = plot.build_figure(an)
    fig.canvas.draw()
    ax, cax = fig.axes[:2]
    box, cbox = ax.get_window_extent(), cax.get_window_extent()
    # the colour bar spans exactly the height of the plot
    assert cbox.y0 == pytest.approx(box.y0, abs=1.0) and cbox.y1 == pytest.approx(box.y1, abs=1.0)
    # the limits hug the model: at most 5 % of its larger side around it
    v = an.problem.blocks.verts
    lo, hi = v.min(axis=0), v.max(axis=0)
    pad = 0.05 * (hi - lo).max()
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    assert lo[0] - pad <= x0 <= lo[0] and hi[0] <= x1 <= hi[0] + pad
    assert lo[1] - pad <= y0 <= lo[1] and hi[1] <= y1 <= hi[1] + pad
    # equal scales: metres per pixel the same both ways
    assert (x1 - x0) / box.width == pytest.approx((y1 - y0) / box.height, rel=0.02)
    # the figure is not much taller than the plot with its title, ticks and legend
    assert fig.bbox.height < box.height + 2.2 * fig.dpi
    import matplotlib.pyplot as plt
    plt.close(fig)
    plot.figure(an, tmp_path / "f.png")
    from matplotlib.image import imread
    img = imread(tmp_path / "f.png")
    rows_with_ink = np.flatnonzero((img[..., :3] < 0.9).any(axis=(1, 2)))
    assert rows_with_ink[0] < 20 and rows_with_ink[-1] > img.shape[0] - 20     # cropped to what is drawn
