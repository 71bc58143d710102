"""High-precision reference orbits for the benchmark and the stress tests.

:func:`reference_orbits` integrates each orbit alone on heyoka's scalar Taylor
integrator in ``numpy.longdouble`` (64-bit mantissa, ε ≈ 1.1e-19) or
``heyoka.real128`` (ε ≈ 1.9e-34), with exact (Taylor-polynomial) event
location and the engine's rules (:mod:`hhscatter.engine`):

* conservative: escape at the first outward crossing of r = r_esc;
* dissipative: closure at H = E_c (settled if r ≤ r_s, else escaped at the
  last outward r_esc crossing), or escaped when r reaches r_far;
* section mode (conservative): the first crossing of ṙ = 0 with φ̇ > 0 after
  t = 1e-10, its state from the dense output.

Results are plain float64 arrays (the rounding to double is far below the
errors measured against them).
"""
from __future__ import annotations

import numpy as np

from ..engine import CENSORED, ESCAPED, SETTLED, _caster, _far_radius
from ..model import HenonHeiles, equations

SECTION = 3
_T_INITIAL = 1e-10


def reference_orbit(ic, *, gamma=0.0, r_esc=1.03, t_max=5000.0, fp_type=np.longdouble, tol=None,
                    section=False, model=None):
    """reference_orbit(ic, gamma=0, r_esc=1.03, t_max=5000, fp_type=longdouble, tol=None, section=False)
    -> (outcome, t_end, state_end (4,), n_steps).

    ``tol`` defaults to heyoka's default for ``fp_type`` (its epsilon).
    ``section=True`` stops at the first section crossing (outcome 3) and
    records its state.
    """
    import heyoka as hy

    model = model or HenonHeiles()
    dissipative = gamma > 0
    (x, y, px, py), _, H = model.expressions()
    sys = equations(model, hy.par[0] if dissipative else None)
    r2 = x**2 + y**2
    pos, neg = hy.event_direction.positive, hy.event_direction.negative
    cast = _caster(fp_type)
    fp = (lambda v: fp_type(v)) if fp_type is not float else float
    rec = {"last_out": None, "sec": None}

    def on_resc(ta, t, d):
        if d > 0:
            ta.update_d_output(t)
            rec["last_out"] = (t, list(ta.d_output))
        else:
            rec["last_out"] = None

    def on_section(ta, t, d):
        if rec["sec"] is not None or t < fp(_T_INITIAL):
            return
        ta.update_d_output(t)
        s = list(ta.d_output)
        if s[0] * s[3] - s[1] * s[2] > 0:
            rec["sec"] = (t, s)

    t_events, nt_events = [], []
    if dissipative:
        t_events.append(hy.t_event(H - model.critical_energy, direction=neg, fp_type=fp_type))
        t_events.append(hy.t_event(r2 / _far_radius_default(r_esc, model) ** 2 - 1.0, direction=pos, fp_type=fp_type))
        nt_events.append(hy.nt_event(r2 - r_esc**2, on_resc, fp_type=fp_type))
    else:
        t_events.append(hy.t_event(r2 - r_esc**2, direction=pos, fp_type=fp_type))
    if section:
        nt_events.append(hy.nt_event(x * px + y * py, on_section, fp_type=fp_type))
    kw = {} if tol is None else {"tol": fp(tol)}
    ta = hy.taylor_adaptive(
        sys, cast(np.asarray(ic, dtype=float)), pars=cast(np.array([gamma])) if dissipative else [],
        t_events=t_events, nt_events=nt_events, fp_type=fp_type, **kw,
    )
    steps = 0
    target = fp(t_max)
    if section:
        # step by step so that the first crossing ends the orbit
        while ta.time < target:
            res = ta.step(target - ta.time)
            steps += 1
            if rec["sec"] is not None:
                t, s = rec["sec"]
                return SECTION, float(t), _f(s), steps
            oc = res[0]
            if oc not in (hy.taylor_outcome.success, hy.taylor_outcome.time_limit) and int(oc) < 0:
                return ESCAPED, float(ta.time), _f(ta.state), steps  # terminal event: escape
        return CENSORED, float(t_max), _f(ta.state), steps
    while True:
        res = ta.propagate_until(target)
        steps += int(res[3])
        oc = res[0]
        if oc == hy.taylor_outcome.time_limit:
            return CENSORED, float(t_max), _f(ta.state), steps
        idx = -int(oc) - 1
        st = ta.state
        if dissipative and idx == 0:
            if st[0] ** 2 + st[1] ** 2 <= model.saddle_radius**2:
                return SETTLED, float(ta.time), _f(st), steps
            if rec["last_out"] is None:
                continue  # outside Ω below E_c: it cannot come back; carry on to r_far
        if dissipative:
            if rec["last_out"] is None:
                raise RuntimeError("reference: orbit left without an outward r_esc crossing")
            t, s = rec["last_out"]
            return ESCAPED, float(t), _f(s), steps
        return ESCAPED, float(ta.time), _f(st), steps


def _f(v):
    return np.array([float(a) for a in v])


def _far_radius_default(r_esc, model):
    """The engine's default r_far for this r_esc (:func:`hhscatter.engine._far_radius`)."""
    from types import SimpleNamespace

    return _far_radius(SimpleNamespace(r_far=None, r_esc=r_esc), model)


def reference_orbits(ics, **kw):
    """reference_orbits(ics, **kw of reference_orbit) -> dict of arrays outcome, t_end, state_end, n_steps."""
    ics = np.asarray(ics, dtype=float)
    n = len(ics)
    out = {"outcome": np.empty(n, np.int8), "t_end": np.empty(n), "state_end": np.empty((n, 4)),
           "n_steps": np.empty(n, np.int64)}
    for i, ic in enumerate(ics):
        o, t, s, k = reference_orbit(ic, **kw)
        out["outcome"][i], out["t_end"][i], out["state_end"][i], out["n_steps"][i] = o, t, s, k
    return out


__all__ = ["SECTION", "reference_orbit", "reference_orbits"]
