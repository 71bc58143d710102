"""What the studies' figures share. Each study draws its figure in its own folder (``studies/<name>/figure.py``);
plot functions draw what they are given and compute nothing.

These write files from the ``study … plot`` stage (Agg backend). To draw on
your own axes in a notebook use :func:`hhscatter.plot_survival` and
:func:`hhscatter.plot_escape_rates`, which never change the backend.
"""

from __future__ import annotations


def agg_pyplot():
    """agg_pyplot() -> matplotlib.pyplot with the file-writing Agg backend selected."""
    import matplotlib  # deferred: matplotlib loads on first use

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # deferred: matplotlib loads on first use

    return plt
