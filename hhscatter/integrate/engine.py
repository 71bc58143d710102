"""Batch Taylor engine: ``run_chunk(scene, ics, traj_ids) -> ChunkResult``.

One block of orbits runs on one ``heyoka.taylor_adaptive_batch`` whose
events come from :mod:`hhscatter.integrate.events` (declared there once, as data). The
same rules (:class:`LaneRules`) drive the scalar reference driver
:func:`simulate_orbit` (long double, real128) used by the tests, the
benchmarks and the stress cases.

Two lane schedulers, chosen by the scene
----------------------------------------
*Stream* (scenes without snapshots). heyoka's batch ``propagate_until``
returns for all lanes when one lane stops, and a return costs more than a
short orbit, so an orbit's end never stops the propagation: its event
callback records the outcome and loads the next initial condition into the
lane. Callbacks cannot change a lane's clock, so an orbit's time is the lane
time minus its start, both double-length (hi, lo); TwoSum keeps the
difference exact to ~2⁻¹⁰⁶ of the lane time, so orbit times do not depend on
how orbits share lanes. One case remains: an orbit time whose exact value is
a tie (halfway between two doubles; sums of steps often are) would round by
that ~2⁻¹⁰⁶ residue, which depends on the lane's start. Orbit times within
2⁻³⁰ of a gap of a tie round to even (:func:`_tie_to_even`), so they too are
the same in every lane.
Censoring is the clock's: σ = (t_max − t)/G, set at load and integrated with
the orbit, is a terminal event at t_max in the orbit's own time (its steps
and root do not depend on the lane's history; σ ∈ [0, 1] adds nothing to
the step-size control: the same steps, measured). No propagation bound ever
clamps a step: a bound (lane start + t_max) used to, and the censored state,
and the root of any event in a step clamped by an earlier orbit's stale
bound, then depended on when the lane's earlier orbits ended (the chunk
size). A chunk is one ``propagate_until`` call, so every orbit's
steps are exactly those it has alone.

*Epochs* (scenes with energy snapshots). A step callback in Python on every
step, which snapshots used to need, cost more than the integration. Here all
lanes advance together in epochs of length P, each one call of
``propagate_grid`` whose grid holds every lane's snapshot times: heyoka's
compiled dense output evaluates them, energies are computed in bulk in numpy,
and no Python runs per step or per snapshot. Every epoch starts with every
lane clock reset to 0, orbits start only at epoch starts, and an orbit that
ends mid-epoch leaves its lane parked at the origin (a fixed point: one step)
until the epoch ends. An orbit's time is its epoch count times P plus the
lane time, and its steps are cut only at multiples of P of its own time, so
results do not depend on chunking, lanes or batch size either.

Dissipative escapes end at the system's no-return radius R(E0) rather than r_far (:func:`_no_return`: the
same tables, bit for bit, in fewer steps).

Everything else is the same in both: the events and outcome rules of
:mod:`hhscatter.integrate.events`, whose roots end heyoka's step exactly (terminal
events with callbacks), so event states and times are the integrator's own.
A process compiles a scene's integrator once and reuses it for its later
chunks, reset to a new one's state (:func:`_batch_integrator`).
"""
from __future__ import annotations

import abc
import collections
import contextlib
import functools
import math
import threading
from dataclasses import dataclass, field

import numpy as np

from hhscatter.integrate import events
from hhscatter.integrate.events import (
    CENSORED,
    ESCAPED,
    OUTCOMES,
    SETTLED,
    STOPPED,
    caster,
)

LIVE, FOLLOWING, CONTINUING = 0, 1, 2  # phase of the orbit in a lane
EPOCH = 8.0  # target epoch length P (time units) of the epoch scheduler
EPOCH_BATCH = 8  # lanes of the epoch scheduler (measured: 8 ≤ 16, 32 at P = 8)
STREAM_BATCH = 8  # lanes of the stream scheduler (measured: 14 % less per lane-step than 4)
SECTION_COLUMNS = ("traj_id", "t", "x", "y", "px", "py", "energy")
CROSSING_COLUMNS = ("traj_id", "t", "radius", "direction")
PROGRESS_EVERY = 1024  # orbits between progress reports from inside a chunk
_NO_BOUND = 1e15  # propagation bound of lanes whose orbits the clock ends at t_max (never reached)
RERUN = -2  # outcome code inside a chunk: decided at the no-return radius too close to t_max; rerun to r_far
NO_RETURN_GRID = 1.0 / 8.0  # the no-return far radius is rounded up to this fraction of r_s (fewer compiles)
NO_RETURN_MARGIN = 0.01  # ... and lies at least this fraction beyond r_esc (its root is never r_esc's)


_ulp = math.ulp
TIE_BAND = 2.0 ** -30  # an orbit time this close (in gaps) to a tie of its rounding is a tie (>> the 2^-106 residue)


def _tie_to_even(r: float, rem: float) -> float:
    """The orbit time r + rem (r the double nearest it, rem the exact remainder) rounded half to even when
    it lies within TIE_BAND gaps of the midpoint between r and its neighbour on rem's side; r otherwise.

    The remainder of an orbit time carries ~2⁻¹⁰⁶ of the lane time of error that depends on the lane's
    start, which decides a tie's rounding; rounding near-ties to even makes it the same in every lane.
    Called only when :func:`_orbit_time`'s screen finds ``rem`` near a half or quarter ulp (the gap below
    a power of two is half the ulp).

    >>> r = 1.0 + 2.0 ** -52                      # odd mantissa; its upper neighbour is even
    >>> _tie_to_even(r, 2.0 ** -53 - 2.0 ** -140) == r + 2.0 ** -52
    True
    >>> _tie_to_even(r, 2.0 ** -55) == r          # not a tie: r is the nearest
    True
    """
    n = math.nextafter(r, math.inf if rem > 0 else -math.inf)
    gap = abs(n - r)
    if abs(abs(rem) - 0.5 * gap) > gap * TIE_BAND:
        return r
    m = math.frexp(r)[0]
    return r if int(m * 9007199254740992.0) % 2 == 0 else n  # the even mantissa of the two


def _orbit_time(a: float, el: float, a0: float, el0: float) -> float:
    """The orbit time (a + el) − (a0 + el0) of double-length lane times (hi, lo), as the double nearest it:
    TwoSum of the high parts, the low parts added, near-ties rounded to even (:func:`_tie_to_even`; the
    screen costs one ``math.ulp`` per call: every orbit end passes here)."""
    b = -a0
    s = a + b
    bb = s - a
    c = ((a - (s - bb)) + (b - bb)) + (el - el0)
    r = s + c
    rem = c - (r - s)
    if rem:
        u, h = _ulp(r), abs(rem)
        if abs(h - 0.5 * u) <= u * TIE_BAND or abs(h - 0.25 * u) <= u * TIE_BAND:  # (the gap below 2^k is u/2)
            return _tie_to_even(r, rem)
    return r


@dataclass
class ChunkResult:
    """Rows produced by one chunk (plain numpy arrays, table column order)."""

    lifetimes: dict
    sections: dict
    snapshots: dict
    crossings: dict
    n_returns: int = 0
    n_steps: int = 0

    def tables(self) -> dict:
        return {"lifetimes": self.lifetimes, "sections": self.sections, "snapshots": self.snapshots,
                "crossings": self.crossings}


class _Callback:
    """An event's callback; heyoka deep-copies it, so its handler is bound afterwards."""

    __slots__ = ("handler",)

    def __init__(self, spec=None):
        self.handler = None

    def __call__(self, ta, d_sgn, lane=0):
        return self.handler(lane, d_sgn)


def _bind(ta, specs, rules, inlined=None):
    """Bind each event's callback to the handler of its rule (``inlined``: {rule: closure} that replace some)."""
    for spec, ev in zip(specs, ta.t_events):
        if inlined and spec.rule in inlined:
            ev.callback.handler = inlined[spec.rule]
        else:
            ev.callback.handler = rules.handler(spec)


def _unbind(ta):
    """Break the cycle integrator → callbacks → rules → integrator (heyoka's objects are
    invisible to Python's cycle collector: without this every chunk's integrator stayed alive)."""
    for ev in ta.t_events:
        ev.callback.handler = None


_FREE = collections.OrderedDict()  # batch_key -> integrators that finished a chunk, ready for the next one
_FREE_LOCK = threading.Lock()  # (a Dask worker may run chunks in threads)
_FREE_KEYS = 4  # distinct compiled systems kept per process (a grid of r_esc values compiles one each)


@contextlib.contextmanager
def _batch_integrator(scene, batch_size, without=()):
    """_batch_integrator(scene, batch_size, without=()) -> context manager yielding (ta, specs, layout).

    One compiled batch integrator per worker process and scene (:func:`hhscatter.integrate.events.batch_key`),
    reused across chunks instead of a new ``taylor_adaptive_batch`` per chunk (measured: ~6 ms and a
    JIT lookup each). A reused integrator is reset to what a new one is: time 0 (both parts of the
    double-length clock), state 0, the scene's parameters (γ; gates closed), no event cooldowns;
    heyoka's step depends on nothing else, so results are bit-identical (tested). An integrator in
    use is out of the cache; the handlers are unbound on return.
    """
    key, specs, lay = events.batch_key(scene, batch_size, without=without)
    with _FREE_LOCK:
        free = _FREE.get(key)
        ta = free.pop() if free else None
    if ta is None:
        ta, specs, lay = events.build_batch(scene, batch_size, _Callback, without=without)
    else:
        zeros = np.zeros(batch_size)
        ta.set_dtime(zeros, zeros)
        ta.state[:] = 0.0
        pars = events.batch_pars(scene, lay, batch_size, without)
        if len(pars):
            ta.pars[:] = pars
        ta.reset_cooldowns()
    try:
        yield ta, specs, lay
    finally:
        _unbind(ta)
        with _FREE_LOCK:
            _FREE.setdefault(key, []).append(ta)
            _FREE.move_to_end(key)
            while len(_FREE) > _FREE_KEYS:
                _FREE.popitem(last=False)


class LaneRules(abc.ABC):
    """Event handlers = the outcome rules of :mod:`hhscatter.integrate.events`, per lane.

    The rules are written once, here; a scheduler (a batch integrator's lanes, or one scalar orbit) subclasses
    this and supplies the integrator access below (the abstract methods). :meth:`handler` gives the handler of an
    event's rule (:attr:`hhscatter.integrate.events.EventSpec.rule`); each handler takes (lane, direction) and
    returns whether the propagation continues.
    """

    # -- the integrator access a scheduler supplies ------------------------------
    @abc.abstractmethod
    def elapsed(self, lane: int) -> float:
        """The orbit time of ``lane`` now (time units)."""
    @abc.abstractmethod
    def state4(self, lane: int) -> tuple:
        """(x, y, px, py) of ``lane`` now, as Python floats."""
    @abc.abstractmethod
    def set_gate(self, lane: int, g: float) -> None:
        """Open (1.0) or close (0.0) the section event of ``lane``."""
    @abc.abstractmethod
    def set_clock(self, lane: int, sigma: float) -> None:
        """Set the clock variable σ of ``lane`` (its root is the next clock target)."""
    @abc.abstractmethod
    def record(self, lane: int, outcome: int, t: float, state) -> None:
        """Record the orbit's outcome (a code of :mod:`hhscatter.outcomes`), its end time and end state."""
    @abc.abstractmethod
    def release(self, lane: int) -> bool:
        """The orbit of ``lane`` needs nothing more: load the next orbit, park the lane, or stop.

        Returns what the event callback returns (False stops the propagation).
        """
    #: None, or f(t, state) -> True when an orbit at the no-return far radius might not have reached the
    #: scene's r_far by t_max (run_chunk's no-return rule: the orbit is then rerun to r_far)
    late = None

    def handler(self, spec):
        """handler(spec) -> the callable (lane, direction) -> continue? of the event ``spec``'s rule."""
        rules = {"escape": self.on_escape, "closure": self.on_closure, "far": self.on_far, "resc": self.on_resc,
                 "radius": self.on_radius, "section": self.on_section, "clock": self.on_clock}
        h = rules[spec.rule]
        return functools.partial(h, spec.index) if spec.index is not None else h

    def setup(self, scene, layout, n_lanes):
        self.scene = scene
        self.model = scene.model
        self.r_s = self.model.omega_radius  # Ω = {r ≤ r_s}: the closure rule's well
        self.energy = self.model.scalar_energy()  # H of one point in plain float arithmetic
        self.layout = layout
        self.win = scene.sections
        self.follow = scene.follow is not None
        self.radii = events.follow_radii(scene) if self.follow else ()
        self.r_esc = float(scene.r_esc)
        self.continue_settled = bool(scene.continue_settled)
        self.targets = events.clock_targets(scene)
        self.clock_scale = layout.clock_scale
        self.orbit = [-1] * n_lanes
        self.phase = [LIVE] * n_lanes
        self.last_out = [None] * n_lanes
        self.sec_found = [False] * n_lanes
        self.clock_i = [0] * n_lanes
        self.pending_sec = [[] for _ in range(n_lanes)]
        self.pending_cross = [[] for _ in range(n_lanes)]
        self.sec_rows, self.cross_rows = [], []
        self.migrate_at_open = False  # first phase of a two-phase scene: hand orbits on at t_from
        self.migrants = []

    def start_orbit(self, lane, k):
        """Per-orbit rule state at load; sets the section gate and the clock."""
        self.orbit[lane] = k
        self.phase[lane] = LIVE
        self.last_out[lane] = None
        self.sec_found[lane] = False
        self.clock_i[lane] = 0
        self.pending_sec[lane] = []
        self.pending_cross[lane] = []
        if self.win is not None:
            self.set_gate(lane, 1.0 if self.win.t_from <= 0 else 0.0)
        if self.targets:
            self.set_clock(lane, self.targets[0][0] / self.clock_scale)

    def end_censored(self, lane):
        """Alive at t_max: censored there (t_end = t_max exactly, the state where the orbit is)."""
        self.record(lane, CENSORED, self.scene.t_max, self.state4(lane))
        return self.release(lane)

    def commit(self, lane, t_end, continuing):
        """Move the orbit's pending rows to the output (rows after t_end belong to no table)."""
        if self.pending_sec[lane]:
            self.sec_rows.extend(r for r in self.pending_sec[lane] if continuing or r[1] <= t_end)
            self.pending_sec[lane] = []
        if self.pending_cross[lane]:
            self.cross_rows.extend(self.pending_cross[lane])
            self.pending_cross[lane] = []

    def end(self, lane, outcome, t, state):
        """The orbit's outcome is known: record it; release the lane unless the scene follows on."""
        self.record(lane, outcome, t, state)
        if outcome == ESCAPED and self.follow:
            self.phase[lane] = FOLLOWING
            return True
        if outcome == SETTLED and self.continue_settled:
            self.phase[lane] = CONTINUING
            return True
        return self.release(lane)

    # -- handlers: (lane, direction) -> continue the propagation? ----------------
    def on_escape(self, lane, d):
        if self.orbit[lane] < 0 or self.phase[lane] != LIVE:
            return True
        return self.end(lane, ESCAPED, self.elapsed(lane), self.state4(lane))

    def on_closure(self, lane, d):
        if self.orbit[lane] < 0 or self.phase[lane] != LIVE:
            return True
        st = self.state4(lane)
        out = events.closure_rule(st[0] * st[0] + st[1] * st[1], self.r_s, self.last_out[lane])
        if out == SETTLED:
            return self.end(lane, SETTLED, self.elapsed(lane), st)
        if out == ESCAPED:
            return self.end(lane, ESCAPED, *self.last_out[lane])
        return True

    def on_far(self, lane, d):
        if self.orbit[lane] < 0:
            return True
        if self.phase[lane] == LIVE:
            if self.last_out[lane] is None:  # unreachable: r_far > r_esc; kept as a guard
                raise RuntimeError("orbit reached r_far without crossing r_esc")
            if self.late is not None and self.late(self.elapsed(lane), self.state4(lane)):
                return self.end(lane, RERUN, *self.last_out[lane])
            return self.end(lane, ESCAPED, *self.last_out[lane])
        return self.release(lane)  # a followed orbit is gone

    def on_resc(self, lane, d):
        if self.orbit[lane] >= 0 and self.phase[lane] == LIVE:
            self.last_out[lane] = (self.elapsed(lane), self.state4(lane)) if d > 0 else None
        return True

    def on_radius(self, k, lane, d):
        if self.orbit[lane] < 0:
            return True
        t = self.elapsed(lane)
        R = self.radii[k]
        self.pending_cross[lane].append((self.orbit[lane], t, R, d))
        if R == self.r_esc and d > 0 and self.phase[lane] == LIVE:  # the escape (follow scenes)
            return self.end(lane, ESCAPED, t, self.state4(lane))
        return True

    def on_section(self, lane, d):
        if self.orbit[lane] < 0:
            return True
        t = self.elapsed(lane)
        x, y, px, py = self.state4(lane)
        e = self.energy(x, y, px, py)
        if not events.section_accepts(self.win, t, x, y, px, py, e):
            return True
        self.pending_sec[lane].append((self.orbit[lane], t, x, y, px, py, e))
        if self.win.first_only:
            self.sec_found[lane] = True
            self.set_gate(lane, 0.0)
            if self.win.stop and self.phase[lane] == LIVE:
                return self.end(lane, STOPPED, t, (x, y, px, py))
        return True

    def on_clock(self, lane, d):
        if self.orbit[lane] < 0:
            self.set_clock(lane, 1.0)
            return True
        t = self.elapsed(lane)
        i = self.clock_i[lane]
        targets = self.targets
        # the root of σ lands within rounding (~ulp(1)·G) of its target, on either side
        while i < len(targets) and targets[i][0] <= t + 1e-12 * self.clock_scale:
            if targets[i][1] == "censor":  # t_max, which the stream scheduler leaves to the clock
                self.clock_i[lane] = i + 1
                if self.phase[lane] == LIVE:
                    return self.end_censored(lane)
                return self.release(lane)
            if targets[i][1] == "open":
                if self.migrate_at_open:  # the window opens: the orbit goes on in the second phase
                    self.migrants.append((self.orbit[lane], self.state4(lane), t, i + 1, self.last_out[lane],
                                          self.phase[lane]))
                    return self.release(lane)
                if not self.sec_found[lane]:
                    self.set_gate(lane, 1.0)
            else:
                self.set_gate(lane, 0.0)
                if self.win.stop and self.phase[lane] == LIVE:
                    self.clock_i[lane] = i + 1
                    return self.end(lane, STOPPED, t, self.state4(lane))
            i += 1
        self.clock_i[lane] = i
        self.set_clock(lane, (targets[i][0] - t) / self.clock_scale if i < len(targets) else 1.0)
        return True


class _BatchRules(LaneRules):
    """Lanes of one batch integrator: the part shared by both schedulers."""

    def __init__(self, scene, ta, layout, ics):
        self.ta = ta
        self.B = ta.batch_size
        self.setup(scene, layout, self.B)
        self.state = ta.state  # live views into the integrator
        self.cols = [self.state[:4, lane] for lane in range(self.B)]  # (x, y, px, py) of each lane
        self.pars = ta.pars if layout.n_pars else None
        self.gate_live = layout.gate is not None and layout.gate < len(ta.pars)
        self.time_hi, self.time_lo = ta.dtime
        self.ics = ics.tolist()
        self.n = len(ics)
        self.next = 0
        self.t_max = scene.t_max
        # Python lists (an element write costs a fifth of numpy's), arrays once per chunk
        self.count_steps = False  # set by run_chunk(count_steps=True): the epoch loop then reads every lane's result
        self.progress = None  # run_chunk(progress=f): f(k) after every PROGRESS_EVERY orbits loaded
        self.ticks = 0
        self.outcome = [-1] * self.n
        self.t_end = [math.nan] * self.n
        # state at t_end; energies and exit channels are computed from it once per chunk
        self.end_state = [None] * self.n

    def state4(self, lane):
        return tuple(self.cols[lane].tolist())

    def set_gate(self, lane, g):
        if self.gate_live:  # (a first phase has no section event, hence no gate)
            self.pars[self.layout.gate, lane] = g

    def set_clock(self, lane, sigma):
        self.state[self.layout.clock, lane] = sigma

    def record(self, lane, outcome, t, state):
        k = self.orbit[lane]
        self.outcome[k] = outcome
        self.t_end[k] = t
        self.end_state[k] = state

    def tick(self):
        """Report progress every PROGRESS_EVERY loaded orbits (``run_chunk(progress=...)``)."""
        self.ticks += 1
        if self.ticks >= PROGRESS_EVERY:
            self.progress(self.ticks)
            self.ticks = 0

    def put(self, lane, k):
        """Initial condition k into ``lane`` (state, rules, cooldowns)."""
        if self.progress is not None:
            self.tick()
        self.state[:4, lane] = self.ics[k]
        self.start_orbit(lane, k)
        self.ta.reset_cooldowns(lane)

    def finish_rows(self, lane):
        if self.pending_sec[lane] or self.pending_cross[lane]:
            k = self.orbit[lane]
            self.commit(lane, self.t_end[k], self.phase[lane] == CONTINUING)


class _Stream(_BatchRules):
    """Stream scheduler: the next orbit is loaded in the callback that ends one."""

    def __init__(self, scene, ta, layout, ics):
        super().__init__(scene, ta, layout, ics)
        self.start_hi = [0.0] * self.B
        self.start_lo = [0.0] * self.B
        # bound of the running propagate_until call: none for live lanes (the clock censors at t_max)
        self.bound = np.zeros(self.B)
        if not any(a == "censor" for _, a in self.targets):
            raise RuntimeError("internal error: a stream scene without the clock's censor target")
        self.t_off = [0.0] * self.B  # orbit time at which the lane's orbit entered this integrator

    def inlined_handlers(self):
        """Lean closures for the hot handlers of plain scenes (no section event, no follow): {rule: handler}.

        The same rules as the methods of :class:`LaneRules`, with the per-orbit
        Python cut to a few list operations (measured: the generic chain of
        method calls cost ~3 µs per orbit, more than half the integration of a
        conservative orbit at E = 0.27).
        """
        elapsed, finish, end_now, next_orbit, cols = self._inlined_orbit_steps()
        orbit, last_out = self.orbit, self.last_out
        r_s2 = self.r_s * self.r_s

        def on_escape(lane, d):
            if orbit[lane] < 0:
                return True
            return end_now(lane, ESCAPED)

        def on_resc(lane, d):
            if orbit[lane] >= 0:
                last_out[lane] = (elapsed(lane), cols[lane].tolist()) if d > 0 else None
            return True

        def on_closure(lane, d):
            if orbit[lane] < 0:
                return True
            x, y, _, _ = cols[lane].tolist()
            if x * x + y * y <= r_s2:  # events.closure_rule, inlined
                return end_now(lane, SETTLED)
            out = last_out[lane]
            return finish(lane, ESCAPED, *out) if out is not None else True

        late = self.late

        def on_far(lane, d):
            if orbit[lane] < 0:
                return True
            out = last_out[lane]
            if out is None:  # unreachable: r_far > r_esc; kept as a guard
                raise RuntimeError("orbit reached r_far without crossing r_esc")
            if late is not None and late(elapsed(lane), cols[lane].tolist()):
                return finish(lane, RERUN, *out)
            return finish(lane, ESCAPED, *out)

        self.load = next_orbit
        return {"escape": on_escape, "resc": on_resc, "closure": on_closure, "far": on_far}

    def _inlined_orbit_steps(self):
        """The closures the inlined handlers share: a lane's orbit time, the end of an orbit at a given time and
        state (record, load the next), the end of an orbit where the lane is now, the loading of the next orbit
        (returns what a callback returns); state captured once, as lists, Python floats and per-lane views.
        Per orbit end (measured): the lane time is read once (an orbit that ends where the lane is
        ends at the time the next starts), the state through ``cols[lane]`` (a third of ``state[:4, lane]``)."""
        orbit, last_out = self.orbit, self.last_out
        hi, lo, starts_hi, starts_lo = self.time_hi, self.time_lo, self.start_hi, self.start_lo
        st, ics, ta, cols = self.state, self.ics, self.ta, self.cols
        outcomes, t_ends, end_states = self.outcome, self.t_end, self.end_state
        n = self.n
        progress = self.progress
        reset = ta.reset_cooldowns
        # a two-phase scene's first phase has the clock (to hand orbits on at t_from, and t_max)
        clock, phase, clock_i = self.layout.clock, self.phase, self.clock_i
        sigma0 = self.targets[0][0] / self.clock_scale

        hi_, lo_ = hi.item, lo.item  # Python floats: numpy scalar arithmetic costs ~5× more
        orbit_time = _orbit_time

        def elapsed(lane):
            return orbit_time(hi_(lane), lo_(lane), starts_hi[lane], starts_lo[lane])

        counter = [self.next]

        def start_next(lane, h, el):
            """Load the next orbit into ``lane``, whose time is (h, el) now."""
            k = counter[0]
            if k >= n:
                orbit[lane] = -1
                self.next = n
                return False
            counter[0] = k + 1
            orbit[lane] = k
            last_out[lane] = None
            if progress is not None:
                self.tick()
            c = cols[lane]
            c[0], c[1], c[2], c[3] = ics[k]  # four scalar writes: half the cost of converting the list
            if clock is not None:
                st[clock, lane] = sigma0
                clock_i[lane] = 0
                phase[lane] = LIVE
            starts_hi[lane] = h
            starts_lo[lane] = el
            reset(lane)
            return True

        def next_orbit(lane):
            return start_next(lane, hi_(lane), lo_(lane))

        def finish(lane, outcome, t, state):
            k = orbit[lane]
            outcomes[k], t_ends[k], end_states[k] = outcome, t, state
            return next_orbit(lane)

        def end_now(lane, outcome):
            k = orbit[lane]
            a, el = hi_(lane), lo_(lane)
            outcomes[k] = outcome
            t_ends[k] = orbit_time(a, el, starts_hi[lane], starts_lo[lane])  # elapsed(lane), lane time read once
            end_states[k] = cols[lane].tolist()
            return start_next(lane, a, el)

        return elapsed, finish, end_now, next_orbit, cols

    def elapsed(self, lane):
        """Orbit time of ``lane`` now: the double nearest (hi + lo) − (hi0 + lo0), via TwoSum."""
        r = _orbit_time(self.time_hi.item(lane), self.time_lo.item(lane), self.start_hi[lane], self.start_lo[lane])
        # + the orbit time at which it entered this integrator (0 but in a second phase)
        return r + self.t_off[lane]

    def load(self, lane):
        """Put the next orbit into ``lane``; park the lane if none is left.

        Returns what a callback must return: False (stop the propagation, so that
        the parked lane holds still) when the lane is parked.
        """
        k = self.next
        if k >= self.n:
            self.orbit[lane] = -1
            if self.layout.gate is not None:
                self.set_gate(lane, 0.0)
            return False
        self.next = k + 1
        self.put(lane, k)
        self.start_hi[lane], self.start_lo[lane] = self.time_hi.item(lane), self.time_lo.item(lane)
        return True

    def release(self, lane):
        self.finish_rows(lane)
        return self.load(lane)

    def run(self):
        B, ta, bound = self.B, self.ta, self.bound
        for lane in range(B):
            self.load(lane)
        n_returns = n_steps = 0
        while True:
            for lane in range(B):
                # parked lanes hold still at their current time
                bound[lane] = _NO_BOUND if self.orbit[lane] >= 0 else self.time_hi[lane]
            if all(k < 0 for k in self.orbit):
                break
            ta.propagate_until(bound)
            n_returns += 1
            n_steps += _check(ta, self)  # once per return (a handful per chunk)
        return n_returns, n_steps, _no_snapshots()


class _SecondPhase(_Stream):
    """The second phase of a two-phase stream scene: the orbits handed on at t_from, with the
    section event compiled in. Loads a migrant's state, orbit time and rule state instead of an
    initial condition; shares the outcome arrays and rows with the first phase."""

    def __init__(self, scene, ta, layout, first):
        self.migrants_in = first.migrants
        super().__init__(scene, ta, layout, np.zeros((len(first.migrants), 4)))
        for name in ("outcome", "t_end", "end_state", "sec_rows", "cross_rows"):
            setattr(self, name, getattr(first, name))
        self.progress = None  # the first phase reported these orbits already

    def put(self, lane, j):
        k, state, t_mig, clock_i, last_out, phase = self.migrants_in[j]
        self.state[:4, lane] = state
        self.start_orbit(lane, k)
        self.last_out[lane], self.phase[lane] = last_out, phase
        self.t_off[lane] = t_mig
        self.set_gate(lane, 1.0)
        self.clock_i[lane] = clock_i
        targets = self.targets
        self.set_clock(lane, (targets[clock_i][0] - t_mig) / self.clock_scale if clock_i < len(targets) else 1.0)
        self.ta.reset_cooldowns(lane)


class _Epochs(_BatchRules):
    """Epoch scheduler: all lanes advance together; snapshots from ``propagate_grid``."""

    def __init__(self, scene, ta, layout, ics):
        super().__init__(scene, ta, layout, ics)
        t_max = scene.t_max
        # P divides t_max, so censoring falls on an epoch's end
        self.n_epochs_max = max(1, math.ceil(t_max / EPOCH))
        self.P = t_max / self.n_epochs_max
        self.snaps = np.asarray(scene.snapshots or (), dtype=float)
        self.s_last = float(self.snaps[-1]) if self.snaps.size else -math.inf
        self.epoch = 0
        self.start_epoch = [0] * self.B
        self.zeros = np.zeros(self.B)

    def elapsed(self, lane):
        return ((self.epoch - self.start_epoch[lane]) * self.P + self.time_hi.item(lane)) + self.time_lo.item(lane)

    def release(self, lane):
        """Park the lane at the origin (a fixed point) until the epoch ends."""
        self.finish_rows(lane)
        self.orbit[lane] = -1
        self.state[:, lane] = 0.0
        if self.layout.clock is not None:
            self.set_clock(lane, 1.0)
        if self.layout.gate is not None:
            self.set_gate(lane, 0.0)
        return True

    def _tables(self):
        """Per epoch index k of an orbit: its grid column and the orbit times of its snapshots.

        Row k of ``grid_times`` holds the lane times of the snapshots s in [kP, (k+1)P)
        (the last epoch before t_max also (k+1)P), padded with fillers (strictly
        increasing, evaluated and discarded) to a common length; ``snap_times`` holds the
        snapshot times, NaN at fillers. Row −1 (parked lanes) is all fillers.
        Computed once per chunk, so an epoch's grid is a gather, not a loop.
        """
        P, S = self.P, self.snaps
        K = self.n_epochs_max
        rows = []
        s_last = S[-1] if S.size else -math.inf
        for k in range(K):
            o = k * P
            # a snapshot on an epoch boundary belongs to the later epoch's start, except the last
            # snapshot (and t_max), which ends the earlier one: orbits that need nothing after
            # them stop there
            i0 = np.searchsorted(S, o, "right" if k and s_last <= o else "left")
            i1 = np.searchsorted(S, o + P, "right" if k + 1 == K or s_last <= o + P else "left")
            s = S[i0:i1]
            rows.append((s - o, s))
        m = max(int(((r[0] > 0) & (r[0] < P)).sum()) for r in rows)
        n = m + 2
        tau = np.empty((K + 1, n))
        tt = np.full((K + 1, n), np.nan)
        tau[:, 0], tau[:, -1] = 0.0, P
        for k, (t, s) in enumerate(rows + [(np.empty(0), np.empty(0))]):
            inner = (t > 0) & (t < P)
            j = int(inner.sum())
            tau[k, 1:1 + j] = t[inner]
            tt[k, 1:1 + j] = s[inner]
            a = t[inner][-1] if j else 0.0
            tau[k, 1 + j:-1] = a + (P - a) * np.arange(1, m - j + 1) / (m - j + 1)
            if len(t) and t[0] == 0.0:
                tt[k, 0] = s[0]
            if len(t) and t[-1] == P:
                tt[k, -1] = s[-1]
        self.grid_times, self.snap_times = tau, tt
        self.has_snapshots = ~np.isnan(tt).all(axis=1)

    def run(self):
        B, ta, P, K = self.B, self.ta, self.P, self.n_epochs_max
        self._tables()
        grid_times, has_snapshots = self.grid_times, self.has_snapshots
        orbit, phase, start_epoch, st = self.orbit, self.phase, self.start_epoch, self.state
        s_last = self.s_last
        buf, rows = [], []
        n_returns = n_steps = 0
        lanes = range(B)
        for lane in lanes:
            self._load(lane)
        while any(k >= 0 for k in orbit):
            ta.set_time(self.zeros)
            epoch = self.epoch
            epoch_index = np.array([epoch - start_epoch[lane] if orbit[lane] >= 0 else -1 for lane in lanes])
            if has_snapshots[epoch_index].any():
                ids = np.array(orbit, dtype=np.int64)  # before the call: orbits end during it
                out = ta.propagate_grid(np.ascontiguousarray(grid_times[epoch_index].T))[1]
                buf.append((out[:, :4, :], epoch_index, ids))
                if len(buf) >= 256:
                    rows.append(self._snapshot_rows(buf))
                    buf = []
            else:
                ta.propagate_until(P)
            n_returns += 1
            if self.count_steps:
                n_steps += _check(ta, self)
            elif not np.isfinite(st).all():
                _check(ta, self)
            for lane in lanes:  # orbits that need nothing after this epoch end here
                if orbit[lane] >= 0:
                    k = epoch - start_epoch[lane] + 1  # epochs completed
                    if k >= K or (phase[lane] == CONTINUING and k * P >= s_last):
                        if phase[lane] == LIVE:
                            self.record(lane, CENSORED, self.t_max, self.state4(lane))
                        self.release(lane)
            self.epoch = epoch + 1
            for lane in lanes:
                if orbit[lane] < 0:
                    self._load(lane)
        if buf:
            rows.append(self._snapshot_rows(buf))
        ids = np.concatenate([r[0] for r in rows]) if rows else np.empty(0, np.int64)
        t = np.concatenate([r[1] for r in rows]) if rows else np.empty(0)
        e = np.concatenate([r[2] for r in rows]) if rows else np.empty(0)
        # rows after an orbit's end belong to no table (settled orbits continued: all rows)
        limit = np.where((np.array(self.outcome) == SETTLED) & self.continue_settled, np.inf,
                         np.array(self.t_end))
        keep = t <= limit[ids]
        return n_returns, n_steps, (ids[keep], t[keep], e[keep])

    def _snapshot_rows(self, buf):
        """Energies at the snapshot grid points of buffered epochs, in bulk: (orbit, t, E) rows."""
        out = np.stack([b[0] for b in buf])  # (epochs, n, 4, B)
        epoch_index = np.stack([b[1] for b in buf])  # (epochs, B)
        ids = np.stack([b[2] for b in buf])
        tt = self.snap_times[epoch_index].transpose(0, 2, 1)  # (epochs, n, B)
        ok = ~np.isnan(tt) & (ids >= 0)[:, None, :]
        x, y, px, py = (out[:, :, i, :][ok] for i in range(4))
        return (np.broadcast_to(ids[:, None, :], tt.shape)[ok], tt[ok], self.model.energy(x, y, px, py))

    def _load(self, lane):
        k = self.next
        if k >= self.n:
            return
        self.next = k + 1
        self.start_epoch[lane] = self.epoch
        self.put(lane, k)


def _check(ta, rules):
    import heyoka as hy  # deferred: heyoka loads on first use

    steps = 0
    for lane, res in enumerate(ta.propagate_res):
        steps += res[3]
        if res[0] == hy.taylor_outcome.err_nf_state:
            raise FloatingPointError(
                f"non-finite state in lane {lane}; this is a bug: escaping orbits must be stopped by the "
                "engine's events")
    return steps


def _no_snapshots():
    return np.empty(0, np.int64), np.empty(0), np.empty(0)


def scheduler(scene) -> str:
    """scheduler(scene) -> 'epochs' for scenes with snapshots, else 'stream'."""
    return "epochs" if scene.snapshots else "stream"


def run_chunk(scene, ics, traj_ids, *, batch_size=None, count_steps=False, progress=None) -> ChunkResult:
    """run_chunk(scene, ics, traj_ids, batch_size=None, count_steps=False, progress=None) -> ChunkResult.

    ``ics``: array (n, 4) of initial states (x, y, px, py); ``traj_ids``: int64
    array (n,). Returns the table rows of this chunk, ordered by traj_id (and
    time). ``batch_size`` (default: the scene's, else 8 lanes for the stream
    scheduler and 8 for epochs) has no effect on the results. ``count_steps``:
    fill ``ChunkResult.n_steps`` (the epoch scheduler otherwise skips reading
    heyoka's per-lane results every epoch; the stream scheduler always counts).
    ``progress``: a callable f(k), called with k = PROGRESS_EVERY each time
    that many more orbits of the chunk have started, so long chunks show
    progress.
    """
    ics = np.ascontiguousarray(ics, dtype=float)
    traj_ids = np.asarray(traj_ids, dtype=np.int64)
    outside = ics[:, 0] ** 2 + ics[:, 1] ** 2 >= scene.r_esc**2
    if outside.any():  # region 'square' (or an IC table): escaped at t = 0, not integrated
        return _with_escaped_at_start(scene, ics, traj_ids, outside, batch_size, count_steps, progress)
    kind = scheduler(scene)
    B = int(batch_size or scene.batch_size or (EPOCH_BATCH if kind == "epochs" else STREAM_BATCH))
    phases = kind == "stream" and events.two_phase(scene)
    orig, (scene, late) = scene, _no_return(scene, ics, kind)  # the integration's scene: maybe an earlier far event
    # first (or only) phase: without the section event when the window opens late
    with _batch_integrator(scene, B, without=("section",) if phases else ()) as (ta, specs, layout):
        lanes = (_Epochs if kind == "epochs" else _Stream)(scene, ta, layout, ics)
        lanes.count_steps = count_steps
        lanes.progress = progress
        lanes.migrate_at_open = phases
        lanes.late = late
        # the inlined handlers serve stream scenes with no section event in this integrator and no follow
        use_inlined = kind == "stream" and scene.follow is None and (scene.sections is None or phases)
        inlined = lanes.inlined_handlers() if use_inlined else {}
        _bind(ta, specs, lanes, inlined)
        try:
            n_returns, n_steps, (s_ids, s_t, s_e) = lanes.run()
        finally:
            lanes.__dict__.pop("load", None)  # the inlined path's closure refers back to the lanes: free them now
            # the integrator goes back to the cache: no view of it stays here
            lanes.ta = lanes.state = lanes.cols = lanes.pars = lanes.time_hi = lanes.time_lo = None
    if phases and lanes.migrants:  # second phase: the orbits alive at t_from, with the section event
        with _batch_integrator(scene, B) as (ta2, specs2, _):
            second = _SecondPhase(scene, ta2, layout, lanes)
            second.late = late
            _bind(ta2, specs2, second)
            try:
                r2, s2, _ = second.run()
            finally:
                second.ta = second.state = second.cols = second.pars = second.time_hi = second.time_lo = None
        n_returns, n_steps = n_returns + r2, n_steps + s2
    outcome = np.array(lanes.outcome, dtype=np.int8)
    if (outcome == -1).any():
        raise RuntimeError("internal error: some orbits of the chunk have no outcome")
    res = _chunk_result(scene, lanes, ics, traj_ids, outcome, (s_ids, s_t, s_e), n_returns, n_steps)
    rerun = outcome == RERUN
    if rerun.any():  # decided at the no-return radius too close to t_max: the scene's own rule decides
        res = _merge_rerun(res, rerun, traj_ids, run_chunk(_own_far(orig), ics[rerun], traj_ids[rerun],
                                                           batch_size=batch_size, count_steps=count_steps))
    return res


def _chunk_result(scene, lanes, ics, traj_ids, outcome, snaps, n_returns, n_steps) -> ChunkResult:
    """The chunk's rows from its lanes: lifetimes in orbit order, the other tables by orbit, then time."""
    n, (s_ids, s_t, s_e) = len(ics), snaps
    model = scene.model
    end = np.array(lanes.end_state, dtype=float).reshape(n, 4)
    t_end = np.array(lanes.t_end, dtype=float)
    channel = np.where(outcome == ESCAPED, model.exit_channel(end[:, 0], end[:, 1]), -1)
    lifetimes = {
        "traj_id": traj_ids,
        "x0": ics[:, 0].copy(),
        "y0": ics[:, 1].copy(),
        "px0": ics[:, 2].copy(),
        "py0": ics[:, 3].copy(),
        "e0": model.energy(ics[:, 0], ics[:, 1], ics[:, 2], ics[:, 3]),
        "gamma": np.full(n, scene.gamma),
        "outcome": outcome,
        "t_end": t_end,
        "exit_channel": channel.astype(np.int8),
        "e_end": model.energy(end[:, 0], end[:, 1], end[:, 2], end[:, 3]),
    }
    sections = _rows_to_columns(lanes.sec_rows, SECTION_COLUMNS, traj_ids)
    crossings = _rows_to_columns(lanes.cross_rows, CROSSING_COLUMNS, traj_ids)
    crossings["direction"] = crossings["direction"].astype(np.int8)
    order = np.lexsort((s_t, s_ids))
    snapshots = {"traj_id": traj_ids[s_ids[order]], "t": s_t[order], "energy": s_e[order]}
    return ChunkResult(lifetimes, sections, snapshots, crossings, n_returns=n_returns, n_steps=int(n_steps))


def _own_far(scene):
    """The scene with its own far radius written out: integrated under the scene's rule, not the no-return one."""
    return scene.replace(r_far=events.far_radius(scene))


def _no_return(scene, ics, kind):
    """_no_return(scene, ics, kind) -> (scene to integrate, late): the no-return rule of dissipative scenes.

    An escaped dissipative orbit is decided at its last outward r_esc crossing (t_end, its state); the scene
    follows it on to r_far = max(10 r_s, 2 r_esc) only to know that no crossing comes after. The system's
    no-return radius R(E) (:meth:`hhscatter.model.base.System.no_return_radius`) proves that earlier: an
    orbit of energy ≤ E at r ≥ R with ṙ > 0 never returns, under either drag law. With E the largest
    initial energy of the chunk (the energy only falls), the far event moves to max(R(E), (1 + 1 %) r_esc),
    rounded up to r_s/8 (so that chunks share one compiled integrator); the outcome, t_end and end state are
    the same at either radius, and no recorded row lies after t_end.

    The one thing r_far still decides: an orbit that has not reached r_far by t_max is censored there.
    ``late(t, state)`` tells at the no-return radius whether that can happen; such an orbit is rerun with the
    scene's own far event (exactly as before: tables byte-identical for the same scene hash). A censored orbit
    never reached R, so its steps are the same under either far event (the clock censors it in orbit time, a
    stream lane's history does not enter). The bound: beyond
    R the radial force is outward, so with the linear drag ṗ_r ≥ −γ p_r, p_r(t) ≥ p_r e^{−γτ}, and r_far is
    reached within τ = −ln(1 − γ(r_far − r)/p_r)/γ (taken with 1 % and 1e-6 of slack); an orbit for which
    that is infinite or ends after t_max is late. Applies to linear drag with the default r_far (a scene with
    an explicit ``r_far`` keeps it, so does quadratic drag, for which no such bound is written down).
    """
    m = scene.model
    if scene.gamma <= 0 or scene.r_far is not None or m.dissipation != "linear" or not len(ics):
        return scene, None
    r_far = events.far_radius(scene)
    e0 = float(np.max(m.energy(ics[:, 0], ics[:, 1], ics[:, 2], ics[:, 3])))
    grid = NO_RETURN_GRID * m.saddle_radius
    R = max(m.no_return_radius(e0 + 1e-12 * abs(e0)) * (1.0 + 1e-9), float(scene.r_esc) * (1.0 + NO_RETURN_MARGIN))
    R = math.ceil(R / grid) * grid
    if R >= r_far:
        return scene, None
    gamma, t_max = float(scene.gamma), float(scene.t_max)

    def late(t, state):
        x, y, px, py = state
        r = math.sqrt(x * x + y * y)
        pr = (x * px + y * py) / r
        a = gamma * (r_far - r)
        if not pr > 0.0 or a >= 0.999 * pr:
            return True
        return t + 1.01 * (-math.log1p(-a / pr) / gamma) + 1e-9 * t_max + 1e-6 >= t_max

    return scene.replace(r_far=R), late


def _merge_rerun(res, rerun, traj_ids, again):
    """res with the orbits ``rerun`` (mask over the chunk) replaced by their rerun ``again``: lifetimes
    entries overwritten, their rows of the other tables taken from ``again``, rows kept in (orbit, t) order."""
    for col, v in res.lifetimes.items():
        v[rerun] = again.lifetimes[col]
    srt = np.argsort(traj_ids, kind="stable")
    sorted_ids = traj_ids[srt]

    def local(ids):  # traj_id -> position in the chunk
        return srt[np.searchsorted(sorted_ids, ids)]

    tables = {}
    for name in ("sections", "snapshots", "crossings"):
        a, b = getattr(res, name), getattr(again, name)
        keep = ~rerun[local(a["traj_id"])]
        cols = {c: np.concatenate([a[c][keep], b[c].astype(a[c].dtype)]) for c in a}
        order = np.lexsort((cols["t"], local(cols["traj_id"])))
        tables[name] = {c: v[order] for c, v in cols.items()}
    return ChunkResult(res.lifetimes, tables["sections"], tables["snapshots"], tables["crossings"],
                       n_returns=res.n_returns + again.n_returns, n_steps=res.n_steps + again.n_steps)


def _with_escaped_at_start(scene, ics, traj_ids, outside, batch_size, count_steps, progress):
    """run_chunk for a chunk with orbits that start at r ≥ r_esc: those are escaped at t = 0
    (the authors' square ICs); the others run as usual. Rows keep traj_id order."""
    inside = ~outside
    model = scene.model
    if inside.any():
        res = run_chunk(scene, ics[inside], traj_ids[inside], batch_size=batch_size, count_steps=count_steps,
                        progress=progress)
    else:
        res = ChunkResult({}, _rows_to_columns([], SECTION_COLUMNS, traj_ids),
                          _rows_to_columns([], ("traj_id", "t", "energy"), traj_ids),
                          _rows_to_columns([], CROSSING_COLUMNS, traj_ids))
        res.crossings["direction"] = res.crossings["direction"].astype(np.int8)
    x, y, px, py = ics.T
    lt = {
        "traj_id": traj_ids, "x0": x.copy(), "y0": y.copy(), "px0": px.copy(), "py0": py.copy(),
        "e0": model.energy(x, y, px, py), "gamma": np.full(len(ics), scene.gamma),
        "outcome": np.full(len(ics), ESCAPED, np.int8), "t_end": np.zeros(len(ics)),
        "exit_channel": model.exit_channel(x, y).astype(np.int8), "e_end": model.energy(x, y, px, py),
    }
    if inside.any():
        for col in ("outcome", "t_end", "exit_channel", "e_end"):
            lt[col][inside] = res.lifetimes[col]
    snaps = res.snapshots
    if scene.snapshots and scene.snapshots[0] == 0.0:  # a snapshot at t = 0 ≤ t_end of the escaped ones
        ids = np.concatenate([snaps["traj_id"], traj_ids[outside]])
        t = np.concatenate([snaps["t"], np.zeros(int(outside.sum()))])
        e = np.concatenate([snaps["energy"], lt["e0"][outside]])
        order = np.lexsort((t, ids))
        snaps = {"traj_id": ids[order], "t": t[order], "energy": e[order]}
    return ChunkResult(lt, res.sections, snaps, res.crossings, n_returns=res.n_returns, n_steps=res.n_steps)


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
    """Result of :func:`simulate_orbit` (times and states in the integrator's precision)."""

    outcome: int
    t_end: object
    state_end: np.ndarray
    sections: list = field(default_factory=list)  # (t, x, y, px, py, energy), window rules applied
    snapshots: list = field(default_factory=list)  # (t, state)
    crossings: list = field(default_factory=list)  # (t, radius, direction)
    n_steps: int = 0


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

    def record(self, lane, outcome, t, state):
        self.result = (outcome, t, np.array(state))

    def release(self, lane):
        self.commit(lane, self.result[1], self.phase[lane] == CONTINUING)
        self.orbit[lane] = -1
        return False


def simulate_orbit(scene, ic, *, fp_type=float, tol=None) -> OrbitResult:
    """simulate_orbit(scene, ic, fp_type=float, tol=None) -> OrbitResult.

    One orbit on heyoka's scalar integrator, time from 0, with the scene's
    events and outcome rules (:mod:`hhscatter.integrate.events`) and the t_max bound:
    the straightforward driver the batch engine is tested against.
    ``fp_type`` may be ``numpy.longdouble`` or ``heyoka.real128`` for a
    high-precision reference (tolerance then defaults to that type's
    epsilon). Snapshots at ``scene.snapshots`` come from stopping at each
    time (so its steps differ from the engine's, as a reference's should).
    """
    import heyoka as hy  # deferred: heyoka loads on first use

    ic = np.asarray(ic, dtype=float)
    if ic[0] ** 2 + ic[1] ** 2 >= scene.r_esc**2:  # starts beyond r_esc: escaped at t = 0
        snaps = [(0.0, ic.copy())] if scene.snapshots and scene.snapshots[0] == 0.0 else []
        return OrbitResult(ESCAPED, 0.0, ic.copy(), [], snaps, [], 0)
    ta, specs, layout = events.build_scalar(scene, _Callback, fp_type=fp_type, tol=tol)
    rules = _Scalar(scene, ta, layout, fp_type)
    _bind(ta, specs, rules)
    cast = caster(fp_type)
    st = np.zeros(layout.n_state)
    st[:4] = np.asarray(ic, dtype=float)
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
    outcome, t_end, state = rules.result
    if scene.snapshots and not (outcome == SETTLED and scene.continue_settled):
        snaps = [s for s in snaps if s[0] <= t_end]
    secs = [r[1:] for r in rules.sec_rows]
    cross = [r[1:] for r in rules.cross_rows]
    return OrbitResult(outcome, t_end, state, secs, snaps, cross, steps)


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


__all__ = ["LaneRules", "run_chunk", "simulate_orbit", "state_at", "scheduler", "ChunkResult", "OrbitResult", "OUTCOMES",
           "ESCAPED", "SETTLED", "CENSORED", "STOPPED"]
