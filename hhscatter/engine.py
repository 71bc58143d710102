"""Batch Taylor engine: lane-refilling driver over heyoka's batch integrator.

``run_chunk(scene, ics, traj_ids)`` integrates a block of orbits on one
``heyoka.taylor_adaptive_batch`` and returns plain arrays (the rows of the
``lifetimes``, ``sections`` and ``snapshots`` tables).

How the lanes stay busy
-----------------------
heyoka's batch ``propagate_until`` returns for *all* lanes as soon as one lane
stops on a terminal event. Returning to Python once per orbit costs ~10 µs,
more than the integration itself, so the driver never stops on an orbit's
end: every terminal event has a callback that records the orbit's outcome,
loads the next initial condition into that lane and returns ``True``
(continue). Callbacks cannot change a lane's time, so each lane's clock keeps
running; an orbit's own time is the lane time minus the orbit's start time,
both kept as double-length (hi, lo) pairs as heyoka keeps time.

Orbits alive at ``t_max`` are censored by a terminal event on
``t − p_tcens`` whose parameter is set per lane to the orbit's start + t_max.
A propagation bound would be shared by all orbits passing through a lane and
would truncate a later orbit's step at a stale bound. Events are located
after a step has been taken and do not enter the step-size choice
(``tests/test_engine.py::test_time_event_does_not_change_steps`` checks that
the trajectory is bitwise the same with and without it); the orbit's last
step ends at t_max exactly as a propagation bound would end it.

The Taylor step size depends only on the state (the system is autonomous), so
an orbit's sequence of steps, and hence its trajectory, does not depend on the
lane it runs in, on the other orbits of the batch, or on the chunking.

Events compiled (only those a scene needs):

======================  =========  ==========================================
event                   kind       when
======================  =========  ==========================================
r² − r_esc², outward    terminal   conservative escape (the root is the time)
H − E_c, downward       terminal   dissipative closure: escaped if r > r_s
r² − r_far², outward    terminal   dissipative: escaped orbit far away
t − p_tcens             terminal   t_max reached: censored
r² − r_esc², both       non-term.  dissipative: last outward crossing time
x px + y py             non-term.  section ṙ = 0 (kept where φ̇ > 0)
t − p_tsnap             non-term.  energy snapshot grid
======================  =========  ==========================================
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .model import HenonHeiles, equations

ESCAPED, SETTLED, CENSORED = 0, 1, 2
OUTCOMES = ("escaped", "settled", "censored")

# parameter slots of the compiled integrator
P_GAMMA, P_TCENS, P_TSNAP = 0, 1, 2
_PARKED = 1e300  # parameter value for lanes without an orbit: never reached
_T_HORIZON = 1e18  # propagation bound for active lanes: never reached either
_T_INITIAL = 1e-10  # section crossings before this are the initial point itself


@dataclass
class ChunkResult:
    """Rows produced by one chunk (plain numpy arrays, table column order)."""

    lifetimes: dict
    sections: dict
    snapshots: dict
    n_returns: int = 0
    n_steps: int = 0


def _far_radius(scene, model):
    return scene.r_far if scene.r_far is not None else max(10.0 * model.saddle_radius, 2.0 * scene.r_esc)


def build_integrator(scene, batch_size, *, fp_type=float, tol=None):
    """build_integrator(scene, batch_size) -> (taylor_adaptive_batch, event_names).

    The system and the events are heyoka expressions; γ, the censoring time
    and the snapshot time are runtime parameters (``hy.par``) so that the JIT
    compilation is shared by every γ and cached by heyoka per process.
    Callbacks are placeholders, bound to a :class:`_Lanes` after construction
    (heyoka deep-copies callbacks it is given).
    """
    import heyoka as hy

    model = scene.model
    dissipative = scene.gamma > 0
    sys = equations(model, hy.par[P_GAMMA] if dissipative else None)
    (x, y, px, py), _, H = model.expressions()
    r2 = x**2 + y**2
    pos, neg = hy.event_direction.positive, hy.event_direction.negative

    names, t_events = [], []

    def term(name, expr, direction=hy.event_direction.any):
        names.append(name)
        t_events.append(hy.t_event_batch(expr, callback=_TermCallback(name), direction=direction))

    if dissipative:
        term("closure", H - model.critical_energy, neg)
        term("far", r2 - _far_radius(scene, model) ** 2, pos)
    else:
        term("escape", r2 - scene.r_esc**2, pos)
    term("censor", hy.time - hy.par[P_TCENS], pos)

    nt_names, nt_events = [], []
    if dissipative:
        nt_names.append("resc")
        nt_events.append(hy.nt_event_batch(r2 - scene.r_esc**2, _NtCallback("resc")))
    if scene.sections is not None:
        nt_names.append("section")
        nt_events.append(hy.nt_event_batch(x * px + y * py, _NtCallback("section")))
    if scene.snapshots:
        nt_names.append("snapshot")
        nt_events.append(hy.nt_event_batch(hy.time - hy.par[P_TSNAP], _NtCallback("snapshot")))

    # heyoka sizes the parameter array by the highest index in use
    npar = P_TSNAP + 1 if scene.snapshots else P_TCENS + 1
    pars = np.full((npar, batch_size), _PARKED)
    pars[P_GAMMA] = scene.gamma
    ta = hy.taylor_adaptive_batch(
        sys,
        np.zeros((4, batch_size)),
        tol=scene.tol if tol is None else tol,
        pars=pars,
        t_events=t_events,
        nt_events=nt_events,
    )
    return ta, names, nt_names


class _TermCallback:
    __slots__ = ("name", "handler")

    def __init__(self, name):
        self.name = name
        self.handler = None

    def __call__(self, ta, d_sgn, lane):
        return self.handler(lane)


class _NtCallback:
    __slots__ = ("name", "handler")

    def __init__(self, name):
        self.name = name
        self.handler = None

    def __call__(self, ta, t, d_sgn, lane):
        self.handler(t, d_sgn, lane)


class _Lanes:
    """Per-lane bookkeeping and the event handlers of one chunk."""

    def __init__(self, scene, ta, ics, names, nt_names):
        self.scene = scene
        self.model = scene.model
        self.ta = ta
        self.B = ta.batch_size
        self.state = ta.state  # live views into the integrator
        self.time_hi, self.time_lo = ta.dtime
        self.pars = ta.pars
        self.ics = ics.tolist()
        self.n = len(ics)
        self.next = 0
        self.r_s = self.model.saddle_radius
        self.t_max = scene.t_max
        self.dissipative = scene.gamma > 0
        self.half_w2 = 0.5 * self.model.omega**2
        self.lam = self.model.lam

        self.orbit = [-1] * self.B
        self.t0_hi = [0.0] * self.B
        self.t0_lo = [0.0] * self.B
        self.last_out = [None] * self.B  # (t, x, y, E) of the last outward r_esc crossing
        self.snap_k = [0] * self.B
        self.pending_sec = [[] for _ in range(self.B)]
        self.pending_snap = [[] for _ in range(self.B)]
        self.sec_found = [False] * self.B

        self.outcome = np.full(self.n, -1, dtype=np.int8)
        self.t_end = np.full(self.n, np.nan)
        # state at t_end (escape crossing, closure or t_max); energies and exit
        # channels are computed from it once per chunk, vectorised
        self.end_state = np.full((self.n, 4), np.nan)
        self.sec_rows = []
        self.snap_rows = []

        win = scene.sections
        if win is not None:
            self.w_t_from, self.w_t_to = win.t_from, win.t_to
            self.w_e_min, self.w_e_max = win.e_min, win.e_max
            self.w_first = win.first_only
        self.snap_times = tuple(scene.snapshots) if scene.snapshots else ()

        handlers = {
            "escape": self.on_escape,
            "closure": self.on_closure,
            "far": self.on_far,
            "censor": self.on_censor,
            "resc": self.on_resc,
            "section": self.on_section,
            "snapshot": self.on_snapshot,
        }
        for name, ev in zip(names, ta.t_events):
            ev.callback.handler = handlers[name]
        for name, ev in zip(nt_names, ta.nt_events):
            ev.callback.handler = handlers[name]

    def energy(self, x, y, px, py):
        """H at one point in plain float arithmetic (numpy calls cost µs per scalar)."""
        x, y, px, py = float(x), float(y), float(px), float(py)
        return 0.5 * (px * px + py * py) + self.half_w2 * (x * x + y * y) + self.lam * (x * x * y - y * y * y / 3.0)

    # -- time helpers -----------------------------------------------------
    def elapsed(self, lane):
        """Orbit time of ``lane`` now: (hi − hi0) + (lo − lo0), exact to an ulp."""
        return (self.time_hi[lane] - self.t0_hi[lane]) + (self.time_lo[lane] - self.t0_lo[lane])

    def orbit_time(self, t_abs, lane):
        return (t_abs - self.t0_hi[lane]) - self.t0_lo[lane]

    def dense_state(self, t_abs, lane):
        """State of ``lane`` at absolute time t_abs inside the last step (dense output)."""
        t = self.time_hi.copy()
        t[lane] = t_abs
        return self.ta.update_d_output(t)[:, lane]

    # -- lane life cycle --------------------------------------------------
    def load(self, lane):
        """Put the next orbit into ``lane``; park the lane if none is left.

        Returns the value the terminal callback must return: ``True`` to go on,
        ``False`` to stop the propagation (only when the lane is parked).
        """
        k = self.next
        ta = self.ta
        if k >= self.n:
            self.orbit[lane] = -1
            self.pars[P_TCENS:, lane] = _PARKED
            return False
        self.next = k + 1
        self.orbit[lane] = k
        self.state[:, lane] = self.ics[k]
        hi, lo = self.time_hi[lane], self.time_lo[lane]
        self.t0_hi[lane], self.t0_lo[lane] = hi, lo
        self.pars[P_TCENS, lane] = hi + self.t_max
        self.last_out[lane] = None
        self.sec_found[lane] = False
        if self.snap_times:
            self.snap_k[lane] = 0
            self.pars[P_TSNAP, lane] = hi + self.snap_times[0]
        ta.reset_cooldowns(lane)
        return True

    def finish(self, lane, outcome, t_end, state):
        k = self.orbit[lane]
        self.outcome[k] = outcome
        self.t_end[k] = t_end
        self.end_state[k] = state
        if self.pending_sec[lane]:
            self.sec_rows.extend(r for r in self.pending_sec[lane] if r[1] <= t_end)
            self.pending_sec[lane] = []
        if self.pending_snap[lane]:
            self.snap_rows.extend(r for r in self.pending_snap[lane] if r[1] <= t_end)
            self.pending_snap[lane] = []
        return self.load(lane)

    # -- terminal events --------------------------------------------------
    def on_escape(self, lane):
        return self.finish(lane, ESCAPED, self.elapsed(lane), self.state[:, lane])

    def on_censor(self, lane):
        return self.finish(lane, CENSORED, self.t_max, self.state[:, lane])

    def on_closure(self, lane):
        st = self.state[:, lane]
        if st[0] * st[0] + st[1] * st[1] <= self.r_s * self.r_s:
            return self.finish(lane, SETTLED, self.elapsed(lane), st)
        out = self.last_out[lane]
        if out is not None:
            return self.finish(lane, ESCAPED, *out)
        # outside Ω below E_c but not yet past r_esc: it cannot come back, the
        # crossing of r_esc (then r_far) ends it
        return True

    def on_far(self, lane):
        out = self.last_out[lane]
        if out is None:  # unreachable: r_far > r_esc; kept as a guard
            raise RuntimeError("orbit reached r_far without crossing r_esc")
        return self.finish(lane, ESCAPED, *out)

    # -- non-terminal events ----------------------------------------------
    def on_resc(self, t_abs, d_sgn, lane):
        if self.orbit[lane] < 0:
            return
        if d_sgn > 0:
            self.last_out[lane] = (self.orbit_time(t_abs, lane), self.dense_state(t_abs, lane).copy())
        else:
            self.last_out[lane] = None

    def on_section(self, t_abs, d_sgn, lane):
        if self.orbit[lane] < 0 or (self.w_first and self.sec_found[lane]):
            return
        t = self.orbit_time(t_abs, lane)
        if t < _T_INITIAL or t < self.w_t_from or t > self.w_t_to:
            return
        s = self.dense_state(t_abs, lane)
        x, y, px, py = s
        if x * py - y * px <= 0:  # φ̇ ≤ 0: the other half of ṙ = 0
            return
        e = self.energy(x, y, px, py)
        if e < self.w_e_min or e > self.w_e_max:
            return
        self.sec_found[lane] = True
        self.pending_sec[lane].append((self.orbit[lane], t, x, y, px, py, e))

    def on_snapshot(self, t_abs, d_sgn, lane):
        k = self.orbit[lane]
        if k < 0:
            return
        i = self.snap_k[lane]
        x, y, px, py = self.dense_state(t_abs, lane)
        self.pending_snap[lane].append((k, self.snap_times[i], self.energy(x, y, px, py)))
        i += 1
        self.snap_k[lane] = i
        self.pars[P_TSNAP, lane] = self.t0_hi[lane] + self.snap_times[i] if i < len(self.snap_times) else _PARKED


def run_chunk(scene, ics, traj_ids, *, batch_size=None) -> ChunkResult:
    """run_chunk(scene, ics, traj_ids, batch_size=None) -> ChunkResult.

    ``ics``: array (n, 4) of initial states (x, y, px, py); ``traj_ids``: int64
    array (n,). Returns the table rows of this chunk, ordered by traj_id.
    """
    import heyoka as hy

    ics = np.ascontiguousarray(ics, dtype=float)
    n = len(ics)
    B = int(batch_size or scene.batch_size or hy.recommended_simd_size())
    ta, names, nt_names = build_integrator(scene, B)
    lanes = _Lanes(scene, ta, ics, names, nt_names)

    tf = np.full(B, _T_HORIZON)
    for lane in range(B):
        if not lanes.load(lane):
            tf[lane] = lanes.time_hi[lane]
    n_returns = 0
    n_steps = 0
    while any(k >= 0 for k in lanes.orbit):
        ta.propagate_until(tf)
        n_returns += 1
        for lane, res in enumerate(ta.propagate_res):
            n_steps += res[3]
            outcome = res[0]
            if outcome in (hy.taylor_outcome.err_nf_state,):
                raise FloatingPointError(
                    f"non-finite state in lane {lane} (orbit {traj_ids[lanes.orbit[lane]]}); "
                    "this is a bug: escaping orbits must be stopped by the engine's events"
                )
            if lanes.orbit[lane] < 0:
                tf[lane] = lanes.time_hi[lane]  # parked: hold the lane still
    if (lanes.outcome < 0).any():
        raise RuntimeError("internal error: some orbits of the chunk have no outcome")

    model = scene.model
    end = lanes.end_state
    channel = np.where(lanes.outcome == ESCAPED, model.exit_channel(end[:, 0], end[:, 1]), -1)
    traj_ids = np.asarray(traj_ids, dtype=np.int64)
    lifetimes = {
        "traj_id": traj_ids,
        "x0": ics[:, 0].copy(),
        "y0": ics[:, 1].copy(),
        "px0": ics[:, 2].copy(),
        "py0": ics[:, 3].copy(),
        "e0": model.energy(ics[:, 0], ics[:, 1], ics[:, 2], ics[:, 3]),
        "gamma": np.full(n, scene.gamma),
        "outcome": lanes.outcome,
        "t_end": lanes.t_end,
        "exit_channel": channel.astype(np.int8),
        "e_end": model.energy(end[:, 0], end[:, 1], end[:, 2], end[:, 3]),
    }
    sections = _rows_to_columns(lanes.sec_rows, ("traj_id", "t", "x", "y", "px", "py", "energy"), traj_ids)
    snapshots = _rows_to_columns(lanes.snap_rows, ("traj_id", "t", "energy"), traj_ids)
    return ChunkResult(lifetimes, sections, snapshots, n_returns=n_returns, n_steps=n_steps)


def _rows_to_columns(rows, columns, traj_ids):
    """Rows (local orbit index first) -> dict of columns sorted by (traj_id, t)."""
    if not rows:
        out = {c: np.empty(0) for c in columns}
        out["traj_id"] = np.empty(0, dtype=np.int64)
        return out
    arr = np.array(rows, dtype=float)
    local = arr[:, 0].astype(np.int64)
    order = np.lexsort((arr[:, 1], local))
    arr = arr[order]
    out = {c: np.ascontiguousarray(arr[:, i]) for i, c in enumerate(columns)}
    out["traj_id"] = traj_ids[local[order]]
    return out


# -- one orbit at a time: the reference driver ---------------------------------

@dataclass
class OrbitResult:
    """Result of :func:`simulate_orbit` (values in the integrator's precision)."""

    outcome: int
    t_end: object
    state_end: np.ndarray
    sections: list = field(default_factory=list)  # (t, x, y, px, py)
    snapshots: list = field(default_factory=list)  # (t, state)


def simulate_orbit(scene, ic, *, fp_type=float, tol=None):
    """simulate_orbit(scene, ic, fp_type=float, tol=None) -> OrbitResult.

    One orbit on heyoka's scalar integrator, time from 0, ``propagate_until``
    with the t_max bound: the straightforward driver the batch engine is
    tested against. ``fp_type`` may be ``numpy.longdouble`` or
    ``heyoka.real128`` for a high-precision reference (tolerance then defaults
    to that type's epsilon). Section crossings are all crossings with φ̇ > 0
    (no window); snapshots at ``scene.snapshots`` times.
    """
    import heyoka as hy

    model = scene.model
    dissipative = scene.gamma > 0
    (x, y, px, py), _, H = model.expressions()
    sys = equations(model, hy.par[0] if dissipative else None)
    r2 = x**2 + y**2
    pos, neg = hy.event_direction.positive, hy.event_direction.negative
    cast = np.vectorize(fp_type) if fp_type is not float else (lambda v: np.asarray(v, dtype=float))

    rec = {"last_out": None, "sections": []}

    def on_resc(ta, t, d):
        rec["last_out"] = t if d > 0 else None

    def on_section(ta, t, d):
        rec["sections"].append(t)

    t_events = []
    if dissipative:
        t_events.append(hy.t_event(H - model.critical_energy, direction=neg, fp_type=fp_type))
        t_events.append(hy.t_event(r2 - _far_radius(scene, model) ** 2, direction=pos, fp_type=fp_type))
        nt_events = [hy.nt_event(r2 - scene.r_esc**2, on_resc, fp_type=fp_type)]
    else:
        t_events.append(hy.t_event(r2 - scene.r_esc**2, direction=pos, fp_type=fp_type))
        nt_events = []
    if scene.sections is not None:
        nt_events.append(hy.nt_event(x * px + y * py, on_section, fp_type=fp_type))

    kw = {}
    if tol is not None:
        kw["tol"] = fp_type(tol) if fp_type is not float else tol
    ta = hy.taylor_adaptive(
        sys,
        cast(np.asarray(ic, dtype=float)),
        pars=cast(np.array([scene.gamma])) if dissipative else [],
        t_events=t_events,
        nt_events=nt_events,
        fp_type=fp_type,
        **kw,
    )
    snaps = []
    for ts in list(scene.snapshots or ()) + [scene.t_max]:
        target = fp_type(ts) if fp_type is not float else ts
        while True:
            res = ta.propagate_until(target)
            outcome = res[0]
            if outcome == hy.taylor_outcome.time_limit:
                break
            idx = -int(outcome) - 1
            if dissipative and idx == 0:
                st = ta.state
                inside = st[0] ** 2 + st[1] ** 2 <= model.saddle_radius**2
                if inside:
                    return _orbit_result(SETTLED, ta.time, ta, rec, snaps)
                if rec["last_out"] is not None:
                    return _orbit_result(ESCAPED, rec["last_out"], ta, rec, snaps)
                continue  # outside Ω below E_c: carry on to r_far
            if dissipative and idx == 1:
                return _orbit_result(ESCAPED, rec["last_out"], ta, rec, snaps)
            return _orbit_result(ESCAPED, ta.time, ta, rec, snaps)
        if ts != scene.t_max:
            snaps.append((ts, ta.state.copy()))
    return _orbit_result(CENSORED, ta.time, ta, rec, snaps)


def _orbit_result(outcome, t_end, ta, rec, snaps):
    # section crossings are kept as times; :func:`state_at` gives their states
    return OrbitResult(outcome, t_end, ta.state.copy(), list(rec["sections"]), snaps)


def state_at(scene, ic, t, *, fp_type=float, tol=None):
    """state_at(scene, ic, t) -> state (4,) at orbit time t from a fresh scalar run (no events)."""
    import heyoka as hy

    sys = equations(scene.model, hy.par[0] if scene.gamma > 0 else None)
    cast = np.vectorize(fp_type) if fp_type is not float else (lambda v: np.asarray(v, dtype=float))
    kw = {}
    if tol is not None:
        kw["tol"] = fp_type(tol) if fp_type is not float else tol
    ta = hy.taylor_adaptive(
        sys,
        cast(np.asarray(ic, dtype=float)),
        pars=cast(np.array([scene.gamma])) if scene.gamma > 0 else [],
        fp_type=fp_type,
        **kw,
    )
    ta.propagate_until(t)
    return ta.state.copy()


__all__ = ["run_chunk", "simulate_orbit", "state_at", "build_integrator", "ChunkResult", "OUTCOMES"]
