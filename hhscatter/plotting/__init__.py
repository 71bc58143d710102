"""Figures. Plot functions draw what they are given and compute nothing."""
from __future__ import annotations


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_survival(curves, path, *, title=None, logx=False):
    """plot_survival(curves, path) -> None; writes a P(t) figure.

    ``curves``: list of dicts with keys t, P, P_err (arrays) and label.
    Log-scale P; shaded ±1σ band.
    """
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 4.2), constrained_layout=True)
    for c in curves:
        keep = c["P"] > 0  # log axis: the final P = 0 step is not drawable
        t, P = c["t"][keep], c["P"][keep]
        (line,) = ax.step(t, P, where="post", label=c["label"], lw=1.4)
        if c.get("P_err") is not None:
            err = c["P_err"][keep]
            ax.fill_between(t, (P - err).clip(min=P * 0.05), P + err, step="post",
                            color=line.get_color(), alpha=0.25, lw=0)
    ax.set_yscale("log")
    if logx:
        ax.set_xscale("log")
    ax.set_xlabel("t")
    ax.set_ylabel("P(t)")
    if title:
        ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.savefig(path, dpi=150)
    plt.close(fig)
