"""Figures of the studies. Plot functions draw what they are given and compute nothing.

These write files from the ``study … plot`` stage (Agg backend). To draw on
your own axes in a notebook use :func:`hhscatter.plot_survival` and
:func:`hhscatter.plot_escape_rates`, which never change the backend.
"""
from __future__ import annotations


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt
