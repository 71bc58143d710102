"""Dissipative grid points: the transition times τ0, τ1, τ2 and the energy decay ⟨E⟩(t) with its μ."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from hhscatter.api import checks
from hhscatter.api.plotting import _axes
from hhscatter.api.points import (
    _key_columns,
    _label,
    _PointRows,
    _same_point,
    _sorted_keys,
    _split_like,
    split_points,
)
from hhscatter.api.rates import EscapeRates, escape_rates
from hhscatter.data.params import FRAME_META, plain_point
from hhscatter.errors import ConfigError

if TYPE_CHECKING:  # annotations only: pandas and matplotlib are imported when a function runs
    import pandas
    from matplotlib.axes import Axes
    from numpy.typing import ArrayLike


@dataclass(frozen=True)
class TransitionTimes(_PointRows):
    """Result of :func:`transition_times`: τ0, τ1, τ2 per dissipative grid point.

    ``.to_frame()`` columns: energy, gamma, n, tau0, tau1, tau2, tau2_lo, tau2_hi, partner (the conservative
    point τ0 and τ1 come from, "" without one), note (one row per γ > 0).

    Attributes
    ----------
    rows : dict
        (energy, gamma) → dict of the point's numbers (the columns of :meth:`to_frame`).
    """

    def plot(self, ax: Axes | None = None, **plot_kwargs: Any) -> Axes:
        """Draw τ1 (circles) and τ2 (squares) against γ, log–log, one colour per E0; returns the axes."""
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


def transition_times(
    lifetimes: pandas.DataFrame, *, alpha: float = 2.0, t_grid: ArrayLike | None = None
) -> TransitionTimes:
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
        ``.to_frame()`` one row per γ > 0 point, with the ``partner`` it was compared with; ``.plot(ax=)`` τ1 and
        τ2 against γ. A point without a conservative partner, or whose τ1 is never reached, gets NaN and a note.

    The partner is the γ = 0 point of the same E0 in the same run; in a frame of several runs
    (:func:`hhscatter.read_lifetimes` of a list) another run's γ = 0 point is a partner only if its scene has the
    same system, initial conditions (region, radius, table, seed), escape rule (r_esc, r_far) and noise
    (:data:`hhscatter.api.checks.PAIRING_KEYS`); the note names a refused one and how it differs.

    Raises
    ------
    ConfigError
        ``lifetimes`` is not a lifetimes table, holds no γ > 0 point, ``alpha`` ≤ 1 or ``t_grid`` is not a grid
        of times.

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
    >>> bool(20 < row.tau1 < 40), bool(row.tau2 > 30), row.partner
    (True, True, 'E0=0.3, γ=0')
    """
    from hhscatter.analysis.dissipative.transitions import (  # deferred: pandas, pyarrow, scipy load on first use
        tau1,
        tau2_observed,
        tau2_observed_interval,
    )
    from hhscatter.analysis.survival.fits import survival_from_lifetimes  # deferred: scipy loads on first use

    checks.frame(lifetimes, "lifetimes", needs=("t_end", "outcome"))
    alpha = checks.number(alpha, "alpha", lo=1.0, lo_open=True)
    t_grid = checks.time_grid(t_grid)
    points = dict(split_points(lifetimes))
    if not any(k[1] > 0 for k in points):
        raise ConfigError(
            "transition_times needs dissipative (γ > 0) points beside their γ = 0 partners; the lifetimes hold "
            f"only γ = 0 ({', '.join(_label(k) for k in _sorted_keys(points))}): read a run with drag as well"
        )
    conservative = lifetimes[lifetimes["gamma"] == 0] if "gamma" in lifetimes.columns else lifetimes
    rates = escape_rates(conservative) if len(conservative) else EscapeRates({}, {}, {})
    scenes = _run_scenes(lifetimes)
    rows = {}
    for key, df in points.items():
        if key[1] == 0:
            continue
        t2 = tau2_observed(df)
        iv = tau2_observed_interval(df) if t2 is not None else None
        row = {
            **_key_columns(key),
            "n": len(df),
            "tau0": math.nan,
            "tau1": math.nan,
            "tau2": math.nan if t2 is None else t2,
            "tau2_lo": math.nan if iv is None else iv.lo,
            "tau2_hi": math.nan if iv is None else iv.hi,
            "partner": "",
            "note": "",
        }
        rows[key] = row
        same_e = [k for k in rates.n if _same_point(k[:2], (key[0], 0.0))]
        ref = [k for k in same_e if k[2:] == key[2:]]  # the same run's partner (a grid run, or one table)
        refused = []
        if not ref:  # another run's γ = 0 point: only of the same system, initial conditions and escape rule
            for k in same_e:
                diff = checks.scene_differences(scenes.get(_run_of(key)), scenes.get(_run_of(k)))
                (refused if diff else ref).append((k, diff) if diff else k)
        if not ref:
            row["note"] = "no conservative (γ = 0) point at this E0 with a κ fit: τ0 and τ1 need one" + (
                "; not paired with "
                + "; ".join(f"{_label(k)}, which differs in {', '.join(d)}" for k, d in refused)
                + " (pairing needs the same system, initial conditions, escape rule and noise)"
                if refused
                else ""
            )
            continue
        if len(ref) > 1:
            row["note"] = (
                f"{len(ref)} conservative points at this E0 ({', '.join(_label(k) for k in ref)}): "
                "τ0 and τ1 need one; read the pair alone"
            )
            continue
        row["partner"] = _label(ref[0])
        r = rates.results.get(ref[0])
        if r is None:
            row["note"] = f"the conservative partner {_label(ref[0])} has no κ fit ({rates.notes.get(ref[0], '')})"
            continue
        grid = (
            t_grid
            if t_grid is not None
            else np.linspace(0.0, float(max(df["t_end"].max(), points[ref[0]]["t_end"].max())), 4001)
        )
        t1 = tau1(
            grid, survival_from_lifetimes(df, grid).P, survival_from_lifetimes(points[ref[0]], grid).P, r.tau0, alpha
        )
        row.update(tau0=r.tau0, tau1=math.nan if t1 is None else t1)
        if t1 is None:
            row["note"] = f"P_γ never reaches {alpha:g}·P_0 after τ0"
    return TransitionTimes(rows)


def _run_of(key):
    """The run a point key names (a frame of several runs), else None (one run)."""
    return key[2] if len(key) > 2 else None


def _run_scenes(lifetimes) -> dict:
    """{run name (None for a frame of one run): its scene dict} from what the readers attached to the frame."""
    meta = getattr(lifetimes, "attrs", {}).get(FRAME_META) or {}
    if "scene" in meta:
        return {None: meta["scene"]}
    return {str(r.get("run")): r.get("scene") for r in meta.get("runs") or []}


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
        """μ per point as a DataFrame: energy, gamma, mu, mu_err, mu_free, mu_free_err, t_lo, t_hi."""
        import pandas as pd  # deferred: pandas loads on first use

        rows = [
            {
                "energy": k[0],
                "gamma": k[1],
                "mu": f.mu,
                "mu_err": f.mu_err,
                "mu_free": f.mu_free,
                "mu_free_err": f.mu_free_err,
                "t_lo": f.window[0],
                "t_hi": f.window[1],
            }
            for k, f in ((k, self.fits[k]) for k in _sorted_keys(self.fits))
        ]
        return pd.DataFrame(rows)

    def curves_frame(self):
        """Every ⟨E⟩(t) curve in one tidy DataFrame: energy, gamma, t, n, mean_E, sem_E …"""
        import pandas as pd  # deferred: pandas loads on first use

        return pd.concat([c.assign(energy=k[0], gamma=k[1]) for k, c in self.curves.items()], ignore_index=True)

    def plot(self, ax: Axes | None = None, **plot_kwargs: Any) -> Axes:
        """Draw ⟨E⟩(t) per point (log y) with the fitted E0·e^{−μγt} dashed; returns the axes."""
        ax = _axes(ax)
        for key in _sorted_keys(self.curves):
            c, f = self.curves[key], self.fits.get(key)
            (line,) = ax.plot(c["t"], c["mean_E"], label=_label(key), **plot_kwargs)
            if f is not None and math.isfinite(f.mu):
                t = c["t"].to_numpy()
                ax.plot(
                    t, key[0] * np.exp(-f.mu * key[1] * t), "--", color=line.get_color(), lw=1, label=f"μ = {f.mu:.3f}"
                )
        ax.set_yscale("log")
        ax.set_xlabel("t")
        ax.set_ylabel("⟨E⟩(t)")
        ax.legend()
        return ax


def energy_decay(
    snapshots: pandas.DataFrame,
    *,
    window: tuple[float, float] = (0.0, 200.0),
    energy: float | None = None,
    gamma: float | None = None,
) -> EnergyDecay:
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
        E0 and γ of a plain (non-grid) run, whose snapshots have no ``point_energy``/``point_gamma``: read
        from the data (the run's scene.json, which :func:`hhscatter.read_snapshots` attaches; else E0 from
        the snapshots' energy at t = 0). A value passed here that contradicts the data raises ValueError
        (:func:`hhscatter.data.params.plain_point`).

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

    checks.frame(
        snapshots,
        "snapshots",
        needs=("traj_id", "t", "energy"),
        what="a snapshots table",
        reader="hhscatter.read_snapshots(run)",
    )
    checks.numeric_columns(snapshots, "snapshots", nonneg=("t",), finite=("energy",))
    window = checks.window(window)
    if energy is not None:
        energy = checks.number(energy, "energy")
    if gamma is not None:
        gamma = checks.number(gamma, "gamma", lo=0.0)
    curves, fits = {}, {}
    energy, gamma = plain_point(snapshots, energy, gamma, what="snapshots table")
    for key, df in _split_like(snapshots, None, energy=energy, gamma=gamma, what="snapshots table").items():
        c = mean_energy(df)
        curves[key] = c
        if key[1] > 0 and math.isfinite(key[0]):
            fits[key] = fit_energy_decay(c["t"].to_numpy(), c["mean_E"].to_numpy(), key[0], key[1], window)
    return EnergyDecay(curves, fits)
