"""The lane-rules contract: the outcome rules of :mod:`hhscatter.integrate.events` as event handlers, per lane.

:class:`LaneRules` holds the rules once; a scheduler (the stream's or the epochs' batch lanes,
:mod:`hhscatter.integrate.batch`, or the reference driver's one scalar orbit, :mod:`hhscatter.integrate.reference`)
subclasses it and supplies the integrator access. Event callbacks (:class:`Callback`) are bound to its handlers.
"""

from __future__ import annotations

import abc
import functools

from hhscatter.integrate import events
from hhscatter.integrate.events import CENSORED, ESCAPED, SETTLED, STOPPED

LIVE, FOLLOWING, CONTINUING = 0, 1, 2  # phase of the orbit in a lane
RERUN = -2  # outcome code inside a chunk: decided at the no-return radius too close to t_max; rerun to r_far


class _Callback:
    """An event's callback; heyoka deep-copies it, so its handler is bound afterwards (:func:`_bind`).

    Each callback is an instance of a class of its own, so that a handler with heyoka's signature
    (ta, direction, lane) can be bound as the class's ``__call__``: heyoka then calls it with no Python frame in
    between (the engine's hot handlers, :meth:`hhscatter.integrate.stream._Stream._inlined_handlers`)."""

    __slots__ = ("handler",)

    def __new__(cls, spec=None):
        if cls is _Callback:
            cls = type("_EventCallback", (_Callback,), {"__slots__": ()})
        return object.__new__(cls)

    def __init__(self, spec=None):
        self.handler = None

    def __call__(self, ta, d_sgn, lane=0):
        return self.handler(lane, d_sgn)


def _bind(ta, specs, rules, inlined=None):
    """Bind each event's callback to the handler of its rule: ``rules.handler(spec)``, a callable (lane,
    direction), or, for the rules in ``inlined`` ({rule: callable (ta, direction, lane)}), that callable as the
    callback itself."""
    for spec, ev in zip(specs, ta.t_events):
        cb = ev.callback
        if inlined and spec.rule in inlined:
            type(cb).__call__ = staticmethod(inlined[spec.rule])
        else:
            cb.handler = rules.handler(spec)


def _unbind(ta):
    """Break the cycle integrator → callbacks → rules → integrator (heyoka's objects are
    invisible to Python's cycle collector: without this every chunk's integrator stayed alive)."""
    for ev in ta.t_events:
        cb = ev.callback
        cb.handler = None
        if type(cb) is not _Callback and "__call__" in type(cb).__dict__:
            del type(cb).__call__


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
    def record(self, lane: int, outcome: int, t: float, state, stretch=None) -> None:
        """Record the orbit's outcome (a code of :mod:`hhscatter.outcomes`), its end time and end state; with the
        tangent dynamics also its log-stretch Λ there (``stretch``; None: the lane's now)."""

    def stretch(self, lane: int):
        """The log-stretch Λ of ``lane`` now (None without the tangent dynamics)."""
        return None

    @abc.abstractmethod
    def release(self, lane: int) -> bool:
        """The orbit of ``lane`` needs nothing more: load the next orbit, park the lane, or stop.

        Returns what the event callback returns (False stops the propagation).
        """

    #: None, or f(t, state) -> True when an orbit at the no-return far radius might not have reached the
    #: scene's r_far by t_max (run_chunk's no-return rule: the orbit is then rerun to r_far)
    late = None
    #: True in the first phase of a two-phase scene: orbits are handed on when the window opens (``migrants``)
    migrate_at_open = False

    def handler(self, spec):
        """handler(spec) -> the callable (lane, direction) -> continue? of the event ``spec``'s rule."""
        rules = {
            "escape": self.on_escape,
            "closure": self.on_closure,
            "far": self.on_far,
            "resc": self.on_resc,
            "radius": self.on_radius,
            "section": self.on_section,
            "clock": self.on_clock,
        }
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
        self.radii = scene.follow_radii
        self.r_esc = float(scene.r_esc)
        self.continue_settled = bool(scene.continue_settled)
        self.targets = scene.clock_targets
        self.clock_scale = layout.clock_scale
        self.orbit = [-1] * n_lanes
        self.phase = [LIVE] * n_lanes
        self.last_out = [None] * n_lanes
        self.sec_found = [False] * n_lanes
        self.clock_i = [0] * n_lanes
        self.pending_sec = [[] for _ in range(n_lanes)]
        self.pending_cross = [[] for _ in range(n_lanes)]
        self.sec_rows, self.cross_rows = [], []
        self.migrants = []
        #: None, or per orbit of the chunk: its section window opens at T_INITIAL (events.opens_late)
        self.open_late = None

    def last_out_of(self, lane):
        """The last outward r_esc crossing of the orbit in ``lane``: (orbit time, state, Λ or None), or None."""
        return self.last_out[lane]

    def start_orbit(self, lane, k):
        """Per-orbit rule state at load; sets the section gate and the clock."""
        self.orbit[lane] = k
        self.phase[lane] = LIVE
        self.last_out[lane] = None
        self.sec_found[lane] = False
        self.clock_i[lane] = 0
        if self.pending_sec[lane]:  # (empty but after an orbit that left rows uncommitted)
            self.pending_sec[lane] = []
        if self.pending_cross[lane]:
            self.pending_cross[lane] = []
        if self.win is not None:
            self.set_gate(lane, 1.0 if self.win.t_from <= 0 else 0.0)
        if self.targets:
            self.set_clock(lane, self.targets[0][0] / self.clock_scale)
        if self.open_late is not None and self.open_late[k]:  # the clock opens the window at T_INITIAL
            self.set_gate(lane, 0.0)
            self.clock_i[lane] = -1
            self.set_clock(lane, events.T_INITIAL / self.clock_scale)

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

    def end(self, lane, outcome, t, state, stretch=None):
        """The orbit's outcome is known: record it; release the lane unless the scene follows on."""
        self.record(lane, outcome, t, state, stretch)
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
            if self.late is not None and self.late(self.elapsed(lane), *self.state4(lane)):
                return self.end(lane, RERUN, *self.last_out[lane])
            return self.end(lane, ESCAPED, *self.last_out[lane])
        return self.release(lane)  # a followed orbit is gone

    def on_resc(self, lane, d):
        if self.orbit[lane] >= 0 and self.phase[lane] == LIVE:
            self.last_out[lane] = (self.elapsed(lane), self.state4(lane), self.stretch(lane)) if d > 0 else None
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
        if i < 0:  # T_INITIAL of an orbit whose window opens late (events.opens_late)
            i = 0
            self.set_gate(lane, 1.0)
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
                    self.migrants.append(
                        (self.orbit[lane], self.state4(lane), t, i + 1, self.last_out_of(lane), self.phase[lane])
                    )
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
