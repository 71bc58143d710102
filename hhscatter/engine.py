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

Censoring uses the propagation bound, never an event on time: heyoka puts the
event equations' Taylor coefficients into its step-size control, so an event
``t − t_max`` (whose value is of the order of the lane's clock) would change
every step (measured: relative energy error 2e-12 instead of 2e-14 at
t = 5000). Each lane's bound is its current orbit's start + t_max. A bound
belongs to the orbit that was in the lane when ``propagate_until`` was
called; an orbit loaded later in the same call may reach that stale bound, its
step is then cut short, and the driver reruns that orbit from its initial
condition, so every orbit's sequence of steps is exactly the one it has when
integrated alone. Callbacks stop the propagation when a lane sits at its bound
so that no lane idles.

Energy snapshots are read from the dense output at the end of each step (a
step callback, compiled in only for scenes that ask for snapshots), for the
same reason.

Events compiled (only those a scene needs):

======================  =========  ==========================================
event                   kind       when
======================  =========  ==========================================
r² − r_esc², outward    terminal   conservative escape (the root is the time)
H − E_c, downward       terminal   dissipative closure: escaped if r > r_s
r² − r_far², outward    terminal   dissipative: escaped orbit far away
r² − r_esc², both       non-term.  dissipative: last outward crossing time
x px + y py             non-term.  section ṙ = 0 (kept where φ̇ > 0)
======================  =========  ==========================================
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .model import HenonHeiles, equations

ESCAPED, SETTLED, CENSORED = 0, 1, 2
OUTCOMES = ("escaped", "settled", "censored")

P_GAMMA = 0  # parameter slot of γ
_T_INITIAL = 1e-10  # section crossings before this are the initial point itself


@dataclass
class ChunkResult:
    """Rows produced by one chunk (plain numpy arrays, table column order)."""

    lifetimes: dict
    sections: dict
    snapshots: dict
    n_returns: int = 0
    n_steps: int = 0
    n_restarts: int = 0


def _far_radius(scene, model):
    return scene.r_far if scene.r_far is not None else max(10.0 * model.saddle_radius, 2.0 * scene.r_esc)


# Every initial condition lies on the section (x px + y py = 0 exactly in
# double). With the event value exactly 0 at the start of a step, heyoka's root
# isolation reported the root at t = 0 twice and lost the next crossing in the
# same (first) step: 6 of 500 orbits at E = 0.27 had their first crossing
# (t ≈ 0.03–0.25) missing (issue 5, `make bench`). A constant offset of 1e-300
# makes the start value non-zero; it moves a crossing by 1e-300/|d(x px + y py)/dt|.
_SECTION_OFFSET = 1e-300


def _section_expr(x, y, px, py):
    return x * px + y * py - _SECTION_OFFSET


def build_integrator(scene, batch_size, *, fp_type=float, tol=None):
    """build_integrator(scene, batch_size) -> (taylor_adaptive_batch, event_names).

    The system and the events are heyoka expressions; γ is a runtime
    parameter (``hy.par[0]``) so that one JIT compilation serves every γ
    (heyoka caches it per process).
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
        # normalised so that the event's value stays O(1): heyoka's step-size
        # control sees event values, and r² − r_far² ~ −r_far² would loosen the
        # effective tolerance by ~r_far² (measured: r_far = 1e4 gave escape-time
        # errors 1e-6 at tol 1e-15; r_far = 1e8 gave wrong outcomes)
        term("far", r2 / _far_radius(scene, model) ** 2 - 1.0, pos)
    else:
        term("escape", r2 - scene.r_esc**2, pos)

    nt_names, nt_events = [], []
    if dissipative:
        nt_names.append("resc")
        nt_events.append(hy.nt_event_batch(r2 - scene.r_esc**2, _NtCallback("resc")))
    if scene.sections is not None:
        nt_names.append("section")
        nt_events.append(hy.nt_event_batch(_section_expr(x, y, px, py), _NtCallback("section")))

    kw = {"pars": np.full((1, batch_size), scene.gamma)} if dissipative else {}
    ta = hy.taylor_adaptive_batch(
        sys,
        np.zeros((4, batch_size)),
        tol=scene.tol if tol is None else tol,
        **kw,
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
        self.model = scene.model
        self.ta = ta
        self.B = ta.batch_size
        self.state = ta.state  # live views into the integrator
        self.time_hi, self.time_lo = ta.dtime
        self.ics = ics.tolist()
        self.n = len(ics)
        self.next = 0
        self.r_s = self.model.saddle_radius
        self.t_max = scene.t_max
        self.half_w2 = 0.5 * self.model.omega**2
        self.lam = self.model.lam

        self.orbit = [-1] * self.B
        self.t0_hi = [0.0] * self.B
        self.t0_lo = [0.0] * self.B
        self.last_out = [None] * self.B  # (t, state) of the last outward r_esc crossing
        # bound of the running propagate_until call (numpy, read by callbacks)
        # and the bound each lane's current orbit needs
        self.tf = np.zeros(self.B)
        self.tf_orbit = [0.0] * self.B
        self.n_restarts = 0
        self.n_loads = 0
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
            "resc": self.on_resc,
            "section": self.on_section,
        }
        for name, ev in zip(names, ta.t_events):
            ev.callback.handler = handlers[name]
        for name, ev in zip(nt_names, ta.nt_events):
            ev.callback.handler = handlers[name]

    def release(self):
        """Unbind the event handlers: break the cycle integrator → callbacks → self → integrator.

        heyoka's integrator is invisible to Python's cycle collector, so without
        this every chunk's integrator and lanes stayed alive (measured: ~250
        bytes per orbit, i.e. simulation memory growing with N).
        """
        for ev in (*self.ta.t_events, *self.ta.nt_events):
            ev.callback.handler = None

    def energy(self, x, y, px, py):
        """H at one point in plain float arithmetic (numpy calls cost µs per scalar)."""
        x, y, px, py = float(x), float(y), float(px), float(py)
        return 0.5 * (px * px + py * py) + self.half_w2 * (x * x + y * y) + self.lam * (x * x * y - y * y * y / 3.0)

    # -- time helpers -----------------------------------------------------
    def elapsed(self, lane):
        """Orbit time of ``lane`` now: the double nearest (hi + lo) − (hi0 + lo0).

        TwoSum keeps the rounding error of hi − hi0, so the result does not
        depend on the lane's clock (i.e. on chunking), as it would with a plain
        (hi − hi0) + (lo − lo0).
        """
        a, b = self.time_hi[lane], -self.t0_hi[lane]
        s = a + b
        bb = s - a
        err = (a - (s - bb)) + (b - bb)
        return s + (err + (self.time_lo[lane] - self.t0_lo[lane]))

    def orbit_time(self, t_abs, lane):
        return (t_abs - self.t0_hi[lane]) - self.t0_lo[lane]

    def dense_state(self, t_abs, lane):
        """State of ``lane`` at absolute time t_abs inside the last step (dense output)."""
        t = self.time_hi.copy()
        t[lane] = t_abs
        return self.ta.update_d_output(t)[:, lane]

    # -- lane life cycle --------------------------------------------------
    def load(self, lane, k=None):
        """Put orbit ``k`` (default: the next one) into ``lane``; park the lane if none is left.

        Returns what a terminal callback must return: ``False`` (stop the
        propagation) when the lane is parked or some lane sits at its bound.
        """
        if k is None:
            k = self.next
            if k >= self.n:
                self.orbit[lane] = -1
                return False
            self.next = k + 1
        self.orbit[lane] = k
        self.state[:, lane] = self.ics[k]
        hi = self.time_hi[lane]
        self.t0_hi[lane], self.t0_lo[lane] = hi, self.time_lo[lane]
        self.tf_orbit[lane] = hi + self.t_max
        self.last_out[lane] = None
        self.sec_found[lane] = False
        self.pending_sec[lane] = []
        if self.snap_times:
            self.pending_snap[lane] = []
            i = 0
            if self.snap_times[0] == 0.0:
                x, y, px, py = self.ics[k]
                self.pending_snap[lane].append((k, 0.0, self.energy(x, y, px, py)))
                i = 1
            self.snap_k[lane] = i
        self.ta.reset_cooldowns(lane)
        # a lane at its bound idles until the call returns; checking costs ~1 µs,
        # so look every 8th load (idle time ≲ 8 orbit ends, once per t_max)
        self.n_loads += 1
        return (self.n_loads & 7) or not (self.time_hi >= self.tf).any()

    def finish(self, lane, outcome, t_end, state):
        k = self.orbit[lane]
        self.outcome[k] = outcome
        self.t_end[k] = t_end
        self.end_state[k] = state
        if self.snap_times:
            if outcome != CENSORED:  # at a bound the step's dense output ends at t_max
                self.take_snapshots(lane, self.elapsed(lane))
            self.snap_rows.extend(r for r in self.pending_snap[lane] if r[1] <= t_end)
            self.pending_snap[lane] = []
        if self.pending_sec[lane]:
            self.sec_rows.extend(r for r in self.pending_sec[lane] if r[1] <= t_end)
            self.pending_sec[lane] = []
        return self.load(lane)

    def at_bound(self, lane):
        """After a return: handle a lane that reached its propagation bound."""
        if self.tf[lane] == self.tf_orbit[lane]:
            st = self.state[:, lane]
            self.finish(lane, CENSORED, self.t_max, st)
        else:
            # a stale bound cut this orbit's step: rerun it from its start
            self.n_restarts += 1
            self.load(lane, self.orbit[lane])

    def take_snapshots(self, lane, upto):
        """Record the energies at the snapshot times ≤ ``upto`` (orbit time) inside the last step."""
        i = self.snap_k[lane]
        times = self.snap_times
        k = self.orbit[lane]
        while i < len(times) and times[i] <= upto:
            x, y, px, py = self.dense_state(self.t0_hi[lane] + (times[i] - self.t0_lo[lane]), lane)
            self.pending_snap[lane].append((k, times[i], self.energy(x, y, px, py)))
            i += 1
        self.snap_k[lane] = i

    def on_step(self, ta):
        """Step callback (snapshot scenes only): snapshots passed by this step."""
        for lane in range(self.B):
            if self.orbit[lane] >= 0:
                i = self.snap_k[lane]
                if i < len(self.snap_times) and self.snap_times[i] <= self.elapsed(lane):
                    # an orbit loaded by this step's terminal callback has elapsed 0
                    self.take_snapshots(lane, self.elapsed(lane))
        return True

    # -- terminal events --------------------------------------------------
    def on_escape(self, lane):
        return self.finish(lane, ESCAPED, self.elapsed(lane), self.state[:, lane])

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

    for lane in range(B):
        lanes.load(lane)
    step_cb = lanes.on_step if scene.snapshots else None
    tf = lanes.tf
    n_returns = 0
    n_steps = 0
    while True:
        for lane in range(B):
            if lanes.orbit[lane] >= 0 and lanes.time_hi[lane] >= tf[lane]:
                lanes.at_bound(lane)
        for lane in range(B):
            # parked lanes hold still at their current time
            tf[lane] = lanes.tf_orbit[lane] if lanes.orbit[lane] >= 0 else lanes.time_hi[lane]
        if all(k < 0 for k in lanes.orbit):
            break
        ta.propagate_until(tf, callback=step_cb)
        n_returns += 1
        for lane, res in enumerate(ta.propagate_res):
            n_steps += res[3]
            if res[0] == hy.taylor_outcome.err_nf_state:
                raise FloatingPointError(
                    f"non-finite state in lane {lane} (orbit {traj_ids[lanes.orbit[lane]]}); "
                    "this is a bug: escaping orbits must be stopped by the engine's events"
                )
    lanes.release()
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
    return ChunkResult(lifetimes, sections, snapshots, n_returns=n_returns, n_steps=n_steps,
                       n_restarts=lanes.n_restarts)


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
    cast = _caster(fp_type)

    rec = {"last_out": None, "sections": []}

    def on_resc(ta, t, d):
        rec["last_out"] = t if d > 0 else None

    def on_section(ta, t, d):
        rec["sections"].append(t)

    t_events = []
    if dissipative:
        t_events.append(hy.t_event(H - model.critical_energy, direction=neg, fp_type=fp_type))
        t_events.append(hy.t_event(r2 / _far_radius(scene, model) ** 2 - 1.0, direction=pos, fp_type=fp_type))
        nt_events = [hy.nt_event(r2 - scene.r_esc**2, on_resc, fp_type=fp_type)]
    else:
        t_events.append(hy.t_event(r2 - scene.r_esc**2, direction=pos, fp_type=fp_type))
        nt_events = []
    if scene.sections is not None:
        nt_events.append(hy.nt_event(_section_expr(x, y, px, py), on_section, fp_type=fp_type))

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


def _caster(fp_type):
    """Values -> what heyoka's constructor takes for ``fp_type`` (lists for real128)."""
    if fp_type is float:
        return lambda v: np.asarray(v, dtype=float)
    if fp_type is np.longdouble:
        return lambda v: np.asarray(v, dtype=np.longdouble)
    return lambda v: [fp_type(float(a)) for a in np.asarray(v, dtype=float)]


def state_at(scene, ic, t, *, fp_type=float, tol=None):
    """state_at(scene, ic, t) -> state (4,) at orbit time t from a fresh scalar run (no events)."""
    import heyoka as hy

    sys = equations(scene.model, hy.par[0] if scene.gamma > 0 else None)
    cast = _caster(fp_type)
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
    ta.propagate_until(fp_type(t) if fp_type is not float else t)
    return ta.state.copy()


__all__ = ["run_chunk", "simulate_orbit", "state_at", "build_integrator", "ChunkResult", "OUTCOMES"]
