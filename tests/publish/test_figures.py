"""Panels cropped from a multi-panel figure (hhscatter.publish.figures.save_panels)."""

from __future__ import annotations

import numpy as np

from hhscatter.publish.figures import agg_pyplot, save_panels


def _red_mask(path) -> np.ndarray:
    import matplotlib.image as mpimg

    img = mpimg.imread(path)[..., :3]
    return (img[..., 0] > 0.8) & (img[..., 1] < 0.2) & (img[..., 2] < 0.2)


def _red_pixels(path) -> int:
    return int(_red_mask(path).sum())


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


def test_a_panel_of_a_constrained_layout_is_cropped_where_it_was_drawn(tmp_path):
    """A 2×2 constrained-layout figure with a wide legend in one panel: each crop holds its own panel's frame on all
    four sides (red frame pixels at the crop's left, right, top and bottom margins) — hiding the other panels must
    not reflow the layout under the crop box."""
    plt = agg_pyplot()
    fig, axs = plt.subplots(2, 2, figsize=(8, 6), constrained_layout=True)
    for ax in axs.ravel():
        ax.plot([0, 1], [0, 1], color="k")
        for side in ax.spines.values():
            side.set_color("red")
            side.set_linewidth(3)
    axs[0, 1].set_ylabel("a long label\nover two lines", fontsize=16)
    axs[1, 0].legend(["a legend entry that is long"], fontsize=14, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    fig.savefig(tmp_path / "fig.png", dpi=60)
    for p in save_panels(fig, tmp_path / "fig.png", dpi=120):
        red = _red_mask(p)
        h, w = red.shape
        cols, rows = np.flatnonzero(red.any(axis=0)), np.flatnonzero(red.any(axis=1))
        # the frame is inside the crop, with margin (ticks, labels) around it, never cut at an edge
        assert 0 < cols[0] and cols[-1] < w - 1 and cols[-1] - cols[0] > 0.3 * w, (p.name, cols[0], cols[-1], w)
        assert 0 < rows[0] and rows[-1] < h - 1 and rows[-1] - rows[0] > 0.3 * h, (p.name, rows[0], rows[-1], h)
    assert fig.get_layout_engine().__class__.__name__ == "ConstrainedLayoutEngine"  # given back
    plt.close(fig)


def test_a_panel_shows_no_part_of_the_composites_suptitle(tmp_path):
    """A two-line panel title right under the composite's suptitle (as the generality figure draws them): the crop of
    the panel holds its own title and no cut strip of the suptitle; the composite keeps it."""
    plt = agg_pyplot()
    fig, (a, b) = plt.subplots(1, 2, figsize=(8, 3))
    a.plot([0, 1], [0, 1], color="k")
    b.plot([0, 1], [1, 0], color="k")
    a.set_title("panel (a) title,\non two lines", fontsize=9)
    fig.tight_layout(rect=(0, 0, 1, 0.85))
    fig.canvas.draw()
    top = a.title.get_window_extent().transformed(fig.transFigure.inverted()).y1
    fig.suptitle("THE COMPOSITE'S TITLE", color="red", fontsize=14, y=top, va="bottom")  # within the pad
    fig.savefig(tmp_path / "fig.png", dpi=80)
    assert _red_pixels(tmp_path / "fig.png") > 50
    pa, pb = save_panels(fig, tmp_path / "fig.png", dpi=80)
    assert _red_pixels(pa) == 0 and _red_pixels(pb) == 0
    assert fig._suptitle.get_visible()  # the figure is left as it was
    fig.savefig(tmp_path / "again.png", dpi=80)
    assert np.array_equal(plt.imread(tmp_path / "again.png"), plt.imread(tmp_path / "fig.png"))
    plt.close(fig)
