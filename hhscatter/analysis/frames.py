"""Notebook API: P(t) and κ of a lifetimes DataFrame, one result per grid point, and plots on your axes.

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

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

__all__ = [
    "EscapeRates",
    "SurvivalCurves",
    "escape_rates",
    "plot_escape_rates",
    "plot_survival",
    "split_points",
    "survival",
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

    - ``curves``: dict (energy, gamma) → :class:`~hhscatter.analysis.survival.SurvivalCurve` (t, P, P_err)
    - ``n``: dict (energy, gamma) → number of orbits N
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

    def to_frame(self):
        """to_frame() -> DataFrame energy, gamma, n, t, P, P_err (one row per curve step or grid time)."""
        import pandas as pd

        parts = [pd.DataFrame({"energy": k[0], "gamma": k[1], "n": self.n[k], "t": c.t, "P": c.P, "P_err": c.P_err})
                 for k, c in self.curves.items()]
        return pd.concat(parts, ignore_index=True)

    def plot(self, ax=None, **kwargs):
        """plot(ax=None, **kwargs) -> ax: :func:`plot_survival` of these curves."""
        return plot_survival(self, ax=ax, **kwargs)


def survival(lifetimes, t_grid=None) -> SurvivalCurves:
    """survival(lifetimes, t_grid=None) -> SurvivalCurves, one P(t) per grid point.

    Kaplan–Meier P(t) = Pr(lifetime > t) (paper Eqs. (1), (2)) with Greenwood
    errors (:func:`~hhscatter.analysis.survival.survival_curve`) of each
    ensemble of ``lifetimes`` (see :func:`split_points`); 'escaped' and
    'settled' end a lifetime, 'censored' orbits are right-censored. Without
    ``t_grid`` each curve has a step at every distinct event time; with it,
    P at those times (time units).
    """
    from .survival import observed_from_outcome, survival_curve

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

    - ``results``: dict (energy, gamma) → :class:`~hhscatter.analysis.escape_rate.EscapeRateResult`
      (only the conservative points that were fitted)
    - ``n``: dict (energy, gamma) → N
    - ``notes``: dict (energy, gamma) → why a point has no κ
    """

    results: dict
    n: dict
    notes: dict = field(default_factory=dict)

    def __getitem__(self, key):
        return self.results[key]

    def to_frame(self):
        """to_frame() -> DataFrame, one row per point.

        Columns: energy, gamma, n, kappa, kappa_err (1σ: spread of the 4 window
        fits and statistics), kappa_stat, kappa_spread, tau0, t_stop, windows
        (the 4 (t_lo, t_hi) fit windows), kappa_mle, kappa_mle_err (maximum
        likelihood on [tau0, t_stop]), tau_star (NaN without power-law tail),
        note (why κ is NaN, else empty).
        """
        import pandas as pd

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
            row["note"] = self.notes.get(key, "")
            rows.append(row)
        return pd.DataFrame(rows)

    def plot(self, ax=None, **kwargs):
        """plot(ax=None, **kwargs) -> ax: :func:`plot_escape_rates` of these rates."""
        return plot_escape_rates(self, ax=ax, **kwargs)


def escape_rates(lifetimes, t_grid=None, **kwargs) -> EscapeRates:
    """escape_rates(lifetimes, t_grid=None, **kwargs) -> EscapeRates: κ ± error, τ0, windows per grid point.

    For each conservative (γ = 0) ensemble of ``lifetimes`` (:func:`split_points`),
    :func:`~hhscatter.analysis.escape_rate.escape_rate`: τ0 and 4 fit windows
    chosen from the data, κ the mean of 4 weighted least-squares fits of
    log P(t) (paper Fig. 2b), its error, an MLE cross-check and the power-law
    tail / τ* when there is one. ``kwargs`` go to that function (e.g.
    ``detect_tail=False``, ``min_survivors=…``). Dissipative points (γ > 0) are
    not fitted (module doc): their rows have NaN and a note, and a
    ``UserWarning`` names them. A point whose fit fails (too few orbits for
    the window choice) gets NaN and the reason as its note.
    """
    from .escape_rate import escape_rate
    from .survival import observed_from_outcome

    results, n, notes = {}, {}, {}
    for key, df in split_points(lifetimes):
        n[key] = len(df)
        if key[1] > 0:
            notes[key] = DISSIPATIVE_NOTE
            continue
        observed = observed_from_outcome(df["outcome"].astype(object).to_numpy())
        try:
            results[key] = escape_rate(df["t_end"].to_numpy(dtype=float), observed, t_grid, **kwargs)
        except ValueError as exc:
            notes[key] = f"no fit: {exc}"
    diss = [k for k, v in notes.items() if v == DISSIPATIVE_NOTE]
    if diss:
        warnings.warn(
            f"escape_rates: κ is the escape rate of the conservative system; not fitted for the dissipative "
            f"point(s) {'; '.join(_label(k) for k in diss)}, whose P(t) is not exponential (paper Sec. III). "
            "Use hhscatter.survival for their P(t) and hhscatter.analysis.transitions for τ1, τ2.",
            UserWarning, stacklevel=2)
    return EscapeRates(results, n, notes)


# ---------------------------------------------------------------------------
# plots: on the caller's axes, never touching the backend
# ---------------------------------------------------------------------------
def _axes(ax):
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt  # the user's backend, whatever it is

    return plt.subplots(figsize=(6, 4.2), constrained_layout=True)[1]


def plot_survival(curves, ax=None, *, labels=None, band=True, logy=True, **line_kwargs):
    """plot_survival(curves, ax=None, *, labels=None, band=True, logy=True, **line_kwargs) -> ax.

    Draws P(t) as steps, one line per curve, with a ±1σ band (``band``), on
    ``ax`` (default: a new pyplot figure). ``curves``: a :class:`SurvivalCurves`,
    one :class:`~hhscatter.analysis.survival.SurvivalCurve`, or a list of
    either. ``labels``: one per curve (default "E0=…, γ=…"). Log-scale P by
    default (the final P = 0 step is not drawn). Does not change the
    matplotlib backend, does not save or show the figure.
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


def plot_escape_rates(rates, ax=None, *, x="energy", **errorbar_kwargs):
    """plot_escape_rates(rates, ax=None, *, x='energy', **errorbar_kwargs) -> ax.

    κ ± kappa_err against ``x`` (a column of ``rates.to_frame()``, default the
    energy), one series per γ, on ``ax`` (default: a new pyplot figure).
    ``rates``: an :class:`EscapeRates` or its ``to_frame()``. Points without κ
    are skipped. Does not change the matplotlib backend.
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
