"""An independent Langevin integrator in numpy: vectorised OBABO (velocity Verlet between exact OU half-steps).

The reference the noise scheduler (:mod:`hhscatter.integrate.noise`) is checked against in distribution, and
timed against at equal weak error (``make bench``): nothing of the engine is shared (no heyoka, no events, its
own random numbers). One step of length h on every orbit at once:

    O(h/2): p ← c p + s ξ;  B(h/2): p ← p + (h/2) F(q);  A(h): q ← q + h p;  B(h/2);  O(h/2),

c, s those of :func:`hhscatter.integrate.noise.ou_coefficients` (the exact Ornstein–Uhlenbeck step), F = −∇V
from the system (``model.force``). Weak order 2 in h (the invariant measure too, unlike the engine's splitting,
whose Hamiltonian part is exact). An orbit escapes at the end of the first step with r > r_esc (its escape time
is resolved to h).
"""

from __future__ import annotations

import numpy as np

from hhscatter.integrate.noise import ou_coefficients


def obabo_escape_times(model, ics, *, gamma: float, sigma: float, h: float, t_max: float, r_esc: float, seed: int):
    """obabo_escape_times(model, ics, *, gamma, sigma, h, t_max, r_esc, seed) -> (t_end, escaped).

    ``ics``: (n, 4) initial states (x, y, px, py); γ (1/time), σ (momentum/√time: √(2γT) for a heat bath),
    step h and t_max (time units). Returns each orbit's end time (escape, or t_max if censored) and the
    boolean mask of escapes. ``seed`` seeds numpy's default generator (one stream for the whole batch).

    Examples
    --------
    >>> from hhscatter.model import HenonHeiles
    >>> ics = np.zeros((200, 4))
    >>> t, esc = obabo_escape_times(HenonHeiles(), ics, gamma=1.0, sigma=(2 / 6) ** 0.5, h=0.05, t_max=20.0,
    ...                             r_esc=1.5, seed=1)
    >>> bool(esc.any()), bool((t[~esc] == 20.0).all())
    (True, True)
    """
    rng = np.random.default_rng(seed)
    st = np.array(ics, dtype=float)
    x, y, px, py = (st[:, k].copy() for k in range(4))
    n = len(x)
    c, s = ou_coefficients(gamma, sigma, 0.5 * h)
    t_end = np.full(n, float(t_max))
    escaped = np.zeros(n, dtype=bool)
    live = np.arange(n)
    steps = int(round(t_max / h))
    for k in range(1, steps + 1):
        if not live.size:
            break
        xi = rng.standard_normal((4, live.size))
        a, b, u, v = x[live], y[live], px[live], py[live]
        u = c * u + s * xi[0]
        v = c * v + s * xi[1]
        fx, fy = model.force(a, b)
        u = u + 0.5 * h * fx
        v = v + 0.5 * h * fy
        a = a + h * u
        b = b + h * v
        fx, fy = model.force(a, b)
        u = u + 0.5 * h * fx
        v = v + 0.5 * h * fy
        u = c * u + s * xi[2]
        v = c * v + s * xi[3]
        x[live], y[live], px[live], py[live] = a, b, u, v
        out = a * a + b * b > r_esc * r_esc
        if out.any():
            gone = live[out]
            t_end[gone] = k * h
            escaped[gone] = True
            live = live[~out]
    return t_end, escaped
