"""Survival and escape rates: Kaplan–Meier P(t) and κ per grid point, and P(t) streamed from a run directory."""

from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from hhscatter.analysis.survival.kaplan_meier import KaplanMeierGrid
from hhscatter.api import checks
from hhscatter.api.plotting import plot_escape_rates, plot_survival
from hhscatter.api.points import _key_columns, _label, _sorted_keys, split_points
from hhscatter.data.read import iter_survival_batches
from hhscatter.errors import ConfigError

if TYPE_CHECKING:  # annotations only: pandas and matplotlib are imported when a function runs
    import pandas
    from matplotlib.axes import Axes
    from numpy.typing import ArrayLike


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
        hits = [k for k in self.curves if (k[0] == key if not isinstance(key, tuple) else k[: len(key)] == key)]
        if len(hits) == 1:
            return self.curves[hits[0]]
        raise KeyError(f"no single point {key!r}; points: {list(self.curves)}")

    def to_frame(self) -> pandas.DataFrame:
        """The curves as one DataFrame: energy, gamma, n, t, P, P_err (one row per curve step or grid time)."""
        import pandas as pd  # deferred: pandas loads on first use

        parts = [
            pd.DataFrame({**_key_columns(k), "n": self.n[k], "t": c.t, "P": c.P, "P_err": c.P_err})
            for k, c in self.curves.items()
        ]
        return pd.concat(parts, ignore_index=True)

    def plot(self, ax: Axes | None = None, **kwargs: Any) -> Axes:
        """Draw these curves with :func:`plot_survival`; returns the axes."""
        return plot_survival(self, ax=ax, **kwargs)


def survival(lifetimes: pandas.DataFrame, t_grid: ArrayLike | None = None) -> SurvivalCurves:
    """Survival probability P(t), one Kaplan–Meier curve per grid point.

    Kaplan–Meier P(t) = Pr(lifetime > t) (paper Eqs. (eqn:kappa_hyperbolic), (eqn:kappa_nonhyperbolic)) with
    Greenwood errors (:func:`~hhscatter.analysis.survival.fits.survival_curve`) of each ensemble of
    ``lifetimes`` (see :func:`split_points`); 'escaped' and 'settled' end a lifetime, 'censored' orbits
    are right-censored.

    Parameters
    ----------
    lifetimes : DataFrame, or str or Path of a run directory
        :func:`hhscatter.read_lifetimes` of a run (columns ``t_end``, ``outcome``, ``gamma`` and
        ``energy`` or ``e0``), or any frame with those columns; or the run directory itself, of which only
        those columns are read (outcome as categories: about 25 bytes per orbit).
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

    t_grid = checks.time_grid(t_grid)
    if isinstance(lifetimes, (str, os.PathLike)):
        lifetimes = _point_columns(lifetimes)
    curves, n = {}, {}
    for key, df in split_points(lifetimes):
        observed = observed_from_outcome(df["outcome"].astype(object).to_numpy())
        curves[key] = survival_curve(df["t_end"].to_numpy(dtype=float), observed, t_grid)
        n[key] = len(df)
    return SurvivalCurves(curves, n)


DISSIPATIVE_NOTE = "dissipative (γ > 0): P(t) is not exponential, no κ fitted"


def _point_columns(run):
    """The lifetimes of run directory ``run`` with only what P(t) and κ need (t_end, outcome as categories, γ and
    the point's energy): about 25 bytes per orbit instead of the whole table."""
    from hhscatter.api.runs import run_scene  # deferred: pydantic loads on first use
    from hhscatter.data.read import read_lifetimes  # deferred: pyarrow loads on first use

    checks.run_dir(run, "lifetimes")
    scene = run_scene(run)
    grid = any(isinstance(scene.get(k), list) for k in ("energy", "gamma"))
    return read_lifetimes(run, columns=["t_end", "outcome", "gamma", "energy" if grid else "e0"], categorical=True)


def _check_rate_options(kwargs: dict) -> None:
    """The options :func:`escape_rates` passes on: names of :func:`~hhscatter.analysis.survival.escape_rate.escape_rate`
    and of the window choice, each of its default's kind (a flag a bool, a number a finite number ≥ 0)."""
    import inspect  # deferred: only for the option check

    from hhscatter.analysis.survival.escape_rate import escape_rate  # deferred: scipy loads on first use
    from hhscatter.analysis.survival.windows import choose_windows  # deferred: scipy loads on first use

    known = {
        p.name: p.default
        for f in (escape_rate, choose_windows)
        for p in inspect.signature(f).parameters.values()
        if p.kind is p.KEYWORD_ONLY and p.name != "n_total"
    }
    for k, v in kwargs.items():
        if k not in known:
            raise ConfigError(f"escape_rates has no option {k!r}; its options: {', '.join(sorted(known))}")
        d = known[k]
        if isinstance(d, bool) and not isinstance(v, bool):
            raise ConfigError(f"{k} must be True or False, got {checks.describe(v)}")
        if isinstance(d, int) and not isinstance(d, bool):
            checks.number(v, k, lo=1, integer=True)
        elif isinstance(d, float):
            checks.number(v, k, lo=0.0)
        elif k == "tail_kwargs" and v is not None and not isinstance(v, dict):
            raise ConfigError(f"tail_kwargs must be a dict of options, got {checks.describe(v)}")


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
        the population (a plateau of censored orbits, a non-exponential decay).
    status : dict
        (energy, gamma) → :class:`~hhscatter.analysis.survival.long_time.RateStatus` of each fitted point:
        'exponential', 'trapped' (a legacy value: censored orbits bias the window, see the glossary),
        'non-exponential', 'too few orbits' (no verdict on one exponential) or 'empty' (no orbit left after τ0),
        with P∞ and κ_tail of the plateau-plus-exponential fit.

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
        """The rates as a DataFrame, one row per point.

        Columns: energy, gamma, n, kappa, kappa_err (1σ: spread of the 4 window
        fits and statistics), kappa_stat, kappa_spread, tau0, t_stop, windows
        (the 4 (t_lo, t_hi) fit windows), kappa_mle, kappa_mle_err (maximum
        likelihood on [tau0, t_stop]), tau_star (NaN without power-law tail),
        status ('exponential', 'trapped' (legacy value: censored orbits bias the window), 'non-exponential',
        'too few orbits', 'empty'; "" where not fitted), p_inf, kappa_inf (the
        plateau-plus-exponential fit from τ0), note (why κ is NaN or not the population's rate, else empty).
        """
        import pandas as pd  # deferred: pandas loads on first use

        rows = []
        for key in _sorted_keys(self.n):
            r = self.results.get(key)
            row = {**_key_columns(key), "n": self.n[key]}
            if r is None:
                row.update(
                    kappa=math.nan,
                    kappa_err=math.nan,
                    kappa_stat=math.nan,
                    kappa_spread=math.nan,
                    tau0=math.nan,
                    t_stop=math.nan,
                    windows=None,
                    kappa_mle=math.nan,
                    kappa_mle_err=math.nan,
                    tau_star=math.nan,
                )
            else:
                row.update(
                    kappa=r.kappa,
                    kappa_err=r.kappa_err,
                    kappa_stat=r.kappa_stat,
                    kappa_spread=r.kappa_spread,
                    tau0=r.tau0,
                    t_stop=r.t_stop,
                    windows=[tuple(float(x) for x in w) for w in r.windows],
                    kappa_mle=r.mle.kappa,
                    kappa_mle_err=r.mle.kappa_err,
                    tau_star=r.tau_star,
                )
            st = self.status.get(key)
            row.update(
                status=st.status if st else "",
                p_inf=st.p_inf if st else math.nan,
                kappa_inf=st.kappa_inf if st else math.nan,
            )
            row["note"] = self.notes.get(key, "")
            rows.append(row)
        return pd.DataFrame(rows)

    def plot(self, ax: Axes | None = None, **kwargs: Any) -> Axes:
        """Draw these rates with :func:`plot_escape_rates`; returns the axes."""
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
    lifetimes : DataFrame, or str or Path of a run directory
        :func:`hhscatter.read_lifetimes` of a run, or any frame with its columns, or the run directory (only the
        columns κ needs are read; see :func:`survival`).
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
        (censored) bias the window (status 'trapped', a legacy value), whose decay is not one exponential ('non-exponential') or has too
        few orbits to tell ('too few orbits') says so in
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

    t_grid = checks.time_grid(t_grid)
    _check_rate_options(kwargs)
    if isinstance(lifetimes, (str, os.PathLike)):
        lifetimes = _point_columns(lifetimes)
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
            UserWarning,
            stacklevel=2,
        )
    return EscapeRates(results, n, notes, status)


def stream_survival(
    run: str | os.PathLike[str], t_grid: ArrayLike, filters: Any = None, *, allow_partial: bool = False
):
    """P(t) of a run's lifetimes at the grid times, streamed from its table in bounded memory.

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

    checks.run_dir(run)
    km = KaplanMeierGrid(checks.time_grid(t_grid))
    for t_end, observed in iter_survival_batches(run, filters, allow_partial=allow_partial):
        km.add(t_end, observed)
        if km.first_censoring < km.grid[-1]:
            raise ConfigError(
                f"an orbit was censored at t = {km.first_censoring:g} < max(t_grid) = "
                f"{km.grid[-1]:g}: use survival_curve (Kaplan–Meier) for this run"
            )
    return km.curve()
