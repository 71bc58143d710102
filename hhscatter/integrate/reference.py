"""The reference driver: one orbit at a time on heyoka's scalar integrator (any floating-point type), with the
same events and rules as the engine."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hhscatter.integrate import events
from hhscatter.integrate.events import CENSORED, ESCAPED, SETTLED
from hhscatter.integrate.integrators import build_scalar, caster
from hhscatter.integrate.lanes import CONTINUING, LIVE, LaneRules, _bind, _Callback, _unbind
from hhscatter.integrate.plan import plan_of


@dataclass
class OrbitResult:
    """Result of :func:`simulate_orbit` (times and states in the integrator's precision)."""

    outcome: int
    t_end: object
    state_end: np.ndarray
    sections: list = field(default_factory=list)  # (t, x, y, px, py, energy), window rules applied
    snapshots: list = field(default_factory=list)  # (t, state)
    crossings: list = field(default_factory=list)  # (t, radius, direction)
    n_steps: int = 0
    log_stretch: float | None = None  # Λ at t_end (a scene with the tangent dynamics; None without)


class _Scalar(LaneRules):
    """The rules on heyoka's scalar integrator (one orbit; any fp type)."""

    def __init__(self, scene, ta, layout, fp_type):
        self.ta = ta
        self.fp = fp_type
        self.setup(scene, layout, 1)
        h = self.energy  # the system's plain-float H; the state here may be long double or real128
        self.energy = lambda x, y, px, py: h(float(x), float(y), float(px), float(py))
        self.result = None

    def elapsed(self, lane):
        return self.ta.time

    def state4(self, lane):
        return tuple(self.ta.state[:4])

    def set_gate(self, lane, g):
        self.ta.pars[self.layout.gate] = self.fp(g)

    def set_clock(self, lane, sigma):
        self.ta.state[self.layout.clock] = self.fp(sigma)

    def stretch(self, lane):
        if self.layout.tangent is None:
            return None
        return events.log_stretch(*self.ta.state[self.layout.tangent : self.layout.tangent + 4])

    def record(self, lane, outcome, t, state, stretch=None):
        self.result = (outcome, t, np.array(state), self.stretch(lane) if stretch is None else stretch)

    def release(self, lane):
        self.commit(lane, self.result[1], self.phase[lane] == CONTINUING)
        self.orbit[lane] = -1
        return False


def simulate_orbit(scene, ic, *, fp_type=float, tol=None) -> OrbitResult:
    """simulate_orbit(scene, ic, fp_type=float, tol=None) -> OrbitResult.

    With the tangent dynamics (``scene.tangent``) the result carries Λ at t_end (``log_stretch``).

    One orbit on heyoka's scalar integrator, time from 0, with the scene's
    events and outcome rules (:mod:`hhscatter.integrate.events`) and the t_max bound:
    the straightforward driver the batch engine is tested against.
    ``fp_type`` may be ``numpy.longdouble`` or ``heyoka.real128`` for a
    high-precision reference (tolerance then defaults to that type's
    epsilon). Snapshots at ``scene.snapshots`` come from stopping at each
    time (so its steps differ from the engine's, as a reference's should).
    A scene with noise has no such driver (its kicks live in the noise scheduler): ValueError.
    """
    import heyoka as hy  # deferred: heyoka loads on first use

    if scene.noise is not None:
        raise ValueError("simulate_orbit integrates the deterministic flow: a scene with noise has no reference driver")
    ic = np.asarray(ic, dtype=float)
    if ic[0] ** 2 + ic[1] ** 2 >= scene.r_esc**2:  # starts beyond r_esc: escaped at t = 0
        snaps = [(0.0, ic.copy())] if scene.snapshots and scene.snapshots[0] == 0.0 else []
        return OrbitResult(ESCAPED, 0.0, ic.copy(), [], snaps, [], 0)
    # a start on the section near an inflection of r (events.opens_late): the window opens at T_INITIAL on the
    # clock, as in the engine; a scene without a clock fixes the section's cooldown instead
    scene = plan_of(scene)
    late = events.opens_late(scene, ic[None]) is not None
    clocked = scene.layout.clock is not None
    cooldown = events.SECTION_COOLDOWN if late and not clocked else -1.0
    products = events.zero_power_start(scene, np.asarray(ic, dtype=float)[None, :4]) is not None  # (as the engine)
    ta, specs, layout = build_scalar(
        scene, _Callback, fp_type=fp_type, tol=tol, section_cooldown=cooldown, products=products
    )
    rules = _Scalar(scene, ta, layout, fp_type)
    if late and clocked:
        rules.open_late = [True]
    _bind(ta, specs, rules)
    cast = caster(fp_type)
    st = np.zeros(layout.n_state)
    st[:4] = np.asarray(ic, dtype=float)
    if layout.tangent is not None:  # δq(0) = ν u(0) as the engine's (Λ = 0)
        st[layout.tangent : layout.tangent + 4] = events.tangent_start(scene, ic[None, :4])[0] * events.TANGENT_NORM
    ta.state[:] = cast(st)
    rules.start_orbit(0, 0)
    ta.reset_cooldowns()
    fp = (lambda v: fp_type(v)) if fp_type is not float else float
    snaps, steps = [], 0
    try:
        for ts in list(scene.snapshots or ()) + [None]:
            if ts is None and rules.phase[0] == CONTINUING:
                break  # past the last snapshot nothing more is needed
            target = fp(scene.t_max if ts is None else min(ts, scene.t_max))
            res = ta.propagate_until(target)
            steps += int(res[3])
            if rules.orbit[0] < 0:  # the orbit ended
                break
            if res[0] != hy.taylor_outcome.time_limit:
                raise RuntimeError(f"unexpected integrator outcome {res[0]}")
            if ts is not None:
                snaps.append((ts, ta.state[:4].copy()))
            elif rules.phase[0] == LIVE:
                rules.record(0, CENSORED, ta.time, rules.state4(0))
                rules.release(0)
            else:
                rules.release(0)
        if rules.orbit[0] >= 0:  # continued past the last snapshot: nothing more is needed
            rules.release(0)
    finally:
        _unbind(ta)
    outcome, t_end, state, stretch = rules.result
    if scene.snapshots and not (outcome == SETTLED and scene.continue_settled):
        snaps = [s for s in snaps if s[0] <= t_end]
    secs = [r[1:] for r in rules.sec_rows]
    cross = [r[1:] for r in rules.cross_rows]
    log_stretch = None if stretch is None else float(stretch)
    return OrbitResult(outcome, t_end, state, secs, snaps, cross, steps, log_stretch)


def state_at(scene, ic, t, *, fp_type=float, tol=None):
    """state_at(scene, ic, t) -> state (4,) at orbit time t from a fresh scalar run (no events)."""
    import heyoka as hy  # deferred: heyoka loads on first use

    layout = events.Layout(4, None, None, 0 if scene.gamma > 0 else None, 1 if scene.gamma > 0 else 0, 1.0)
    cast = caster(fp_type)
    kw = {}
    if tol is not None:
        kw["tol"] = fp_type(tol) if fp_type is not float else tol
    ta = hy.taylor_adaptive(
        events.system(scene, layout),
        cast(np.asarray(ic, dtype=float)),
        pars=cast(np.array([scene.gamma])) if scene.gamma > 0 else [],
        fp_type=fp_type,
        **kw,
    )
    ta.propagate_until(fp_type(t) if fp_type is not float else t)
    return np.array(ta.state[:4])
