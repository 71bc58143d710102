"""Plots of ``make bench`` / ``make stress``; they read the CSV tables and compute nothing."""

from __future__ import annotations

import numpy as np

from hhscatter.publish.figures import agg_pyplot

_FLOOR = 1e-17  # errors of exactly 0 are drawn at this floor


def plot_workprecision(csv_path, png_path):
    """plot_workprecision(csv, png) -> png path: error vs µs/orbit (log–log), one curve per method.

    Columns: scenes (conservative, dissipative); rows: median and 99th
    percentile of the relative escape-time error. Error bars: min–max µs/orbit.
    """
    import pandas as pd  # deferred: pandas loads on first use

    plt = agg_pyplot()
    df = pd.read_csv(csv_path)
    scenes = list(dict.fromkeys(df.scene))
    fig, axes = plt.subplots(2, len(scenes), figsize=(6.2 * len(scenes), 8.5), squeeze=False)
    markers = "osD^v<>ph*"
    fams = list(dict.fromkeys(df.family))
    colors = {f: plt.get_cmap("tab10")(i % 10) for i, f in enumerate(fams)}  # one colour per method in every panel
    for j, scene in enumerate(scenes):
        d = df[df.scene == scene]
        for i, (col, lab) in enumerate((("rel_err_median", "median"), ("rel_err_p99", "99th percentile"))):
            ax = axes[i, j]
            for f in fams:
                g = d[d.family == f].sort_values("us_per_orbit")
                if g.empty:
                    continue
                y = np.clip(g[col].to_numpy(dtype=float), _FLOOR, 1e3)
                x = g.us_per_orbit.to_numpy()
                err = [x - g.us_min.to_numpy(), g.us_max.to_numpy() - x]
                eng = bool(g.is_engine.iloc[0])
                ax.errorbar(
                    x,
                    y,
                    xerr=err,
                    marker=markers[fams.index(f) % len(markers)],
                    lw=2.2 if eng else 1.2,
                    ms=6,
                    capsize=2,
                    label=f,
                    color=colors[f],
                )
                for xi, yi, s in zip(x, y, g.setting):
                    ax.annotate(s, (xi, yi), fontsize=6, xytext=(3, 3), textcoords="offset points")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel("µs per orbit (median of repeats; bars: min–max)")
            ax.set_ylabel(f"relative escape-time error, {lab}")
            ax.set_title(f"{scene}: {lab}")
            ax.grid(True, which="both", alpha=0.3)
        axes[0, j].legend(fontsize=7)
    fig.suptitle("Work–precision vs heyoka long-double reference (same ICs, one core; machine shared)")
    fig.tight_layout()
    fig.savefig(png_path, dpi=110)
    plt.close(fig)
    return png_path


def plot_energy_drift(csv_path, png_path):
    """plot_energy_drift(csv, png) -> png path: max relative energy error vs t per tolerance (log–log)."""
    import pandas as pd  # deferred: pandas loads on first use

    plt = agg_pyplot()
    df = pd.read_csv(csv_path)
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for tol, g in df.groupby("tol"):
        g = g.sort_values("t")
        ax.plot(g.t, np.clip(g.max_rel_energy_err, _FLOOR, None), "o-", label=f"tol={tol:g} (max)")
        ax.plot(
            g.t,
            np.clip(g.median_rel_energy_err, _FLOOR, None),
            "--",
            color=ax.lines[-1].get_color(),
            label=f"tol={tol:g} (median)",
        )
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("t")
    ax.set_ylabel("|H(t) − H(0)| / H(0)")
    ax.set_title("Energy drift of censored orbits (engine)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(png_path, dpi=110)
    plt.close(fig)
    return png_path
