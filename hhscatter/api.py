"""The notebook API: one function per concept, per grid point, each result with ``.to_frame()`` and ``.plot(ax=)``.

P(t) and κ of a lifetimes DataFrame, one result per grid point, and plots on your axes;
:func:`kappa_cmeasure` and :func:`run_scene` start from a run directory.

These functions take the DataFrame of :func:`hhscatter.read_lifetimes` (or of
pandas, DuckDB, polars … with the same columns) and analyse each ensemble
separately; the :mod:`survival` and :mod:`escape_rate` modules below them
work on arrays of one ensemble.

An *ensemble* (a grid point) is one (energy, γ): the nominal E0 in the
``energy`` column of a grid run, never the per-orbit ``e0``, which differs
from orbit to orbit in the last bits. A frame without ``energy`` (a plain run,
or several plain runs concatenated) is split by clustering ``e0`` with a
relative tolerance of 1e-9; a frame whose ``e0`` varies continuously (a run
from an initial-condition table) is one ensemble per γ, with energy NaN.

* :func:`survival` → :class:`SurvivalCurves`: Kaplan–Meier P(t) per point;
* :func:`escape_rates` → :class:`EscapeRates`: κ ± error, τ0, the fit windows,
  the MLE cross-check and τ* per point (paper Sec. II, Eq. (1)). κ is the
  escape rate of the *conservative* system: for a dissipative point (γ > 0)
  P(t) is not exponential (paper Sec. III), so no κ is fitted there; its row
  has NaN and a note, and a warning names those points;
* :func:`plot_survival`, :func:`plot_escape_rates` draw on ``ax`` (default: a
  new figure from pyplot) and return it. They never change the matplotlib
  backend, so inline figures in Jupyter keep working.

Both result objects have ``.to_frame()`` (a tidy pandas DataFrame) and
``.plot(ax=None)``.
"""
from __future__ import annotations

import dataclasses
import json
import math
import os
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from hhscatter.analysis.survival.kaplan_meier import KaplanMeierGrid
from hhscatter.data.store import Store
from hhscatter.data.read import iter_survival_batches, read_lifetimes, read_sections

if TYPE_CHECKING:  # annotations only: pandas and matplotlib are imported when a function runs
    import pandas
    from matplotlib.axes import Axes
    from numpy.typing import ArrayLike

__all__ = [
    "BasinMeasures",
    "CMeasureDistances",
    "CMeasurePoints",
    "CMeasureRates",
    "EnergyDecay",
    "EscapeRates",
    "SurvivalCurves",
    "TransitionTimes",
    "basin_measures",
    "cmeasure_distances",
    "cmeasure_points",
    "energy_decay",
    "escape_rates",
    "kappa_cmeasure",
    "kappa_cmeasure_tables",
    "plot_escape_rates",
    "plot_survival",
    "run_scene",
    "split_points",
    "stream_survival",
    "survival",
    "transition_times",
]

E0_RTOL = 1e-9  # e0 of one ensemble differs in the last bits only
MAX_E0_CLUSTERS = 50  # beyond this, e0 varies continuously (an ics run): one ensemble per γ


def _clusters(values: np.ndarray) -> np.ndarray:
    """Label of each value's cluster: sorted values split where the gap exceeds E0_RTOL (relative)."""
    order = np.argsort(values, kind="stable")
    v = values[order]
    gap = np.diff(v) > E0_RTOL * np.maximum(1.0, np.abs(v[1:]))
    labels = np.empty(v.size, dtype=np.int64)
    labels[order] = np.concatenate([[0], np.cumsum(gap)])
    return labels


def split_points(lifetimes):
    """split_points(lifetimes) -> [((energy, gamma), sub-DataFrame)], sorted by energy then γ.

    The ensembles of a lifetimes frame (module doc): by the ``energy`` and
    ``gamma`` columns when present; otherwise by clusters of ``e0`` (relative
    tolerance 1e-9; the key's energy is the cluster's median e0 to 12
    significant digits) and ``gamma``. Raises ValueError if the frame is empty
    or lacks ``t_end``/``outcome``.
    """
    cols = set(lifetimes.columns)
    missing = {"t_end", "outcome"} - cols
    if missing:
        raise ValueError(f"lifetimes lacks column(s) {sorted(missing)}: pass a frame of hhscatter.read_lifetimes")
    if len(lifetimes) == 0:
        raise ValueError("lifetimes is empty: no orbits to analyse")
    n = len(lifetimes)
    gamma = lifetimes["gamma"].to_numpy(dtype=float) if "gamma" in cols else np.zeros(n)
    if "energy" in cols:
        energy = lifetimes["energy"].to_numpy(dtype=float)
    elif "e0" in cols:
        e0 = lifetimes["e0"].to_numpy(dtype=float)
        labels = _clusters(e0)
        if labels.max() + 1 > MAX_E0_CLUSTERS:
            energy = np.full(n, math.nan)
        else:
            med = {k: float(f"{np.median(e0[labels == k]):.12g}") for k in np.unique(labels)}
            energy = np.array([med[k] for k in labels])
    else:
        energy = np.full(n, math.nan)
    key_e = np.where(np.isnan(energy), -np.inf, energy)  # NaN sorts and compares as one value
    pairs = np.unique(np.column_stack([key_e, gamma]), axis=0)
    out = []
    for e, g in pairs:
        mask = (key_e == e) & (gamma == g)
        out.append(((math.nan if e == -np.inf else float(e), float(g)), lifetimes[mask]))
    return out


def _label(key) -> str:
    e, g = key
    return f"E0={e:g}, γ={g:g}" if math.isfinite(e) else f"γ={g:g}"


# ---------------------------------------------------------------------------
# survival curves
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class SurvivalCurves:
    """Result of :func:`survival`: one Kaplan–Meier P(t) per grid point.

    Attributes
    ----------
    curves : dict
        (energy, gamma) → :class:`~hhscatter.analysis.survival.fits.SurvivalCurve` with arrays ``t`` (time
        units), ``P`` and its Greenwood error ``P_err``.
    n : dict
        (energy, gamma) → number of orbits N of that point.

    Examples
    --------
    >>> import numpy as np, pandas as pd, hhscatter
    >>> lt = pd.DataFrame({"t_end": [1.0, 2.0, 3.0, 4.0], "outcome": "escaped", "e0": 0.3, "gamma": 0.0})
    >>> curves = hhscatter.survival(lt, t_grid=[0.0, 2.5])
    >>> len(curves), curves.to_frame()["P"].round(12).tolist()
    (1, [1.0, 0.5])
    """

    curves: dict
    n: dict

    def __len__(self):
        return len(self.curves)

    def __iter__(self):
        return iter(self.curves.items())

    def __getitem__(self, key):
        """curves[(energy, gamma)] -> SurvivalCurve; ``curves[energy]`` if that energy has one point."""
        if key in self.curves:
            return self.curves[key]
        hits = [k for k in self.curves if not isinstance(key, tuple) and k[0] == key]
        if len(hits) == 1:
            return self.curves[hits[0]]
        raise KeyError(f"no single point {key!r}; points: {list(self.curves)}")

    def to_frame(self) -> pandas.DataFrame:
        """to_frame() -> DataFrame energy, gamma, n, t, P, P_err (one row per curve step or grid time)."""
        import pandas as pd  # deferred: pandas loads on first use

        parts = [pd.DataFrame({"energy": k[0], "gamma": k[1], "n": self.n[k], "t": c.t, "P": c.P, "P_err": c.P_err})
                 for k, c in self.curves.items()]
        return pd.concat(parts, ignore_index=True)

    def plot(self, ax: Axes | None = None, **kwargs: Any) -> Axes:
        """plot(ax=None, **kwargs) -> ax: :func:`plot_survival` of these curves."""
        return plot_survival(self, ax=ax, **kwargs)


def survival(lifetimes: pandas.DataFrame, t_grid: ArrayLike | None = None) -> SurvivalCurves:
    """Survival probability P(t), one Kaplan–Meier curve per grid point.

    Kaplan–Meier P(t) = Pr(lifetime > t) (paper Eqs. (eqn:kappa_hyperbolic), (eqn:kappa_nonhyperbolic)) with
    Greenwood errors (:func:`~hhscatter.analysis.survival.fits.survival_curve`) of each ensemble of
    ``lifetimes`` (see :func:`split_points`); 'escaped' and 'settled' end a lifetime, 'censored' orbits
    are right-censored.

    Parameters
    ----------
    lifetimes : DataFrame
        :func:`hhscatter.read_lifetimes` of a run (columns ``t_end``, ``outcome``, ``gamma`` and
        ``energy`` or ``e0``), or any frame with those columns.
    t_grid : array_like of float, optional
        Times (time units) at which P is given. Default: a step at every distinct event time.

    Returns
    -------
    SurvivalCurves
        One curve per (energy, γ); ``.to_frame()`` a tidy frame (energy, gamma, t, P, P_err),
        ``.plot(ax=)`` the curves.

    Examples
    --------
    >>> import pandas as pd, hhscatter
    >>> lt = pd.DataFrame({"t_end": [1.0, 2.0, 3.0, 4.0], "e0": 0.3, "gamma": 0.0,
    ...                    "outcome": ["escaped", "escaped", "censored", "escaped"]})
    >>> hhscatter.survival(lt, t_grid=[0.0, 1.5, 3.5]).to_frame()["P"].round(12).tolist()
    [1.0, 0.75, 0.5]

    (By hand: 3 of 4 at risk survive t = 1, then 2 of 3 survive t = 2, so P(3.5) = 3/4 · 2/3 = 1/2; the
    orbit censored at t = 3 is not counted as escaped, which would give 1/4.)
    """
    from hhscatter.analysis.survival.fits import (  # deferred: scipy loads on first use
        observed_from_outcome,
        survival_curve,
    )

    curves, n = {}, {}
    for key, df in split_points(lifetimes):
        observed = observed_from_outcome(df["outcome"].astype(object).to_numpy())
        curves[key] = survival_curve(df["t_end"].to_numpy(dtype=float), observed, t_grid)
        n[key] = len(df)
    return SurvivalCurves(curves, n)


# ---------------------------------------------------------------------------
# escape rates
# ---------------------------------------------------------------------------
DISSIPATIVE_NOTE = "dissipative (γ > 0): P(t) is not exponential, no κ fitted"


@dataclass(frozen=True)
class EscapeRates:
    """Result of :func:`escape_rates`: κ per grid point.

    Attributes
    ----------
    results : dict
        (energy, gamma) → :class:`~hhscatter.analysis.survival.escape_rate.EscapeRateResult` (only the
        conservative points that were fitted): κ (1/time), its error, τ0, the fit windows.
    n : dict
        (energy, gamma) → number of orbits N.
    notes : dict
        (energy, gamma) → why a point has no κ (dissipative, too few orbits, …), or why its κ is not the rate of
        the population (a trapped plateau, a non-exponential decay).
    status : dict
        (energy, gamma) → :class:`~hhscatter.analysis.survival.long_time.RateStatus` of each fitted point:
        'exponential', 'trapped' or 'non-exponential', with P∞ and κ∞ of the plateau-plus-exponential fit.

    Examples
    --------
    >>> import numpy as np, pandas as pd, hhscatter
    >>> t = np.random.default_rng(1).exponential(1 / 0.2, 20000)            # κ = 0.2 exactly
    >>> lt = pd.DataFrame({"t_end": t, "outcome": "escaped", "e0": 0.3, "gamma": 0.0})
    >>> rates = hhscatter.escape_rates(lt, detect_tail=False)
    >>> bool(abs(rates.to_frame().kappa.iloc[0] - 0.2) < 4 * rates.to_frame().kappa_err.iloc[0])
    True
    """

    results: dict
    n: dict
    notes: dict = field(default_factory=dict)
    status: dict = field(default_factory=dict)

    def __getitem__(self, key):
        return self.results[key]

    def to_frame(self) -> pandas.DataFrame:
        """to_frame() -> DataFrame, one row per point.

        Columns: energy, gamma, n, kappa, kappa_err (1σ: spread of the 4 window
        fits and statistics), kappa_stat, kappa_spread, tau0, t_stop, windows
        (the 4 (t_lo, t_hi) fit windows), kappa_mle, kappa_mle_err (maximum
        likelihood on [tau0, t_stop]), tau_star (NaN without power-law tail),
        status ('exponential', 'trapped', 'non-exponential'; empty where not fitted), p_inf, kappa_inf (the
        plateau-plus-exponential fit from τ0), note (why κ is NaN or not the population's rate, else empty).
        """
        import pandas as pd  # deferred: pandas loads on first use

        rows = []
        for key in sorted(self.n, key=lambda k: (np.nan_to_num(k[0], nan=-np.inf), k[1])):
            r = self.results.get(key)
            row = {"energy": key[0], "gamma": key[1], "n": self.n[key]}
            if r is None:
                row.update(kappa=math.nan, kappa_err=math.nan, kappa_stat=math.nan, kappa_spread=math.nan,
                           tau0=math.nan, t_stop=math.nan, windows=None, kappa_mle=math.nan,
                           kappa_mle_err=math.nan, tau_star=math.nan)
            else:
                row.update(kappa=r.kappa, kappa_err=r.kappa_err, kappa_stat=r.kappa_stat,
                           kappa_spread=r.kappa_spread, tau0=r.tau0, t_stop=r.t_stop,
                           windows=[tuple(float(x) for x in w) for w in r.windows], kappa_mle=r.mle.kappa,
                           kappa_mle_err=r.mle.kappa_err, tau_star=r.tau_star)
            st = self.status.get(key)
            row.update(status=st.status if st else "", p_inf=st.p_inf if st else math.nan,
                       kappa_inf=st.kappa_inf if st else math.nan)
            row["note"] = self.notes.get(key, "")
            rows.append(row)
        return pd.DataFrame(rows)

    def plot(self, ax: Axes | None = None, **kwargs: Any) -> Axes:
        """plot(ax=None, **kwargs) -> ax: :func:`plot_escape_rates` of these rates."""
        return plot_escape_rates(self, ax=ax, **kwargs)


def escape_rates(lifetimes: pandas.DataFrame, t_grid: ArrayLike | None = None, **kwargs: Any) -> EscapeRates:
    """Escape rate κ ± error, τ0 and the fit windows, per conservative grid point.

    For each conservative (γ = 0) ensemble of ``lifetimes`` (:func:`split_points`),
    :func:`~hhscatter.analysis.survival.escape_rate.escape_rate`: τ0 and 4 fit windows chosen from the data, κ
    (1/time) the mean of 4 weighted least-squares fits of log P(t) = log f0 − κt
    (Eq. (eqn:kappa_hyperbolic), paper Fig. 2b), its error, an MLE cross-check and the power-law tail /
    τ* when there is one (Eq. (eqn:kappa_nonhyperbolic)). Dissipative points (γ > 0) are not fitted (module
    doc): their rows have NaN and a note, and a ``UserWarning`` names them. A point whose fit fails (too
    few orbits for the window choice) gets NaN and the reason as its note.

    Parameters
    ----------
    lifetimes : DataFrame
        :func:`hhscatter.read_lifetimes` of a run, or any frame with its columns (see :func:`survival`).
    t_grid : array_like of float, optional
        Times (time units) of the P(t) that is fitted. Default: every distinct event time.
    **kwargs
        Passed to :func:`~hhscatter.analysis.survival.escape_rate.escape_rate` (e.g. ``detect_tail=False``,
        ``min_survivors=…``).

    Returns
    -------
    EscapeRates
        ``.to_frame()`` one row per point (energy, gamma, n, kappa, kappa_err, tau0, windows, tau_star,
        status, p_inf, kappa_inf, note), ``.plot(ax=)`` κ against E. A point whose orbits still inside at t_max
        bias the window (status 'trapped') or whose decay is not one exponential ('non-exponential') says so in
        ``status`` and ``note`` (:func:`~hhscatter.analysis.survival.long_time.rate_status`); its κ is then not
        the population's escape rate.

    Examples
    --------
    >>> import numpy as np, pandas as pd, hhscatter
    >>> t = np.random.default_rng(1).exponential(1 / 0.2, 20000)            # κ = 0.2 exactly
    >>> lt = pd.DataFrame({"t_end": t, "outcome": "escaped", "e0": 0.3, "gamma": 0.0})
    >>> row = hhscatter.escape_rates(lt, detect_tail=False).to_frame().iloc[0]
    >>> bool(abs(row.kappa - 0.2) < 4 * row.kappa_err)
    True
    """
    from hhscatter.analysis.survival.escape_rate import escape_rate  # deferred: scipy loads on first use
    from hhscatter.analysis.survival.fits import observed_from_outcome  # deferred: scipy loads on first use

    from hhscatter.analysis.survival.long_time import rate_status  # deferred: scipy loads on first use

    results, n, notes, status = {}, {}, {}, {}
    for key, df in split_points(lifetimes):
        n[key] = len(df)
        if key[1] > 0:
            notes[key] = DISSIPATIVE_NOTE
            continue
        observed = observed_from_outcome(df["outcome"].astype(object).to_numpy())
        try:
            results[key] = r = escape_rate(df["t_end"].to_numpy(dtype=float), observed, t_grid, **kwargs)
        except ValueError as exc:
            notes[key] = f"no fit: {exc}"
            continue
        status[key] = rate_status(df["t_end"].to_numpy(dtype=float), observed, r.tau0, r.t_stop)
        if status[key].note:
            notes[key] = status[key].note
    diss = [k for k, v in notes.items() if v == DISSIPATIVE_NOTE]
    if diss:
        warnings.warn(
            f"escape_rates: κ is the escape rate of the conservative system; not fitted for the dissipative "
            f"point(s) {'; '.join(_label(k) for k in diss)}, whose P(t) is not exponential (paper Sec. III). "
            "Use hhscatter.survival for their P(t) and hhscatter.analysis.dissipative.transitions for τ1, τ2.",
            UserWarning, stacklevel=2)
    return EscapeRates(results, n, notes, status)


# ---------------------------------------------------------------------------
# plots: on the caller's axes, never touching the backend
# ---------------------------------------------------------------------------
def _axes(ax):
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt  # the user's backend, whatever it is  # deferred: matplotlib loads on first use

    return plt.subplots(figsize=(6, 4.2), constrained_layout=True)[1]


def plot_survival(curves: Any, ax: Axes | None = None, *, labels: list[str] | None = None, band: bool = True,
                  logy: bool = True, **line_kwargs: Any) -> Axes:
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
    items = []
    for c in curves if isinstance(curves, list) else [curves]:
        if isinstance(c, SurvivalCurves):
            items.extend((f"{_label(k)} (N={c.n[k]})", v) for k, v in c.curves.items())
        else:
            items.append((None, c))
    if labels is not None:
        if len(labels) != len(items):
            raise ValueError(f"{len(labels)} labels for {len(items)} curves")
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


def plot_escape_rates(rates: EscapeRates | pandas.DataFrame, ax: Axes | None = None, *, x: str = "energy",
                      **errorbar_kwargs: Any) -> Axes:
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
    df = rates.to_frame() if isinstance(rates, EscapeRates) else rates
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


# ---------------------------------------------------------------------------
# more concepts, one function each (per grid point, results with .to_frame() and .plot(ax=))
# ---------------------------------------------------------------------------
def _sorted_keys(keys):
    return sorted(keys, key=lambda k: (np.nan_to_num(k[0], nan=-np.inf), k[1]))


def _same_point(a, b) -> bool:
    """Two (energy, gamma) keys name the same point (energies to 1e-9 relative, NaN equal to NaN)."""
    (ea, ga), (eb, gb) = a, b
    same_e = (math.isnan(ea) and math.isnan(eb)) or (math.isfinite(ea) and math.isfinite(eb)
                                                     and abs(ea - eb) <= E0_RTOL * max(1.0, abs(ea)))
    return same_e and ga == gb


def _split_like(table, keys, *, energy=None, gamma=None, what="table"):
    """{key: rows of ``table`` of that point}: by ``point_energy``/``point_gamma`` (a grid run's sections or
    snapshots); a table without them belongs to the one point of ``keys`` (or to ``energy``/``gamma``)."""
    cols = set(table.columns)
    if {"point_energy", "point_gamma"} <= cols:  # a grid run: the points' nominal E0 and γ, exact values
        out = {}
        for (e, g), df in table.groupby(["point_energy", "point_gamma"], sort=True, dropna=False):
            key = (float(e), float(g))
            match = [k for k in keys if _same_point(k, key)] if keys else [key]
            if match:
                out[match[0]] = df
        return out
    if energy is not None or gamma is not None:
        return {(math.nan if energy is None else float(energy), 0.0 if gamma is None else float(gamma)): table}
    if keys is not None and len(keys) == 1:
        return {keys[0]: table}
    raise ValueError(f"the {what} has no point_energy/point_gamma columns (a plain run): pass energy= and gamma=, "
                     "or the lifetimes of that one run")


@dataclass(frozen=True)
class _PointRows:
    """A result made of one row of numbers per grid point: ``rows[(energy, gamma)]`` → dict."""

    rows: dict

    def __getitem__(self, key):
        return self.rows[key]

    def to_frame(self) -> pandas.DataFrame:
        """to_frame() -> DataFrame, one row per point (sorted by energy, then γ)."""
        import pandas as pd  # deferred: pandas loads on first use

        return pd.DataFrame([self.rows[k] for k in _sorted_keys(self.rows)])


@dataclass(frozen=True)
class CMeasureRates(_PointRows):
    """Result of :func:`kappa_cmeasure`: κ from the c-measure beside κ from P(t), per grid point.

    ``.to_frame()`` columns: energy, gamma, n, kappa_cm, kappa_cm_err (bootstrap over orbits, 1σ), mu_exit
    (μ_c(𝓔)), n_samples, n_exit, n_undetermined, t_from, t_to (the sampling window), t_record_end, kappa_pt,
    kappa_pt_err (κ from P(t) of the same run, :func:`escape_rates`), note (why κ is NaN, else empty).

    Attributes
    ----------
    rows : dict
        (energy, gamma) → dict of the point's numbers (the columns of :meth:`to_frame`).
    """

    def plot(self, ax: Axes | None = None, **errorbar_kwargs: Any) -> Axes:
        """plot(ax=None, **errorbar_kwargs) -> ax: κ from the c-measure and from P(t) against E0."""
        df = self.to_frame()
        ax = _axes(ax)
        kw = {"capsize": 3, **errorbar_kwargs}
        ax.errorbar(df["energy"], df["kappa_pt"], yerr=df["kappa_pt_err"], fmt="o", label="κ from P(t)", **kw)
        ax.errorbar(df["energy"], df["kappa_cm"], yerr=df["kappa_cm_err"], fmt="D", mfc="none",
                    label="κ from the c-measure", **kw)
        ax.set_xlabel("E0")
        ax.set_ylabel("κ")
        ax.legend()
        return ax


def kappa_cmeasure_tables(lifetimes: pandas.DataFrame, sections: pandas.DataFrame, *, window: tuple[float, float],
                          t_max: float, t_from: float | None = None, t_to: float | None = None,
                          rec_efolds: float = 2.0, margin: float = 40.0, n_boot: int = 200,
                          seed: int = 0) -> CMeasureRates:
    """κ from the c-measure of the true-time map, per conservative grid point of a run, beside κ from P(t).

    Solves ∫_Ω e^{κT} dμ_c = 1 + μ_c(𝓔), Eq. (eqn:kappa_cmeasure_truetime), with every section crossing of
    the run in a late window [t_from, t_to] as a sample point of μ_c, T its time to the orbit's next crossing
    and 𝓔 the crossings after which the orbit leaves (:func:`~hhscatter.analysis.survival.cmeasure.kappa_from_cmeasure`,
    bootstrap over orbits). The run's requirements are checked here, from its section window: its sections
    must hold *every* crossing (a ``SectionWindow`` without energy filter, not ``first_only``) and the
    recording must go on after t_to (its end, ``t_record_end`` = min(window ``t_to``, ``t_max``), closes the
    sample: a crossing whose next one would come after it is undetermined, dropped and counted). Orbits still
    inside at ``t_max`` are left out when ``t_max`` > t_record_end (they sit on KAM tori and are not part of the
    c-measure of the chaotic saddle); run with t_max ≫ t_record_end for that. ``hhscatter.kappa_cmeasure(run)``
    reads all of this from a run directory (:func:`kappa_cmeasure`).

    Parameters
    ----------
    lifetimes, sections : DataFrame
        :func:`hhscatter.read_lifetimes` and :func:`hhscatter.read_sections` of one run (a scene or a grid;
        γ > 0 points get NaN and a note).
    window : SectionWindow or dict
        The section window the run recorded (``Scene.sections``).
    t_max : float
        The run's ``t_max`` (time units).
    t_from, t_to : float, optional
        The sampling window (time units). Default per point: t_from = max(window start, ⌈τ0 + rec_efolds/κ⌉)
        with τ0, κ from P(t) of the same point, t_to = t_record_end − ``margin``.
    rec_efolds : float
        e-folds of P(t) after τ0 before sampling starts (the ensemble relaxes towards μ_c).
    margin : float
        Time units kept between t_to and the end of the recording (longer than almost every return time).
    n_boot : int
        Bootstrap replicates over orbits for ``kappa_cm_err``.
    seed : int
        Seed of the bootstrap.

    Returns
    -------
    CMeasureRates
        ``.to_frame()`` one row per point (κ_cm ± err, μ_c(𝓔), the window, κ from P(t) ± err),
        ``.plot(ax=)`` both κ against E0.

    Examples
    --------
    >>> import tempfile, hhscatter
    >>> window = hhscatter.SectionWindow(t_from=10.0, t_to=70.0)       # every crossing in [10, 70]
    >>> scene = hhscatter.Scene(energy=0.3, n=400, seed=1, t_max=1000.0, sections=window)
    >>> run = tempfile.mkdtemp()
    >>> _ = hhscatter.simulate(scene, run, overwrite=True, workers=1, progress=False)
    >>> lt, sec = hhscatter.read_lifetimes(run), hhscatter.read_sections(run)
    >>> from hhscatter.api import kappa_cmeasure_tables
    >>> row = kappa_cmeasure_tables(lt, sec, window=window, t_max=1000.0).to_frame().iloc[0]
    >>> bool(abs(row.kappa_cm - row.kappa_pt) < 3 * (row.kappa_cm_err + row.kappa_pt_err))
    True
    """

    window = _checked_cmeasure_window(window)
    t_max = float(t_max)
    t_record_end = min(float(window.get("t_to", math.inf)), t_max)
    lt, sec = lifetimes, sections
    rates = escape_rates(lt) if any(g == 0 for (_, g), _ in split_points(lt)) else EscapeRates({}, {}, {})
    keys = [k for k, _ in split_points(lt)]
    sec_by = _split_like(sec, keys, what="sections table")
    rows = {}
    for key, df in split_points(lt):
        rows[key] = _cmeasure_point_row(key, df, sec_by.get(key, sec.iloc[:0]), rates, window, t_max, t_record_end,
                                        t_from, t_to, rec_efolds, margin, n_boot, seed)
    return CMeasureRates(rows)


def _checked_cmeasure_window(window) -> dict:
    """The run's section window as a dict, refused unless it records every crossing (no filter, not first_only)."""
    if window is not None and dataclasses.is_dataclass(window):
        window = dataclasses.asdict(window)
    if not window:
        raise ValueError("the run recorded no sections; simulate with sections=SectionWindow(t_from=…, t_to=…) "
                         "(every crossing, no energy filter)")
    if window.get("first_only") or math.isfinite(window.get("e_min", -math.inf)) or \
            math.isfinite(window.get("e_max", math.inf)):
        raise ValueError(f"the c-measure needs every section crossing; the run's window {window} filters them "
                         "(first_only or e_min/e_max): record with a plain SectionWindow(t_from, t_to)")
    return window


def _cmeasure_point_row(key, df, sec, rates, window, t_max, t_record_end, t_from, t_to, rec_efolds, margin,
                        n_boot, seed) -> dict:
    """One grid point's row of :func:`kappa_cmeasure_tables`: its sampling window (time units) from τ0 and κ of
    P(t), the c-measure sample of its crossings in it, κ_cm ± err (1/time) beside κ from P(t), or a note."""
    from hhscatter.analysis.survival.cmeasure import (  # deferred: scipy loads on first use
        cmeasure_sample_from_sections,
        kappa_from_cmeasure,
    )

    row = {"energy": key[0], "gamma": key[1], "n": len(df), "kappa_cm": math.nan, "kappa_cm_err": math.nan,
           "mu_exit": math.nan, "n_samples": 0, "n_exit": 0, "n_undetermined": 0, "t_from": math.nan,
           "t_to": math.nan, "t_record_end": t_record_end, "kappa_pt": math.nan, "kappa_pt_err": math.nan,
           "note": ""}
    r = rates.results.get(key)
    if r is None:
        row["note"] = DISSIPATIVE_NOTE if key[1] > 0 else rates.notes.get(key, "no κ from P(t)")
        return row
    row.update(kappa_pt=r.kappa, kappa_pt_err=r.kappa_err)
    t0 = float(t_from) if t_from is not None else max(float(window.get("t_from", 0.0)),
                                                       math.ceil(r.tau0 + rec_efolds / r.kappa))
    t1 = float(t_to) if t_to is not None else t_record_end - margin
    row.update(t_from=t0, t_to=t1)
    if not t1 > t0 or t0 < float(window.get("t_from", 0.0)) or t1 > t_record_end:
        row["note"] = (f"sampling window [{t0:g}, {t1:g}] does not fit the recording [{window.get('t_from', 0)}, "
                       f"{t_record_end:g}]: record sections until ≥ {t0 + margin + 2 / r.kappa:.0f}")
        return row
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the undetermined count is a column
        T, n_exit, n_und, orb, exit_orb = cmeasure_sample_from_sections(
            sec, df, t0, t1, t_record_end=t_record_end, drop_censored=t_max > t_record_end, with_orbits=True)
    if T.size + n_exit == 0:
        row["note"] = "no section crossing in the sampling window"
        return row
    k = kappa_from_cmeasure(T, n_exit, orbits=orb, exit_orbits=exit_orb, n_boot=n_boot, rng=seed)
    row.update(kappa_cm=k.kappa, kappa_cm_err=k.kappa_err, mu_exit=k.mu_exit, n_samples=k.n_samples,
               n_exit=k.n_exit, n_undetermined=n_und)
    return row


@dataclass(frozen=True)
class TransitionTimes(_PointRows):
    """Result of :func:`transition_times`: τ0, τ1, τ2 per dissipative grid point.

    ``.to_frame()`` columns: energy, gamma, n, tau0, tau1, tau2, tau2_lo, tau2_hi, note (one row per γ > 0).

    Attributes
    ----------
    rows : dict
        (energy, gamma) → dict of the point's numbers (the columns of :meth:`to_frame`).
    """

    def plot(self, ax: Axes | None = None, **plot_kwargs: Any) -> Axes:
        """plot(ax=None, **plot_kwargs) -> ax: τ1 (circles) and τ2 (squares) against γ, log–log, one colour per E0."""
        df = self.to_frame()
        ax = _axes(ax)
        for e, d in df.groupby("energy", sort=True, dropna=False):
            d = d.sort_values("gamma")
            (line,) = ax.plot(d["gamma"], d["tau1"], "o-", label=f"τ1, E0={e:g}", **plot_kwargs)
            ax.plot(d["gamma"], d["tau2"], "s--", color=line.get_color(), label=f"τ2, E0={e:g}", **plot_kwargs)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("γ")
        ax.set_ylabel("time")
        ax.legend()
        return ax


def transition_times(lifetimes: pandas.DataFrame, *, alpha: float = 2.0,
                     t_grid: ArrayLike | None = None) -> TransitionTimes:
    """τ0, τ1 and τ2 of each dissipative grid point, against the conservative point of the same E0.

    * τ0: end of the irregular start of the conservative P_0(t) (:func:`escape_rates` of the γ = 0 point);
    * τ1: first t ≥ τ0 with P_γ(t) ≥ α P_0(t), Eq. (eqn:tau1), where drag starts to matter
      (:func:`~hhscatter.analysis.dissipative.transitions.tau1`, both P(t) by Kaplan–Meier on ``t_grid``);
    * τ2: the first time a non-escaping orbit's energy reached E_c, i.e. the earliest settling time
      (paper Fig. 6b; :func:`~hhscatter.analysis.dissipative.transitions.tau2_observed`), with a 1σ order-statistic
      interval (``tau2_lo``, ``tau2_hi``). The prediction of Eq. (eq:tau2) needs μ:
      :func:`energy_decay` and :func:`~hhscatter.analysis.dissipative.transitions.tau2_predicted`.

    Parameters
    ----------
    lifetimes : DataFrame
        The lifetimes of a grid with γ = 0 and γ > 0 points at the same energies (:func:`hhscatter.read_lifetimes`).
    alpha : float
        The factor α of Eq. (eqn:tau1) (paper: 2).
    t_grid : array, optional
        Times (time units) of the two P(t); default 4001 points from 0 to the latest t_end of the pair.

    Returns
    -------
    TransitionTimes
        ``.to_frame()`` one row per γ > 0 point; ``.plot(ax=)`` τ1 and τ2 against γ. A point without a
        conservative partner, or whose τ1 is never reached, gets NaN and a note.

    Examples
    --------
    >>> import numpy as np, pandas as pd, hhscatter
    >>> rng = np.random.default_rng(0)
    >>> def point(gamma, t):  # synthetic: escapes at rate 0.2 after t = 5; with drag, settling from t = 30 on
    ...     settled = t > 30
    ...     return pd.DataFrame({"energy": 0.3, "gamma": gamma, "t_end": t,
    ...                          "outcome": np.where(settled, "settled", "escaped")})
    >>> t0 = 5 + rng.exponential(5.0, 20000)
    >>> tg = np.where(t0 > 20, 20 + rng.exponential(40.0, 20000), t0)   # from t = 20 on, escape slows down
    >>> lt = pd.concat([point(0.0, t0).assign(outcome="escaped"), point(0.01, tg)])
    >>> row = hhscatter.transition_times(lt).to_frame().iloc[0]
    >>> bool(20 < row.tau1 < 40), bool(row.tau2 > 30)
    (True, True)
    """
    from hhscatter.analysis.dissipative.transitions import (  # deferred: pandas, pyarrow, scipy load on first use
        tau1,
        tau2_observed,
        tau2_observed_interval,
    )
    from hhscatter.analysis.survival.fits import survival_from_lifetimes  # deferred: scipy loads on first use

    points = dict(split_points(lifetimes))
    conservative = lifetimes[lifetimes["gamma"] == 0] if "gamma" in lifetimes.columns else lifetimes
    rates = escape_rates(conservative) if len(conservative) else EscapeRates({}, {}, {})
    rows = {}
    for key, df in points.items():
        if key[1] == 0:
            continue
        t2 = tau2_observed(df)
        iv = tau2_observed_interval(df) if t2 is not None else None
        row = {"energy": key[0], "gamma": key[1], "n": len(df), "tau0": math.nan, "tau1": math.nan,
               "tau2": math.nan if t2 is None else t2, "tau2_lo": math.nan if iv is None else iv.lo,
               "tau2_hi": math.nan if iv is None else iv.hi, "note": ""}
        rows[key] = row
        ref = [k for k in rates.results if _same_point(k, (key[0], 0.0))]
        if not ref:
            row["note"] = "no conservative (γ = 0) point at this E0 with a κ fit: τ0 and τ1 need one"
            continue
        r = rates.results[ref[0]]
        grid = np.asarray(t_grid, dtype=float) if t_grid is not None else np.linspace(
            0.0, float(max(df["t_end"].max(), points[ref[0]]["t_end"].max())), 4001)
        t1 = tau1(grid, survival_from_lifetimes(df, grid).P, survival_from_lifetimes(points[ref[0]], grid).P,
                  r.tau0, alpha)
        row.update(tau0=r.tau0, tau1=math.nan if t1 is None else t1)
        if t1 is None:
            row["note"] = f"P_γ never reaches {alpha:g}·P_0 after τ0"
    return TransitionTimes(rows)


@dataclass(frozen=True)
class EnergyDecay:
    """Result of :func:`energy_decay`: ⟨E⟩(t) and μ per dissipative grid point.

    Attributes
    ----------
    curves : dict
        (energy, gamma) → DataFrame t, n, mean_E, std_E, sem_E, lo_3sigma, hi_3sigma
        (:func:`~hhscatter.analysis.dissipative.decay.mean_energy`).
    fits : dict
        (energy, gamma) → :class:`~hhscatter.analysis.dissipative.decay.EnergyDecayFit` (μ with E(0) = E0 fixed, and free).
    """

    curves: dict
    fits: dict

    def to_frame(self) -> pandas.DataFrame:
        """to_frame() -> DataFrame, one row per point: energy, gamma, mu, mu_err, mu_free, mu_free_err, t_lo, t_hi."""
        import pandas as pd  # deferred: pandas loads on first use

        rows = [{"energy": k[0], "gamma": k[1], "mu": f.mu, "mu_err": f.mu_err, "mu_free": f.mu_free,
                 "mu_free_err": f.mu_free_err, "t_lo": f.window[0], "t_hi": f.window[1]}
                for k, f in ((k, self.fits[k]) for k in _sorted_keys(self.fits))]
        return pd.DataFrame(rows)

    def curves_frame(self):
        """curves_frame() -> DataFrame energy, gamma, t, n, mean_E, sem_E … (all ⟨E⟩(t) curves, tidy)."""
        import pandas as pd  # deferred: pandas loads on first use

        return pd.concat([c.assign(energy=k[0], gamma=k[1]) for k, c in self.curves.items()], ignore_index=True)

    def plot(self, ax: Axes | None = None, **plot_kwargs: Any) -> Axes:
        """plot(ax=None, **plot_kwargs) -> ax: ⟨E⟩(t) per point (log y) with the fitted E0·e^{−μγt} dashed."""
        ax = _axes(ax)
        for key in _sorted_keys(self.curves):
            c, f = self.curves[key], self.fits.get(key)
            (line,) = ax.plot(c["t"], c["mean_E"], label=_label(key), **plot_kwargs)
            if f is not None and math.isfinite(f.mu):
                t = c["t"].to_numpy()
                ax.plot(t, key[0] * np.exp(-f.mu * key[1] * t), "--", color=line.get_color(), lw=1,
                        label=f"μ = {f.mu:.3f}")
        ax.set_yscale("log")
        ax.set_xlabel("t")
        ax.set_ylabel("⟨E⟩(t)")
        ax.legend()
        return ax


def energy_decay(snapshots: pandas.DataFrame, *, window: tuple[float, float] = (0.0, 200.0),
                 energy: float | None = None, gamma: float | None = None) -> EnergyDecay:
    """⟨E⟩(t) of the orbits still inside, and μ of E(t) = E0 e^{−μγt} (Eq. (eqn:energy_exp_decay)), per point.

    ⟨E⟩(t) is the mean energy over the orbits still inside Ω at each snapshot time (the paper's Fig. 3);
    μ is fitted on log⟨E⟩ over ``window`` with the intercept fixed at log E0 (the paper's fit: μ = 0.91 on
    [0, 200] at E0 = 0.3, γ = 0.01) and with a free one (the local exponent)
    (:func:`~hhscatter.analysis.dissipative.decay.fit_energy_decay`). Conservative points (γ = 0) get a curve, no fit.

    Parameters
    ----------
    snapshots : DataFrame
        :func:`hhscatter.read_snapshots` of a run that recorded snapshots (``Scene(snapshots=…)``).
    window : (float, float)
        Fit window (time units).
    energy, gamma : float, optional
        E0 and γ of a plain (non-grid) run, whose snapshots have no ``point_energy``/``point_gamma``.

    Returns
    -------
    EnergyDecay
        ``.to_frame()`` μ per point, ``.curves_frame()`` the ⟨E⟩(t) curves, ``.plot(ax=)`` both.

    Examples
    --------
    >>> import numpy as np, pandas as pd, hhscatter
    >>> t = np.repeat(np.arange(0.0, 201.0, 10.0), 50)                  # 50 orbits, no escapes
    >>> snaps = pd.DataFrame({"traj_id": np.tile(np.arange(50), 21), "t": t,
    ...                       "energy": 0.3 * np.exp(-0.9 * 0.01 * t)})   # E0 = 0.3, μ = 0.9, γ = 0.01
    >>> fit = hhscatter.energy_decay(snaps, energy=0.3, gamma=0.01).to_frame().iloc[0]
    >>> print(f"{fit.mu:.6f} {fit.mu_free:.6f}")
    0.900000 0.900000
    """
    from hhscatter.analysis.dissipative.decay import (  # deferred: pandas, pyarrow load on first use
        fit_energy_decay,
        mean_energy,
    )

    curves, fits = {}, {}
    for key, df in _split_like(snapshots, None, energy=energy, gamma=gamma, what="snapshots table").items():
        c = mean_energy(df)
        curves[key] = c
        if key[1] > 0 and math.isfinite(key[0]):
            fits[key] = fit_energy_decay(c["t"].to_numpy(), c["mean_E"].to_numpy(), key[0], key[1], window)
    return EnergyDecay(curves, fits)


@dataclass(frozen=True)
class CMeasurePoints:
    """Result of :func:`cmeasure_points`: section points (x, y, px, py, t) per grid point.

    Attributes
    ----------
    points : dict
        (energy, gamma) → DataFrame of the selected section crossings (traj_id, t, x, y, px, py, energy).
    """

    points: dict

    def __getitem__(self, key):
        if key in self.points:
            return self.points[key]
        hits = [k for k in self.points if _same_point(k, key)] if isinstance(key, tuple) else []
        if len(hits) == 1:
            return self.points[hits[0]]
        raise KeyError(f"no point {key!r}; points: {list(self.points)}")

    def to_frame(self) -> pandas.DataFrame:
        """to_frame() -> DataFrame point_energy, point_gamma, traj_id, t, x, y, … (every selected crossing)."""
        import pandas as pd  # deferred: pandas loads on first use

        return pd.concat([p.assign(point_energy=k[0], point_gamma=k[1]) for k, p in self.points.items()],
                         ignore_index=True)

    def plot(self, ax: Axes | None = None, *, key: tuple[float, float] | None = None, s: float = 0.5,
             **scatter_kwargs: Any) -> Axes:
        """plot(ax=None, *, key=None, s=0.5, **scatter_kwargs) -> ax: the points in (x, y), one colour per point
        (or only point ``key``)."""
        ax = _axes(ax)
        for k in ([key] if key is not None else _sorted_keys(self.points)):
            p = self[k]
            ax.scatter(p["x"], p["y"], s=s, label=f"{_label(k)} ({len(p)})", **scatter_kwargs)
        ax.set_aspect("equal")
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        ax.legend(markerscale=8)
        return ax


def cmeasure_points(sections: pandas.DataFrame, *, t_from: float, t_to: float = math.inf, first_only: bool = False,
                    e_min: float = -math.inf, e_max: float = math.inf,
                    lifetimes: pandas.DataFrame | None = None) -> CMeasurePoints:
    """Points of the c-measure on the section ṙ = 0, φ̇ > 0: the crossings of the survivors after ``t_from``.

    With ``first_only=False`` every crossing in [t_from, t_to] (the flux measure, paper Fig. 1b); with
    ``first_only=True`` the first crossing of each orbit at t ≥ t_from (the "first intersection for t ≥ t*"
    of the paper's Fig. 5a, :func:`~hhscatter.analysis.geometry.distance.first_crossings`), then kept if its energy is
    in [e_min, e_max] (Fig. 5b). The run must have recorded every crossing from t_from on.

    Parameters
    ----------
    sections : DataFrame
        :func:`hhscatter.read_sections` of a run.
    t_from, t_to : float
        Orbit-time window (time units).
    first_only : bool
        One point per orbit (its first crossing at t ≥ t_from).
    e_min, e_max : float
        Energy band at the crossing.
    lifetimes : DataFrame, optional
        The run's lifetimes, to name the point of a plain run (whose sections have no point columns).

    Returns
    -------
    CMeasurePoints
        ``.to_frame()`` the points, ``.plot(ax=)`` them in (x, y); ``[key]`` one point's DataFrame.

    Examples
    --------
    >>> import pandas as pd, hhscatter
    >>> sec = pd.DataFrame({"traj_id": [1, 1, 2, 2], "t": [5.0, 25.0, 22.0, 30.0], "x": [0.1, 0.2, 0.3, 0.4],
    ...                     "y": 0.0, "px": 0.0, "py": 0.0, "energy": 0.3, "point_energy": 0.3, "point_gamma": 0.0})
    >>> pts = hhscatter.cmeasure_points(sec, t_from=20.0, first_only=True)
    >>> pts[(0.3, 0.0)]["x"].tolist()
    [0.2, 0.3]
    """
    from hhscatter.analysis.geometry.distance import first_crossings  # deferred: pandas, pyarrow load on first use

    keys = [k for k, _ in split_points(lifetimes)] if lifetimes is not None else None
    out = {}
    for key, df in _split_like(sections, keys, what="sections table").items():
        df = df[df["t"] <= t_to]
        if first_only:
            df = first_crossings(df, t_from, e_min=e_min, e_max=e_max)
        else:
            df = df[df["t"] >= t_from]
            if "energy" in df.columns:
                df = df[(df["energy"] >= e_min) & (df["energy"] <= e_max)]
        out[key] = df.drop(columns=["point_energy", "point_gamma"], errors="ignore").reset_index(drop=True)
    return CMeasurePoints(out)


@dataclass(frozen=True)
class CMeasureDistances:
    """Result of :func:`cmeasure_distances`: distances of each point's section points to a reference set.

    Attributes
    ----------
    tables : dict
        (energy, gamma) → :func:`~hhscatter.analysis.geometry.distance.distance_vs_scale` table (one row per box side).
    scales : dict
        (energy, gamma) → agreement scale ε* (:func:`~hhscatter.analysis.geometry.distance.agreement_scale`), or NaN.
    """

    tables: dict
    scales: dict

    def to_frame(self) -> pandas.DataFrame:
        """to_frame() -> DataFrame energy, gamma, box, hellinger, tv, …_noise, …_excess, agreement_scale."""
        import pandas as pd  # deferred: pandas loads on first use

        return pd.concat([self.tables[k].assign(energy=k[0], gamma=k[1], agreement_scale=self.scales[k])
                          for k in _sorted_keys(self.tables)], ignore_index=True)

    def plot(self, ax: Axes | None = None, *, kind: str = "hellinger", **plot_kwargs: Any) -> Axes:
        """plot(ax=None, *, kind='hellinger') -> ax: distance and its split-half noise floor against the box side."""
        ax = _axes(ax)
        for k in _sorted_keys(self.tables):
            d = self.tables[k]
            col = f"{kind}_pq" if f"{kind}_pq" in d else kind
            (line,) = ax.plot(d["box"], d[col], "o-", label=_label(k), **plot_kwargs)
            if f"{kind}_noise" in d:
                ax.plot(d["box"], d[f"{kind}_noise"], ":", color=line.get_color())
        ax.set_xscale("log")
        ax.set_xlabel("box side ε")
        ax.set_ylabel(f"{kind} distance (dotted: noise floor)")
        ax.legend()
        return ax


def cmeasure_distances(points: CMeasurePoints, reference: pandas.DataFrame | np.ndarray,
                       boxes: tuple[float, ...] = (0.4, 0.2, 0.1, 0.05), *, n_splits: int = 8, seed: int = 0,
                       m: int | None = None) -> CMeasureDistances:
    """Hellinger and total-variation distances between each point's section points and a reference set, vs scale.

    Box histograms of the two sets over a common partition at each box side ε, the distance of the full sets,
    and, at a common sample size m, the split-half noise floor (the distance two halves of one set have) and the
    excess over it (:func:`~hhscatter.analysis.geometry.distance.distance_vs_scale`). The agreement scale ε* is the
    smallest box side at which the excess is within noise (:func:`~hhscatter.analysis.geometry.distance.agreement_scale`).
    Beyond the paper (study fig5 compares dissipative points after t* with the conservative c-measure).

    Parameters
    ----------
    points : CMeasurePoints
        The sets to compare (every point of it).
    reference : DataFrame or array (n, 2)
        The reference points (columns x, y), e.g. ``conservative[(0.3, 0.0)]`` of another
        :func:`cmeasure_points`.
    boxes : sequence of float
        Box sides ε (position units).
    n_splits, seed, m
        Split-half repetitions, their seed, the common sample size of the split halves (default: the smallest
        ⌊min(n_P, n_Q)/2⌋ over the points, one m for all, so that their distances and noise floors compare).

    Returns
    -------
    CMeasureDistances
        ``.to_frame()`` one row per (point, box side), ``.plot(ax=)`` distance against ε. A point with fewer
        than 4 section points is left out, with a ``UserWarning`` naming it.

    Examples
    --------
    >>> import numpy as np, pandas as pd, hhscatter
    >>> rng = np.random.default_rng(1)
    >>> ref = pd.DataFrame(rng.uniform(-1, 1, (4000, 2)), columns=["x", "y"])
    >>> same = pd.DataFrame(rng.uniform(-1, 1, (4000, 2)), columns=["x", "y"]).assign(
    ...     point_energy=0.3, point_gamma=0.01, t=50.0, traj_id=np.arange(4000))
    >>> d = hhscatter.cmeasure_distances(hhscatter.cmeasure_points(same, t_from=0.0), ref, boxes=[1.0, 0.5])
    >>> bool((d.to_frame()["hellinger_excess"].abs() < 0.05).all())
    True
    """
    from hhscatter.analysis.geometry.distance import (  # deferred: pandas, pyarrow load on first use
        agreement_scale,
        distance_vs_scale,
    )
    from hhscatter.analysis.geometry.distance import points as xy  # deferred: pandas, pyarrow load on first use

    Q = xy(reference) if hasattr(reference, "columns") else np.asarray(reference, dtype=float)
    tables, scales, few = {}, {}, []
    if m is None and n_splits > 0:  # one sample size for every point, so their noise floors compare
        sizes = [min(len(df), len(Q)) // 2 for df in points.points.values() if len(df) >= 4]
        m = min(sizes) if sizes else None
    for key, df in points.points.items():
        if n_splits > 0 and len(df) < 4:  # the split-half noise floor needs two points per half
            few.append(f"{_label(key)} ({len(df)} points)")
            continue
        t = distance_vs_scale(xy(df), Q, boxes, n_splits=n_splits, seed=seed, m=m)
        tables[key] = t
        eps = agreement_scale(t) if n_splits >= 2 else None
        scales[key] = math.nan if eps is None else float(eps)
    if few:
        warnings.warn(f"cmeasure_distances: left out, too few points: {'; '.join(few)}", UserWarning, stacklevel=2)
    return CMeasureDistances(tables, scales)


#: basin codes of :func:`basin_measures`: the exit channel number for an escape, these two otherwise
SETTLED_BASIN, TRAPPED_BASIN, OUTSIDE_BASIN = 100, 101, -1


def _basin_name(code: int) -> str:
    return {SETTLED_BASIN: "settled", TRAPPED_BASIN: "trapped"}.get(int(code), f"exit {int(code)}")


@dataclass(frozen=True)
class BasinMeasures:
    """Result of :func:`basin_measures`: exit-basin maps and their measures, per grid point.

    Attributes
    ----------
    maps : dict
        (energy, gamma) → int array (ny, nx): exit channel of each cell's orbit, ``SETTLED_BASIN`` (100),
        ``TRAPPED_BASIN`` (101, still inside at t_max), ``OUTSIDE_BASIN`` (−1, no orbit: energetically forbidden).
    fractions : dict
        (energy, gamma) → :class:`~hhscatter.analysis.geometry.basins.BasinFractions` (share of each basin, Wilson 1σ).
    entropy : dict
        (energy, gamma) → :func:`~hhscatter.analysis.geometry.basins.basin_entropy_table` (S_b, S_bb per box side).
    wada : dict
        (energy, gamma) → :class:`~hhscatter.analysis.geometry.basins.WadaTest`, or None (``wada=False``).
    extent : tuple or None
        (x0, x1, y0, y1) of the maps, for :meth:`plot`.
    """

    maps: dict
    fractions: dict
    entropy: dict
    wada: dict
    extent: tuple | None = None

    def to_frame(self) -> pandas.DataFrame:
        """to_frame() -> DataFrame, one row per (point, box side): energy, gamma, box, S_b, S_b_err, S_bb, S_bb_err,
        a column ``share <basin>`` per basin, wada (verdict, or None)."""
        import pandas as pd  # deferred: pandas loads on first use

        parts = []
        for k in _sorted_keys(self.maps):
            fr, w = self.fractions[k], self.wada.get(k)
            shares = {f"share {_basin_name(b)}": float(f) for b, f in zip(fr.basins, fr.frac)}
            parts.append(self.entropy[k][["box", "S_b", "S_b_err", "S_bb", "S_bb_err"]].assign(
                energy=k[0], gamma=k[1], **shares, wada=None if w is None else bool(w.wada)))
        df = pd.concat(parts, ignore_index=True)
        return df[["energy", "gamma", *[c for c in df.columns if c not in ("energy", "gamma")]]]

    def plot(self, ax: Axes | None = None, *, key: tuple[float, float] | None = None,
             **imshow_kwargs: Any) -> Axes:
        """plot(ax=None, *, key=None, **imshow_kwargs) -> ax: the basin map of point ``key`` (default: the first),
        one colour per basin, forbidden cells blank."""
        from matplotlib.colors import ListedColormap  # deferred: matplotlib loads on first use
        from matplotlib.patches import Patch  # deferred: matplotlib loads on first use

        ax = _axes(ax)
        k = key if key is not None else _sorted_keys(self.maps)[0]
        lab = self.maps[k]
        codes = sorted(int(c) for c in np.unique(lab) if c != OUTSIDE_BASIN)
        colours = ["tab:blue", "tab:red", "tab:green", "tab:purple", "tab:brown", "tab:pink"]
        palette = {c: ("0.55" if c == TRAPPED_BASIN else "orange" if c == SETTLED_BASIN else colours[i % 6])
                   for i, c in enumerate(codes)}
        index = np.full(lab.shape, np.nan)
        for i, c in enumerate(codes):
            index[lab == c] = i
        ax.imshow(index, origin="lower", extent=self.extent, interpolation="nearest",
                  cmap=ListedColormap([palette[c] for c in codes]), vmin=-0.5, vmax=len(codes) - 0.5,
                  **imshow_kwargs)
        ax.legend(handles=[Patch(color=palette[c], label=_basin_name(c)) for c in codes], loc="upper right",
                  fontsize="small")
        ax.set_title(_label(k))
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        return ax


def basin_measures(lifetimes: pandas.DataFrame, cell: ArrayLike, shape: tuple[int, int], *,
                   boxes: tuple[int, ...] = (2, 5, 10), extent: tuple[float, float, float, float] | None = None,
                   wada: bool = True) -> BasinMeasures:
    """Exit-basin maps of a grid of initial conditions, per grid point, with their basin measures.

    Each cell of a (ny, nx) grid of initial conditions (e.g. :func:`hhscatter.scene.ics.section_grid`, which also gives
    ``cell``) is coloured by its orbit's fate: the exit channel it escaped through, settled (its energy fell
    below E_c inside Ω, with drag), or trapped (inside at t_max). Measures of each map: the share of every basin
    (:func:`~hhscatter.analysis.geometry.basins.basin_fractions`), the basin entropy S_b and boundary basin entropy S_bb
    at each box side (Daza et al. 2016; :func:`~hhscatter.analysis.geometry.basins.basin_entropy_table`) and the Wada
    test by merging (:func:`~hhscatter.analysis.geometry.basins.wada_merging`, on the basins holding ≥ 0.5 % of the
    cells). Beyond the paper (study basins).

    Parameters
    ----------
    lifetimes : DataFrame
        :func:`hhscatter.read_lifetimes` of runs of those initial conditions (``traj_id`` = row of the IC table;
        several γ concatenated are several points). Needs the columns traj_id, outcome, exit_channel.
    cell : int array (m,)
        Flat (row-major) index into the (ny, nx) grid of IC row i.
    shape : (int, int)
        (ny, nx).
    boxes : sequence of int
        Box sides (cells) of the basin entropy.
    extent : (x0, x1, y0, y1), optional
        The grid's extent, for the plot's axes.
    wada : bool
        Run the Wada test (the slowest part on large maps).

    Returns
    -------
    BasinMeasures
        ``.maps`` the label arrays, ``.to_frame()`` one row per (point, box side), ``.plot(ax=, key=)`` a map.

    Examples
    --------
    >>> import numpy as np, pandas as pd, hhscatter
    >>> lab = np.repeat([0, 1], 32)                                       # left half exit 0, right half exit 1
    >>> cell = np.arange(64 * 64)
    >>> lt = pd.DataFrame({"traj_id": cell, "gamma": 0.0, "e0": 0.3, "outcome": "escaped",
    ...                    "exit_channel": np.tile(lab, 64), "t_end": 1.0})
    >>> m = hhscatter.basin_measures(lt, cell, (64, 64), boxes=[4], wada=False)
    >>> m.maps[(0.3, 0.0)][0, :3].tolist(), m.to_frame()[["box", "share exit 0"]].values.tolist()
    ([0, 0, 0], [[4.0, 0.5]])
    """
    from hhscatter.analysis.geometry.basins import (  # deferred: pandas, pyarrow, scipy load on first use
        basin_entropy_table,
        basin_fractions,
        wada_merging,
    )

    cell = np.asarray(cell, dtype=np.int64).ravel()
    ny, nx = (int(v) for v in shape)
    maps, fracs, ent, wd = {}, {}, {}, {}
    for key, df in split_points(lifetimes):
        df = df.sort_values("traj_id")
        ids = df["traj_id"].to_numpy(dtype=np.int64)
        if ids.size and (ids.min() < 0 or ids.max() >= cell.size):
            raise ValueError(f"traj_id {ids.max()} has no cell: cell holds {cell.size} initial conditions")
        oc = df["outcome"].astype(str).to_numpy()
        code = np.full(ids.size, TRAPPED_BASIN, dtype=np.int64)
        esc = oc == "escaped"
        code[esc] = df["exit_channel"].to_numpy(dtype=float, na_value=-1)[esc].astype(np.int64)
        code[oc == "settled"] = SETTLED_BASIN
        img = np.full(ny * nx, OUTSIDE_BASIN, dtype=np.int64)
        img[cell[ids]] = code
        lab = img.reshape(ny, nx)
        maps[key] = lab
        fracs[key] = basin_fractions(lab, outside=OUTSIDE_BASIN)
        ent[key] = basin_entropy_table(lab, boxes, outside=OUTSIDE_BASIN)
        present = [int(b) for b, f in zip(fracs[key].basins, fracs[key].frac) if f >= 0.005]
        wd[key] = wada_merging(lab, basins=present, outside=OUTSIDE_BASIN) if wada and len(present) >= 3 else None
    return BasinMeasures(maps, fracs, ent, wd, None if extent is None else tuple(float(v) for v in extent))


# -- entry points that start from a run directory (the analysis layer itself reads no files) --

def run_scene(run) -> dict:
    """run_scene(run) -> the scene dict a run directory was written with (``scene.json``; infinities decoded).

    Raises ValueError if ``run`` holds no ``scene.json`` (not a run of :func:`hhscatter.simulate`).
    """
    from hhscatter.run.plan import SCENE_FILE, _decode  # deferred: pydantic loads on first use

    store = Store(run)
    if not store.exists(SCENE_FILE):
        raise ValueError(f"{run}: no {SCENE_FILE}: not a run directory written by hhscatter.simulate")
    return _decode(json.loads(store.read_text(SCENE_FILE))["scene"])


def kappa_cmeasure(run: str | os.PathLike[str], **kwargs: Any) -> CMeasureRates:
    """κ from the c-measure of a run's section crossings, per conservative grid point, beside κ from P(t).

    Parameters
    ----------
    run : str or Path
        A run directory of :func:`hhscatter.simulate` whose scene recorded every section crossing
        (``sections=SectionWindow(t_from=…, t_to=…)``, no energy filter, not ``first_only``).
    **kwargs
        ``t_from``, ``t_to``, ``rec_efolds``, ``margin``, ``n_boot``, ``seed`` of
        :func:`kappa_cmeasure_tables`, which does the work (its docstring has the method).

    Returns
    -------
    CMeasureRates
        ``.to_frame()`` one row per point (κ_cm ± err, μ_c(𝓔), the sampling window, κ from P(t) ± err),
        ``.plot(ax=)`` both κ against E0.

    Examples
    --------
    >>> import tempfile, hhscatter
    >>> scene = hhscatter.Scene(energy=0.3, n=400, seed=1, t_max=1000.0,
    ...                         sections=hhscatter.SectionWindow(t_from=10.0, t_to=70.0))
    >>> run = tempfile.mkdtemp()
    >>> _ = hhscatter.simulate(scene, run, overwrite=True, workers=1, progress=False)
    >>> hhscatter.kappa_cmeasure(run).to_frame()[["energy", "t_record_end", "note"]].values.tolist()
    [[0.3, 70.0, '']]
    """
    scene = run_scene(run)
    if not scene.get("sections"):
        raise ValueError(f"{run}: the run recorded no sections; simulate with sections=SectionWindow(t_from=…, "
                         "t_to=…) (every crossing, no energy filter)")
    return kappa_cmeasure_tables(read_lifetimes(run), read_sections(run), window=scene["sections"],
                       t_max=float(scene["t_max"]), **kwargs)


def stream_survival(run: str | os.PathLike[str], t_grid: ArrayLike, filters: Any = None, *,
                    allow_partial: bool = False):
    """stream_survival(run, t_grid, filters=None) -> SurvivalCurve(t, P, P_err) of a run's lifetimes at the grid times.

    P(t) = Pr(lifetime > t) (paper Eqs. (eqn:kappa_hyperbolic), (eqn:kappa_nonhyperbolic)) streamed over the run's
    lifetimes table in record batches (:func:`hhscatter.data.read.iter_survival_batches`) into
    :class:`hhscatter.analysis.survival.kaplan_meier.KaplanMeierGrid`: memory O(len(t_grid) + one batch), whatever
    N (1e9 orbits fit). hhscatter censors orbits only at t_max, so for t below every censoring time the estimate is
    exact (the fraction #{t_end > t}/N, Greenwood's error the binomial √(P(1−P)/N)).

    Parameters
    ----------
    run : str or Path
        A run directory of :func:`hhscatter.simulate`.
    t_grid : array_like
        Increasing times (time units).
    filters : pyarrow filter, optional
        Rows to keep, e.g. one point of a grid run.
    allow_partial : bool
        Read the finished chunks of an unfinished run (with a warning).

    Returns
    -------
    SurvivalCurve
        ``t``, ``P``, ``P_err`` at the grid times.

    Raises
    ------
    ValueError
        If some orbit was censored before max(t_grid) (use :func:`hhscatter.survival` then).
    """

    km = KaplanMeierGrid(t_grid)
    for t_end, observed in iter_survival_batches(run, filters, allow_partial=allow_partial):
        km.add(t_end, observed)
        if km.first_censoring < km.grid[-1]:
            raise ValueError(f"an orbit was censored at t = {km.first_censoring:g} < max(t_grid) = "
                             f"{km.grid[-1]:g}: use survival_curve (Kaplan–Meier) for this run")
    return km.curve()
