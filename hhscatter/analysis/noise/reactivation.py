"""P(t) in a heat bath: the drag-only survival model extended by the thermal re-escape of settled orbits.

Without noise (T = 0) an orbit of the dissipative ensemble either escapes during the transient (at t_i) or
settles in the well (at τ_j, its energy crossing E_c inside Ω) and stays there for ever: P_0(t) → f_s, the
settled fraction. In a heat bath a settled orbit is re-activated: it escapes over a saddle at the thermal
rate k (Kramers; measured independently from orbits started in the well). The extension, with no free
parameter once k is known:

    P_T(t) = (1/N) [ #{escapers: t_i > t} + Σ_{settled j} (1 if t < τ_j else e^{−k (t − τ_j)}) ],

i.e. the noise is assumed to leave the transient alone and to act only through re-activation; at long times
P_T(t) ≈ f_s e^{−k (t − τ̄)}. Comparing it with the measured P_T(t) tests both assumptions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from hhscatter.analysis.noise.kramers import ThermalRate, thermal_rate
from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.survival.kaplan_meier import survival_curve
from hhscatter.errors import ConfigError

__all__ = ["ReactivationCheck", "reactivation_check", "reactivation_survival"]


def reactivation_survival(t, t_end, escaped, settled, rate: float) -> np.ndarray:
    """reactivation_survival(t, t_end, escaped, settled, rate) -> P_T(t) of the module docstring at times ``t``.

    Parameters
    ----------
    t : array
        Times (time units).
    t_end, escaped, settled : arrays (N,)
        The drag-only (T = 0) ensemble: each orbit's end time and whether it escaped or settled there
        (neither: censored at t_end, counted alive up to it and unknown after, so ``t`` must not pass the
        earliest censoring time).
    rate : float
        The thermal escape rate k of a settled orbit (1/time).

    Examples
    --------
    Every orbit settled at τ = 0: P_T(t) = e^{−kt}; one of two escaping at t = 1 first: the mean of both.

    >>> reactivation_survival([0.0, 2.0], [0.0, 0.0], [False, False], [True, True], 0.5).round(6)
    array([1.      , 0.367879])
    >>> reactivation_survival([0.5, 2.0], [1.0, 0.0], [True, False], [False, True], 0.5).round(6)
    array([0.8894 , 0.18394])
    """
    t = check.numbers(t, "t", minimum=0.0)
    t_end = check.numbers(t_end, "t_end", minimum=0.0)
    escaped = check.mask(escaped, "escaped", t_end.size)
    settled = check.mask(settled, "settled", t_end.size)
    rate = check.number(rate, "rate", minimum=0.0)
    censored = ~(escaped | settled)
    if censored.any() and t.size and t.max() > t_end[censored].min():
        raise ConfigError("times beyond the earliest censoring of the T = 0 ensemble: P_T is unknown there")
    n = len(t_end)
    esc = np.sort(t_end[escaped])
    alive_esc = len(esc) - np.searchsorted(esc, t, side="right")
    tau = t_end[settled]
    wait = np.clip(t[:, None] - tau[None, :], 0.0, None)
    react = np.exp(-rate * wait).sum(axis=1)
    alive_cens = (t_end[censored][None, :] > t[:, None]).sum(axis=1)
    return (alive_esc + react + alive_cens) / n


@dataclass(frozen=True)
class ReactivationCheck:
    """Result of :func:`reactivation_check` (times in time units, rates in 1/time).

    table               t, P_T, P_T_err (Kaplan–Meier of the heat-bath ensemble), P_0 (drag only, leaving =
                        escaped or settled), P_0_settled_inside (drag only, settled orbits inside for ever:
                        1 − escapes up to t / N), model (:func:`reactivation_survival` with the thermal rate)
    settled_fraction, escaped_fraction   of the drag-only ensemble
    t_settled_99        99 % quantile of the drag-only settling times (0 without a settled orbit)
    tail                the constant-hazard MLE of P_T on [tail_start, t_max] (:func:`thermal_rate`)
    max_deviation, max_deviation_at, max_deviation_sigma
                        max |P_T − model| over the grid, where, and in units of P_T's error there (inf: no error)
    """

    table: pd.DataFrame
    settled_fraction: float
    escaped_fraction: float
    t_settled_99: float
    tail: ThermalRate
    max_deviation: float
    max_deviation_at: float
    max_deviation_sigma: float


def reactivation_check(
    t_end0, escaped0, settled0, t_end, escaped, rate: float, t_max: float, tail_start: float, n_grid: int = 401
) -> ReactivationCheck:
    """reactivation_check(drag-only t_end0, escaped0, settled0, heat-bath t_end, escaped, thermal rate, t_max,
    tail_start) -> :class:`ReactivationCheck`: the measured P_T(t) of the heat-bath ensemble against the
    re-activation extension of the drag-only one (:func:`reactivation_survival`), and the rate of its tail.

    Parameters
    ----------
    t_end0, escaped0, settled0 : arrays (N0,)
        The drag-only ensemble: end times (time units), escaped and settled masks (neither: censored).
    t_end, escaped : arrays (N,)
        The heat-bath ensemble: end times and escaped mask.
    rate : float
        The thermal escape rate of a settled orbit (1/time), measured apart (e.g. :func:`thermal_rate` of orbits
        started in the well).
    t_max : float
        The heat-bath runs' end time; the grid of ``n_grid`` times runs from 0 to it, or to the earliest
        censoring of the drag-only ensemble if sooner.
    tail_start : float
        Start of the window [tail_start, t_max] of the tail's rate; it must not precede the drag-only orbits'
        99 % settling time (``ValueError``).

    Examples
    --------
    Orbits that settle at τ ~ U(0, 10) and then leave at rate k = 0.05 in the bath: the model holds, the tail's
    rate is k.

    >>> rng = np.random.default_rng(0)
    >>> tau = rng.uniform(0, 10, 4000)
    >>> t_bath = tau + rng.exponential(20.0, tau.size)
    >>> c = reactivation_check(tau, np.zeros(tau.size, bool), np.ones(tau.size, bool),
    ...                        np.minimum(t_bath, 200.0), t_bath < 200.0, 0.05, 200.0, 20.0)
    >>> c.settled_fraction, bool(c.max_deviation < 0.03), bool(abs(c.tail.rate - 0.05) < 3 * c.tail.rate_err)
    (1.0, True, True)
    """
    t0 = check.numbers(t_end0, "t_end0", minimum=0.0)
    esc0, set0 = check.mask(escaped0, "escaped0", t0.size), check.mask(settled0, "settled0", t0.size)
    tT = check.numbers(t_end, "t_end", minimum=0.0)
    escT = check.mask(escaped, "escaped", tT.size)
    rate = check.number(rate, "rate", minimum=0.0)
    t_max = check.number(t_max, "t_max", positive=True)
    tail_start = check.number(tail_start, "tail_start", minimum=0.0)
    n_grid = check.count(n_grid, "n_grid", 2)
    cens0 = ~(esc0 | set0)
    t_hi = min(t_max, float(t0[cens0].min()) if cens0.any() else t_max)
    grid = np.linspace(0.0, t_hi, n_grid)
    P_T = survival_curve(tT, escT, grid)
    P_0 = survival_curve(t0, esc0 | set0, grid)  # drag only: leaving = escaped or settled
    # drag only, settled orbits counted inside for ever: 1 − (escapes up to t)/N (t ≤ the earliest censoring)
    settled_alive = 1.0 - np.searchsorted(np.sort(t0[esc0]), grid, side="right") / len(t0)
    model = reactivation_survival(grid, t0, esc0, set0, rate)
    # the tail of P_T: the MLE rate on [tail_start, t_max], after the drag-only orbits have settled (their
    # 99 % settling time is recorded beside it) and relaxed
    t_settled = float(np.quantile(t0[set0], 0.99)) if set0.any() else 0.0
    if tail_start < t_settled:
        raise ConfigError(
            f"tail_start = {tail_start:g} is before the drag-only orbits have settled (99 % by t = {t_settled:g})"
        )
    tail = thermal_rate(tT, escT, tail_start, t_max)
    dev = np.abs(P_T.P - model)
    ok = np.isfinite(dev)
    i = int(np.nanargmax(np.where(ok, dev, -1)))
    table = pd.DataFrame(
        {
            "t": grid,
            "P_T": P_T.P,
            "P_T_err": P_T.P_err,
            "P_0": P_0.P,
            "P_0_settled_inside": settled_alive,
            "model": model,
        }
    )
    return ReactivationCheck(
        table=table,
        settled_fraction=float(set0.mean()),
        escaped_fraction=float(esc0.mean()),
        t_settled_99=t_settled,
        tail=tail,
        max_deviation=float(dev[i]),
        max_deviation_at=float(grid[i]),
        max_deviation_sigma=float(dev[i] / P_T.P_err[i]) if P_T.P_err[i] > 0 else math.inf,
    )
