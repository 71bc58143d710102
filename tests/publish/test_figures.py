"""Panels cropped from a multi-panel figure (hhscatter.publish.figures.save_panels)."""

from __future__ import annotations

import numpy as np

from hhscatter.publish.figures import agg_pyplot, save_panels


def _red_pixels(path) -> int:
    import matplotlib.image as mpimg

    img = mpimg.imread(path)[..., :3]
    return int(((img[..., 0] > 0.8) & (img[..., 1] < 0.2) & (img[..., 2] < 0.2)).sum())


def test_a_panel_shows_none_of_its_neighbours_labels(tmp_path):
    """Panel (b)'s y label reaches back over panel (a): panel (a)'s crop must not show it, the composite must."""
    plt = agg_pyplot()
    fig, (a, b) = plt.subplots(1, 2, figsize=(8, 3))
    a.plot([0, 1], [0, 1], color="k")
    b.plot([0, 1], [1, 0], color="k")
    b.set_ylabel("NEIGHBOUR LABEL", color="red", fontsize=20)
    b.yaxis.set_label_coords(-0.9, 0.5)  # drawn inside panel (a)'s box
    fig.savefig(tmp_path / "fig.png", dpi=80)
    pa, pb = save_panels(fig, tmp_path / "fig.png", dpi=80)
    assert _red_pixels(pa) == 0
    assert _red_pixels(pb) > 50  # the label is drawn with its own panel
    assert all(ax.get_visible() for ax in fig.axes)  # the figure is left as it was
    fig.savefig(tmp_path / "again.png", dpi=80)
    assert np.array_equal(plt.imread(tmp_path / "again.png"), plt.imread(tmp_path / "fig.png"))
    plt.close(fig)
