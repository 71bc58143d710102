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

import numpy as np

__all__ = ["reactivation_survival"]


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
    t = np.asarray(t, dtype=float)
    t_end = np.asarray(t_end, dtype=float)
    escaped = np.asarray(escaped, dtype=bool)
    settled = np.asarray(settled, dtype=bool)
    censored = ~(escaped | settled)
    if censored.any() and t.size and t.max() > t_end[censored].min():
        raise ValueError("times beyond the earliest censoring of the T = 0 ensemble: P_T is unknown there")
    n = len(t_end)
    esc = np.sort(t_end[escaped])
    alive_esc = len(esc) - np.searchsorted(esc, t, side="right")
    tau = t_end[settled]
    wait = np.clip(t[:, None] - tau[None, :], 0.0, None)
    react = np.exp(-rate * wait).sum(axis=1)
    alive_cens = (t_end[censored][None, :] > t[:, None]).sum(axis=1)
    return (alive_esc + react + alive_cens) / n
