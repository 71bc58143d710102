"""What the studies' figures share. Each study draws its figure in its own folder (``studies/<name>/figure.py``);
plot functions draw what they are given and compute nothing.

These write files from the ``study … plot`` stage (Agg backend). To draw on
your own axes in a notebook use :func:`hhscatter.plot_survival` and
:func:`hhscatter.plot_escape_rates`, which never change the backend.
"""

from __future__ import annotations

from pathlib import Path


def agg_pyplot():
    """agg_pyplot() -> matplotlib.pyplot with the file-writing Agg backend selected."""
    import matplotlib  # deferred: matplotlib loads on first use

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # deferred: matplotlib loads on first use

    return plt


def _same_box(a, b) -> bool:
    return all(abs(x - y) < 1e-9 for x, y in zip(a, b))


def save_panels(fig, path, groups=None, *, dpi=None, pad: float = 0.08) -> list:
    """save_panels(fig, path, groups=None, dpi=None) -> the paths of one PNG per panel of a drawn multi-panel figure.

    A page shows each at the full width of its text, where a composite of four or six panels would print its
    labels at a few pixels. Panel ``i`` goes to ``<stem>_panel_<letter>.png`` beside ``path`` (``a``, ``b``, …
    in the order of ``groups``), cropped from ``fig`` as drawn (same data and fonts; give the composite's ``dpi``): the
    tight box of the group's axes, their titles, labels and legends, ``pad`` inches around, the other panels hidden
    (a neighbour's label that reaches into the box is not drawn, nor the composite's suptitle and figure texts,
    which a crop would cut through). ``groups`` is a list
    of lists of axes drawn on together (a panel and its colour bar); default: every visible axes of ``fig``
    except colour bars, one each, with each colour bar joined to the panel it sits beside and a twin axes
    (``ax.twinx()``: the same box) to the panel it twins; inset axes travel with their parent.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> plt = agg_pyplot()
    >>> fig, axs = plt.subplots(1, 2, figsize=(8, 3))
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> [p.name for p in save_panels(fig, d / "fig9.png")]
    ['fig9_panel_a.png', 'fig9_panel_b.png']
    >>> _ = axs[1].twinx()   # a second y axis on panel (b): still two panels
    >>> [p.name for p in save_panels(fig, d / "fig9.png")]
    ['fig9_panel_a.png', 'fig9_panel_b.png']
    >>> plt.close(fig)
    """
    from matplotlib.transforms import Bbox  # deferred: matplotlib loads on first use

    path = Path(path)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    if groups is None:
        axes = [ax for ax in fig.axes if ax.get_visible()]
        bars = [ax for ax in axes if hasattr(ax, "_colorbar")]
        groups = []
        for ax in axes:
            if ax in bars:
                continue
            box = ax.get_position().bounds
            twin = next((g for g in groups if _same_box(g[0].get_position().bounds, box)), None)
            if twin is not None:  # a twinx/twiny axes: one panel with the axes it shares its box with
                twin.append(ax)
            else:
                groups.append([ax])

        def centre(ax):
            b = ax.get_position()
            return (b.x0 + b.x1) / 2, (b.y0 + b.y1) / 2

        for bar in bars:  # a colour bar belongs to the nearest panel
            cx, cy = centre(bar)
            near = min(groups, key=lambda g: (centre(g[0])[0] - cx) ** 2 + (centre(g[0])[1] - cy) ** 2)
            near.append(bar)
    for old in path.parent.glob(f"{path.stem}_panel_*.png"):  # panels of an earlier layout
        old.unlink()
    out = []
    inches = fig.dpi_scale_trans.inverted()
    boxes = [Bbox.union([ax.get_tightbbox(renderer) for ax in g]).transformed(inches).padded(pad) for g in groups]
    shown = {ax: ax.get_visible() for ax in fig.axes}
    # the composite's own title and texts belong to no panel: a crop would cut through them
    supers = [getattr(fig, k, None) for k in ("_suptitle", "_supxlabel", "_supylabel")]
    texts = {t: t.get_visible() for t in [*supers, *fig.texts] if t is not None}
    engine = fig.get_layout_engine()
    fig.set_layout_engine("none")  # the layout as drawn: a layout engine would reflow around the hidden panels
    try:
        for t in texts:
            t.set_visible(False)
        for i, (group, box) in enumerate(zip(groups, boxes)):
            for ax in fig.axes:  # the other panels hidden: no neighbour's label reaches into the crop
                ax.set_visible(shown[ax] and ax in group)
            p = path.with_name(f"{path.stem}_panel_{chr(ord('a') + i)}.png")
            fig.savefig(p, bbox_inches=box, dpi=dpi or "figure")
            out.append(p)
    finally:
        for ax, vis in shown.items():
            ax.set_visible(vis)
        for t, vis in texts.items():
            t.set_visible(vis)
        fig.set_layout_engine(engine)
    return out
