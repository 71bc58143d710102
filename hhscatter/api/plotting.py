"""Plots of P(t) and κ on the caller's axes (default: a new pyplot figure), never touching the matplotlib backend."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from hhscatter.api import checks
from hhscatter.api.points import _label
from hhscatter.errors import ConfigError

if TYPE_CHECKING:  # annotations only: matplotlib is imported when a function runs
    from matplotlib.axes import Axes


def _axes(ax):
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt  # the user's backend, whatever it is  # deferred: matplotlib loads on first use

    return plt.subplots(figsize=(6, 4.2), constrained_layout=True)[1]


def plot_survival(
    curves: Any,
    ax: Axes | None = None,
    *,
    labels: list[str] | None = None,
    band: bool = True,
    logy: bool = True,
    **line_kwargs: Any,
) -> Axes:
    """Draw P(t) as steps, one line per curve, with a ±1σ band.

    Log-scale P by default (the final P = 0 step is not drawn). Does not change the matplotlib backend,
    does not save or show the figure.

    Parameters
    ----------
    curves : SurvivalCurves, SurvivalCurve or list of either
        What :func:`survival` returns, or curves of :mod:`hhscatter.analysis.survival.fits`.
    ax : matplotlib Axes, optional
        Where to draw (default: a new pyplot figure).
    labels : list of str, optional
        One per curve (default "E0=…, γ=…").
    band : bool
        Draw the ±1σ Greenwood band.
    logy : bool
        Log-scale P axis.
    **line_kwargs
        Passed to ``ax.step``.

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import matplotlib; matplotlib.use("Agg")
    >>> import pandas as pd, hhscatter
    >>> lt = pd.DataFrame({"t_end": [1.0, 2.0, 3.0], "outcome": "escaped", "e0": 0.3, "gamma": 0.0})
    >>> ax = hhscatter.plot_survival(hhscatter.survival(lt))
    >>> ax.get_ylabel()
    'P(t)'
    """
    for c in curves if isinstance(curves, list) else [curves]:
        if not (isinstance(getattr(c, "curves", None), dict) or all(hasattr(c, a) for a in ("t", "P", "P_err"))):
            raise ConfigError(
                "curves must be a SurvivalCurves (what hhscatter.survival returns), a SurvivalCurve (t, P, P_err) "
                f"or a list of them, got {checks.describe(c)}"
            )
    if isinstance(curves, list) and not curves:
        raise ConfigError("curves is an empty list: nothing to draw")
    items = []
    for c in curves if isinstance(curves, list) else [curves]:
        if isinstance(getattr(c, "curves", None), dict):  # a SurvivalCurves: one line per grid point
            items.extend((f"{_label(k)} (N={c.n[k]})", v) for k, v in c.curves.items())
        else:
            items.append((None, c))
    if labels is not None:
        if len(labels) != len(items):
            raise ConfigError(f"{len(labels)} labels for {len(items)} curves")
        items = [(lab, c) for lab, (_, c) in zip(labels, items)]
    ax = _axes(ax)
    for label, c in items:
        t, P, err = (np.asarray(x, dtype=float) for x in (c.t, c.P, c.P_err))
        keep = np.isfinite(P) & ((P > 0) if logy else True)
        (line,) = ax.step(t[keep], P[keep], where="post", label=label, **line_kwargs)
        if band:
            lo = P[keep] - err[keep]
            if logy:
                lo = np.clip(lo, P[keep] * 0.05, None)
            ax.fill_between(t[keep], lo, P[keep] + err[keep], step="post", color=line.get_color(), alpha=0.25, lw=0)
    if logy:
        ax.set_yscale("log")
    ax.set_xlabel("t")
    ax.set_ylabel("P(t)")
    if any(label for label, _ in items):
        ax.legend()
    return ax


def plot_escape_rates(rates: Any, ax: Axes | None = None, *, x: str = "energy", **errorbar_kwargs: Any) -> Axes:
    """Draw κ ± its error against the energy (or another column), one series per γ.

    Points without κ are skipped. Does not change the matplotlib backend.

    Parameters
    ----------
    rates : EscapeRates or DataFrame
        What :func:`escape_rates` returns, or its ``to_frame()``.
    ax : matplotlib Axes, optional
        Where to draw (default: a new pyplot figure).
    x : str
        Column of ``rates.to_frame()`` on the horizontal axis (default the energy E0).
    **errorbar_kwargs
        Passed to ``ax.errorbar``.

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import matplotlib; matplotlib.use("Agg")
    >>> import pandas as pd, hhscatter
    >>> rates = pd.DataFrame({"energy": [0.25, 0.3], "gamma": 0.0, "kappa": [0.1, 0.2], "kappa_err": 0.01})
    >>> hhscatter.plot_escape_rates(rates).get_xlabel()
    'E0'
    """
    if isinstance(getattr(rates, "results", None), dict) and hasattr(rates, "to_frame"):  # an EscapeRates
        df = rates.to_frame()
    else:
        df = checks.frame(
            rates, "rates", needs=("gamma", "kappa", "kappa_err"), what="escape rates", reader="hhscatter.escape_rates"
        )
    if x not in df.columns:
        raise ConfigError(f"x = {x!r} is not a column of the rates; columns: {', '.join(map(str, df.columns))}")
    df = df[np.isfinite(df["kappa"].to_numpy(dtype=float))]
    ax = _axes(ax)
    kw = {"fmt": "o-", "capsize": 3, **errorbar_kwargs}
    for g, d in df.groupby("gamma", sort=True):
        d = d.sort_values(x)
        ax.errorbar(d[x], d["kappa"], yerr=d["kappa_err"], label=f"γ={g:g}", **kw)
    ax.set_xlabel("E0" if x == "energy" else x)
    ax.set_ylabel("κ")
    if len(df):
        ax.legend()
    return ax
