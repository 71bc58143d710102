"""Fig. 1 of the paper: potential contours (a) and the c-measure support (b). Draws only."""

from __future__ import annotations

import numpy as np

from hhscatter.publish.figures import agg_pyplot, save_panels

# paper's colours: E = 0.35 orange, E = 0.30 black
POINT_COLOURS = {"E0.35": "tab:orange", "E0.30": "black"}


def _grid_arrays(grid):
    xs = np.unique(grid["x"].to_numpy())
    ys = np.unique(grid["y"].to_numpy())
    V = grid.sort_values(["y", "x"])["V"].to_numpy().reshape(ys.size, xs.size)
    return xs, ys, V


def plot_fig1(grid, points, numbers, path):
    """plot_fig1(grid, points, numbers, path) -> None; writes the two-panel Fig. 1 PNG.

    ``grid``: DataFrame x, y, V (potential on a square grid); ``points``:
    DataFrame energy, x, y (c-measure samples); ``numbers``: fig1.json
    (contour_levels, E_c, saddles, energies{key: t_rec, n_points, kappa_used}).
    """
    plt = agg_pyplot()
    from matplotlib.lines import Line2D

    xs, ys, V = _grid_arrays(grid)
    levels = np.asarray(numbers["contour_levels"], dtype=float)
    E_c = float(numbers["E_c"])
    saddles = np.asarray(numbers["saddles"], dtype=float)
    lim = (float(xs.min()), float(xs.max()))

    fig, axes = plt.subplots(1, 2, figsize=(11.0, 5.4), constrained_layout=True)
    ax = axes[0]
    cmap = plt.get_cmap("copper")
    norm = plt.Normalize(0.0, 0.5)
    colours = [cmap(norm(e)) for e in levels]
    others = ~np.isclose(levels, E_c, rtol=0, atol=1e-12)
    ax.contour(xs, ys, V, levels=levels[others], colors=[c for c, o in zip(colours, others) if o], linewidths=0.9)
    ax.contour(xs, ys, V, levels=[E_c], colors="tab:blue", linewidths=2.2)
    ax.plot(saddles[:, 0], saddles[:, 1], "o", color="tab:green", ms=7, mec="k", mew=0.6, zorder=5)
    sm = plt.cm.ScalarMappable(cmap=cmap, norm=norm)
    cb = fig.colorbar(sm, ax=ax, shrink=0.8, pad=0.02)
    cb.set_label("energy $E$ of the contour $V(x,y)=E$")
    ax.legend(
        handles=[
            Line2D([], [], color="tab:blue", lw=2.2, label=r"$E = E_c = 1/6$"),
            Line2D([], [], ls="", marker="o", color="tab:green", mec="k", label="saddle points"),
        ],
        loc="upper right",
        fontsize=9,
        framealpha=0.9,
    )
    ax.set_title(f"(a) potential contours, {levels.size} energies in (0, 0.5)", loc="left", fontsize=11)

    ax = axes[1]
    ax.contour(xs, ys, V, levels=[E_c], colors="0.6", linewidths=0.8, linestyles="--")
    handles = []
    energies = numbers["energies"]
    for key in sorted(energies, key=lambda k: -energies[k]["energy"]):  # higher energy first, underneath
        info = energies[key]
        sel = np.isclose(points["energy"].to_numpy(), info["energy"])
        colour = POINT_COLOURS.get(key, None)
        ax.scatter(
            points["x"].to_numpy()[sel],
            points["y"].to_numpy()[sel],
            s=0.8,
            lw=0,
            color=colour,
            alpha=0.8,
            rasterized=True,
        )
        handles.append(
            Line2D(
                [],
                [],
                ls="",
                marker="o",
                ms=5,
                color=colour,
                label=(
                    f"$E = {info['energy']:.2f}$: {info['n_points']} points, "
                    f"$t_{{rec}} = {info['t_rec']:g}$ ($\\kappa t_{{rec}} = {info['t_rec_times_kappa']:.1f}$)"
                ),
            )
        )
    ax.plot(saddles[:, 0], saddles[:, 1], "o", color="tab:green", ms=5, mec="k", mew=0.5, zorder=5)
    ax.legend(handles=handles, loc="lower center", fontsize=8.5, framealpha=0.9)
    ax.set_title(r"(b) support of $\mu_c$ (sprinkler: first crossing after $t_{rec}$)", loc="left", fontsize=11)
    for ax in axes:
        ax.set_xlim(*lim)
        ax.set_ylim(*lim)
        ax.set_aspect("equal")
        ax.set_xlabel("$x$")
        ax.set_ylabel("$y$")
    fig.savefig(path, dpi=180)
    save_panels(fig, path, dpi=180)  # each panel legible at a page's full width
    plt.close(fig)
