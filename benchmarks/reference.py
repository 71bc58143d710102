"""High-precision reference orbits for the benchmark and the stress tests.

:func:`reference_orbits` integrates each orbit alone on heyoka's scalar Taylor
integrator in ``numpy.longdouble`` (64-bit mantissa, ε ≈ 1.1e-19) or
``heyoka.real128`` (ε ≈ 1.9e-34), with exact (Taylor-polynomial) event
location and the engine's events and rules (:mod:`hhscatter.integrate.events`), through
the engine's scalar driver :func:`hhscatter.integrate.engine.simulate_orbit`:

* conservative: escape at the first outward crossing of r = r_esc;
* dissipative: closure at H = E_c (settled if r ≤ r_s, else escaped at the
  last outward r_esc crossing), or escaped when r reaches r_far;
* section mode (conservative): the first crossing of ṙ = 0 with φ̇ > 0 after
  t = 1e-10, where the orbit stops.

Results are plain float64 arrays (the rounding to double is far below the
errors measured against them).
"""

from __future__ import annotations

import numpy as np

from hhscatter.integrate.engine import (
    CENSORED,
    ESCAPED,
    SETTLED,
    STOPPED,
    simulate_orbit,
)
from hhscatter.model import HenonHeiles
from hhscatter.scene.scene import Scene, SectionWindow

SECTION = STOPPED  # outcome of ``section=True``: stopped at the first section crossing


def reference_orbit(
    ic, *, gamma=0.0, r_esc=1.03, t_max=5000.0, fp_type=np.longdouble, tol=None, section=False, model=None
):
    """reference_orbit(ic, gamma=0, r_esc=1.03, t_max=5000, fp_type=longdouble, tol=None, section=False)
    -> (outcome, t_end, state_end (4,), n_steps).

    The engine's scalar driver :func:`hhscatter.integrate.engine.simulate_orbit` (same
    events and rules, :mod:`hhscatter.integrate.events`) in ``fp_type``. ``tol``
    defaults to heyoka's default for ``fp_type`` (its epsilon).
    ``section=True`` stops at the first section crossing (outcome
    ``SECTION``) and returns its state.
    """
    model = model or HenonHeiles()
    # the scene's energy is only validated, never used: the initial condition sets the orbit's energy
    scene = Scene(
        energy=2.0 * model.critical_energy,
        n=1,
        gamma=gamma,
        r_esc=r_esc,
        t_max=t_max,
        omega=model.omega,
        lam=model.lam,
        sections=SectionWindow(first_only=True, stop=True) if section else None,
    )
    res = simulate_orbit(scene, ic, fp_type=fp_type, tol=tol)
    return int(res.outcome), float(res.t_end), _f(res.state_end), res.n_steps


def _f(v):
    return np.array([float(a) for a in v])


def reference_orbits(ics, **kw):
    """reference_orbits(ics, **kw of reference_orbit) -> dict of arrays outcome, t_end, state_end, n_steps."""
    ics = np.asarray(ics, dtype=float)
    n = len(ics)
    out = {
        "outcome": np.empty(n, np.int8),
        "t_end": np.empty(n),
        "state_end": np.empty((n, 4)),
        "n_steps": np.empty(n, np.int64),
    }
    for i, ic in enumerate(ics):
        o, t, s, k = reference_orbit(ic, **kw)
        out["outcome"][i], out["t_end"][i], out["state_end"][i], out["n_steps"][i] = o, t, s, k
    return out


__all__ = ["CENSORED", "ESCAPED", "SECTION", "SETTLED", "reference_orbit", "reference_orbits"]
